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
  const auto names = hair::style_preset_names();
  auto check_preset = [&](const std::string& name, const std::string& at) {
    if (std::find(names.begin(), names.end(), name) != names.end()) return;
    const std::string hint = suggest(name, names);
    json_fail(src, at,
              "unknown hairstyle preset \"" + name + "\"" +
                  (hint.empty() ? "" : " (did you mean \"" + hint + "\"?)") + "; expected one of " +
                  detail::quoted_list(names) + " or a style object");
  };
  avoid_mesh.reset();
  collision_margin.reset();
  if (j.is_string()) {
    check_preset(j.get<std::string>(), path);
    preset = j.get<std::string>();
    custom.reset();
    return;
  }
  if (!j.is_object())
    json_fail(src, path,
              "expected a preset name (string) or a style object, got " + describe_json(j));
  // Whole-style settings, allowed with a preset or beside a full style.
  Json rest = j;
  if (const auto it = rest.find("avoid_mesh"); it != rest.end()) {
    if (!it->is_boolean())
      json_fail(src, join_path(path, "avoid_mesh"),
                "expected true or false, got " + describe_json(*it));
    avoid_mesh = it->get<bool>();
    rest.erase(it);
  }
  if (const auto it = rest.find("collision_margin"); it != rest.end()) {
    const std::string at = join_path(path, "collision_margin");
    if (!it->is_number()) json_fail(src, at, "expected a number (m), got " + describe_json(*it));
    const double m = it->get<double>();
    if (!(m >= 0 && m <= 0.05))
      json_fail(src, at, fmt::format("{} m is out of range: expected [0, 0.05] m", m));
    collision_margin = m;
    rest.erase(it);
  }
  if (const auto it = rest.find("preset"); it != rest.end()) {
    const std::string at = join_path(path, "preset");
    if (!it->is_string())
      json_fail(src, at, "expected a preset name (string), got " + describe_json(*it));
    check_preset(it->get<std::string>(), at);
    preset = it->get<std::string>();
    rest.erase(it);
    for (const auto& [key, value] : rest.items())
      json_fail(src, join_path(path, key),
                "a style with \"preset\" takes only \"avoid_mesh\" and \"collision_margin\" "
                "besides it; to change its parts write the whole style without \"preset\"");
    custom.reset();
    return;
  }
  hair::HairStyle st;
  read_json(rest, path, st, src);
  try {
    st.validate();
  } catch (const Error& e) {
    json_fail(src, path, e.what());
  }
  custom = std::move(st);
}

Json HairStyleSpec::to_json_custom() const {
  Json out = custom ? to_json(*custom) : Json(preset);
  if (!avoid_mesh && !collision_margin) return out;
  if (!custom) out = Json{{"preset", preset}};
  if (avoid_mesh) out["avoid_mesh"] = *avoid_mesh;
  if (collision_margin) out["collision_margin"] = *collision_margin;
  return out;
}

hair::HairStyle HairStyleSpec::resolve(double density_scale) const {
  hair::HairStyle st = custom ? *custom : hair::style_preset(preset, density_scale);
  for (auto& part : st.parts) {
    if (custom)
      for (auto& r : part.pores) r.density *= density_scale;
    if (avoid_mesh) part.beam.avoid_mesh = *avoid_mesh;
    if (collision_margin) part.beam.collision_margin = *collision_margin;
  }
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
