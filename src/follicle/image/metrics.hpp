#pragma once
// Image comparison metrics for golden-image tests and `follicle compare`. Differences are taken
// per channel in the image's own value range (0..255 for 8-bit, as stored for float images).
#include <limits>

#include "follicle/image/image.hpp"

namespace follicle::image {

struct DiffOptions {
  /// A pixel counts as "over" when any compared channel differs by more than this.
  double threshold = 0.0;
  /// Peak value for PSNR; <= 0 means 255 for 8-bit images and 1 for float images.
  double peak = 0.0;
  /// Leave the alpha channel (channel 3 of 4-channel images) out of every metric.
  bool ignore_alpha = false;
};

struct ImageDiff {
  double rmse = 0.0;  // sqrt(mean over pixels and channels of (a-b)^2)
  double psnr = std::numeric_limits<double>::infinity();  // 20 log10(peak / rmse) [dB]
  double max_abs = 0.0;                                   // largest |a-b| over pixels and channels
  double share_over = 0.0;  // share of pixels (0..1) with some channel |a-b| > threshold
  std::size_t pixels_over = 0;
};

/// Throws follicle::Error when the sizes differ.
template <class T, int C>
ImageDiff compare_images(const Image<T, C>& a, const Image<T, C>& b, const DiffOptions& opt = {});

double rmse(const ImageRGBA8& a, const ImageRGBA8& b);
double psnr(const ImageRGBA8& a, const ImageRGBA8& b);

}  // namespace follicle::image
