#include "follicle/scene/hair_section.hpp"

#include <fmt/format.h>

#include <algorithm>
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

void HairStylerSpec::read_json_custom(const Json& j, const std::string& path,
                                      const JsonSource& src) {
  auto check_preset = [&](const std::string& name, const std::string& p) {
    const auto names = hair::styler_preset_names();
    for (const auto& n : names)
      if (n == name) return;
    const std::string hint = suggest(name, names);
    json_fail(src, p,
              "unknown styler preset \"" + name + "\"" +
                  (hint.empty() ? "" : " (did you mean \"" + hint + "\"?)") + "; expected one of " +
                  detail::quoted_list(names) + " or a style object");
  };
  preset.clear();
  overrides = Json::object();
  if (j.is_string()) {
    preset = j.get<std::string>();
    check_preset(preset, path);
    return;
  }
  if (!j.is_object())
    json_fail(src, path,
              "expected a styler preset name (string) or a style object, got " + describe_json(j));
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (it.key() == "preset") {
      if (!it.value().is_string())
        json_fail(src, join_path(path, "preset"),
                  "expected a preset name (string), got " + describe_json(it.value()));
      preset = it.value().get<std::string>();
      check_preset(preset, join_path(path, "preset"));
    } else {
      overrides[it.key()] = it.value();
    }
  }
  // Strict check of the keys and ranges now; the preset itself needs the mesh (resolve()).
  hair::HairStylerParams probe;
  read_json(overrides, path, probe, src);
  if (preset.empty()) {
    try {
      probe.validate(path);
    } catch (const Error& e) {  // the message names the path inside the styler
      throw Error(src.file, e.what());
    }
  }
}

Json HairStylerSpec::to_json_custom() const {
  if (overrides.empty()) return Json(preset);
  Json j = overrides;
  if (!preset.empty()) j["preset"] = preset;
  return j;
}

hair::HairStylerParams HairStylerSpec::resolve(const geom::TriMesh& mesh, const Vec3& up,
                                               const Vec3& front, const std::string& path,
                                               const JsonSource& src) const {
  hair::HairStylerParams p;
  if (!preset.empty()) p = hair::styler_preset(preset, mesh, up, front);
  read_json(overrides, path, p, src);
  try {
    p.validate(path);
  } catch (const Error& e) {  // the message names the path inside the styler
    throw Error(src.file, e.what());
  }
  return p;
}

Vec3 AirGustSpec::at(double t) const {
  auto smooth = [](double x) {
    x = std::clamp(x, 0.0, 1.0);
    return x * x * (3.0 - 2.0 * x);
  };
  const double up = smooth((t - t0) / rise);
  const double down = 1.0 - smooth((t - t1) / rise);
  return std::min(up, down) * peak;
}

int AnimationSpec::frame_count() const {
  if (frames > 0) return frames;
  return std::max(1, int(std::lround(duration * fps)));
}

}  // namespace follicle::scene
