// Soak (issue 24 item 2, label "slow"): every hair model runs at least 10,000 of its own steps on
// somebody else's groom (the Sintel bust and her TressFX guides) while the head shakes the whole
// time and a gusting wind blows: every frame finite, the kinetic energy bounded (the second half
// of the run never exceeds twice the first half's peak: a slow blow-up grows without bound), and
// the resident memory flat (the peak after the long run within 64 MiB of the peak after a run a
// tenth as long). Takes a few minutes (bando2003 is ~3 s per simulated second); run with
// `ctest -L slow` or FOLLICLE_SLOW_TESTS=1 tools/test.sh. Results: docs/reliability.md.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <string>

#include "follicle/core/context.hpp"
#include "follicle/scene/harness.hpp"
#include "follicle/scene/session.hpp"
#include "testing/testing.hpp"
#include "unit/scene/scene_test_util.hpp"

using namespace follicle;
using namespace follicle::scene;
using namespace follicle::scene::testutil;

namespace {

// Peak resident memory of this process [bytes] (VmHWM of /proc/self/status).
double peak_rss_bytes() {
  std::ifstream f("/proc/self/status");
  std::string key;
  while (f >> key) {
    if (key == "VmHWM:") {
      double kb = 0;
      f >> kb;
      return kb * 1024.0;
    }
    f.ignore(1 << 20, '\n');
  }
  return 0.0;
}

}  // namespace

TEST(Soak, EveryHairModelRunsTenThousandStepsFiniteBoundedAndWithFlatMemory) {
  Json j = scene_json("sintel_bando");
  const double max_dt = 1.0 / 120.0;  // the longest model step here (anjyo1992, bando2003)
  const double duration = 10000 * max_dt;
  j["animation"]["duration"] = duration;
  j["animation"]["head_motion"] = Json{{"kind", "shake"}, {"axis", {0, 1, 0}},
                                       {"angle_deg", 25}, {"cycles", int(duration / 1.5)},
                                       {"t0", 0.1},       {"t1", duration - 0.1}};
  j["animation"]["wind"] = Json{
      {"uniform", {0.0, 0.0, -1.0}},
      {"gust", {{"before", {0.0, 0.0, -3.0}}, {"after", {0.0, -2.0, -0.5}}, {"switch_time", 30.0}}},
      {"velocity", {0.0, 0.0, -0.5}},
      {"velocity_gust", {{"peak", {0.0, 0.0, -3.0}}, {"t0", 5.0}, {"t1", 60.0}, {"rise", 2.0}}}};
  Context ctx(2);
  const Scene scene = Session::from_json(j, scenes_dir(), "soak.json", ctx).scene();
  const int frames = int(std::floor(duration * 24.0));

  HarnessOptions opt;
  opt.thumb_size = 0;
  opt.last_frame = frames / 10;
  (void)run_harness(scene, scenes_dir(), "soak.json", ctx, opt);
  const double short_peak = peak_rss_bytes();
  opt.last_frame = -1;
  const HarnessReport rep = run_harness(scene, scenes_dir(), "soak.json", ctx, opt);
  const double long_peak = peak_rss_bytes();

  ASSERT_EQ(rep.models.size(), 3u);
  for (const auto& m : rep.models) {
    SCOPED_TRACE(m.model);
    ASSERT_EQ(m.error, "");
    ASSERT_EQ(m.frames, rep.last_frame - rep.first_frame + 1);
    const std::size_t half = m.kinetic_j.size() / 2;
    double first = 0, second = 0;
    for (std::size_t f = 0; f < m.kinetic_j.size(); ++f) {
      ASSERT_TRUE(std::isfinite(m.kinetic_j[f]) && std::isfinite(m.total_j[f])) << "frame " << f;
      ASSERT_TRUE(std::isfinite(m.stretch_percent[f])) << "frame " << f;
      (f < half ? first : second) = std::max(f < half ? first : second, m.kinetic_j[f]);
    }
    EXPECT_GT(first, 0.0);
    EXPECT_LE(second, 2.0 * first)
        << "kinetic energy peaks: first half " << first << " J, second half " << second << " J";
    std::printf(
        "soak %s: %d frames (%.0f s), kinetic peak %.3g J / %.3g J, stretch %.1f %%, "
        "penetration %.1f mm, %.0f ms per simulated s\n",
        m.model.c_str(), m.frames, duration, first, second, m.max_stretch_percent,
        m.max_penetration_mm, m.ms_per_simulated_second);
  }
  std::printf("soak peak resident memory: %.0f MiB after %d frames, %.0f MiB after %d\n",
              short_peak / 1048576.0, frames / 10, long_peak / 1048576.0, frames);
  EXPECT_LT(long_peak - short_peak, 64.0 * 1048576.0);
}
