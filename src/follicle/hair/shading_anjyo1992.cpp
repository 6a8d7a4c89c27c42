#include "follicle/hair/shading_anjyo1992.hpp"

#include <algorithm>
#include <cmath>

#include "follicle/core/parallel.hpp"
#include "follicle/core/params.hpp"
#include "follicle/core/rng.hpp"

namespace follicle::hair {

void AnjyoShadingParams::validate() const {
  validate_params(*this, "anjyo_shading");
}

double anjyo_specular(const Vec3& T, const Vec3& H, double ks, double n) {
  const double th = T.dot(H);
  // (7) (N, H) = sqrt(1 - (T, H)^2) for the best normal in the plane of T and H;
  // (8) Φs = ks (1 - (T, H)^2)^(n/2).
  return ks * std::pow(std::max(0.0, 1.0 - th * th), 0.5 * n);
}

void shade_anjyo1992(const Context& ctx, geom::StrandSet& strands, const AnjyoShadingParams& p,
                     const Vec3& eye, const Vec3& to_light, uint64_t seed) {
  p.validate();
  strands.color.resize(strands.points.size());
  const Vec3 L = to_light.normalized();
  parallel_for(
      ctx, 0, strands.num_strands(),
      [&](std::size_t s) {
        Rng rng = Rng::stream(seed, s);
        const double ka = std::max(0.0, rng.normal(p.ka_mean, p.ka_sigma));
        const uint32_t b = strands.offsets[s], e = strands.offsets[s + 1];
        for (uint32_t i = b; i < e; ++i) {
          Vec3 T = Vec3::UnitY();
          if (e - b >= 2) {
            const uint32_t j = i == b ? b + 1 : i;
            const Vec3 t = (strands.points[j] - strands.points[j - 1]).cast<double>();
            if (t.norm() > 0) T = t.normalized();
          }
          const Vec3 P = strands.points[i].cast<double>();
          const Vec3 V = (eye - P).normalized();
          const Vec3 H = (L + V).normalized();
          const double phi = anjyo_specular(T, H, p.ks, p.exponent);
          // (9) I = Ia ka + Is Φs, coloured: ambient with the hair colour, highlight with the
          // light's.
          const Vec3 c =
              p.ambient_intensity * ka * p.hair_color + p.light_intensity * phi * p.specular_color;
          strands.color[i] = c.cwiseMax(0.0).cwiseMin(1.0).cast<float>();
        }
      },
      256);
}

}  // namespace follicle::hair
