// PNG via stb (libstb.so already holds the implementations, so no STB_*_IMPLEMENTATION here),
// JPEG via libjpeg-turbo and EXR via OpenEXR. Every writer goes through write_atomically (temp
// file + rename).
#include "follicle/image/image_io.hpp"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <jerror.h>
#include <jpeglib.h>
#include <stb_image.h>
#include <stb_image_write.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <csetjmp>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "follicle/core/atomic_file.hpp"
#include "follicle/core/resources.hpp"

namespace follicle::image {
namespace {

// Resource guard: a header may declare any size; a 40-byte file claiming 40000 x 40000 pixels
// made the decoder allocate gigabytes before it found the data missing. Images are refused above
// 2^28 pixels (16384 x 16384, far beyond any texture or map Follicle uses) and whenever the decoded
// image would not fit in the available memory.
constexpr long long kMaxImagePixels = 1LL << 28;

void check_image_size(const std::string& where, long long w, long long h, int channels,
                      int bytes_per_channel, const char* format) {
  if (w <= 0 || h <= 0) fail_at(where, "{} image size {}x{} is invalid", format, w, h);
  // In double: an EXR window of two 32-bit spans reaches 2^64 pixels, past long long (found by
  // fuzz/fuzz_exr: signed overflow, fuzz/regressions/exr/window_product_overflow.exr).
  if (double(w) * double(h) > double(kMaxImagePixels))
    fail_at(where,
            "{} image is {}x{} ({} pixels); Follicle reads images of at most {} pixels "
            "(16384x16384)",
            format, w, h, format_count(double(w) * double(h)),
            format_count(double(kMaxImagePixels)));
  // The decoder's buffer and our copy of it.
  check_memory(where, fmt::format("decoding the {}x{} {} image", w, h, format),
               2.0 * double(w) * double(h) * channels * bytes_per_channel, "");
}

struct StbFree {
  void operator()(unsigned char* p) const { stbi_image_free(p); }
};

// JPEG is decoded by libjpeg-turbo, not stb. stb_image (Debian's 2022 snapshot) wrote past its
// Huffman size table for a DHT segment of more than 256 codes (fuzz/fuzz_png, first campaign);
// the guard that walked the markers before stb was bypassed in the third campaign by a file in
// which stb resynchronised on bytes between segments that the walk stopped at
// (fuzz/regressions/png/stb_jpeg_resync_huffman_overflow.jpg). libjpeg-turbo is the reference
// decoder, fuzzed continuously by OSS-Fuzz, and checks its tables itself.
//
// libjpeg reports fatal errors through error_exit, which must not return: it longjmps back into
// the function that called the library. To keep that defined in C++, the setjmp sits in small
// functions (jpeg_read_header_guarded, jpeg_decode_guarded) whose own locals are never touched
// after it, the state the error path reads lives in the caller's JpegState, and no object with
// a destructor is created between setjmp and the library calls.
constexpr int kMaxJpegScans = 1000;  // progressive files with endless scans decode for minutes

struct JpegState {
  jpeg_decompress_struct cinfo{};
  jpeg_error_mgr err{};
  jpeg_progress_mgr progress{};
  std::jmp_buf jump{};
  char message[JMSG_LENGTH_MAX] = {};
  JpegState() = default;
  JpegState(const JpegState&) = delete;
  JpegState& operator=(const JpegState&) = delete;
  ~JpegState() { jpeg_destroy_decompress(&cinfo); }
};

JpegState& jpeg_state(j_common_ptr c) {
  return *reinterpret_cast<JpegState*>(c->client_data);
}

[[noreturn]] void jpeg_fatal(j_common_ptr c) {
  JpegState& st = jpeg_state(c);
  (*c->err->format_message)(c, st.message);
  std::longjmp(st.jump, 1);
}

void jpeg_message(j_common_ptr c, int level) {
  // A truncated file is an error (libjpeg would fill the rest with grey and warn); other
  // warnings (stray bytes between markers and the like) are tolerated as every viewer does.
  if (level == -1 && c->err->msg_code == JWRN_JPEG_EOF) jpeg_fatal(c);
}

void jpeg_progress(j_common_ptr c) {
  const auto* d = reinterpret_cast<j_decompress_ptr>(c);
  if (d->input_scan_number > kMaxJpegScans) {
    JpegState& st = jpeg_state(c);
    std::snprintf(st.message, sizeof st.message,
                  "more than %d scans (a progressive JPEG is made of at most a few dozen)",
                  kMaxJpegScans);
    std::longjmp(st.jump, 1);
  }
}

bool jpeg_read_header_guarded(JpegState& st, const std::string& bytes) {
  if (setjmp(st.jump)) return false;
  st.cinfo.client_data = &st;  // kept by jpeg_create_decompress
  jpeg_create_decompress(&st.cinfo);
  st.progress.progress_monitor = jpeg_progress;
  st.cinfo.progress = &st.progress;
  jpeg_mem_src(&st.cinfo, reinterpret_cast<const unsigned char*>(bytes.data()),
               static_cast<unsigned long>(bytes.size()));
  jpeg_read_header(&st.cinfo, TRUE);
  return true;
}

// Decodes into `out` (width * height * channels bytes, already sized) as grey, RGBA or, for
// CMYK/YCCK files, CMYK that the caller converts.
bool jpeg_decode_guarded(JpegState& st, J_COLOR_SPACE space, unsigned char* out,
                         std::size_t row_bytes) {
  if (setjmp(st.jump)) return false;
  st.cinfo.out_color_space = space;
  jpeg_start_decompress(&st.cinfo);
  while (st.cinfo.output_scanline < st.cinfo.output_height) {
    JSAMPROW row = out + std::size_t(st.cinfo.output_scanline) * row_bytes;
    jpeg_read_scanlines(&st.cinfo, &row, 1);
  }
  jpeg_finish_decompress(&st.cinfo);
  return true;
}

template <int C>
Image<uint8_t, C> read_jpeg(const std::string& bytes, const std::string& where) {
  static_assert(C == 1 || C == 4);
  JpegState st;
  st.cinfo.err = jpeg_std_error(&st.err);
  st.err.error_exit = jpeg_fatal;
  st.err.emit_message = jpeg_message;
  if (!jpeg_read_header_guarded(st, bytes)) fail_at(where, "cannot decode JPEG: {}", st.message);
  const long long w = st.cinfo.image_width, h = st.cinfo.image_height;
  const bool cmyk = st.cinfo.jpeg_color_space == JCS_CMYK || st.cinfo.jpeg_color_space == JCS_YCCK;
  check_image_size(where, w, h, cmyk ? 4 : C, 1, "JPEG");
  Image<uint8_t, C> img(static_cast<int>(w), static_cast<int>(h));
  if (!cmyk) {
    if (!jpeg_decode_guarded(st, C == 1 ? JCS_GRAYSCALE : JCS_EXT_RGBA, img.data(),
                             std::size_t(w) * C))
      fail_at(where, "cannot decode JPEG: {}", st.message);
    return img;
  }
  // CMYK (print) JPEGs: libjpeg gives C, M, Y, K; files with an Adobe marker store them
  // inverted (as Photoshop writes them). RGB = (1 - C)(1 - K) etc. on the non-inverted values.
  std::vector<unsigned char> raw(std::size_t(w) * std::size_t(h) * 4);
  if (!jpeg_decode_guarded(st, JCS_CMYK, raw.data(), std::size_t(w) * 4))
    fail_at(where, "cannot decode JPEG: {}", st.message);
  const bool inverted = st.cinfo.saw_Adobe_marker;
  for (std::size_t i = 0; i < std::size_t(w) * std::size_t(h); ++i) {
    int ch[4];
    for (int k = 0; k < 4; ++k) ch[k] = inverted ? raw[4 * i + k] : 255 - raw[4 * i + k];
    const int r = ch[0] * ch[3] / 255, g = ch[1] * ch[3] / 255, b = ch[2] * ch[3] / 255;
    if constexpr (C == 1) {
      img.data()[i] = uint8_t((77 * r + 150 * g + 29 * b) >> 8);
    } else {
      img.data()[4 * i] = uint8_t(r);
      img.data()[4 * i + 1] = uint8_t(g);
      img.data()[4 * i + 2] = uint8_t(b);
      img.data()[4 * i + 3] = 255;
    }
  }
  return img;
}

// The PNG chunk list is walked before stb sees the file, in step with stb (which reads every chunk
// by its declared length, then its CRC, and stops at IEND):
// - a chunk declaring more bytes than the file has left is refused: stb grows its IDAT buffer to
//   the declared length before reading (164 bytes declared a 2 GB IDAT; found by fuzz/fuzz_png,
//   fuzz/regressions/png/stb_idat_larger_than_file.png);
// - zero-length IDAT chunks are dropped: before any other, stb computes `nullptr + 0` for one
//   (undefined behaviour; fuzz/regressions/png/stb_empty_first_idat.png), and they add nothing to
//   the image's zlib stream.
// Returns the bytes unchanged when there is nothing to drop (no copy in the common case).
std::string checked_png_chunks(const std::string& b, const std::string& where) {
  auto be32 = [&](std::size_t at) {
    return (uint32_t(uint8_t(b[at])) << 24) | (uint32_t(uint8_t(b[at + 1])) << 16) |
           (uint32_t(uint8_t(b[at + 2])) << 8) | uint32_t(uint8_t(b[at + 3]));
  };
  std::vector<std::size_t> empty_idat;
  std::size_t pos = 8;
  while (pos + 8 <= b.size()) {
    const std::size_t len = be32(pos);
    std::string type = b.substr(pos + 4, 4);
    if (type == "IEND") break;  // stb stops here (and reads no CRC)
    for (char& c : type)
      if (!std::isalnum(static_cast<unsigned char>(c))) c = '?';
    if (len > 0x7fffffffu)
      fail_at(where, "PNG chunk '{}' at byte {} declares {} bytes (at most 2^31 - 1)", type, pos,
              len);
    const std::size_t left = b.size() - pos;  // >= 8 here
    if (len + 12 > left)
      fail_at(where,
              "PNG chunk '{}' at byte {} declares {} bytes but the file has {} left "
              "(truncated?)",
              type, pos, len, left >= 12 ? left - 12 : 0);
    if (type == "IDAT" && len == 0) empty_idat.push_back(pos);
    pos += 12 + len;
  }
  if (empty_idat.empty()) return b;
  std::string out;
  out.reserve(b.size());
  std::size_t from = 0;
  for (const std::size_t at : empty_idat) {
    out.append(b, from, at - from);
    from = at + 12;
  }
  out.append(b, from, std::string::npos);
  return out;
}

template <int C>
Image<uint8_t, C> read_png_stb(const std::string& bytes, const std::string& where) {
  int w = 0, h = 0, n = 0;
  if (stbi_info_from_memory(reinterpret_cast<const stbi_uc*>(bytes.data()), int(bytes.size()), &w,
                            &h, &n))
    check_image_size(where, w, h, C, 1, "PNG");
  std::unique_ptr<unsigned char, StbFree> px(stbi_load_from_memory(
      reinterpret_cast<const stbi_uc*>(bytes.data()), int(bytes.size()), &w, &h, &n, C));
  if (!px) {
    fail_at(where, "cannot decode PNG ({})",
            stbi_failure_reason() ? stbi_failure_reason() : "unknown error");
  }
  Image<uint8_t, C> img(w, h);
  std::copy(px.get(), px.get() + img.storage().size(), img.data());
  return img;
}

template <int C>
Image<uint8_t, C> read_stb(const std::filesystem::path& path) {
  const std::string bytes = read_file(path);
  if (bytes.empty()) fail_at(path.string(), "empty file, expected a PNG or JPEG image");
  if (bytes.size() > std::size_t(INT32_MAX)) fail_at(path.string(), "file too large");
  // Only the formats Follicle documents: stb also decodes TGA, BMP, PSD, GIF, HDR, PIC and PNM,
  // and a 120-byte file taken for an RLE TGA of 65496 x 224 pixels decoded for seconds (found by
  // fuzz/fuzz_png; fuzz/regressions/png/tga_decompression_bomb.bin).
  const bool png = bytes.size() >= 8 && bytes.compare(0, 8, "\x89PNG\r\n\x1a\n") == 0;
  const bool jpeg = bytes.size() >= 3 && bytes.compare(0, 3, "\xff\xd8\xff") == 0;
  if (!png && !jpeg)
    fail_at(path.string(),
            "not a PNG or JPEG file (it starts with neither the PNG signature nor a JPEG start "
            "of image)");
  if (jpeg) return read_jpeg<C>(bytes, path.string());
  return read_png_stb<C>(checked_png_chunks(bytes, path.string()), path.string());
}

template <int C>
void write_stb_png(const std::filesystem::path& path, const Image<uint8_t, C>& img) {
  if (img.empty()) fail_at(path.string(), "cannot write an empty image");
  // Encoded in memory, then written with every write checked (stbi_write_png's own file path
  // ignores fwrite/fclose errors and left truncated PNGs on a full disk).
  std::string bytes;
  const auto append = [](void* ctx, void* data, int size) {
    static_cast<std::string*>(ctx)->append(static_cast<const char*>(data), std::size_t(size));
  };
  if (!stbi_write_png_to_func(append, &bytes, img.width(), img.height(), C, img.data(),
                              img.width() * C) ||
      bytes.empty())
    fail_at(path.string(), "cannot encode PNG");
  write_file_atomically(path, bytes);
}

template <int C>
void write_exr_impl(const std::filesystem::path& path, const Image<float, C>& img,
                    const char* const* names) {
  if (img.empty()) fail_at(path.string(), "cannot write an empty image");
  write_atomically(path, [&](const std::filesystem::path& tmp) {
    try {
      Imf::Header header(img.width(), img.height());
      for (int c = 0; c < C; ++c) header.channels().insert(names[c], Imf::Channel(Imf::FLOAT));
      Imf::OutputFile file(tmp.string().c_str(), header);
      Imf::FrameBuffer fb;
      const std::size_t xs = sizeof(float) * C, ys = xs * std::size_t(img.width());
      for (int c = 0; c < C; ++c) {
        fb.insert(names[c], Imf::Slice(Imf::FLOAT, (char*)(img.data() + c), xs, ys));
      }
      file.setFrameBuffer(fb);
      file.writePixels(img.height());
    } catch (const Error&) {
      throw;
    } catch (const std::exception& e) {
      fail_at(path.string(), "cannot write EXR: {}", e.what());
    }
  });
}

// OpenEXR 3.1 allocates whatever size a header attribute declares before it notices the file
// is shorter (a 44-byte file took 10-33 s; found by fuzz/fuzz_exr, reproducers in
// fuzz/regressions/exr/). The attribute list is walked first: every declared size must fit in
// the file. The data window found on the way is checked against the image size guard before
// OpenEXR reads the line offsets or we allocate the pixels.
// Sizes of the attribute types OpenEXR 3.1 reads by content (Imf::TypedAttribute<T> with Xdr),
// ignoring the declared size; -1 for the others (string, opaque types and the ones checked
// separately).
int exr_fixed_attribute_size(const std::string& type) {
  static constexpr std::pair<std::string_view, int> kSizes[] = {
      {"box2i", 16},   {"box2f", 16},   {"compression", 1},    {"chromaticities", 32},
      {"double", 8},   {"envmap", 1},   {"deepImageState", 1}, {"float", 4},
      {"int", 4},      {"keycode", 28}, {"lineOrder", 1},      {"m33d", 72},
      {"m33f", 36},    {"m44d", 128},   {"m44f", 64},          {"rational", 8},
      {"tiledesc", 9}, {"timecode", 8}, {"v2d", 16},           {"v2f", 8},
      {"v2i", 8},      {"v3d", 24},     {"v3f", 12},           {"v3i", 12}};
  for (const auto& [name, size] : kSizes)
    if (type == name) return size;
  return -1;
}

void check_exr_header(const std::string& b, const std::string& where, int channels) {
  if (b.size() < 8 || b.compare(0, 4, "\x76\x2f\x31\x01") != 0)
    fail_at(where, "not an OpenEXR file (bad magic number)");
  // A multi-part file holds several headers, each ended by an empty name, and an empty header
  // after the last (a 177-byte multi-part file, unchecked before, took 20 s and gigabytes; found
  // by fuzz/fuzz_exr, fuzz/regressions/exr/multipart_attribute_size.exr).
  const bool multipart = (uint8_t(b[5]) & 0x10) != 0;
  // Names (attributes, their types, channels) are at most 31 characters, 255 with the long-names
  // flag; OpenEXR reads no further than that for a name, so a longer one would put it out of
  // step with this walk.
  const std::size_t max_name = (uint8_t(b[5]) & 0x04) != 0 ? 255 : 31;
  auto name_at = [&](std::size_t from, const char* what) {
    const std::size_t z = b.find('\0', from);
    if (z == std::string::npos) fail_at(where, "truncated EXR header");
    if (z - from > max_name)
      fail_at(where, "EXR {} at byte {} is longer than {} characters", what, from, max_name);
    return z;
  };
  // Per header: the data window, the channels' sample sizes and the compression, checked
  // together when the header ends.
  long long win_w = -1, win_h = -1;
  int compression = -1;
  struct Sampled {
    int bytes, xs, ys;
  };
  std::vector<Sampled> sampled;
  auto check_window = [&] {
    if (win_w < 0 || sampled.empty()) return;  // OpenEXR refuses a header without them
    // A decompression bomb: 268 bytes declared 16383753 x 7 pixels, which we would have
    // allocated (1.8 GB) and zeroed before OpenEXR found no data (found by fuzz/fuzz_exr;
    // fuzz/regressions/exr/window_larger_than_any_compression.exr), and 427 bytes declaring
    // 34 M pixels took 2 s and 0.5 GB (fuzz/regressions/exr/window_beyond_zip_ratio.exr). The
    // pixel data the channels hold (with their subsampling) cannot be packed tighter than the
    // compression allows: stored as is, RLE (64:1), zlib (ZIP, ZIPS, PXR24: 1032:1), PIZ
    // (Huffman with runs of 255: ~400:1), B44 (32:14), B44A (32:3); DWA codes 8x8 blocks by their
    // DC term and zlib, so a flat image can approach 66,000:1. Ratios with a margin:
    static constexpr double kMaxRatio[10] = {1, 80, 1500, 1500, 1500, 2000, 3, 12, 1e5, 1e5};
    // Without a compression attribute OpenEXR's default header applies: ZIP.
    const int kind = compression < 0 ? 3 : compression;
    const double ratio = kind < 10 ? kMaxRatio[kind] : 1e5;
    double least = 0;
    for (const Sampled& c : sampled)
      least += std::ceil(double(win_w) / std::max(1, c.xs)) *
               std::ceil(double(win_h) / std::max(1, c.ys)) * c.bytes;
    if (least > ratio * double(b.size()))
      fail_at(where,
              "EXR declares {}x{} pixels ({} of channel data) but holds only {} bytes; its "
              "compression packs at most {}:1",
              win_w, win_h, format_bytes(least), b.size(), ratio);
  };
  std::size_t pos = 8;
  for (int attr = 0;; ++attr) {
    const std::size_t name_end = name_at(pos, "attribute name");
    if (name_end == pos) {  // the empty name ends the header
      check_window();
      win_w = win_h = -1;
      compression = -1;
      sampled.clear();
      if (!multipart) return;
      ++pos;
      if (pos >= b.size()) fail_at(where, "truncated EXR header");
      if (b[pos] == '\0') return;  // the empty header ends the list
      continue;
    }
    const std::string name = b.substr(pos, std::min<std::size_t>(name_end - pos, 64));
    const std::size_t type_end = name_at(name_end + 1, "attribute type");
    if (type_end + 5 > b.size()) fail_at(where, "truncated EXR header (attribute {})", attr);
    int32_t size = 0;
    std::memcpy(&size, b.data() + type_end + 1, 4);  // little-endian, as the format
    pos = type_end + 5;
    if (size < 0 || std::size_t(size) > b.size() - pos)
      fail_at(where, "EXR header attribute \"{}\" declares {} bytes but the file has {} left", name,
              size, b.size() - pos);
    // OpenEXR parses a channel list and a preview by their content, not by the declared size,
    // and goes on reading where the content ends: a file whose declared size differs put OpenEXR
    // out of step with this walk and made it allocate a 221 MB "attribute" from the pixels that
    // followed (fuzz/regressions/exr/window_without_offsets.exr). Such files are refused.
    const std::string type = b.substr(name_end + 1, type_end - name_end - 1);
    if (type == "chlist") {
      std::size_t q = pos;
      const std::size_t end = pos + std::size_t(size);
      while (q < end && b[q] != '\0') {
        const std::size_t z = name_at(q, "channel name");
        if (z >= end || z + 17 > end) break;
        int32_t f[4];  // pixel type, pLinear + 3 reserved, x and y sampling
        std::memcpy(f, b.data() + z + 1, sizeof f);
        sampled.push_back({f[0] == 1 ? 2 : 4, f[2], f[3]});  // HALF = 1; UINT, FLOAT: 4 bytes
        q = z + 1 + 16;
      }
      // The list ends with an empty name in its last byte. (Before, a channel name left
      // unfinished in the last byte passed for that end, and OpenEXR read on past the declared
      // size into the next attributes: 106 bytes took 10 s and 1.6 GB; found by fuzz/fuzz_exr,
      // fuzz/regressions/exr/chlist_unfinished_name.exr.)
      if (q + 1 != end || b[q] != '\0')
        fail_at(where, "EXR channel list declares {} bytes but its channels take {}", size,
                q + 1 - pos);
    } else if (type == "preview") {
      uint32_t wh[2] = {0, 0};
      if (size >= 8) std::memcpy(wh, b.data() + pos, 8);
      if (size < 8 || double(wh[0]) * wh[1] * 4 + 8 != double(size))
        fail_at(where, "EXR preview image of {}x{} does not match its {} bytes", wh[0], wh[1],
                size);
    } else if (type == "stringvector") {
      // Strings of (int32 length, bytes) until the declared size; OpenEXR resizes each string to
      // its length before reading it, so every length must fit in what is left.
      std::size_t q = pos;
      const std::size_t end = pos + std::size_t(size);
      while (q < end) {
        int32_t n = -1;
        if (end - q >= 4) std::memcpy(&n, b.data() + q, 4);
        if (n < 0 || std::size_t(n) > end - q - 4)
          fail_at(where, "EXR string vector \"{}\" holds a string that runs past its {} bytes",
                  name, size);
        q += 4 + std::size_t(n);
      }
    } else if (type == "floatvector") {
      if (size % 4 != 0)
        fail_at(where, "EXR float vector \"{}\" of {} bytes is not a whole number of floats", name,
                size);
    } else if (const int fixed = exr_fixed_attribute_size(type); fixed >= 0 && size != fixed) {
      // OpenEXR reads these types by their content and ignores the declared size, so a size
      // that differs put it out of step with this walk: a `box2i` dataWindow declaring 111
      // bytes made it take the next 95 bytes for attributes and allocate a 1.6 GB string (13 s
      // in release; found by fuzz/fuzz_exr, fuzz/regressions/exr/box_size_mismatch.exr).
      fail_at(where, "EXR attribute \"{}\" of type {} declares {} bytes; that type has {}", name,
              type, size, fixed);
    }
    if (name == "dataWindow" && size == 16) {
      int32_t box[4];  // xmin, ymin, xmax, ymax
      std::memcpy(box, b.data() + pos, sizeof box);
      win_w = (long long)box[2] - box[0] + 1;
      win_h = (long long)box[3] - box[1] + 1;
      check_image_size(where, win_w, win_h, channels, int(sizeof(float)), "EXR");
    }
    if (name == "compression" && size == 1) compression = uint8_t(b[pos]);
    pos += std::size_t(size);
  }
}

/// Reads the named channels (first match of each alternative list) into a float image;
/// channels that are absent are filled with `fill[c]`.
template <int C>
Image<float, C> read_exr_impl(const std::filesystem::path& path,
                              const std::vector<std::vector<std::string>>& wanted,
                              const float* fill) {
  if (!std::filesystem::exists(path)) fail_at(path.string(), "cannot open: no such file");
  check_exr_header(read_file(path), path.string(), C);
  try {
    Imf::InputFile file(path.string().c_str());
    const Imath::Box2i dw = file.header().dataWindow();
    const long long w = (long long)dw.max.x - dw.min.x + 1;
    const long long h = (long long)dw.max.y - dw.min.y + 1;
    if (w <= 0 || h <= 0) fail_at(path.string(), "EXR data window {}x{} is invalid", w, h);
    check_image_size(path.string(), w, h, C, int(sizeof(float)), "EXR");
    // Before the pixels are allocated: a 132-byte file without its line offsets declared a
    // window of ~2^28 pixels and had 4 GB zeroed before isComplete() refused it (found by
    // fuzz/fuzz_exr; fuzz/regressions/exr/window_without_offsets.exr).
    if (!file.isComplete()) fail_at(path.string(), "EXR file is incomplete (truncated)");
    Image<float, C> img{int(w), int(h)};
    Imf::FrameBuffer fb;
    const std::size_t xs = sizeof(float) * C, ys = xs * std::size_t(w);
    bool any = false;
    for (int c = 0; c < C; ++c) {
      std::string found;
      for (const auto& name : wanted[std::size_t(c)]) {
        if (file.header().channels().findChannel(name)) {
          found = name;
          break;
        }
      }
      if (!found.empty()) any = true;
      // The base pointer is offset so that (dw.min.x, dw.min.y) lands on pixel (0, 0).
      char* base = (char*)(img.data() + c) - std::ptrdiff_t(dw.min.x) * std::ptrdiff_t(xs) -
                   std::ptrdiff_t(dw.min.y) * std::ptrdiff_t(ys);
      fb.insert(found.empty() ? wanted[std::size_t(c)][0] : found,
                Imf::Slice(Imf::FLOAT, base, xs, ys, 1, 1, double(fill[c])));
    }
    if (!any) fail_at(path.string(), "EXR has none of the expected channels (Y or R,G,B,A)");
    file.setFrameBuffer(fb);
    file.readPixels(dw.min.y, dw.max.y);
    return img;
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    fail_at(path.string(), "cannot read EXR: {}", e.what());
  }
}

}  // namespace

ImageRGBA8 read_png_rgba(const std::filesystem::path& path) {
  return read_stb<4>(path);
}
ImageGray8 read_png_gray(const std::filesystem::path& path) {
  return read_stb<1>(path);
}
void write_png(const std::filesystem::path& path, const ImageRGBA8& img) {
  write_stb_png(path, img);
}
void write_png(const std::filesystem::path& path, const ImageRGB8& img) {
  write_stb_png(path, img);
}
void write_png(const std::filesystem::path& path, const ImageGray8& img) {
  write_stb_png(path, img);
}

ImageF read_exr_gray(const std::filesystem::path& path) {
  const float fill[1] = {0.f};
  return read_exr_impl<1>(path, {{"Y", "R", "Z", "H"}}, fill);
}
ImageRGBAF read_exr_rgba(const std::filesystem::path& path) {
  const float fill[4] = {0.f, 0.f, 0.f, 1.f};
  return read_exr_impl<4>(path, {{"R", "Y"}, {"G", "Y"}, {"B", "Y"}, {"A"}}, fill);
}
void write_exr(const std::filesystem::path& path, const ImageF& img) {
  static constexpr const char* kNames[] = {"Y"};
  write_exr_impl(path, img, kNames);
}
void write_exr(const std::filesystem::path& path, const ImageRGBF& img) {
  static constexpr const char* kNames[] = {"R", "G", "B"};
  write_exr_impl(path, img, kNames);
}
void write_exr(const std::filesystem::path& path, const ImageRGBAF& img) {
  static constexpr const char* kNames[] = {"R", "G", "B", "A"};
  write_exr_impl(path, img, kNames);
}

ImageF read_gray_map(const std::filesystem::path& path) {
  auto ext = path.extension().string();
  for (auto& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".exr") return read_exr_gray(path);
  const ImageGray8 g = read_png_gray(path);
  ImageF out(g.width(), g.height());
  for (int y = 0; y < g.height(); ++y)
    for (int x = 0; x < g.width(); ++x) out.at(x, y) = float(g.at(x, y)) / 255.0f;
  return out;
}

}  // namespace follicle::image
