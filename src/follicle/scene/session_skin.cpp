// Session: face rigs of the "skin" section (Bando 2002 §2.5, §2.7). Each rig deforms one mesh
// asset (in the mesh file's coordinates, metres; the asset transform is applied by the renderer)
// with Waters muscles, subcutaneous tissue and large-scale wrinkles; the pose is the section's
// expression or its contraction track sampled at the frame time. Rigs build on first use.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "follicle/core/error.hpp"
#include "follicle/core/log.hpp"
#include "follicle/geom/mesh_io.hpp"
#include "follicle/geom/spatial_embree.hpp"
#include "follicle/geom/uv_locator.hpp"
#include "follicle/image/image_io.hpp"
#include "follicle/render/lafortune.hpp"
#include "follicle/scene/session.hpp"
#include "follicle/scene/skin_runtime.hpp"
#include "follicle/skin/setup_fit.hpp"
#include "follicle/skin/skin_color_bando2002.hpp"
#include "follicle/skin/wrinkle_transfer.hpp"

namespace follicle::scene {

namespace {

std::vector<std::string> expression_names(const skin::MuscleSet& set) {
  std::vector<std::string> out;
  for (const auto& e : set.expressions) out.push_back(e.name);
  return out;
}

skin::MusclePose expression_pose(const skin::MuscleSet& set, const std::string& expression,
                                 double weight, const JsonSource& src, const std::string& path,
                                 const std::string& setup_file) {
  const skin::Expression* expr = nullptr;
  for (const auto& e : set.expressions)
    if (e.name == expression) expr = &e;
  if (!expr && expression == "neutral") {
    // The default expression on a setup without one of that name (or without a setup file: a
    // blendshape rig): neutral is every muscle relaxed.
    skin::MusclePose relaxed;
    relaxed.contractions.assign(set.num_muscles(), 0.0);
    return relaxed;
  }
  if (!expr) {
    const auto names = expression_names(set);
    const std::string hint = suggest(expression, names);
    json_fail(src, path + ".expression",
              "unknown expression \"" + expression + "\"" +
                  (hint.empty() ? "" : " (did you mean \"" + hint + "\"?)") + "; " + setup_file +
                  " has " + detail::quoted_list(names));
  }
  return skin::pose_from_expression(set, *expr, weight);
}

// expression * weight (none when `expression` is empty: every muscle relaxed), then explicit
// contractions and jaw angle; errors name the JSON path.
skin::MusclePose resolve_pose(const skin::MuscleSet& set, const std::string& expression,
                              double weight, const std::map<std::string, double>& contractions,
                              const std::optional<double>& jaw, const JsonSource& src,
                              const std::string& path, const std::string& setup_file) {
  skin::MusclePose pose;
  if (expression.empty()) {
    pose.contractions.assign(set.num_muscles(), 0.0);
  } else {
    pose = expression_pose(set, expression, weight, src, path, setup_file);
  }
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

// Blendshape weights in target order (skin[].blendshapes; targets not named weigh 0). The names
// are checked against the targets by validate_skin_section.
std::vector<double> shape_weights(const std::vector<BlendshapeSpec>& targets,
                                  const std::map<std::string, double>& weights) {
  std::vector<double> w(targets.size(), 0.0);
  for (std::size_t i = 0; i < targets.size(); ++i)
    if (auto it = weights.find(targets[i].name); it != weights.end()) w[i] = it->second;
  return w;
}

// Direction keys of one fine-wrinkle field on the uv vertices of the rig's base mesh `base`.
// `asset` is the mesh asset (the same surface; `remapped`: base has a texture layout of its own,
// skin[].mapping). A key in the asset's own layout on an unchanged layout is taken as it is ("uv":
// the nearest uv vertex used by a face); anything else goes through the surface: the key's face
// and barycentric weights, its direction as a surface tangent (J_asset d, or the given tangent),
// then the base layout's uv vertex of the nearest corner and J_base^+ t scaled to the key's
// magnitude. Errors name the JSON path.
std::vector<skin::DirectionKey> fine_keys(const geom::TriMesh& base, const geom::TriMesh& asset,
                                          bool remapped,
                                          const std::vector<FineDirectionKeySpec>& keys,
                                          const JsonSource& src, const std::string& path) {
  std::vector<char> used(base.uvs.size(), 0);
  for (const auto& f : base.uv_faces)
    for (int c = 0; c < 3; ++c)
      if (f[c] >= 0 && std::size_t(f[c]) < used.size()) used[std::size_t(f[c])] = 1;
  std::unique_ptr<geom::MeshQuery> query;
  std::unique_ptr<geom::UvLocator> own;
  std::vector<skin::DirectionKey> out;
  for (std::size_t k = 0; k < keys.size(); ++k) {
    const auto& key = keys[k];
    const std::string at = index_path(path, k);
    if (key.vertex && !(*key.vertex >= 0 && std::size_t(*key.vertex) < asset.uvs.size()))
      json_fail(src, at + ".vertex",
                fmt::format("uv vertex {} out of range: the mesh has {} uv vertices", *key.vertex,
                            asset.uvs.size()));
    if ((key.vertex || key.uv || key.direction) && !asset.has_uvs())
      json_fail(src, at,
                "the mesh has no texture coordinates of its own: give the key as \"point\" (on "
                "the skin) with a \"tangent\"");
    if (!remapped && !key.point && key.direction) {
      int v = -1;
      if (key.vertex) {
        v = *key.vertex;
      } else {
        double best = 1e300;
        for (std::size_t t = 0; t < base.uvs.size(); ++t) {
          if (!used[t]) continue;
          const double d = (base.uvs[t] - *key.uv).squaredNorm();
          if (d < best) {
            best = d;
            v = int(t);
          }
        }
        if (v < 0) json_fail(src, at + ".uv", "the mesh has no texture coordinates");
      }
      out.push_back({v, *key.direction});
      continue;
    }
    // Where on the surface: a face and barycentric weights (the same faces on asset and base).
    int face = -1;
    Vec3 bary = Vec3::Zero();
    if (key.point) {
      if (!query) query = std::make_unique<geom::MeshQuery>(base);
      const auto cp = query->closest_point(*key.point);
      if (cp.face < 0 || !(cp.distance <= skin::kMuscleTolerance))
        json_fail(src, at + ".point",
                  fmt::format("lies {:.1f} mm from the skin (at most {:.0f} mm): points are metres "
                              "in the mesh's frame",
                              1e3 * cp.distance, 1e3 * skin::kMuscleTolerance));
      face = cp.face;
      bary = cp.bary;
    } else {
      if (!own) own = std::make_unique<geom::UvLocator>(asset);
      const Vec2 q = key.vertex ? asset.uvs[std::size_t(*key.vertex)] : *key.uv;
      const auto hit = own->locate(q, 1e-6);
      if (hit.face < 0)
        json_fail(src, at + (key.vertex ? ".vertex" : ".uv"),
                  fmt::format("({:.4f}, {:.4f}) lies on no triangle of the mesh's own texture "
                              "layout, so it cannot be carried to the rig's layout",
                              q.x(), q.y()));
      face = hit.face;
      bary = hit.bary;
    }
    const auto f = std::size_t(face);
    Vec3 t;
    double m;
    if (key.tangent) {
      t = *key.tangent;
      m = t.norm();
    } else {
      t = geom::uv_jacobian(asset, f) * *key.direction;
      m = key.direction->norm();
    }
    Vec2 d = Vec2::Zero();
    if (m > 0) {
      const Eigen::Matrix<double, 3, 2> jb = geom::uv_jacobian(base, f);
      d = (jb.transpose() * jb).ldlt().solve(jb.transpose() * t);
      if (!(d.allFinite() && d.norm() > 1e-12 * t.norm()))
        json_fail(src, at + (key.tangent ? ".tangent" : ".direction"),
                  "the direction lies along the skin's normal there (no direction on the skin)");
      d = d.normalized() * m;
    }
    int corner = 0;
    bary.maxCoeff(&corner);
    out.push_back({base.uv_faces[f][corner], d});
  }
  return out;
}

// The rig's base mesh: the mesh asset, or the asset in a texture space of its own (Bando 2002
// §2.4) when skin[].mapping asks for one or the asset has no UVs.
std::shared_ptr<const geom::TriMesh> rig_base_mesh(std::shared_ptr<const geom::TriMesh> asset,
                                                   const geom::TextureMappingParams& mapping,
                                                   const std::string& where, spdlog::logger& log) {
  using geom::MappingMethod;
  if (mapping.method == MappingMethod::Uv && !asset->has_uvs())
    fail(
        "{}: mapping.method \"uv\" but the mesh has no texture coordinates; use \"auto\", "
        "\"planar\" or \"cylindrical\" (Bando 2002 §2.4)",
        where);
  if (mapping.method == MappingMethod::Uv ||
      (mapping.method == MappingMethod::Auto && asset->has_uvs()))
    return asset;
  geom::TextureMappingReport rep;
  auto mapped = std::make_shared<geom::TriMesh>(geom::map_to_texture_space(*asset, mapping, &rep));
  log.info("{}: texture space ({}): {}", where,
           asset->has_uvs() ? "replacing the mesh's UVs" : "the mesh has no UVs", rep.summary());
  if (rep.flipped > 0)
    log.warn("{}: the texture mapping folds {} triangles over (wrinkles there may be misplaced)",
             where, rep.flipped);
  return mapped;
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
    if (!s.muscles.empty()) {
      const auto file = resolve(s.muscles);
      if (!std::filesystem::is_regular_file(file))
        json_fail(src, p + ".muscles", "face-setup file not found: " + file.string());
    }
    for (std::size_t k = 0; k < s.blendshapes.size(); ++k) {
      const auto file = resolve(s.blendshapes[k].path);
      if (!std::filesystem::is_regular_file(file))
        json_fail(src, index_path(p + ".blendshapes", k) + ".path",
                  "blendshape target not found: " + file.string());
    }
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
  // A rig without a face-setup file (blendshapes only) has no muscles, expressions or wrinkles
  // but those the scene adds.
  const std::string file = s.muscles.empty() ? "(no face-setup file)" : resolve(s.muscles).string();
  skin::FaceSetup setup;
  if (!s.muscles.empty())
    setup = skin::load_face_setup(file);  // errors name the setup file and path
  // Wrinkle edits: r for every wrinkle, then per-wrinkle overrides, then extra wrinkles.
  if (s.wrinkle_r) {
    for (auto& w : setup.wrinkles) w.r = *s.wrinkle_r;
    for (auto& w : setup.surface_wrinkles) w.r = *s.wrinkle_r;
  }
  for (std::size_t k = 0; k < s.wrinkle_overrides.size(); ++k) {
    const auto& o = s.wrinkle_overrides[k];
    const std::string op = index_path(p + ".wrinkle_overrides", k);
    skin::LargeWrinkle* w = nullptr;
    skin::SurfaceWrinkle* sw = nullptr;
    std::vector<std::string> names;
    for (auto& x : setup.wrinkles) {
      if (x.name == o.name) w = &x;
      names.push_back(x.name);
    }
    for (auto& x : setup.surface_wrinkles) {
      if (x.name == o.name) sw = &x;
      names.push_back(x.name);
    }
    if (!w && !sw) {
      const std::string hint = suggest(o.name, names);
      json_fail(src, op + ".name",
                "no wrinkle named \"" + o.name + "\" in " + file +
                    (hint.empty() ? "" : " (did you mean \"" + hint + "\"?)"));
    }
    if (w) {
      if (o.depth) w->depth = *o.depth;
      if (o.width) w->width = *o.width;
      if (o.r) w->r = *o.r;
      if (o.end_taper) w->end_taper = *o.end_taper;
      if (o.p0) w->control[0] = *o.p0;
      if (o.p1) w->control[1] = *o.p1;
      if (o.p2) w->control[2] = *o.p2;
      if (o.p3) w->control[3] = *o.p3;
    } else {
      if (o.p0 || o.p1 || o.p2 || o.p3)
        json_fail(src, op,
                  "\"" + o.name +
                      "\" is a surface wrinkle: its shape is its points on the skin, not Bezier "
                      "control points (edit depth, width, r, end_taper, or add the changed "
                      "wrinkle with add_surface_wrinkles)");
      if (o.depth) sw->depth = *o.depth;
      if (o.width) sw->width = *o.width;
      if (o.r) sw->r = *o.r;
      if (o.end_taper) sw->end_taper = *o.end_taper;
    }
  }
  for (const auto& w : s.add_wrinkles) setup.wrinkles.push_back(w);
  for (const auto& w : s.add_surface_wrinkles) setup.surface_wrinkles.push_back(w);
  // Poses: the still expression and the track keys (checked against the muscle set).
  r.static_pose = resolve_pose(setup.muscles, s.expression, s.weight, s.contractions, s.jaw_angle,
                               src, p, file);
  r.static_pose.shape_weights = shape_weights(s.blendshapes, s.shapes);
  if (!s.track.empty()) {
    const std::size_t nm = setup.muscles.num_muscles();
    const std::size_t ns = s.blendshapes.size();
    std::vector<std::vector<anim::Key<double>>> keys(nm), shape_keys(ns);
    std::vector<anim::Key<double>> jaw;
    for (std::size_t k = 0; k < s.track.size(); ++k) {
      const auto& key = s.track[k];
      const auto pose = resolve_pose(setup.muscles, key.expression, key.weight, key.contractions,
                                     key.jaw_angle, src, index_path(p + ".track", k), file);
      for (std::size_t m = 0; m < nm; ++m) keys[m].push_back({key.t, pose.contractions[m]});
      jaw.push_back({key.t, pose.jaw_angle});
      const auto w = shape_weights(s.blendshapes, key.shapes);
      for (std::size_t b = 0; b < ns; ++b) shape_keys[b].push_back({key.t, w[b]});
    }
    const auto interp = anim::parse_interp(s.interp);
    for (std::size_t m = 0; m < nm; ++m)
      r.muscle_tracks.emplace_back(std::move(keys[m]), interp, p + ".track");
    for (std::size_t b = 0; b < ns; ++b)
      r.shape_tracks.emplace_back(std::move(shape_keys[b]), interp, p + ".track");
    r.jaw_track = anim::ScalarTrack(std::move(jaw), interp, p + ".track");
    r.tracked = true;
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
  const auto asset = mesh(mesh_index(s.mesh));
  // The mapping's axes default to the head's declared (or fitted) orientation.
  geom::TextureMappingParams mapping = s.mapping;
  const auto& a = m_scene.assets.meshes[mesh_index(s.mesh)];
  if (mapping.up == Vec3::UnitY() && mapping.front == Vec3::UnitZ()) {
    mapping.up = a.up;
    mapping.front = a.front;
  }
  r.base = rig_base_mesh(asset, mapping, where, m_ctx->log());
  const geom::TriMesh& base = *r.base;
  const bool remapped = r.base != asset;
  if (remapped && !s.tissue.thickness_map.empty())
    fail(
        "{}: tissue.thickness_map is painted in the mesh's own texture space, and the rig maps "
        "the mesh anew ({}): drop the map, or give the mesh UVs and mapping \"uv\"",
        where, asset->has_uvs() ? "skin[].mapping" : "the mesh has no UVs");
  // The wrinkles in the rig's texture space: the setup's curves (in the texture space of the
  // mesh asset's own layout) carried to a new layout through the surface, and the surface
  // wrinkles placed on it.
  // With "wrinkles": false they are placed all the same (the refinement around them is the same
  // mesh), only not applied; curves that cannot be placed are then left out instead of refused.
  r.wrinkles.clear();
  try {
    if (!remapped) {
      r.wrinkles = r.setup.wrinkles;
    } else if (!r.setup.wrinkles.empty() && asset->has_uvs()) {
      r.wrinkles = skin::carry_wrinkles(*asset, base, r.setup.wrinkles, where);
    } else if (!r.setup.wrinkles.empty() && s.wrinkles) {
      fail(
          "{}: the face-setup file's {} wrinkles are Bezier curves in the texture space of the "
          "head it was made for, and this mesh has no texture coordinates: give them as "
          "\"surface_wrinkles\" (points on the skin, metres) in the setup or as "
          "skin[].add_surface_wrinkles, or set \"wrinkles\": false",
          where, r.setup.wrinkles.size());
    }
    const auto placed = skin::place_surface_wrinkles(base, r.setup.surface_wrinkles, where);
    r.wrinkles.insert(r.wrinkles.end(), placed.begin(), placed.end());
  } catch (const Error& e) {
    const std::string what = e.what();
    if (what.rfind(where, 0) == 0) throw;
    fail("{}: {}", where, what);
  }
  // A setup made for another head or unit would deform nothing where it should and show no
  // wrinkles, silently: measured and refused or warned with numbers (skin/setup_fit).
  {
    const auto fit = skin::measure_setup_fit(
        base, r.setup.muscles, s.wrinkles ? r.wrinkles : std::vector<skin::LargeWrinkle>{});
    for (const auto& w : skin::judge_setup_fit(fit, where)) m_ctx->log().warn("{}: {}", where, w);
  }
  skin::FaceRigParams fp;
  fp.tissue = s.tissue;
  fp.refine = s.refine;
  fp.wrinkles_enabled = s.wrinkles;
  std::optional<image::ImageF> thickness;
  if (!s.tissue.thickness_map.empty()) {
    thickness = image::read_gray_map(resolve(s.tissue.thickness_map));
  }
  // Blendshape targets, read in the mesh asset's units and checked against its topology.
  skin::Blendshapes shapes;
  if (!s.blendshapes.empty()) {
    const auto& asset_spec = m_scene.assets.meshes[mesh_index(s.mesh)];
    std::vector<std::string> names;
    std::vector<geom::TriMesh> targets;
    for (std::size_t k = 0; k < s.blendshapes.size(); ++k) {
      const auto& b = s.blendshapes[k];
      const auto file = resolve(b.path);
      const std::string bp = index_path(index_path("skin", ri) + ".blendshapes", k) + ".path";
      try {
        targets.push_back(geom::load_mesh(file, asset_spec.units));
      } catch (const Error& e) {
        json_fail(JsonSource{m_source}, bp, e.what());
      }
      names.push_back(b.name);
    }
    shapes = skin::Blendshapes::from_meshes(*asset, names, targets, where);
    for (std::size_t k = 0; k < shapes.size(); ++k)
      m_ctx->log().info("{}: blendshape \"{}\" moves {} vertices, up to {:.2f} mm", where,
                        shapes.names()[k], shapes.moved(k), 1e3 * shapes.max_offset(k));
  }
  try {
    r.rig = std::make_unique<skin::FaceRig>(base, r.setup.muscles, r.wrinkles, fp,
                                            thickness ? &*thickness : nullptr);
    r.rig->set_blendshapes(shapes);
  } catch (const Error& e) {
    fail("{}: {}", where, e.what());
  }
  m_ctx->log().info("{}: face rig with {} muscles, {} wrinkles, {} vertices after refinement",
                    where, r.setup.muscles.num_muscles(), r.wrinkles.size(),
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
  if (r.pose_override) return *r.pose_override;
  if (!r.tracked) return r.static_pose;
  const double t = frame_time(frame);
  skin::MusclePose pose;
  pose.contractions.reserve(r.muscle_tracks.size());
  for (const auto& tr : r.muscle_tracks) pose.contractions.push_back(tr.value(t));
  for (const auto& tr : r.shape_tracks) pose.shape_weights.push_back(tr.value(t));
  pose.jaw_angle = r.jaw_track.value(t);
  return pose;
}

std::shared_ptr<const geom::TriMesh> Session::skin_mesh(std::size_t ri, int frame) {
  const skin::FaceRig& rig = face_rig(ri);
  auto& r = skin_runtime().rigs[ri];
  const bool still = !r.tracked || r.pose_override.has_value();
  if (r.last && (r.last_frame == frame || (still && r.last_frame == -2))) return r.last;
  rig.update(*m_ctx, skin_pose(ri, frame), r.state);
  r.last = std::make_shared<const geom::TriMesh>(rig.deformed_mesh(r.state));
  r.last_frame = still ? -2 : frame;
  return r.last;
}

void Session::set_skin_pose(std::size_t ri, const std::string& expression, double weight,
                            const std::map<std::string, double>& contractions,
                            std::optional<double> jaw_angle) {
  if (ri >= m_scene.skin.size())
    fail("skin rig {} out of range ({} rigs)", ri, m_scene.skin.size());
  if (!std::isfinite(weight)) fail("skin[{}]: expression weight is not finite", ri);
  for (const auto& [name, k] : contractions)
    if (!std::isfinite(k)) fail("skin[{}]: contraction of \"{}\" is not finite", ri, name);
  if (jaw_angle && !std::isfinite(*jaw_angle)) fail("skin[{}]: jaw angle is not finite", ri);
  resolve_skin(ri);
  auto& r = skin_runtime().rigs[ri];
  const JsonSource src{"set_skin_pose"};
  const std::string path = index_path("skin", ri);
  r.pose_override = resolve_pose(r.setup.muscles, expression, weight, contractions, jaw_angle, src,
                                 path, m_scene.skin[ri].muscles);
  r.pose_override->shape_weights = r.static_pose.shape_weights;  // the scene's blendshape weights
  forget_frames_of_rig(ri);
}

void Session::clear_skin_pose(std::size_t ri) {
  if (ri >= m_scene.skin.size())
    fail("skin rig {} out of range ({} rigs)", ri, m_scene.skin.size());
  resolve_skin(ri);
  auto& r = skin_runtime().rigs[ri];
  if (!r.pose_override) return;
  r.pose_override.reset();
  forget_frames_of_rig(ri);
}

void Session::skin_forget_last(std::size_t ri) {
  auto& r = skin_runtime().rigs.at(ri);
  r.last.reset();
  r.last_frame = -1;
}

bool Session::skin_pose_overridden() const {
  if (!m_skin) return false;
  return std::any_of(m_skin->rigs.begin(), m_skin->rigs.end(),
                     [](const SkinRuntime::Rig& r) { return r.pose_override.has_value(); });
}

std::vector<std::string> Session::skin_muscle_names(std::size_t ri) {
  if (ri >= m_scene.skin.size())
    fail("skin rig {} out of range ({} rigs)", ri, m_scene.skin.size());
  resolve_skin(ri);
  return skin_runtime().rigs[ri].setup.muscles.muscle_names();
}

std::vector<std::string> Session::skin_expression_names(std::size_t ri) {
  if (ri >= m_scene.skin.size())
    fail("skin rig {} out of range ({} rigs)", ri, m_scene.skin.size());
  resolve_skin(ri);
  return expression_names(skin_runtime().rigs[ri].setup.muscles);
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
  if (s.fine) {
    mat.height_map = skin_fine_relief(*ri, frame);
    mat.bump_strength = s.fine->bump_strength;
  }
}

std::shared_ptr<const image::ImageF> Session::skin_fine_relief(std::size_t ri, int frame) {
  if (ri >= m_scene.skin.size())
    fail("skin rig {} out of range ({} rigs)", ri, m_scene.skin.size());
  const SkinSpec& s = m_scene.skin[ri];
  if (!s.fine) return nullptr;
  const FineWrinkleSpec& f = *s.fine;
  (void)skin_mesh(ri, frame);  // the state of this frame (cached)
  auto& r = skin_runtime().rigs[ri];
  if (!r.fine) {
    // §2.6.1-2.6.2 once per rig, on the base mesh (the mesh asset the FaceRig refines).
    const JsonSource src{m_source};
    const std::string p = index_path("skin", ri) + ".fine";
    (void)face_rig(ri);
    const auto asset = mesh(mesh_index(s.mesh));
    const auto& base = *r.base;
    // The refinement appends vertices: the base vertices come first, unchanged.
    const auto& rest = r.rig->rest_mesh().positions;
    if (rest.size() < base.positions.size() ||
        !std::equal(base.positions.begin(), base.positions.end(), rest.begin()))
      fail("{}: {}: the face rig's mesh does not start with the {} base vertices", m_source, p,
           base.positions.size());
    const bool remapped = r.base != asset;
    const std::array<std::vector<skin::DirectionKey>, 2> keys{
        fine_keys(base, *asset, remapped, f.field0, src, p + ".field0"),
        fine_keys(base, *asset, remapped, f.field1, src, p + ".field1")};
    const Context gctx(m_ctx->threads(), f.seed, m_ctx->logger_ptr());
    try {
      const skin::FineWrinkles w = skin::generate_fine_wrinkles(gctx, base, keys, f.params);
      r.fine = std::make_unique<skin::FineWrinkleAnimator>(base, w);
      r.fine_depth_m = w.depth_m;
      m_ctx->log().info("{}: fine wrinkles {}x{} texels, {} + {} furrows", p, w.texels.size,
                        w.texels.size, w.fields[0].furrows.size(), w.fields[1].furrows.size());
    } catch (const Error& e) {
      fail("{}: {}: {}", m_source, p, e.what());
    }
  }
  // The weak pointer keeps the mesh's allocation reserved: an expired one never compares equal.
  if (r.fine_height && (r.fine_for.lock() == r.last || !f.modulate)) return r.fine_height;
  auto h = std::make_shared<image::ImageF>();
  if (f.modulate) {
    // (2.3) shrinkage perpendicular to each field, measured on the animated surface (muscles,
    // jaw, tissue; no large wrinkles) at the base vertices, which are the first vertices of the
    // refined mesh; then (2.4) M(s) modulation of both height fields.
    r.fine->shrinkage(*m_ctx, r.state.animated, r.fine_s);
    r.fine->modulate(*m_ctx, r.fine_s, *h);
  } else {
    r.fine->rest_relief(*m_ctx, *h);
  }
  const float depth = float(r.fine_depth_m);
  for (float& x : h->storage()) x *= depth;  // relief units -> metres
  r.fine_height = std::move(h);
  r.fine_for = r.last;
  return r.fine_height;
}

}  // namespace follicle::scene
