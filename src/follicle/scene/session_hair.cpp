// Session: hair groups (Anjyo, Usami, Kurihara 1992) and the animation clock. Hair is styled
// once per group on the mesh at rest (the mesh asset's transform applied), in scene coordinates;
// the dynamics run in the head frame (hull centre and axes) and follow the rigid head motion.
#include <fmt/format.h>

#include <cmath>
#include <set>

#include "follicle/core/atomic_file.hpp"
#include "follicle/core/log.hpp"
#include "follicle/core/resources.hpp"
#include "follicle/geom/spatial_embree.hpp"
#include "follicle/geom/strand_io.hpp"
#include "follicle/hair/hair_model.hpp"
#include "follicle/hair/hair_model_daldegan1993.hpp"
#include "follicle/hair/hairstyler_daldegan1993.hpp"
#include "follicle/hair/pores.hpp"
#include "follicle/hair/scalp.hpp"
#include "follicle/hair/strand_cache.hpp"
#include "follicle/scene/hair_runtime.hpp"
#include "follicle/scene/session.hpp"

namespace follicle::scene {

namespace {

std::filesystem::path group_cache_dir(const std::filesystem::path& dir, std::size_t g) {
  return dir / fmt::format("hair{}", g);
}

}  // namespace

Session::~Session() = default;
Session::Session(Session&&) noexcept = default;
Session& Session::operator=(Session&&) noexcept = default;

HairRuntime& Session::hair_runtime() {
  if (!m_hair) m_hair = std::make_unique<HairRuntime>();
  if (m_hair->groups.size() != m_scene.hair.size()) m_hair->groups.resize(m_scene.hair.size());
  return *m_hair;
}

const HairStats& Session::hair_stats() const {
  static const HairStats kNone{};  // read-only empty counters (no mutable state)
  return m_hair ? m_hair->stats : kNone;
}

int Session::frame_count() const {
  return m_scene.animation ? m_scene.animation->frame_count() : 1;
}

double Session::frame_time(int frame) const {
  return m_scene.animation ? double(frame) / m_scene.animation->fps : 0.0;
}

void Session::set_strand_cache(const std::filesystem::path& dir) {
  auto& rt = hair_runtime();
  rt.cache_dir = dir;
  rt.cache_ready = false;
}

namespace {

// Everything the cached strands depend on; a cache made with other settings is discarded.
std::string cache_key(const Scene& s) {
  Json k = Json::object();
  k["cache_format"] = 2;  // 2: strands placed by the head pose at the frame time
  k["hair"] = to_json(s.hair);
  k["animation"] = to_json(s.animation);
  k["meshes"] = to_json(s.assets.meshes);
  k["grooms"] = to_json(s.assets.grooms);
  return k.dump(1) + "\n";
}

// The rigid motion of the head: x(t) = R(t) (x - pivot) + pivot + p(t).
anim::RigidMotionTrack make_track(const HeadMotionSpec& m, const Vec3& pivot) {
  const double k = kPi / 180.0;
  switch (m.kind) {
    case HeadMotionKind::Turn:
      return anim::RigidMotionTrack::turn(pivot, m.axis.normalized(), m.angle_deg * k, m.t0, m.t1);
    case HeadMotionKind::Shake:
      return anim::RigidMotionTrack::shake(pivot, m.axis.normalized(), m.angle_deg * k, m.cycles,
                                           m.t0, m.t1);
    case HeadMotionKind::Keyframes: {
      std::vector<anim::Key<Vec3>> pos, rot;
      for (const auto& key : m.keys) {
        pos.push_back({key.t, key.translate});
        rot.push_back({key.t, key.rotate_deg * k});
      }
      const auto interp = anim::parse_interp(m.interp);
      return anim::RigidMotionTrack(anim::VectorTrack(pos, interp, "animation.head_motion.keys"),
                                    anim::VectorTrack(rot, interp, "animation.head_motion.keys"),
                                    pivot);
    }
    case HeadMotionKind::None: break;
  }
  return {};
}

}  // namespace

namespace {

// The model table: one line per hair model (docs/adr/0010-one-hair-system.md).
std::unique_ptr<hair::HairSimulation> make_simulation(const Context& ctx, const HairGroupSpec& h,
                                                      const hair::HairModelSetup& setup) {
  switch (h.model) {
    case HairModel::Anjyo1992: return hair::make_anjyo1992(ctx, h.dynamics, setup);
    case HairModel::Daldegan1993: return hair::make_daldegan1993(ctx, h.daldegan, setup);
    case HairModel::Bando2003: return hair::make_bando2003(ctx, h.bando, setup);
  }
  fail("unknown hair model");
}

// Whether the model's state at t = 0 differs from the groom (it settles before frame 0), so a
// still scene must run the model instead of showing the groom.
bool settles_before_start(const HairGroupSpec& h) {
  switch (h.model) {
    case HairModel::Anjyo1992: return false;
    case HairModel::Daldegan1993: return h.daldegan.settle_time > 0.0;
    case HairModel::Bando2003: return h.bando.settle_time > 0.0;
  }
  return false;
}

}  // namespace

std::shared_ptr<const geom::StrandSet> Session::groom_strands(std::size_t index) {
  if (index >= m_scene.assets.grooms.size())
    fail("groom index {} out of range ({} grooms)", index, m_scene.assets.grooms.size());
  const auto& a = m_scene.assets.grooms[index];
  const auto file = resolve(a.path);
  const std::string key = file.lexically_normal().string() + "|" + to_string(a.units);
  auto& rt = hair_runtime();
  if (auto it = rt.groom_files.find(key); it != rt.groom_files.end()) return it->second;
  m_ctx->log().info("loading groom {} ({})", file.string(), to_string(a.units));
  geom::StrandSet s;
  try {
    s = geom::load_strands(file, a.units);
  } catch (const Error& e) {
    fail_at(m_source, "{}: {}", index_path("assets.grooms", index), e.what());
  }
  auto ptr = std::make_shared<const geom::StrandSet>(std::move(s));
  rt.groom_files.emplace(key, ptr);
  return ptr;
}

std::size_t Session::groom_index(const std::string& name) const {
  for (std::size_t i = 0; i < m_scene.assets.grooms.size(); ++i)
    if (m_scene.assets.grooms[i].name == name) return i;
  fail_at(m_source, "no groom asset named \"{}\"", name);
}

void Session::check_head_size(std::size_t mi, const geom::TriMesh& world,
                              const std::string& where) const {
  // A head is 0.2-0.3 m across, a bust up to 0.6 m. A mesh declared in the wrong units grows hair
  // for minutes and gigabytes (a cm head read as metres: 6.9 M strands, 11 GB, then a GL error), so
  // an implausible size is named with the unit that would make it a head: a warning up to 10 m and
  // 1 cm, an error beyond.
  const auto& a = m_scene.assets.meshes[mi];
  const double diag = world.bounds().diagonal().norm();
  if (!std::isfinite(diag) || diag < 0.05 || diag > 2.0) {
    std::string hint;
    for (const LengthUnit u : {LengthUnit::mm, LengthUnit::cm, LengthUnit::dm, LengthUnit::m}) {
      const double d = diag / unit_to_metres(a.units) * unit_to_metres(u);
      if (u != a.units && d >= 0.1 && d <= 1.0)
        hint = fmt::format("; with \"units\": \"{}\" it would be {:.2f} m", to_string(u), d);
    }
    const std::string msg = fmt::format(
        "mesh \"{}\" is {:.3g} m across (assets.meshes[{}].units is \"{}\"); a head or bust is "
        "0.2-0.6 m (a wrong unit grows hair for minutes and gigabytes){}",
        a.name, diag, mi, to_string(a.units), hint);
    if (!(diag <= 10.0) || diag < 0.01) fail("{}: {}", where, msg);
    m_ctx->log().warn("{}: {}", where, msg);
  }
}

void Session::build_hair_group(std::size_t gi) {
  auto& rt = hair_runtime();
  auto& g = rt.groups[gi];
  if (g.built) return;
  const HairGroupSpec& hs = m_scene.hair[gi];
  const std::string w = fmt::format("{}: hair[{}] (\"{}\")", m_source, gi, hs.name);
  const std::size_t mi = mesh_index(hs.mesh);
  geom::TriMesh world = *mesh(mi);
  world.transform(m_scene.assets.meshes[mi].transform.matrix());
  check_head_size(mi, world, w);
  auto groom = std::make_shared<hair::Groom>();
  try {
    g.hull = hair_hull(gi);
    const geom::MeshQuery query(world);
    if (!hs.groom.empty()) {  // an imported groom, placed like its asset says
      const std::size_t gai = groom_index(hs.groom);
      groom->strands = *groom_strands(gai);
      const Affine3 T = m_scene.assets.grooms[gai].transform.matrix();
      for (auto& p : groom->strands.points) p = (T * p.cast<double>()).cast<float>();
      const std::string where = fmt::format("{}: assets.grooms[{}] (\"{}\")", m_source, gai,
                                            m_scene.assets.grooms[gai].name);
      groom->check(where);
      if (hs.segment_length > 0.0) *groom = hair::resample_groom(*groom, hs.segment_length);
      const double far = hair::bind_roots(*m_ctx, query, *groom);
      if (far > 0.01)
        m_ctx->log().warn(
            "{}: a root of groom \"{}\" lies {:.1f} mm from mesh \"{}\" (check the groom's units "
            "and transform against the mesh's)",
            w, hs.groom, far * 1e3, hs.mesh);
    } else if (hs.styler) {  // grown by the HairStyler (Daldegan 1993 §2) on the mesh
      const std::string path = index_path("hair", gi) + ".styler";
      const JsonSource src{m_source};
      const Vec3 up = g.hull.rotation.col(1), front = g.hull.rotation.col(2);
      hair::HairStylerParams sp = hs.styler->resolve(world, up, front, path, src);
      sp.density_scale *= hs.density_scale;
      // The group's seed drives the styler unless the styler object names its own.
      if (!hs.styler->overrides.contains("seed")) sp.seed = hs.seed;
      hair::StylerInputs inputs;
      try {
        inputs = hair::load_styler_inputs(sp, [&](const std::string& f) { return resolve(f); });
      } catch (const Error& e) {
        fail_at(m_source, "{}.{}", path, e.what());
      }
      *groom = hair::HairStyler(world, sp, inputs).grow(*m_ctx);
      g.materials = sp.materials;
    } else {  // generated by the Anjyo 1992 styling on the hull
      const auto scalp = hair::mesh_query_closest_point(query);
      const hair::HairStyle style = hs.style.resolve(hs.density_scale);
      // Resource guard before any strand grows: pore count from the densities and the hull, and
      // the memory of the strands (points of the styled, rest and simulated copies, and the
      // drawn geometry: about six Vec3f per point).
      double expected = 0, points = 0;
      for (const auto& part : style.parts)
        for (const auto& r : part.pores) {
          const double n = hair::region_area(g.hull, r) * r.density;
          expected += n;
          points += n * (part.beam.segments + 1);
        }
      if (expected > hs.max_strands)
        fail_at("max_strands",
                "the style would grow about {} strands (pore density x hull area x "
                "density_scale), more than the budget of {}; lower density_scale or the pore "
                "densities, check the hull against the head's size, or raise max_strands",
                format_count(expected), format_count(hs.max_strands));
      check_memory("style", fmt::format("growing {} strands", format_count(expected)),
                   points * 6 * 3 * sizeof(float), "lower density_scale");
      auto styled = hair::build_style(*m_ctx, g.hull, style, hs.seed, scalp);
      groom->strands = std::move(styled.strands);
      hair::bind_roots(*m_ctx, query, *groom);
    }
  } catch (const Error& e) {
    // Errors that already name the scene file and their JSON path (styler) pass unchanged.
    if (std::string_view(e.what()).starts_with(m_source + ": hair[")) throw;
    fail("{}: {}", w, e.what());
  }
  if (double(groom->num_strands()) > hs.max_strands)
    fail(
        "{}: max_strands: the groom has {} strands, more than the budget of {}; raise "
        "max_strands or thin the groom",
        w, groom->num_strands(), format_count(hs.max_strands));
  if (groom->num_strands() == 0)
    m_ctx->log().warn(
        "{}: no strands grew: the head is bald (check the style's density and density_scale, "
        "the scalp region and the hull's size against mesh \"{}\")",
        w, hs.mesh);
  // A mesh with a skin rig deforms: the roots ride its refined surface (ride_skin).
  if (const auto ri = skin_rig_of_mesh(mi)) {
    geom::TriMesh refined = face_rig(*ri).rest_mesh();
    refined.transform(m_scene.assets.meshes[mi].transform.matrix());
    g.skin_rig = ri;
    g.skin_binding = hair::Groom{};
    g.skin_binding.strands = groom->strands;
    hair::bind_roots(*m_ctx, geom::MeshQuery(refined), g.skin_binding);
    // The strands are moved so their roots land on the bound points of the (deformed) refined
    // surface: the offset from the groom's roots (a fraction of a mm where refinement moved the
    // surface) is taken up at rest too.
    g.skin_rest_roots.resize(groom->num_strands());
    for (std::size_t k = 0; k < groom->num_strands(); ++k)
      g.skin_rest_roots[k] = groom->strands.points[groom->strands.strand_begin(k)].cast<double>();
    g.skin_binding.strands = geom::StrandSet{};  // only the bindings are needed
    g.skin_binding.strands.offsets.assign(groom->num_strands() + 1, 0);
  }
  g.groom = groom;
  g.styled = std::shared_ptr<const geom::StrandSet>(groom, &groom->strands);
  g.built = true;
  ++rt.stats.builds;
  m_ctx->log().info("{}: {} strands, {} points", w, g.styled->num_strands(),
                    g.styled->num_points());
}

void Session::forget_frames_of_rig(std::size_t ri) {
  // The skin mesh of the rig and every hair frame riding it were made with the old pose.
  skin_forget_last(ri);
  if (!m_hair) return;
  for (auto& g : m_hair->groups)
    if (g.skin_rig == ri) {
      g.last.reset();
      g.last_frame = -1;
    }
}

std::vector<Vec3> Session::hair_root_targets(std::size_t gi, int frame) {
  const auto groom = hair_groom(gi);
  auto& g = hair_runtime().groups[gi];
  const auto motion = head_motion_transform(frame);
  // Each root at its rest place (the groom's root, which may sit off the surface), moved by the
  // skin's displacement of its binding point when the mesh has a skin rig.
  std::vector<Vec3> pts(groom->num_strands());
  for (std::size_t s = 0; s < pts.size(); ++s)
    pts[s] = groom->strands.points[groom->strands.strand_begin(s)].cast<double>();
  if (g.skin_rig) {
    const std::size_t mi = mesh_index(m_scene.hair[gi].mesh);
    geom::TriMesh now = *skin_mesh(*g.skin_rig, frame);
    now.transform(m_scene.assets.meshes[mi].transform.matrix());
    const auto bound = hair::bound_root_positions(g.skin_binding, now);
    for (std::size_t s = 0; s < pts.size(); ++s) pts[s] += bound[s] - g.skin_rest_roots[s];
  }
  if (motion)
    for (auto& p : pts) p = *motion * p;
  return pts;
}

void Session::ride_skin(std::size_t gi, int frame, geom::StrandSet& strands) {
  auto& g = hair_runtime().groups[gi];
  if (!g.skin_rig) return;
  // The skin's non-rigid displacement of every root (a few mm for an expression) moves its strand
  // rigidly; the head's rigid motion is already in the strands (it drives the dynamics).
  const std::size_t mi = mesh_index(m_scene.hair[gi].mesh);
  geom::TriMesh now = *skin_mesh(*g.skin_rig, frame);
  now.transform(m_scene.assets.meshes[mi].transform.matrix());
  const auto roots = hair::bound_root_positions(g.skin_binding, now);
  const auto motion = head_motion_transform(frame);
  const Mat3 R = motion ? Mat3(motion->linear()) : Mat3::Identity();
  if (roots.size() != strands.num_strands())
    fail("hair[{}]: {} strands but {} skin-bound roots", gi, strands.num_strands(), roots.size());
  for (std::size_t s = 0; s < roots.size(); ++s) {
    const Vec3f d = (R * (roots[s] - g.skin_rest_roots[s])).cast<float>();
    for (uint32_t i = strands.strand_begin(s); i < strands.offsets[s + 1]; ++i)
      strands.points[i] += d;
  }
}

sim::Ellipsoid Session::hair_hull(std::size_t gi) {
  const HairGroupSpec& hs = m_scene.hair.at(gi);
  if (hs.hull) return hs.hull->ellipsoid();
  const std::size_t mi = mesh_index(hs.mesh);
  geom::TriMesh world = *mesh(mi);
  world.transform(m_scene.assets.meshes[mi].transform.matrix());
  return sim::fit_head_ellipsoid(world.positions, head_frame(mi), hs.hull_fit);
}

Mat3 Session::head_frame(std::size_t mi) const {
  const auto& a = m_scene.assets.meshes.at(mi);
  const Mat3 L = a.transform.matrix().linear();
  const Vec3 up = (L * a.up).normalized();
  Vec3 front = L * a.front;
  front = (front - front.dot(up) * up).normalized();  // validated: at least 30 degrees apart
  Mat3 R;
  R.col(0) = up.cross(front);
  R.col(1) = up;
  R.col(2) = front;
  return R;
}

Vec3 Session::head_motion_pivot() {
  if (m_scene.animation && m_scene.animation->head_motion.pivot)
    return *m_scene.animation->head_motion.pivot;
  if (m_scene.hair.empty()) return Vec3::Zero();
  // The bottom of the first group's hull: roughly where the neck turns the head.
  const sim::Ellipsoid h0 = hair_hull(0);
  return h0.centre - h0.rotation * Vec3(0.0, h0.radii.y(), 0.0);
}

std::shared_ptr<const hair::Groom> Session::hair_groom(std::size_t gi) {
  if (gi >= m_scene.hair.size())
    fail("hair group {} out of range ({} groups)", gi, m_scene.hair.size());
  build_hair_group(gi);
  return hair_runtime().groups[gi].groom;
}

std::shared_ptr<const geom::StrandSet> Session::hair_strands(std::size_t gi, int frame) {
  if (gi >= m_scene.hair.size())
    fail("hair group {} out of range ({} groups)", gi, m_scene.hair.size());
  if (frame < 0) fail("frame {} is negative", frame);
  auto& rt = hair_runtime();
  auto& g = rt.groups[gi];
  const HairGroupSpec& h = m_scene.hair[gi];
  const std::string where = fmt::format("{}: hair[{}] (\"{}\")", m_source, gi, h.name);

  build_hair_group(gi);
  if (g.last && g.last_frame == frame) return g.last;
  // A still scene shows the groom at rest, or the model's settled pose.
  const bool settles = settles_before_start(h);
  if (!m_scene.animation && !settles) {
    if (!g.skin_rig) return g.styled;
    auto on_skin = std::make_shared<geom::StrandSet>(*g.styled);
    ride_skin(gi, 0, *on_skin);
    g.last = std::move(on_skin);
    g.last_frame = frame;
    return g.last;
  }

  const AnimationSpec anim_spec = m_scene.animation ? *m_scene.animation : AnimationSpec{};
  if (!m_scene.animation) frame = 0;
  if (!rt.track_built) {
    if (anim_spec.head_motion.kind != HeadMotionKind::None) {
      rt.track = make_track(anim_spec.head_motion, head_motion_pivot());
    }
    rt.track_built = true;
  }

  // Strand cache: check (or start) it once; frames found there are not simulated.
  const bool use_cache = !rt.cache_dir.empty() && !skin_pose_overridden();
  if (use_cache && !rt.cache_ready) {
    const std::string key = cache_key(m_scene);
    const auto key_file = rt.cache_dir / "cache_key.json";
    std::error_code ec;
    std::filesystem::create_directories(rt.cache_dir, ec);
    if (ec)
      fail_at(rt.cache_dir.string(), "cannot create the strand cache folder: {}", ec.message());
    const bool same = std::filesystem::is_regular_file(key_file) && read_file(key_file) == key;
    if (!same) {  // stale frames from other settings: remove our own files only
      for (std::size_t i = 0; i < m_scene.hair.size(); ++i) {
        const auto d = group_cache_dir(rt.cache_dir, i);
        if (!std::filesystem::is_directory(d)) continue;
        for (const auto& e : std::filesystem::directory_iterator(d)) {
          const auto name = e.path().filename().string();
          if (name.rfind("strands_", 0) == 0 && e.path().extension() == ".fsc")
            std::filesystem::remove(e.path(), ec);
        }
      }
      write_file_atomically(key_file, key);
    }
    rt.cache_ready = true;
  }
  const auto gdir = group_cache_dir(rt.cache_dir, gi);
  if (use_cache && hair::has_strand_frame(gdir, frame)) {
    auto f = hair::read_strand_frame(gdir, frame);
    ++rt.stats.cache_reads;
    g.last = std::make_shared<const geom::StrandSet>(std::move(f.strands));
    g.last_frame = frame;
    return g.last;
  }

  // Head frame: origin at the hull centre, axes of the hull (y up, z to the face).
  const Vec3 c = g.hull.centre;
  const Mat3 Rh = g.hull.rotation;
  if (!g.sim) {
    hair::HairModelSetup setup;
    setup.rest = *g.groom;
    for (auto& p : setup.rest.strands.points)
      p = (Rh.transpose() * (p.cast<double>() - c)).cast<float>();
    setup.hull = g.hull;
    setup.hull.centre = Vec3::Zero();
    setup.hull.rotation = Mat3::Identity();
    setup.seed = h.seed;
    {  // the head surface at rest in the head frame, for models that collide with it
      const std::size_t mi = mesh_index(h.mesh);
      auto head = std::make_shared<geom::TriMesh>(*mesh(mi));
      head->transform(m_scene.assets.meshes[mi].transform.matrix());
      for (auto& p : head->positions) p = Rh.transpose() * (p - c);
      head->compute_normals();
      setup.head_mesh = std::move(head);
    }
    try {
      g.sim = make_simulation(*m_ctx, h, setup);
    } catch (const Error& e) {
      fail("{}: dynamics: {}", where, e.what());
    }
  }
  auto head_at = [&](double t) {
    hair::HeadMotion hm;
    hm.position = c;
    hm.rotation = Quat(Rh);
    if (!rt.track) return hm;
    const anim::RigidSample s = rt.track->sample(t);
    hm.position = s.apply(c);
    hm.rotation = Quat(s.rotation * Rh);
    hm.velocity = s.point_velocity(hm.position);
    hm.acceleration = s.point_acceleration(hm.position);
    hm.angular_velocity = s.angular_velocity;
    hm.angular_acceleration = s.angular_acceleration;
    return hm;
  };
  const hair::EnvironmentFn env = [&](double t) {
    hair::HairEnvironment e;
    e.gravity = anim_spec.gravity;
    e.wind = anim_spec.wind.at(t);
    e.air_velocity = anim_spec.wind.air_at(t);
    e.head = head_at(t);
    return e;
  };
  auto positions_at = [&](int f) {
    // Placed by the head pose at the frame's time, like the meshes: the model's own time may
    // differ from it by up to half a step (a frame time that is no multiple of its step), which
    // would shift the whole hair off a moving head on such frames.
    auto out = std::make_shared<geom::StrandSet>();
    g.sim->strands(head_at(frame_time(f)), *out);
    ride_skin(gi, f, *out);
    if (use_cache) {
      hair::StrandFrame sf;
      sf.frame = f;
      sf.time = frame_time(f);
      sf.strands = *out;
      hair::write_strand_frame(gdir, sf);
      ++rt.stats.cache_writes;
    }
    return std::shared_ptr<const geom::StrandSet>(std::move(out));
  };

  std::shared_ptr<const geom::StrandSet> result;
  if (g.state_frame < 0 || g.state_frame > frame) {  // (re)start deterministically at frame 0
    g.sim->reset();
    g.state_frame = 0;
    if (frame == 0 || use_cache) result = positions_at(0);
  }
  while (g.state_frame < frame) {
    const int f = g.state_frame + 1;
    const uint64_t before = g.sim->steps();
    const sim::StepReport rep = g.sim->advance(*m_ctx, frame_time(f), env);
    rt.stats.steps += g.sim->steps() - before;
    if (!rep.ok)
      fail("{}: dynamics failed at frame {} (t = {:.4f} s): {}; try a smaller time step", where, f,
           g.sim->time(), rep.message);
    g.state_frame = f;
    if (f == frame || use_cache) result = positions_at(f);
  }
  if (!result) result = positions_at(frame);  // state already at `frame` (after a cache read)
  g.last = result;
  g.last_frame = frame;
  return result;
}

std::optional<Affine3> Session::head_motion_transform(int frame) {
  if (!m_scene.animation || m_scene.animation->head_motion.kind == HeadMotionKind::None ||
      m_scene.hair.empty())
    return std::nullopt;
  auto& rt = hair_runtime();
  if (!rt.track_built) hair_strands(0, 0);  // builds the hull the default pivot needs
  if (!rt.track) return std::nullopt;
  return rt.track->sample(frame_time(frame)).transform();
}

geom::StrandSet Session::all_hair(int frame) {
  geom::StrandSet out;
  for (std::size_t i = 0; i < m_scene.hair.size(); ++i) {
    const auto s = hair_strands(i, frame);
    const uint32_t base = uint32_t(out.points.size());
    out.points.insert(out.points.end(), s->points.begin(), s->points.end());
    for (std::size_t k = 1; k < s->offsets.size(); ++k) out.offsets.push_back(base + s->offsets[k]);
  }
  return out;
}

}  // namespace follicle::scene
