#pragma once
// Skin colour (Bando 2002 §2.7, (2.6)): c = b - m a_m - h a_h, a plane in RGB spanned by melanin
// and hemoglobin absorption. The spec's a_m, a_h were "determined empirically"; ours are
// empirical too (chosen so the presets look like light/medium/dark skin; a_m absorbs blue most
// and a_h green/blue most, following the spectral shapes in docs skin-constants §4.3).
#include <string>
#include <vector>

#include "follicle/core/params.hpp"
#include "follicle/core/types.hpp"
#include "follicle/image/image.hpp"

namespace follicle::skin {

struct SkinColorParams {
  Vec3 base{0.96, 0.84, 0.76};                   // b (linear RGB)
  Vec3 melanin_absorption{0.50, 0.58, 0.62};     // a_m
  Vec3 hemoglobin_absorption{0.02, 0.30, 0.22};  // a_h
  double melanin = 0.1;                          // m in [0, 1]
  double hemoglobin = 0.3;                       // h in [0, 1]
  template <class V>
  void visit(V&& v) {
    v("base", base, ParamInfo{"base colour b", "", 0.0, 1.0});
    v("melanin_absorption", melanin_absorption, ParamInfo{"melanin absorption a_m", "", 0.0, 1.0});
    v("hemoglobin_absorption", hemoglobin_absorption,
      ParamInfo{"hemoglobin absorption a_h", "", 0.0, 1.0});
    v("melanin", melanin, ParamInfo{"amount of melanin m", "", 0.0, 1.0});
    v("hemoglobin", hemoglobin, ParamInfo{"amount of hemoglobin h", "", 0.0, 1.0});
  }
  void validate() const { validate_params(*this, "skin_color"); }
};

/// Presets: "pale", "caucasian", "asian", "tanned", "african". Throws with a did-you-mean.
SkinColorParams skin_color_preset(const std::string& name);
std::vector<std::string> skin_color_preset_names();

/// (2.6) c = b - m a_m - h a_h, clamped to [0, 1].
Vec3 skin_color(const SkinColorParams& p);
/// Per-vertex colours with optional per-vertex melanin/hemoglobin multipliers (empty = 1).
std::vector<Vec3> skin_vertex_colors(const SkinColorParams& p, std::size_t n,
                                     const std::vector<double>& melanin_scale = {},
                                     const std::vector<double>& hemoglobin_scale = {});
/// Colour texture from melanin and hemoglobin maps (same size; values in [0, 1] scale m and h).
image::ImageRGBF skin_color_texture(const SkinColorParams& p, const image::ImageF& melanin_map,
                                    const image::ImageF& hemoglobin_map);

}  // namespace follicle::skin
