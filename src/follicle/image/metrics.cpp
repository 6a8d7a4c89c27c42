#include "follicle/image/metrics.hpp"

#include <cmath>
#include <type_traits>

namespace follicle::image {

template <class T, int C>
ImageDiff compare_images(const Image<T, C>& a, const Image<T, C>& b, const DiffOptions& opt) {
  if (a.width() != b.width() || a.height() != b.height()) {
    fail("cannot compare images of different sizes: {}x{} vs {}x{}", a.width(), a.height(),
         b.width(), b.height());
  }
  const int nc = (opt.ignore_alpha && C == 4) ? 3 : C;
  const double peak = opt.peak > 0 ? opt.peak : (std::is_integral_v<T> ? 255.0 : 1.0);
  ImageDiff d;
  // Fixed-order serial sum in long double: metrics are cheap and must not depend on threads.
  long double sum2 = 0;
  const std::size_t n = a.num_pixels();
  for (std::size_t i = 0; i < n; ++i) {
    const T* pa = a.data() + i * C;
    const T* pb = b.data() + i * C;
    bool over = false;
    for (int c = 0; c < nc; ++c) {
      const double e = std::abs(double(pa[c]) - double(pb[c]));
      if (std::isnan(e)) {
        d.max_abs = std::numeric_limits<double>::infinity();
        over = true;
        sum2 += std::numeric_limits<long double>::infinity();
        continue;
      }
      sum2 += (long double)e * e;
      if (e > d.max_abs) d.max_abs = e;
      if (e > opt.threshold) over = true;
    }
    if (over) ++d.pixels_over;
  }
  if (n > 0) {
    d.rmse = double(std::sqrt(sum2 / (long double)(n * std::size_t(nc))));
    d.share_over = double(d.pixels_over) / double(n);
  }
  d.psnr = d.rmse > 0 ? 20.0 * std::log10(peak / d.rmse) : std::numeric_limits<double>::infinity();
  return d;
}

#define FOLLICLE_INSTANTIATE(T, C)                                                \
  template ImageDiff compare_images<T, C>(const Image<T, C>&, const Image<T, C>&, \
                                          const DiffOptions&);
FOLLICLE_INSTANTIATE(uint8_t, 1)
FOLLICLE_INSTANTIATE(uint8_t, 3)
FOLLICLE_INSTANTIATE(uint8_t, 4)
FOLLICLE_INSTANTIATE(float, 1)
FOLLICLE_INSTANTIATE(float, 3)
FOLLICLE_INSTANTIATE(float, 4)
#undef FOLLICLE_INSTANTIATE

double rmse(const ImageRGBA8& a, const ImageRGBA8& b) {
  return compare_images(a, b).rmse;
}
double psnr(const ImageRGBA8& a, const ImageRGBA8& b) {
  return compare_images(a, b).psnr;
}

}  // namespace follicle::image
