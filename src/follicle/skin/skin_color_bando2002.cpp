#include "follicle/skin/skin_color_bando2002.hpp"

#include <algorithm>

#include "follicle/core/error.hpp"

namespace follicle::skin {

std::vector<std::string> skin_color_preset_names() {
  return {"pale", "caucasian", "asian", "tanned", "african"};
}

SkinColorParams skin_color_preset(const std::string& name) {
  SkinColorParams p;
  if (name == "pale") {
    p.melanin = 0.02;
    p.hemoglobin = 0.2;
  } else if (name == "caucasian") {
    p.melanin = 0.08;
    p.hemoglobin = 0.35;
  } else if (name == "asian") {
    p.melanin = 0.22;
    p.hemoglobin = 0.3;
  } else if (name == "tanned") {
    p.melanin = 0.4;
    p.hemoglobin = 0.3;
  } else if (name == "african") {
    p.melanin = 0.95;
    p.hemoglobin = 0.4;
  } else {
    const std::string d = did_you_mean(name, skin_color_preset_names());
    fail(
        "unknown skin colour preset '{}'{}; expected one of pale, caucasian, asian, tanned, "
        "african",
        name, d.empty() ? std::string() : " (did you mean '" + d + "'?)");
  }
  return p;
}

Vec3 skin_color(const SkinColorParams& p) {
  const Vec3 c =
      p.base - p.melanin * p.melanin_absorption - p.hemoglobin * p.hemoglobin_absorption;  // (2.6)
  return c.cwiseMax(0.0).cwiseMin(1.0);
}

std::vector<Vec3> skin_vertex_colors(const SkinColorParams& p, std::size_t n,
                                     const std::vector<double>& ms, const std::vector<double>& hs) {
  p.validate();
  if ((!ms.empty() && ms.size() != n) || (!hs.empty() && hs.size() != n))
    fail("skin_vertex_colors: scale arrays must be empty or have {} entries", n);
  std::vector<Vec3> out(n);
  for (std::size_t i = 0; i < n; ++i) {
    SkinColorParams q = p;
    if (!ms.empty()) q.melanin = p.melanin * ms[i];
    if (!hs.empty()) q.hemoglobin = p.hemoglobin * hs[i];
    out[i] = skin_color(q);
  }
  return out;
}

image::ImageRGBF skin_color_texture(const SkinColorParams& p, const image::ImageF& mm,
                                    const image::ImageF& hm) {
  p.validate();
  if (mm.width() != hm.width() || mm.height() != hm.height())
    fail("skin_color_texture: melanin map {}x{} and hemoglobin map {}x{} differ", mm.width(),
         mm.height(), hm.width(), hm.height());
  image::ImageRGBF out(mm.width(), mm.height());
  for (int y = 0; y < mm.height(); ++y)
    for (int x = 0; x < mm.width(); ++x) {
      SkinColorParams q = p;
      q.melanin = p.melanin * double(mm.at(x, y));
      q.hemoglobin = p.hemoglobin * double(hm.at(x, y));
      const Vec3 c = skin_color(q);
      for (int k = 0; k < 3; ++k) out.at(x, y, k) = float(c[k]);
    }
  return out;
}

}  // namespace follicle::skin
