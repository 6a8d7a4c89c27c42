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

#include <cctype>
#include <exception>
#include <memory>
#include <string>

#include "follicle/core/atomic_file.hpp"

namespace follicle::image {
namespace {

struct StbFree {
  void operator()(unsigned char* p) const { stbi_image_free(p); }
};

template <int C>
Image<uint8_t, C> read_stb(const std::filesystem::path& path) {
  const std::string bytes = read_file(path);
  if (bytes.empty()) fail_at(path.string(), "empty file, expected a PNG or JPEG image");
  if (bytes.size() > std::size_t(INT32_MAX)) fail_at(path.string(), "file too large");
  int w = 0, h = 0, n = 0;
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

/// Reads the named channels (first match of each alternative list) into a float image;
/// channels that are absent are filled with `fill[c]`.
template <int C>
Image<float, C> read_exr_impl(const std::filesystem::path& path,
                              const std::vector<std::vector<std::string>>& wanted,
                              const float* fill) {
  if (!std::filesystem::exists(path)) fail_at(path.string(), "cannot open: no such file");
  try {
    Imf::InputFile file(path.string().c_str());
    const Imath::Box2i dw = file.header().dataWindow();
    const long long w = (long long)dw.max.x - dw.min.x + 1;
    const long long h = (long long)dw.max.y - dw.min.y + 1;
    if (w <= 0 || h <= 0 || w * h > (1LL << 31)) {
      fail_at(path.string(), "EXR data window {}x{} is invalid", w, h);
    }
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
    if (!file.isComplete()) fail_at(path.string(), "EXR file is incomplete (truncated)");
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
