#pragma once
// PNG (stb) and EXR (OpenEXR) reading and writing. Writers are atomic (temp file + rename).
#include <filesystem>

#include "follicle/image/image.hpp"

namespace follicle::image {

ImageRGBA8 read_png_rgba(const std::filesystem::path& path);  // also reads JPEG (stb)
ImageGray8 read_png_gray(const std::filesystem::path& path);
void write_png(const std::filesystem::path& path, const ImageRGBA8& img);
void write_png(const std::filesystem::path& path, const ImageRGB8& img);
void write_png(const std::filesystem::path& path, const ImageGray8& img);

ImageF read_exr_gray(const std::filesystem::path& path);
ImageRGBAF read_exr_rgba(const std::filesystem::path& path);
/// A grayscale map as floats: EXR values as stored, PNG/JPEG 8-bit values scaled to [0, 1].
ImageF read_gray_map(const std::filesystem::path& path);
void write_exr(const std::filesystem::path& path, const ImageF& img);      // channel "Y", float
void write_exr(const std::filesystem::path& path, const ImageRGBF& img);   // R,G,B float
void write_exr(const std::filesystem::path& path, const ImageRGBAF& img);  // R,G,B,A float

}  // namespace follicle::image
