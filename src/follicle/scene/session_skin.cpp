// Session: face rigs of the "skin" section (Bando 2002 §2.5, §2.7). Each rig deforms one mesh
// asset (in the mesh file's coordinates, metres; the asset transform is applied by the renderer)
// with Waters muscles, subcutaneous tissue and large-scale wrinkles; the pose is the section's
// expression or its contraction track sampled at the frame time. Rigs build on first use.
#include <fmt/format.h>

#include <filesystem>

#include "follicle/core/error.hpp"
#include "follicle/core/log.hpp"
#include "follicle/image/image_io.hpp"
#include "follicle/render/lafortune.hpp"
#include "follicle/scene/session.hpp"
#include "follicle/scene/skin_runtime.hpp"
#include "follicle/skin/skin_color_bando2002.hpp"

namespace follicle::scene {

namespace {

std::vector<std::string> expression_names(const skin::MuscleSet& set) {
  std::vector<std::string> out;
  for (const auto& e : set.expressions) out.push_back(e.name);
  return out;
}

// expression * weight, then explicit contractions and jaw angle; errors name the JSON path.
skin::MusclePose resolve_pose(const skin::MuscleSet& set, const std::string& expression,
                              double weight, const std::map<std::string, double>& contractions,
                              const std::optional<double>& jaw, const JsonSource& src,
                              const std::string& path, const std::string& setup_file) {
  const skin::Expression* expr = nullptr;
  for (const auto& e : set.expressions)
    if (e.name == expression) expr = &e;
  if (!expr) {
    const auto names = expression_names(set);
    const std::string hint = suggest(expression, names);
    json_fail(src, path + ".expression",
              "unknown expression \"" + expression + "\"" +
                  (hint.empty() ? "" : " (did you mean \"" + hint + "\"?)") + "; " + setup_file +
                  " has " + detail::quoted_list(names));
  }
  skin::MusclePose pose = skin::pose_from_expression(set, *expr, weight);
  for (const auto& [name, k] : contractions) {
    int idx = -1;
    try {
      idx = set.muscle_index(name);
    } catch (const Error& e) {
      json_fail(src, path + ".contractions." + name, std::string(e.what()) + " in " + setup_file);
    }
    pose.contractions[std::size_t(idx)] = k;
  }
  if (jaw) pose.jaw_angle = *jaw;
  return pose;
}

}  // namespace

SkinRuntime& Session::skin_runtime() {
  if (!m_skin) m_skin = std::make_shared<SkinRuntime>();
  if (m_skin->rigs.size() != m_scene.skin.size()) m_skin->rigs.resize(m_scene.skin.size());
  return *m_skin;
}

void Session::validate_skin_files() const {
  const JsonSource src{m_source};
  for (std::size_t i = 0; i < m_scene.skin.size(); ++i) {
    const auto& s = m_scene.skin[i];
    const std::string p = index_path("skin", i);
    const auto file = resolve(s.muscles);
    if (!std::filesystem::is_regular_file(file))
      json_fail(src, p + ".muscles", "face-setup file not found: " + file.string());
    if (!s.tissue.thickness_map.empty()) {
      const auto tex = resolve(s.tissue.thickness_map);
      if (!std::filesystem::is_regular_file(tex))
        json_fail(src, p + ".tissue.thickness_map", "thickness map not found: " + tex.string());
    }
  }
}

void Session::resolve_skin(std::size_t ri) {
  auto& rt = skin_runtime();
  auto& r = rt.rigs.at(ri);
  if (r.resolved) return;
  const SkinSpec& s = m_scene.skin[ri];
  const JsonSource src{m_source};
  const std::string p = index_path("skin", ri);
  const std::string file = resolve(s.muscles).string();
  skin::FaceSetup setup = skin::load_face_setup(file);  // errors name the setup file and path
  // Wrinkle edits: r for every wrinkle, then per-wrinkle overrides, then extra wrinkles.
  if (s.wrinkle_r)
    for (auto& w : setup.wrinkles) w.r = *s.wrinkle_r;
  for (std::size_t k = 0; k < s.wrinkle_overrides.size(); ++k) {
    const auto& o = s.wrinkle_overrides[k];
    const std::string op = index_path(p + ".wrinkle_overrides", k);
    skin::LargeWrinkle* w = nullptr;
    std::vector<std::string> names;
    for (auto& x : setup.wrinkles) {
      if (x.name == o.name) w = &x;
      names.push_back(x.name);
    }
    if (!w) {
      const std::string hint = suggest(o.name, names);
      json_fail(src, op + ".name",
                "no wrinkle named \"" + o.name + "\" in " + file +
                    (hint.empty() ? "" : " (did you mean \"" + hint + "\"?)"));
    }
    if (o.depth) w->depth = *o.depth;
    if (o.width) w->width = *o.width;
    if (o.r) w->r = *o.r;
    if (o.end_taper) w->end_taper = *o.end_taper;
    if (o.p0) w->control[0] = *o.p0;
    if (o.p1) w->control[1] = *o.p1;
    if (o.p2) w->control[2] = *o.p2;
    if (o.p3) w->control[3] = *o.p3;
  }
  for (const auto& w : s.add_wrinkles) setup.wrinkles.push_back(w);
  // Poses: the still expression and the track keys (checked against the muscle set).
  r.static_pose = resolve_pose(setup.muscles, s.expression, s.weight, s.contractions, s.jaw_angle,
                               src, p, file);
  if (!s.track.empty()) {
    const std::size_t nm = setup.muscles.num_muscles();
    std::vector<std::vector<anim::Key<double>>> keys(nm);
    std::vector<anim::Key<double>> jaw;
    for (std::size_t k = 0; k < s.track.size(); ++k) {
      const auto& key = s.track[k];
      const auto pose = resolve_pose(setup.muscles, key.expression, key.weight, key.contractions,
                                     key.jaw_angle, src, index_path(p + ".track", k), file);
      for (std::size_t m = 0; m < nm; ++m) keys[m].push_back({key.t, pose.contractions[m]});
      jaw.push_back({key.t, pose.jaw_angle});
    }
    const auto interp = anim::parse_interp(s.interp);
    for (std::size_t m = 0; m < nm; ++m)
      r.muscle_tracks.emplace_back(std::move(keys[m]), interp, p + ".track");
    r.jaw_track = anim::ScalarTrack(std::move(jaw), interp, p + ".track");
  }
  r.setup = std::move(setup);
  r.resolved = true;
}

void Session::load_skin_setups() {
  for (std::size_t i = 0; i < m_scene.skin.size(); ++i) resolve_skin(i);
}

const skin::FaceRig& Session::face_rig(std::size_t ri) {
  if (ri >= m_scene.skin.size())
    fail("skin rig {} out of range ({} rigs)", ri, m_scene.skin.size());
  resolve_skin(ri);
  auto& r = skin_runtime().rigs[ri];
  if (r.rig) return *r.rig;
  const SkinSpec& s = m_scene.skin[ri];
  const std::string where = fmt::format("{}: skin[{}] (mesh \"{}\")", m_source, ri, s.mesh);
  const auto base = mesh(mesh_index(s.mesh));
  if (base->uvs.empty())
    fail("{}: the mesh has no texture coordinates; the wrinkles live in texture space", where);
  skin::FaceRigParams fp;
  fp.tissue = s.tissue;
  fp.refine = s.refine;
  fp.wrinkles_enabled = s.wrinkles;
  std::optional<image::ImageF> thickness;
  if (!s.tissue.thickness_map.empty()) {
    const auto f = resolve(s.tissue.thickness_map);
    auto ext = f.extension().string();
    for (auto& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (ext == ".exr") {
      thickness = image::read_exr_gray(f);
    } else {
      const auto g = image::read_png_gray(f);
      image::ImageF t(g.width(), g.height());
      for (int y = 0; y < g.height(); ++y)
        for (int x = 0; x < g.width(); ++x) t.at(x, y) = float(g.at(x, y)) / 255.0f;
      thickness = std::move(t);
    }
  }
  try {
    r.rig = std::make_unique<skin::FaceRig>(*base, r.setup.muscles, r.setup.wrinkles, fp,
                                            thickness ? &*thickness : nullptr);
  } catch (const Error& e) {
    fail("{}: {}", where, e.what());
  }
  m_ctx->log().info("{}: face rig with {} muscles, {} wrinkles, {} vertices after refinement",
                    where, r.setup.muscles.num_muscles(), r.setup.wrinkles.size(),
                    r.rig->rest_mesh().positions.size());
  if (s.albedo == SkinAlbedo::SkinColor) {
    const auto c = skin::skin_vertex_colors(s.color.resolve(), r.rig->rest_mesh().positions.size());
    r.colors.reserve(c.size());
    for (const auto& v : c) r.colors.push_back(v.cast<float>());
  }
  return *r.rig;
}

skin::MusclePose Session::skin_pose(std::size_t ri, int frame) {
  if (ri >= m_scene.skin.size())
    fail("skin rig {} out of range ({} rigs)", ri, m_scene.skin.size());
  if (frame < 0) fail("frame {} is negative", frame);
  resolve_skin(ri);
  const auto& r = skin_runtime().rigs[ri];
  if (r.muscle_tracks.empty()) return r.static_pose;
  const double t = frame_time(frame);
  skin::MusclePose pose;
  pose.contractions.reserve(r.muscle_tracks.size());
  for (const auto& tr : r.muscle_tracks) pose.contractions.push_back(tr.value(t));
  pose.jaw_angle = r.jaw_track.value(t);
  return pose;
}

std::shared_ptr<const geom::TriMesh> Session::skin_mesh(std::size_t ri, int frame) {
  const skin::FaceRig& rig = face_rig(ri);
  auto& r = skin_runtime().rigs[ri];
  const bool still = r.muscle_tracks.empty();
  if (r.last && (r.last_frame == frame || (still && r.last_frame == -2))) return r.last;
  rig.update(*m_ctx, skin_pose(ri, frame), r.state);
  r.last = std::make_shared<const geom::TriMesh>(rig.deformed_mesh(r.state));
  r.last_frame = still ? -2 : frame;
  return r.last;
}

std::optional<std::size_t> Session::skin_rig_of_mesh(std::size_t asset) const {
  const auto& name = m_scene.assets.meshes.at(asset).name;
  if (name.empty()) return std::nullopt;
  for (std::size_t i = 0; i < m_scene.skin.size(); ++i)
    if (m_scene.skin[i].mesh == name) return i;
  return std::nullopt;
}

void Session::apply_skin(std::size_t asset, render::MeshItem& item, int frame) {
  const auto ri = skin_rig_of_mesh(asset);
  if (!ri) return;
  const SkinSpec& s = m_scene.skin[*ri];
  item.mesh = skin_mesh(*ri, frame);
  auto& mat = item.material;
  if (s.shading == SkinShading::Lafortune) {
    mat.shading = render::MeshShading::LafortuneSkin;
    mat.lafortune = render::lafortune_skin_marschner();
  } else {
    mat.shading = render::MeshShading::BlinnPhong;
  }
  if (s.albedo == SkinAlbedo::SkinColor) {
    mat.albedo_map.reset();
    item.vertex_colors = skin_runtime().rigs[*ri].colors;
  }
}

}  // namespace follicle::scene
