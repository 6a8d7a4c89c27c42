#include "follicle/scene/hair_section.hpp"

#include <fmt/format.h>

#include <cmath>

#include "follicle/core/error.hpp"

namespace follicle::scene {

sim::Ellipsoid HullSpec::ellipsoid() const {
  const double k = kPi / 180.0;
  sim::Ellipsoid e;
  e.centre = centre;
  e.radii = radii;
  e.rotation = (Eigen::AngleAxisd(rotate_deg.z() * k, Vec3::UnitZ()) *
                Eigen::AngleAxisd(rotate_deg.y() * k, Vec3::UnitY()) *
                Eigen::AngleAxisd(rotate_deg.x() * k, Vec3::UnitX()))
                   .toRotationMatrix();
  return e;
}

void HairStyleSpec::read_json_custom(const Json& j, const std::string& path,
                                     const JsonSource& src) {
  if (j.is_string()) {
    const auto name = j.get<std::string>();
    const auto names = hair::style_preset_names();
    for (const auto& n : names) {
      if (n == name) {
        preset = name;
        custom.reset();
        return;
      }
    }
    const std::string hint = suggest(name, names);
    json_fail(src, path,
              "unknown hairstyle preset \"" + name + "\"" +
                  (hint.empty() ? "" : " (did you mean \"" + hint + "\"?)") + "; expected one of " +
                  detail::quoted_list(names) + " or a style object");
  }
  if (!j.is_object())
    json_fail(src, path,
              "expected a preset name (string) or a style object, got " + describe_json(j));
  hair::HairStyle st;
  read_json(j, path, st, src);
  try {
    st.validate();
  } catch (const Error& e) {
    json_fail(src, path, e.what());
  }
  custom = std::move(st);
}

Json HairStyleSpec::to_json_custom() const {
  if (custom) return to_json(*custom);
  return Json(preset);
}

hair::HairStyle HairStyleSpec::resolve(double density_scale) const {
  if (!custom) return hair::style_preset(preset, density_scale);
  hair::HairStyle st = *custom;
  for (auto& part : st.parts)
    for (auto& r : part.pores) r.density *= density_scale;
  return st;
}

int AnimationSpec::frame_count() const {
  if (frames > 0) return frames;
  return std::max(1, int(std::lround(duration * fps)));
}

}  // namespace follicle::scene
