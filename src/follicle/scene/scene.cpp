#include "follicle/scene/scene.hpp"

#include <fmt/format.h>

#include <set>

#include "follicle/render/render_scene.hpp"

namespace follicle::scene {

Affine3 Transform::matrix() const {
  const double k = kPi / 180.0;
  const Mat3 r = (Eigen::AngleAxisd(rotate_deg.z() * k, Vec3::UnitZ()) *
                  Eigen::AngleAxisd(rotate_deg.y() * k, Vec3::UnitY()) *
                  Eigen::AngleAxisd(rotate_deg.x() * k, Vec3::UnitX()))
                     .toRotationMatrix();
  Affine3 m = Affine3::Identity();
  m.linear() = r * scale;
  m.translation() = translate;
  return m;
}

void Scene::validate(const JsonSource& src) const {
  // Per-key types and ranges were checked while reading; these span several keys.
  const Vec3 view = camera.target - camera.eye;
  if (view.norm() < 1e-9)
    json_fail(src, "camera.target", "camera target coincides with camera eye");
  if (camera.up.norm() < 1e-12) json_fail(src, "camera.up", "up vector is zero");
  if (view.normalized().cross(camera.up.normalized()).norm() < 1e-6)
    json_fail(src, "camera.up", "up vector is parallel to the viewing direction");
  if (!(camera.near < camera.far))
    json_fail(src, "camera.far",
              fmt::format("far ({}) must be greater than near ({})", camera.far, camera.near));
  if (const std::string e = render::RenderSettings::hair_light_pass_error(render.hair_light_pass);
      !e.empty())
    json_fail(src, "render.hair_light_pass", e);
  if (const std::string e = render::RenderSettings::hair_light_pass_error(render.hair_view_pass);
      !e.empty())
    json_fail(src, "render.hair_view_pass", e);
  if (const std::string e = render::RenderSettings::hair_light_pass_error(render.strand_pass);
      !e.empty())
    json_fail(src, "render.strand_pass", e);
  std::set<std::string> names;
  for (std::size_t i = 0; i < assets.meshes.size(); ++i) {
    const auto& m = assets.meshes[i];
    const std::string p = index_path("assets.meshes", i);
    if (m.path.empty()) json_fail(src, p + ".path", "mesh path is empty");
    if (m.up.norm() < 1e-9) json_fail(src, p + ".up", "up direction is zero");
    if (m.front.norm() < 1e-9) json_fail(src, p + ".front", "front direction is zero");
    if (m.up.normalized().cross(m.front.normalized()).norm() < 0.5)
      json_fail(src, p + ".front",
                fmt::format("front [{}, {}, {}] is within 30 degrees of up [{}, {}, {}]; the face "
                            "looks across the head's up direction",
                            m.front.x(), m.front.y(), m.front.z(), m.up.x(), m.up.y(), m.up.z()));
    if (!m.name.empty() && !names.insert(m.name).second)
      json_fail(src, p + ".name", "duplicate mesh name \"" + m.name + "\"");
  }
  std::set<std::string> groom_names;
  for (std::size_t i = 0; i < assets.grooms.size(); ++i) {
    const auto& g = assets.grooms[i];
    const std::string p = index_path("assets.grooms", i);
    if (g.name.empty()) json_fail(src, p + ".name", "groom name is empty");
    if (g.path.empty()) json_fail(src, p + ".path", "groom path is empty");
    if (!groom_names.insert(g.name).second)
      json_fail(src, p + ".name", "duplicate groom name \"" + g.name + "\"");
  }
  for (std::size_t i = 0; i < lights.size(); ++i) {
    if (lights[i].direction.norm() < 1e-12)
      json_fail(src, index_path("lights", i) + ".direction", "light direction is zero");
  }
  for (std::size_t i = 0; i < hair.size(); ++i) {
    const auto& h = hair[i];
    const std::string p = index_path("hair", i);
    if (h.mesh.empty()) json_fail(src, p + ".mesh", "mesh name is empty");
    if (!names.count(h.mesh)) {
      const std::vector<std::string> known(names.begin(), names.end());
      const std::string hint = suggest(h.mesh, known);
      json_fail(src, p + ".mesh",
                "no mesh asset named \"" + h.mesh + "\"" +
                    (hint.empty() ? "" : " (did you mean \"" + hint + "\"?)") +
                    "; hair grows on a mesh of assets.meshes with that name");
    }
    if (!h.groom.empty() && !groom_names.count(h.groom)) {
      const std::vector<std::string> known(groom_names.begin(), groom_names.end());
      const std::string hint = suggest(h.groom, known);
      json_fail(src, p + ".groom",
                "no groom asset named \"" + h.groom + "\"" +
                    (hint.empty() ? "" : " (did you mean \"" + hint + "\"?)") +
                    "; name one of assets.grooms, or leave \"groom\" out to generate the hair");
    }
    try {
      h.dynamics.validate();
    } catch (const Error& e) {
      json_fail(src, p + ".dynamics", e.what());
    }
    try {
      h.daldegan.validate();
    } catch (const Error& e) {
      json_fail(src, p + ".daldegan", e.what());
    }
    try {
      h.bando.validate();
    } catch (const Error& e) {
      json_fail(src, p + ".bando", e.what());
    }
    try {
      h.shading.validate();
    } catch (const Error& e) {
      json_fail(src, p + ".shading", e.what());
    }
    try {
      h.hull_fit.validate();
    } catch (const Error& e) {
      json_fail(src, p + ".hull_fit", e.what());
    }
  }
  if (animation) {
    const auto& a = *animation;
    const auto& m = a.head_motion;
    if (a.frames == 0 && a.duration <= 0.0)
      json_fail(src, "animation.frames", "give the clip length: frames > 0 or duration > 0");
    if ((m.kind == HeadMotionKind::Turn || m.kind == HeadMotionKind::Shake)) {
      if (!(m.t1 > m.t0))
        json_fail(src, "animation.head_motion.t1",
                  fmt::format("t1 ({}) must be greater than t0 ({})", m.t1, m.t0));
      if (m.axis.norm() < 1e-9) json_fail(src, "animation.head_motion.axis", "axis is zero");
    }
    if (m.interp != "step" && m.interp != "linear" && m.interp != "smooth")
      json_fail(
          src, "animation.head_motion.interp",
          "unknown value \"" + m.interp + "\"; expected one of \"step\", \"linear\", \"smooth\"");
    if (a.wind.velocity_gust && !(a.wind.velocity_gust->t1 >= a.wind.velocity_gust->t0))
      json_fail(src, "animation.wind.velocity_gust.t1",
                fmt::format("t1 ({}) must not be before t0 ({})", a.wind.velocity_gust->t1,
                            a.wind.velocity_gust->t0));
    if (m.kind == HeadMotionKind::Keyframes && m.keys.empty())
      json_fail(src, "animation.head_motion.keys", "kind \"keyframes\" needs at least one key");
    for (std::size_t k = 1; k < m.keys.size(); ++k)
      if (!(m.keys[k].t > m.keys[k - 1].t))
        json_fail(src, index_path("animation.head_motion.keys", k) + ".t",
                  "key times must increase strictly");
  }
  if (hand) {
    try {
      hand->validate();
    } catch (const Error& e) {
      json_fail(src, "hand", e.what());
    }
  }
  if (lcp) {
    try {
      lcp->validate();
    } catch (const Error& e) {
      json_fail(src, "lcp", e.what());
    }
    if (!lcp->mesh.empty() && !names.count(lcp->mesh)) {
      const std::vector<std::string> known(names.begin(), names.end());
      const std::string hint = suggest(lcp->mesh, known);
      json_fail(src, "lcp.mesh",
                "no mesh asset named \"" + lcp->mesh + "\"" +
                    (hint.empty() ? "" : " (did you mean \"" + hint + "\"?)") +
                    "; the LCP hair grows on a mesh of assets.meshes with that name");
    }
  }
  {  // skin_section.cpp
    std::vector<std::string> mesh_names;
    for (const auto& m : assets.meshes) mesh_names.push_back(m.name);
    validate_skin_section(skin, mesh_names, animation.has_value(), src);
  }
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    const auto& o = outputs[i];
    const std::string p = index_path("outputs", i) + ".path";
    if (o.path.empty()) json_fail(src, p, "output path is empty");
    if (o.type == OutputType::Image) {
      auto ext = std::filesystem::path(o.path).extension().string();
      for (auto& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
      if (ext != ".png")
        json_fail(src, p, "an image output must end in .png, got \"" + o.path + "\"");
    }
  }
}

Scene read_scene(const Json& j, const JsonSource& src) {
  if (!j.is_object())
    json_fail(src, "",
              "expected a JSON object with \"follicle_scene\": 1, got " + describe_json(j));
  auto v = j.find("follicle_scene");
  if (v == j.end())
    json_fail(src, "follicle_scene",
              fmt::format("missing required key \"follicle_scene\" (the scene format version; "
                          "this Follicle reads {}): is this a Follicle scene file?",
                          kSceneVersion));
  if (!v->is_number_integer())
    json_fail(src, "follicle_scene",
              "expected the integer scene format version, got " + describe_json(*v));
  if (v->get<long long>() != kSceneVersion)
    json_fail(src, "follicle_scene",
              fmt::format("unsupported scene format version {}: this Follicle reads version {}",
                          v->dump(), kSceneVersion));
  Scene s;
  read_json(j, "", s, src);
  s.validate(src);
  return s;
}

Scene load_scene_file(const std::filesystem::path& path) {
  return read_scene(parse_json_file(path), JsonSource{path.string()});
}

Json write_scene(const Scene& s) {
  return to_json(s);
}

}  // namespace follicle::scene
