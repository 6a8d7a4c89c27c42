#pragma once
// Anisotropic hair shading, Anjyo, Usami, Kurihara 1992 §4.1: per node, the specular term (8)
// Φs = ks (1 - (T·H)²)^(n/2) and the intensity (9) I = Ia ka + Is Φs, with the ambient
// coefficient ka drawn per strand from a normal distribution. The result is written into
// StrandSet::color so the renderer draws it as StrandShading::VertexColor (the z-buffer then
// interpolates colour linearly along each segment, §4.2).
#include <cstdint>

#include "follicle/core/context.hpp"
#include "follicle/core/types.hpp"
#include "follicle/geom/strands.hpp"

namespace follicle::hair {

struct AnjyoShadingParams {
  Vec3 hair_color{0.16, 0.09, 0.05};     // linear RGB albedo multiplying the ambient term
  Vec3 specular_color{1.0, 0.95, 0.85};  // linear RGB of the highlight
  double ambient_intensity = 1.0;        // Ia
  double ka_mean = 0.8;                  // mean of the per-strand ambient coefficient ka
  double ka_sigma = 0.15;                // standard deviation of ka (normal distribution)
  double ks = 0.25;                      // specular coefficient
  double exponent = 120.0;               // n, sharpness of the highlight
  double light_intensity = 1.0;          // Is
  template <class V>
  void visit(V&& v) {
    v("hair_color", hair_color, {"ambient hair colour (linear RGB)", "", 0.0, 1.0});
    v("specular_color", specular_color, {"highlight colour (linear RGB)", "", 0.0, 1.0});
    v("ambient_intensity", ambient_intensity, {"Ia", "", 0.0, 100.0});
    v("ka_mean", ka_mean, {"mean ambient coefficient", "", 0.0, 10.0});
    v("ka_sigma", ka_sigma, {"spread of the ambient coefficient", "", 0.0, 10.0});
    v("ks", ks, {"specular coefficient", "", 0.0, 10.0});
    v("exponent", exponent, {"highlight exponent n", "", 0.0, 1e4});
    v("light_intensity", light_intensity, {"Is", "", 0.0, 100.0});
  }
  void validate() const;
};

/// (8) specular term for unit tangent T and unit halfway vector H.
double anjyo_specular(const Vec3& T, const Vec3& H, double ks, double n);

/// Writes StrandSet::color (one per point, clamped to [0,1]). `eye` is the camera position and
/// `to_light` the unit direction towards a directional light, both world. T at node i is the
/// direction of the segment p_{i-1} p_i (the first segment's for the root). ka per strand comes
/// from Rng::stream(seed, strand). Parallel, identical for any thread count.
void shade_anjyo1992(const Context& ctx, geom::StrandSet& strands, const AnjyoShadingParams& p,
                     const Vec3& eye, const Vec3& to_light, uint64_t seed);

}  // namespace follicle::hair
