// Bando 2003 LCP hair workloads (issue 6). What one "step" (one run_once) is:
//  - "lcp-step": one LcpSolver::step() of dt = 0.1 ms with exactly one leapfrog sub-step (fixed,
//    cfl = 0) of the back hair, about 2,000 particles, hair-hair interaction and body collision
//    on: the unit cost that the adaptive sub-stepping multiplies.
//  - "lcp-frame": one 1/60 s animation frame of the same scene with the default adaptive
//    sub-stepping (as many leapfrog sub-steps as the CFL rule needs): comparable to the paper's
//    per-frame figure. Size clip=1 (default): the hair settled for 0.5 s under gravity, then
//    the head shake of Fig. 3.8 (0.7 rad about +y, 0.5 s per cycle), the thesis's animation;
//    clip=0: the fall from the initial cantilever shape (after the 20 ms warm-up), the hardest
//    transient (the hair at up to 1.7 m/s). Iterations cycle through the clip's first `frames`
//    frames (default 30: one shake cycle) and then start over from its first state, so every run
//    times the same motion (until the twenty-second session each iteration went on from the
//    last one: the frames timed depended on how many iterations the timer asked for, and long
//    runs timed hair that had come to rest).
//  - "lcp-wind": one hair step of dt = the hair's stable sub-step (the adaptive rule of
//    LcpParams::cfl at the rest state, ≈ 0.12 ms at the default sizes; one leapfrog sub-step)
//    for a block of hanging strands (100,000 hair particles) in SPH wind (25,000 air
//    particles), two-way coupled by hair::LcpWindCoupling. The air advances at its own stable step
//    (SphAir::stable_step at the start, ≈ 1.1 ms, cut to a whole number k of hair steps, k ≈ 9 at
//    the default sizes): every k-th iteration runs one air step of k dt, whose mean drag force the
//    next k hair steps apply (multi-rate coupling; the scenes couple coarser still, once per scene
//    step of 1/(fps steps_per_frame) ≈ 21 ms). Size "air_every" sets k (1: an air step with every
//    hair step, the tightest coupling; 0, the default: the air's stable step). After one untimed
//    step (allocation). A blow-up fails the benchmark. (Until the ninth session dt was a fixed
//    0.2 ms, twice the stable sub-step: the hair's speed grew without bound and the run blew up
//    after ≈ 400 steps; until the tenth the air stepped with every hair step.)
//  - "lcp-wind-frame": the same block and air, one 1/60 s animation frame per iteration with the
//    implicit hair integrator (ADR 0014): the air over the frame first (SphAir::step sub-steps at
//    its stable step, the hair held at the frame's start), then one implicit hair step of the
//    frame with the air's mean drag (as the scenes couple, once per scene step). Size "implicit"
//    of "lcp-frame" (default 1) selects the same integrator there (0: adaptive leapfrog).
// Size "simd" (default 1): 0 runs the scalar hair-hair pair loop instead of the AVX2 batch
// kernel (same results, ADR 0008), for A/B timing.
#include <cmath>
#include <memory>

#include "follicle/core/error.hpp"
#include "follicle/core/log.hpp"
#include "follicle/hair/lcp_bando2003.hpp"
#include "follicle/hair/lcp_scenario_bando2003.hpp"
#include "follicle/hair/sph_air_bando2003.hpp"
#include "workloads/workload.hpp"

namespace follicle::workloads {

namespace {

// A blow-up (or any failed step) fails the benchmark with the step report's message.
void check(const sim::StepReport& r, const char* what) {
  if (!r.ok) fail("{}: {}", what, r.message);
}

class LcpStepInstance : public WorkloadInstance {
 public:
  LcpStepInstance(const Context& ctx, const Sizes& s, bool frame = false)
      : m_ctx(ctx), m_frame(frame) {
    // The particle count scales as spacing^-3: one correction from a trial scene.
    const double target = s.at("particles");
    hair::LcpScenarioParams sp;
    sp.spacing = 0.012;
    const double n0 = double(hair::LcpScenario(ctx, sp).state().x.size());
    sp.spacing = 0.012 * std::cbrt(n0 / target);
    hair::LcpParams fp;
    if (frame && s.at("implicit") != 0) fp.integrator = "implicit";
    if (frame) fp.implicit.speculative_contact = s.at("speculative") != 0;
    const double clip = frame ? s.at("clip") : 0;
    if (clip != 0 && clip != 1)
      fail("lcp-frame: size clip must be 0 (the fall) or 1 (the head shake), got {}", clip);
    const bool shake = clip == 1;
    if (shake) {  // Fig. 3.8: the settled hair on a head shaking about +y, 0.5 s per cycle
      sp.settle_time = 0.5;
      sp.shake = true;
    }
    m_scene = std::make_unique<hair::LcpScenario>(ctx, sp, frame ? fp : fixed_params());
    // The fall (and lcp-step): leave the rest state: 20 ms of falling in stable 0.2 ms sub-steps
    // (a single 1 ms leapfrog sub-step is beyond the CFL limit and blew the hair up, so the
    // benchmark used to time an exploded state with particles at up to 100 m/s).
    if (!shake)
      for (int k = 0; k < 100; ++k) check(m_scene->step(ctx, 2e-4), kWhat);
    m_n = double(m_scene->state().x.size());
    m_scene->use_simd(s.at("simd") != 0);  // after the warm-up: the same state either way
    if (frame) {
      m_frames = int(s.at("frames"));
      if (m_frames < 1) fail("lcp-frame: size frames must be >= 1 (got {})", m_frames);
      m_start = m_scene->state();
    }
  }
  static hair::LcpParams fixed_params() {
    hair::LcpParams p;
    p.substeps = 1;  // one sub-step per iteration: the cost the CFL sub-stepping multiplies
    p.cfl = 0;
    return p;
  }
  void run_once() override {
    if (m_frame && m_done == m_frames) {  // replay the same clip: every run times the same frames
      m_scene->restore(m_start);
      m_done = 0;
    }
    check(m_scene->step(m_ctx, m_frame ? 1.0 / 60 : 1e-4), kWhat);
    ++m_done;
  }
  static constexpr const char* kWhat = "lcp: the benchmark's hair blew up";
  double items_per_iter() const override { return m_n; }
  double particles() const { return m_n; }

 private:
  const Context& m_ctx;
  bool m_frame = false;
  std::unique_ptr<hair::LcpScenario> m_scene;
  double m_n = 0;
  int m_frames = 0, m_done = 0;  // frame mode: the clip's length and the frames stepped of it
  hair::LcpState m_start;        // frame mode: the clip's first state
};

// A block of hanging strands (lattice, spacing a) in an SPH wind; one hair sub-step and one air
// step per iteration.
class LcpWindInstance : public WorkloadInstance {
 public:
  LcpWindInstance(const Context& ctx, const Sizes& s, bool frame = false)
      : m_ctx(ctx), m_frame(frame) {
    const double a = 0.005;
    const int len = 100;  // particles per strand
    const int strands = std::max(1, int(std::lround(s.at("hair") / len)));
    const int nx = std::max(1, int(std::lround(std::sqrt(strands * 2.5)))),
              nz = std::max(1, strands / nx);
    const hair::LcpStrandBlock block = hair::lcp_strand_block(nx, nz, len, a);
    hair::LcpInitParams ip;
    ip.spacing = a;
    std::vector<double> mass(block.x.size(), 0.05 / double(block.x.size()));
    hair::LcpParams p;
    p.substeps = 1;
    p.cfl = 0;
    if (frame) p.integrator = "implicit";
    m_solver = std::make_unique<hair::LcpSolver>(
        p, hair::connect_particles(ctx, block.x, block.t, block.uvs, mass, ip));
    m_solver->use_simd(s.at("simd") != 0);
    m_state = m_solver->rest_state();
    // Air box around the block, spacing chosen for the requested air particle count.
    hair::SphAirParams ap;
    ap.wind_velocity = Vec3(0, 0, -3);
    ap.box_min = Vec3(-0.05, -a * len - 0.05, -0.1);
    ap.box_max = Vec3(a * nx + 0.05, 0.05, a * nz + 0.1);
    const Vec3 ext = ap.box_max - ap.box_min;
    ap.spacing = std::cbrt(ext.prod() / s.at("air"));
    ap.coupling_radius = std::min(ap.spacing, 2 * a);
    ap.max_particles = int(2 * s.at("air")) + 1000;
    m_air = std::make_unique<hair::SphAir>(ctx, ap);
    m_nh = double(block.x.size());
    m_na = double(m_air->size());
    // The sub-step the adaptive rule (default cfl) takes at the rest state.
    hair::LcpWorkspace probe;
    m_dt = frame ? 1.0 / 60 : hair::LcpParams{}.cfl / m_solver->stiffness_rate(ctx, m_state, probe);
    if (!(m_dt > 0) || !std::isfinite(m_dt)) fail("lcp-wind: no stable time step ({})", m_dt);
    // Hair steps per air step: the air's own stable step (coupled), or as given.
    const double every = frame ? 1.0 : s.at("air_every");
    if (!(every >= 0) || every > 1e6 || every != std::floor(every))
      fail("lcp-wind: air_every must be a whole number >= 0 (0: the air's stable step), got {}",
           every);
    m_coupling = hair::LcpWindCoupling(
        every > 0 ? int(every) : hair::LcpWindCoupling::air_every(ctx, *m_air, m_dt));
    ctx.log().info(
        "{}: {} hair + {} air particles, hair step {:.4f} ms, an air step every {} "
        "hair steps",
        m_frame ? "lcp-wind-frame" : "lcp-wind", block.x.size(), m_air->size(), 1e3 * m_dt,
        m_coupling.every());
    // One untimed step: it allocates the workspaces and faults in their pages (≈ 0.3 s at the
    // default sizes), which every later step reuses; timing it added ≈ 6 ms to the mean step
    // of a 3 s run.
    run_once();
  }
  void run_once() override {
    check(m_coupling.step(m_ctx, *m_solver, m_state, m_ws, *m_air, m_dt), "lcp-wind: blow-up");
  }
  double items_per_iter() const override { return 1.0; }

 private:
  const Context& m_ctx;
  bool m_frame = false;
  std::unique_ptr<hair::LcpSolver> m_solver;
  hair::LcpState m_state;
  hair::LcpWorkspace m_ws;
  std::unique_ptr<hair::SphAir> m_air;
  hair::LcpWindCoupling m_coupling{1};
  double m_nh = 0, m_na = 0;
  double m_dt = 0;  // [s] one hair step
};

}  // namespace

void add_lcp_workloads(std::vector<Workload>& out) {
  out.push_back({"lcp-step",
                 "LCP hair (Bando 2003): one step = one leapfrog sub-step of 0.1 ms, back hair, "
                 "hair-hair + body on",
                 {{"particles", 2000}, {"simd", 1}},
                 "particles/s",
                 [](const Context& ctx, const Sizes& s) -> std::unique_ptr<WorkloadInstance> {
                   return std::make_unique<LcpStepInstance>(ctx, s);
                 }});
  out.push_back(
      {"lcp-frame",
       "LCP hair (Bando 2003): one 1/60 s frame of the back hair, cycling through the first "
       "`frames` frames of a clip: clip=1 the settled hair in the head shake of Fig. 3.8, 0 its "
       "fall from the initial shape; implicit=1: the implicit integrator (ADR 0014), 0: "
       "adaptive leapfrog sub-steps; speculative=0: the implicit sub-steps bounded by the contact "
       "band instead of speculative contact (ADR 0016)",
       {{"particles", 2000},
        {"simd", 1},
        {"implicit", 1},
        {"frames", 30},
        {"clip", 1},
        {"speculative", 1}},
       "particles/s",
       [](const Context& ctx, const Sizes& s) -> std::unique_ptr<WorkloadInstance> {
         return std::make_unique<LcpStepInstance>(ctx, s, true);
       }});
  out.push_back({"lcp-wind",
                 "LCP hair in SPH wind (Bando 2003 §3.6): one hair sub-step of the stable "
                 "length (≈ 0.12 ms), two-way coupled to the air, which steps at its own "
                 "stable step (every air_every-th hair step; 0: automatic)",
                 {{"hair", 100000}, {"air", 25000}, {"air_every", 0}, {"simd", 1}},
                 "steps/s",
                 [](const Context& ctx, const Sizes& s) -> std::unique_ptr<WorkloadInstance> {
                   return std::make_unique<LcpWindInstance>(ctx, s);
                 }});
  out.push_back({"lcp-wind-frame",
                 "LCP hair in SPH wind (Bando 2003 §3.6): one 1/60 s frame of the implicit hair "
                 "(ADR 0014), the air first over the frame at its own stable sub-steps with the "
                 "hair at the frame's start, its mean drag then the hair's external force",
                 {{"hair", 100000}, {"air", 25000}, {"simd", 1}},
                 "frames/s",
                 [](const Context& ctx, const Sizes& s) -> std::unique_ptr<WorkloadInstance> {
                   return std::make_unique<LcpWindInstance>(ctx, s, true);
                 }});
}

}  // namespace follicle::workloads
