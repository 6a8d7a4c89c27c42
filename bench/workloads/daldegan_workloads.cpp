// Daldegan 1993 workloads (issue 19):
//   "daldegan-style"     the HairStyler (§2) grows the "long" preset on the default head
//                        (≈113,000 hairs × 20 points); timed: HairStyler construction (regions,
//                        smoothing, curve shapes) + grow.
//   "daldegan-dynamics"  the hinge dynamics (§3.1, eqs. (1)-(3)) of 10,000 typical strands × 40
//                        segments with the cylindrical body tables (§3.2, (4)-(6)) of the head,
//                        under gravity, a head turn (±turn_deg yaw at 1 Hz) and a wind from the
//                        front (`wind` m/s); timed: one HingeSolver::step (dt = 1/240 s, the
//                        HingeParams defaults but the scenes' tip_stiffness).
//   "daldegan-render"    data/scenes/daldegan_long.json trimmed to 100,000 strands: head mesh,
//                        three lights, scene and hair shadow buffers of the key light, eq. (7)
//                        blending (§4); timed: one Renderer::render call.
#include <algorithm>
#include <cmath>
#include <memory>
#include <utility>

#include "follicle/core/error.hpp"
#include "follicle/geom/mesh_io.hpp"
#include "follicle/hair/groom.hpp"
#include "follicle/hair/hair_model_daldegan1993.hpp"
#include "follicle/hair/hairstyler_daldegan1993.hpp"
#include "follicle/hair/hinge_daldegan1993.hpp"
#include "follicle/render/renderer.hpp"
#include "follicle/scene/session.hpp"
#include "follicle/sim/cylinder_table_daldegan1993.hpp"
#include "follicle/sim/ellipsoid.hpp"
#include "workloads/data_path.hpp"
#include "workloads/workload.hpp"

namespace follicle::workloads {
namespace {

geom::TriMesh load_head() {
  geom::TriMesh m = geom::load_mesh(find_data("meshes/lee_perry_smith/head.obj"), LengthUnit::mm);
  if (m.normals.empty()) m.compute_normals();
  return m;
}

void check(const sim::StepReport& r, const char* what) {
  if (!r.ok) fail("{}: {}", what, r.message);
}

// ---- daldegan-style ---------------------------------------------------------------------------

class StyleInstance final : public WorkloadInstance {
 public:
  StyleInstance(const Context& ctx, const Sizes& s) : m_ctx(ctx), m_head(load_head()) {
    m_params = hair::styler_preset("long", m_head);
    m_params.density_scale = s.at("density_scale");
    m_params.points_per_hair = int(s.at("points"));
    m_params.validate("daldegan-style");
    m_hairs = hair::HairStyler(m_head, m_params).grow(ctx).num_strands();  // untimed count
    if (m_hairs == 0) fail("daldegan-style: the long preset grew no hairs");
  }
  void run_once() override {
    const hair::HairStyler styler(m_head, m_params);
    const hair::Groom g = styler.grow(m_ctx);
    if (g.num_strands() != m_hairs) fail("daldegan-style: the hair count changed between runs");
  }
  double items_per_iter() const override { return double(m_hairs); }

 private:
  const Context& m_ctx;
  geom::TriMesh m_head;
  hair::HairStylerParams m_params;
  std::size_t m_hairs = 0;
};

// ---- daldegan-dynamics ------------------------------------------------------------------------

class DynamicsInstance final : public WorkloadInstance {
 public:
  static constexpr const char* kWhat = "daldegan-dynamics: the typical strands blew up";
  static constexpr int kWarmup = 48;  // steps (0.2 s): the hair has left its styled pose

  DynamicsInstance(const Context& ctx, const Sizes& s)
      : m_ctx(ctx), m_turn(s.at("turn_deg") * kPi / 180.0), m_wind(s.at("wind")) {
    const auto strands = std::size_t(s.at("strands"));
    const int segments = int(s.at("segments"));
    if (strands < 1) fail("daldegan-dynamics: strands must be >= 1");
    if (segments < 1) fail("daldegan-dynamics: segments must be >= 1");
    geom::TriMesh head = load_head();
    // §3.4 step 1: the style at full density, `strands` typical strands spread evenly through it
    // (the groom's order is spatial), resampled to `segments` segments.
    const hair::Groom full = hair::grow_hairstyler(ctx, head, hair::styler_preset("long", head));
    const auto idx = hair::select_guides(full.num_strands(), strands);
    if (idx.size() < strands)
      fail("daldegan-dynamics: the long preset has only {} hairs, {} asked", full.num_strands(),
           strands);
    hair::Groom typical;
    for (uint32_t k : idx) {
      const uint32_t b = full.strands.strand_begin(k);
      typical.strands.add_strand(
          std::vector<Vec3f>(full.strands.points.begin() + b,
                             full.strands.points.begin() + b + full.strands.strand_size(k)));
    }
    typical = hair::resample_groom_fixed(typical, std::size_t(segments) + 1);
    // Head frame: origin at the fitted hull's centre, its axes (y up, z to the face).
    const sim::Ellipsoid hull = sim::fit_head_ellipsoid(head.positions);
    m_centre = hull.centre;
    m_rh = hull.rotation;
    for (auto& p : typical.strands.points)
      p = (m_rh.transpose() * (p.cast<double>() - m_centre)).cast<float>();
    for (auto& p : head.positions) p = m_rh.transpose() * (p - m_centre);
    head.normals.clear();
    head.compute_normals();
    // §3.2: cylindrical radius tables of the body (automatic head / neck / trunk bands), head
    // frame.
    auto body = std::make_shared<const sim::CylinderBody>(sim::build_cylinder_body(
        ctx, head, Vec3::UnitY(), Vec3::UnitZ(), sim::CylinderBodyParams{}));
    // HingeParams defaults except the tip stiffness, which is that of the shipped Daldegan scenes
    // (data/scenes/daldegan_*.json: 0.03); the default 1 blows up here within 1-3 s of wind or
    // head turn (see docs/performance/daldegan.md).
    hair::HingeParams hp;
    hp.tip_stiffness = s.at("tip_stiffness");
    m_solver = std::make_unique<hair::HingeSolver>(hp, typical.strands, body);
    m_state = m_solver->initial_state();
    for (int k = 0; k < kWarmup; ++k) run_once();
  }

  // Gravity, a wind from the front of the face (drag, §3.4 Fig. 4) and the head turning left and
  // right about its vertical axis (Fig. 5): yaw = A sin(ωt), A = turn_deg, ω = 2π rad/s.
  hair::HingeInput input(double t) const {
    const double A = m_turn, w = 2.0 * kPi;
    hair::HingeInput in;
    in.wind_velocity = -m_wind * m_rh.col(2);
    const Vec3 axis = m_rh.col(1);
    const double yaw = A * std::sin(w * t);
    in.head.position = m_centre;  // the axis passes through the hull centre
    in.head.rotation = Quat(Eigen::AngleAxisd(yaw, axis)) * Quat(m_rh);
    in.head.angular_velocity = axis * (A * w * std::cos(w * t));
    in.head.angular_acceleration = axis * (-A * w * w * std::sin(w * t));
    return in;
  }
  void run_once() override {
    const double t = double(m_state.step) * m_solver->params().dt;
    check(m_solver->step(m_ctx, input(t), m_state), kWhat);
  }
  double items_per_iter() const override { return 1.0; }

 private:
  const Context& m_ctx;
  double m_turn = 0, m_wind = 0;  // [rad] yaw amplitude, [m/s] wind speed
  Vec3 m_centre = Vec3::Zero();
  Mat3 m_rh = Mat3::Identity();
  std::unique_ptr<hair::HingeSolver> m_solver;
  hair::HingeState m_state;
};

// ---- daldegan-render --------------------------------------------------------------------------

// Keeps the first n strands of s.
void truncate_strands(geom::StrandSet& s, std::size_t n) {
  if (s.num_strands() <= n) return;
  s.offsets.resize(n + 1);
  const std::size_t np = s.offsets.back();
  s.points.resize(np);
  if (!s.color.empty()) s.color.resize(np);
  if (!s.radius.empty()) s.radius.resize(np);
}

class RenderInstance final : public WorkloadInstance {
 public:
  RenderInstance(const Context& ctx, const Sizes& sz) {
    const auto scenes = find_data("scenes");
    const std::size_t want = std::size_t(sz.at("strands"));
    if (want < 1) fail("daldegan-render: strands must be >= 1");
    scene::Json j = scene::parse_json_file(scenes / "daldegan_long.json");
    // Density for the wanted count (the styled groom only, no dynamics): scale the shipped
    // count with 3 % slack, then trim.
    std::size_t n1 = 0;
    {
      auto probe = scene::Session::from_json(j, scenes, "daldegan_long.json", ctx);
      n1 = probe.hair_groom(0)->num_strands();
    }
    if (n1 == 0) fail("daldegan-render: the long preset grew no strands");
    j["hair"][0]["density_scale"] = std::min(100.0, double(want) / double(n1) * 1.03);
    // The settle of the typical strands before frame 0 (setup only); < 0 keeps the scene's.
    if (sz.at("settle_time") >= 0.0) j["hair"][0]["daldegan"]["settle_time"] = sz.at("settle_time");
    j["render"]["width"] = int(sz.at("width"));
    j["render"]["height"] = int(sz.at("height"));
    j["render"]["supersample"] = int(sz.at("supersample"));
    auto session = scene::Session::from_json(j, scenes, "daldegan_long.json", ctx);
    m_scene = session.render_scene(0);  // settles the typical strands, wisps (untimed)
    // One item per hair material (one in this scene): trim the strand items to `want` in all.
    std::size_t left = want;
    for (auto& item : m_scene.strands) {
      auto hair = std::make_shared<geom::StrandSet>(*item.strands);
      truncate_strands(*hair, left);
      left -= hair->num_strands();
      m_strands += hair->num_strands();
      item.strands = std::move(hair);
    }
    m_settings = session.render_settings();
    m_renderer = render::Renderer::create_headless(ctx);
    (void)m_renderer->render(m_scene, m_settings);  // warm-up: shaders, targets, textures
  }
  void run_once() override { (void)m_renderer->render(m_scene, m_settings); }
  double items_per_iter() const override { return double(m_strands); }

 private:
  render::RenderScene m_scene;
  render::RenderSettings m_settings;
  std::unique_ptr<render::Renderer> m_renderer;
  std::size_t m_strands = 0;
};

}  // namespace

void add_daldegan_workloads(std::vector<Workload>& out) {
  out.push_back({"daldegan-style",
                 "HairStyler (Daldegan 1993 §2): grow the long preset on the default head",
                 {{"density_scale", 1.0}, {"points", 20}},
                 "hairs/s",
                 [](const Context& ctx, const Sizes& s) -> std::unique_ptr<WorkloadInstance> {
                   return std::make_unique<StyleInstance>(ctx, s);
                 }});
  out.push_back({"daldegan-dynamics",
                 "hinge dynamics (Daldegan 1993 §3) with cylinder-table collision, one step "
                 "(1/240 s) under gravity, wind and a head turn",
                 {{"strands", 10000},
                  {"segments", 40},
                  {"turn_deg", 30},
                  {"wind", 3},
                  {"tip_stiffness", 0.03}},
                 "steps/s",
                 [](const Context& ctx, const Sizes& s) -> std::unique_ptr<WorkloadInstance> {
                   return std::make_unique<DynamicsInstance>(ctx, s);
                 }});
  out.push_back({"daldegan-render",
                 "render the long style (daldegan_long.json) with scene and hair shadow buffers "
                 "and eq. (7) headless (settle_time < 0: the scene's)",
                 {{"strands", 100000},
                  {"width", 1024},
                  {"height", 1024},
                  {"supersample", 1},
                  {"settle_time", -1}},
                 "strands/s",
                 [](const Context& ctx, const Sizes& sz) -> std::unique_ptr<WorkloadInstance> {
                   return std::make_unique<RenderInstance>(ctx, sz);
                 }});
}

}  // namespace follicle::workloads
