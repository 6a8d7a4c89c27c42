#include "follicle/skin/wrinkle_maps.hpp"

#include <algorithm>
#include <cmath>

#include "follicle/core/error.hpp"
#include "follicle/core/parallel.hpp"
#include "follicle/core/types.hpp"
#include "follicle/image/image_io.hpp"

namespace follicle::skin {

image::ImageRGBF normal_map_from_relief(const Context& ctx, const image::ImageF& relief,
                                        double depth_m, double metres_per_texel, double strength) {
  if (!(metres_per_texel > 0)) fail("normal map: metres_per_texel must be > 0");
  const int w = relief.width(), h = relief.height();
  image::ImageRGBF out(w, h);
  const double k = depth_m * strength / (2.0 * metres_per_texel);
  parallel_for(
      ctx, 0, std::size_t(h),
      [&](std::size_t yy) {
        const int y = int(yy);
        const int ym = std::max(0, y - 1), yp = std::min(h - 1, y + 1);
        for (int x = 0; x < w; ++x) {
          const int xm = std::max(0, x - 1), xp = std::min(w - 1, x + 1);
          const double dzdu = (relief.at(xp, y) - relief.at(xm, y)) * k;
          const double dzdv = -(relief.at(x, yp) - relief.at(x, ym)) * k;  // +v is up (-y)
          Vec3 n(-dzdu, -dzdv, 1.0);
          n.normalize();
          for (int c = 0; c < 3; ++c) out.at(x, y, c) = float(n[c]);
        }
      },
      8);
  return out;
}

void export_wrinkle_maps(const Context& ctx, const std::filesystem::path& dir,
                         const std::string& stem, const image::ImageF& relief,
                         const MapExportInfo& info) {
  std::filesystem::create_directories(dir);
  const int w = relief.width(), h = relief.height();
  image::ImageF height(w, h), disp(w, h);
  image::ImageGray8 height8(w, h), disp8(w, h);
  for (std::size_t i = 0; i < relief.num_pixels(); ++i) {
    const float r = relief.data()[i];
    height.data()[i] = 1.0f + r;
    disp.data()[i] = float(r * info.depth_m);
    const float v = std::clamp(1.0f + 0.5f * r, 0.0f, 1.0f);
    height8.data()[i] = uint8_t(std::lround(255.0f * v));
    disp8.data()[i] = height8.data()[i];
  }
  const image::ImageRGBF n =
      normal_map_from_relief(ctx, relief, info.depth_m, info.metres_per_texel, info.strength);
  image::ImageRGB8 n8(w, h);
  for (std::size_t i = 0; i < n.num_pixels() * 3; ++i)
    n8.data()[i] = uint8_t(std::lround(255.0f * std::clamp(0.5f * n.data()[i] + 0.5f, 0.f, 1.f)));
  image::write_exr(dir / (stem + "_height.exr"), height);
  image::write_png(dir / (stem + "_height.png"), height8);
  image::write_exr(dir / (stem + "_displacement.exr"), disp);
  image::write_png(dir / (stem + "_displacement.png"), disp8);
  image::write_exr(dir / (stem + "_normal.exr"), n);
  image::write_png(dir / (stem + "_normal.png"), n8);
}

}  // namespace follicle::skin
