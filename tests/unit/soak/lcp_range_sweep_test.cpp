// Range sweep (issue 22, label "slow"): every numeric simulation parameter of the loosely
// connected particles (LcpParams, with its nested implicit and contact settings) set to the
// minimum and to the maximum of its documented range, one at a time, the others at their
// defaults; each setting runs a small back-hair scene through a head shake for 0.5 s with both
// integrators, and must either be refused (by validate() with a message naming the key, or by
// the first step before it integrates anything: the leapfrog's sub-step cap and fixed sub-steps
// depend on the step length) or run to the end with every particle finite. The list of settings
// that ran, failed or were refused is printed. Run with `ctest -L slow` or FOLLICLE_SLOW_TESTS=1
// tools/test.sh.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include "../hair/lcp_test_scenes.hpp"
#include "follicle/anim/rigid_motion.hpp"
#include "follicle/core/error.hpp"
#include "follicle/hair/lcp_bando2003.hpp"

using namespace follicle;
using namespace follicle::hair;

namespace {

struct Knob {
  std::string path;
  double min, max;
  std::function<void(LcpParams&, double)> set;
};

// Collects every finite-ranged numeric field of LcpParams (nested structs by path) with a setter.
struct Collector {
  std::vector<Knob>* out;
  std::string prefix;
  std::function<void*(LcpParams&)> base;  // the struct being visited inside a LcpParams
  template <class T>
  void operator()(const char* name, T& value, const ParamInfo& info = {}) {
    const std::string path = prefix.empty() ? name : prefix + "." + name;
    const std::ptrdiff_t off = reinterpret_cast<char*>(&value) - static_cast<char*>(base_ptr);
    auto field = [b = base, off](LcpParams& p) -> T& {
      return *reinterpret_cast<T*>(static_cast<char*>(b(p)) + off);
    };
    if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>) {
      if (!std::isfinite(info.min) || !std::isfinite(info.max)) return;
      // max_speed is the blow-up detector's threshold, not a simulation parameter: a run whose
      // hair moves faster than the caller's own limit is reported by design.
      if (path == "max_speed") return;
      out->push_back(
          {path, info.min, info.max, [field](LcpParams& p, double v) { field(p) = T(v); }});
    } else if constexpr (std::is_class_v<T> && !std::is_same_v<T, std::string> &&
                         !std::is_same_v<T, Vec3> && !std::is_same_v<T, Vec2>) {
      if constexpr (requires { value.visit(*this); }) {
        Collector inner{out, path, [field](LcpParams& p) -> void* { return &field(p); }, &value};
        value.visit(inner);
      }
    }
  }
  void* base_ptr = nullptr;
};

std::vector<Knob> knobs() {
  std::vector<Knob> out;
  LcpParams proto;
  Collector c{&out, "", [](LcpParams& p) -> void* { return &p; }, &proto};
  proto.visit(c);
  return out;
}

// Runs the scene; "" when it ran to the end with finite particles, else what went wrong.
std::string run(const Context& ctx, const test::LcpScene& sc, const LcpParams& p) {
  LcpSolver solver(p, sc.init.model, &sc.body);
  LcpState s = solver.rest_state();
  LcpWorkspace ws;
  const auto track = anim::RigidMotionTrack::shake(Vec3::Zero(), Vec3::UnitY(), 0.5, 2, 0.0, 0.5);
  const double dt = 1.0 / 60;
  for (int k = 0; k < 30; ++k) {
    LcpStepInput in;
    in.dt = dt;
    in.head = track.sample(k * dt);
    const auto rep = solver.step(ctx, in, s, ws);
    if (!rep.ok) return fmt::format("frame {}: {}", k, rep.message);
  }
  for (const Vec3& x : s.x)
    if (!x.allFinite()) return "a non-finite position";
  return "";
}

}  // namespace

TEST(LcpRangeSweep, EveryDocumentedValueRunsOrIsRefusedAtValidation) {
  Context ctx(2);
  const auto sc = test::lcp_small_scene(ctx, 0.02, 0.1);
  const std::vector<Knob> ks = knobs();
  ASSERT_GT(ks.size(), 20u);
  int ran = 0, refused = 0;
  std::vector<std::string> failures;
  for (const char* integrator : {"leapfrog", "implicit"})
    for (const Knob& k : ks)
      for (const double v : {k.min, k.max}) {
        LcpParams p;
        p.integrator = integrator;
        k.set(p, v);
        const std::string what = fmt::format("{} {} = {}", integrator, k.path, v);
        try {
          p.validate();
        } catch (const Error& e) {
          ++refused;
          std::printf("refused: %s: %s\n", what.c_str(), e.what());
          EXPECT_NE(std::string(e.what()).find(k.path), std::string::npos) << e.what();
          continue;
        }
        const std::string err = run(ctx, sc, p);
        if (err.empty()) {
          ++ran;
        } else if (err.rfind("frame 0: ", 0) == 0 && err.find("blow-up") == std::string::npos &&
                   err.find("lcp.dynamics.") != std::string::npos) {
          ++refused;  // refused by the first step with the key to change
          std::printf("refused at the first step: %s: %s\n", what.c_str(), err.c_str());
        } else {
          failures.push_back(what + ": " + err);
          std::printf("FAILED: %s: %s\n", what.c_str(), err.c_str());
        }
      }
  std::printf(
      "range sweep: %zu settings x 2 ends x 2 integrators: %d ran, %d refused, %zu failed\n",
      ks.size(), ran, refused, failures.size());
  EXPECT_TRUE(failures.empty()) << failures.size()
                                << " settings failed mid-run, first: " << failures.front();
}
