// PNG/JPEG via stb (libstb.so already holds the implementations, so no STB_*_IMPLEMENTATION
// here) and EXR via OpenEXR. Every writer goes through write_atomically (temp file + rename).
#include "follicle/image/image_io.hpp"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <stb_image.h>
#include <stb_image_write.h>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <exception>
#include <memory>
#include <string>

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
  if (w * h > kMaxImagePixels)
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

// stb_image (Debian's 2022 snapshot) writes past its Huffman size table when a JPEG's DHT
// segment declares more than 256 codes (found by fuzz/fuzz_png, reproducer in
// fuzz/regressions/png/). Walks the JPEG markers up to the scan and refuses such tables first.
void check_jpeg_huffman_tables(const std::string& b, const std::string& where) {
  if (b.size() < 4 || uint8_t(b[0]) != 0xFF || uint8_t(b[1]) != 0xD8) return;  // not a JPEG
  std::size_t pos = 2;
  while (pos + 4 <= b.size()) {
    if (uint8_t(b[pos]) != 0xFF) return;  // stb reports the corruption itself
    const uint8_t marker = uint8_t(b[pos + 1]);
    if (marker == 0xFF) {  // fill byte
      ++pos;
      continue;
    }
    if (marker == 0xD8 || (marker >= 0xD0 && marker <= 0xD7) || marker == 0x01) {
      pos += 2;
      continue;
    }
    if (marker == 0xDA || marker == 0xD9) return;  // start of scan / end of image
    const std::size_t len = (std::size_t(uint8_t(b[pos + 2])) << 8) | uint8_t(b[pos + 3]);
    const std::size_t end = std::min(b.size(), pos + 2 + len);
    if (marker == 0xC4) {  // DHT: tables of (class/id, 16 counts, symbols)
      std::size_t q = pos + 4;
      while (q + 17 <= end) {
        std::size_t codes = 0;
        for (int k = 1; k <= 16; ++k) codes += uint8_t(b[q + std::size_t(k)]);
        if (codes > 256)
          fail_at(where, "corrupt JPEG: a Huffman table declares {} codes (at most 256)", codes);
        q += 17 + codes;
      }
    }
    pos += 2 + len;
  }
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
  check_jpeg_huffman_tables(bytes, path.string());
  int w = 0, h = 0, n = 0;
  if (stbi_info_from_memory(reinterpret_cast<const stbi_uc*>(bytes.data()), int(bytes.size()), &w,
                            &h, &n))
    check_image_size(path.string(), w, h, C, 1, "PNG/JPEG");
  std::unique_ptr<unsigned char, StbFree> px(stbi_load_from_memory(
      reinterpret_cast<const stbi_uc*>(bytes.data()), int(bytes.size()), &w, &h, &n, C));
  if (!px) {
    fail_at(path.string(), "cannot decode image ({}), expected a valid PNG or JPEG",
            stbi_failure_reason() ? stbi_failure_reason() : "unknown error");
  }
  Image<uint8_t, C> img(w, h);
  std::copy(px.get(), px.get() + img.storage().size(), img.data());
  return img;
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
void check_exr_header(const std::string& b, const std::string& where, int channels) {
  if (b.size() < 8 || b.compare(0, 4, "\x76\x2f\x31\x01") != 0)
    fail_at(where, "not an OpenEXR file (bad magic number)");
  // A multi-part file holds several headers, each ended by an empty name, and an empty header
  // after the last (a 177-byte multi-part file, unchecked before, took 20 s and gigabytes; found
  // by fuzz/fuzz_exr, fuzz/regressions/exr/multipart_attribute_size.exr).
  const bool multipart = (uint8_t(b[5]) & 0x10) != 0;
  std::size_t pos = 8;
  for (int attr = 0;; ++attr) {
    const std::size_t name_end = b.find('\0', pos);
    if (name_end == std::string::npos) fail_at(where, "truncated EXR header");
    if (name_end == pos) {  // the empty name ends the header
      if (!multipart) return;
      ++pos;
      if (pos >= b.size()) fail_at(where, "truncated EXR header");
      if (b[pos] == '\0') return;  // the empty header ends the list
      continue;
    }
    const std::string name = b.substr(pos, std::min<std::size_t>(name_end - pos, 64));
    const std::size_t type_end = b.find('\0', name_end + 1);
    if (type_end == std::string::npos || type_end + 5 > b.size())
      fail_at(where, "truncated EXR header (attribute {})", attr);
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
        const std::size_t z = b.find('\0', q);
        if (z == std::string::npos || z >= end) break;
        q = z + 1 + 16;  // pixel type, pLinear + 3 reserved, x and y sampling
      }
      if (q + 1 != end)
        fail_at(where, "EXR channel list declares {} bytes but its channels take {}", size,
                q + 1 - pos);
    } else if (type == "preview") {
      uint32_t wh[2] = {0, 0};
      if (size >= 8) std::memcpy(wh, b.data() + pos, 8);
      if (size < 8 || double(wh[0]) * wh[1] * 4 + 8 != double(size))
        fail_at(where, "EXR preview image of {}x{} does not match its {} bytes", wh[0], wh[1],
                size);
    }
    if (name == "dataWindow" && size == 16) {
      int32_t box[4];  // xmin, ymin, xmax, ymax
      std::memcpy(box, b.data() + pos, sizeof box);
      const long long w = (long long)box[2] - box[0] + 1, h = (long long)box[3] - box[1] + 1;
      check_image_size(where, w, h, channels, int(sizeof(float)), "EXR");
      // A decompression bomb: 268 bytes declared 16383753 x 7 pixels, which we would have
      // allocated (1.8 GB) and zeroed before OpenEXR found no data (found by fuzz/fuzz_exr;
      // fuzz/regressions/exr/window_larger_than_any_compression.exr). No EXR compression packs
      // one half-float channel more than ~1000:1 (zlib's limit is 1032:1); 10,000:1 plus 64 MB is
      // far beyond any real file.
      const double least = double(w) * double(h) * 2.0;  // one half channel, no header
      if (least > 1e4 * double(b.size()) + 64e6)
        fail_at(where,
                "EXR declares {}x{} pixels but holds only {} bytes; no compression packs that "
                "much (more than 10,000:1)",
                w, h, b.size());
    }
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
