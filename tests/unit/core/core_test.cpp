#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "follicle/core/atomic_file.hpp"
#include "follicle/core/context.hpp"
#include "follicle/core/cpu.hpp"
#include "follicle/core/error.hpp"
#include "follicle/core/parallel.hpp"
#include "follicle/core/params.hpp"
#include "follicle/core/rng.hpp"
#include "follicle/core/units.hpp"
#include "testing/testing.hpp"

using namespace follicle;

TEST(Rng, SameSeedSameSequence) {
  Rng a(42), b(42), c(43);
  bool differs = false;
  for (int i = 0; i < 100; ++i) {
    const auto x = a.next_u64();
    EXPECT_EQ(x, b.next_u64());
    differs |= x != c.next_u64();
  }
  EXPECT_TRUE(differs);
}

TEST(Rng, UniformMomentsAndRange) {
  Rng r(7);
  double sum = 0, sum2 = 0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    const double u = r.uniform();
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    sum += u;
    sum2 += u * u;
  }
  EXPECT_NEAR(sum / n, 0.5, 0.005);
  EXPECT_NEAR(sum2 / n - 0.25, 1.0 / 12.0, 0.002);
}

TEST(Rng, NormalMoments) {
  Rng r(9);
  double sum = 0, sum2 = 0;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    const double x = r.normal();
    sum += x;
    sum2 += x * x;
  }
  EXPECT_NEAR(sum / n, 0.0, 0.01);
  EXPECT_NEAR(sum2 / n, 1.0, 0.01);
}

TEST(Rng, BelowIsInRangeAndCoversAll) {
  Rng r(3);
  int hist[7] = {};
  for (int i = 0; i < 7000; ++i) {
    const auto k = r.below(7);
    ASSERT_LT(k, 7u);
    ++hist[k];
  }
  for (int h : hist) EXPECT_GT(h, 800);
}

TEST(Rng, StreamsAreIndependentOfOrder) {
  auto a = Rng::stream(5, 10).next_u64();
  auto b = Rng::stream(5, 11).next_u64();
  EXPECT_NE(a, b);
  EXPECT_EQ(a, Rng::stream(5, 10).next_u64());
}

TEST(Parallel, ForVisitsEveryIndexOnce) {
  Context ctx(2);
  std::vector<std::atomic<int>> hits(10000);
  parallel_for(
      ctx, 0, hits.size(), [&](std::size_t i) { hits[i]++; }, 16);
  for (auto& h : hits) EXPECT_EQ(h.load(), 1);
}

TEST(Parallel, ReductionIsBitIdenticalForAnyThreadCount) {
  std::vector<double> v(100003);
  Rng r(1);
  for (auto& x : v) x = r.uniform(-1e6, 1e6) * std::pow(10.0, r.uniform(-8, 8));
  auto sum_with = [&](int threads) {
    Context ctx(threads);
    return deterministic_reduce(
        ctx, v.size(), 1000, 0.0,
        [&](std::size_t a, std::size_t b) {
          double s = 0;
          for (std::size_t i = a; i < b; ++i) s += v[i];
          return s;
        },
        [](double x, double y) { return x + y; });
  };
  const double s1 = sum_with(1);
  EXPECT_EQ(s1, sum_with(2));
  EXPECT_EQ(s1, sum_with(4));
}

TEST(Units, ParseAndScale) {
  EXPECT_DOUBLE_EQ(unit_to_metres(parse_length_unit("mm")), 1e-3);
  EXPECT_DOUBLE_EQ(unit_to_metres(parse_length_unit("cm")), 1e-2);
  EXPECT_DOUBLE_EQ(unit_to_metres(parse_length_unit("dm")), 1e-1);
  EXPECT_DOUBLE_EQ(unit_to_metres(parse_length_unit("m")), 1.0);
  EXPECT_THROW(parse_length_unit("inch"), Error);
  EXPECT_EQ(to_string(LengthUnit::cm), "cm");
}

struct DemoParams {
  double dt = 0.01;
  int steps = 10;
  Vec3 gravity{0, -9.81, 0};
  template <class V>
  void visit(V&& v) {
    v("dt", dt, ParamInfo{"time step", "s", 1e-6, 1.0});
    v("steps", steps, ParamInfo{"step count", "", 1, 1e6});
    v("gravity", gravity, ParamInfo{"gravity", "m/s^2", -100, 100});
  }
};

TEST(Params, ValidatorNamesFieldAndBound) {
  DemoParams p;
  EXPECT_NO_THROW(validate_params(p, "sim"));
  p.dt = 2.0;
  try {
    validate_params(p, "sim");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("sim.dt"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("[1e-06, 1]"), std::string::npos) << e.what();
  }
  p.dt = 0.01;
  p.gravity.y() = std::nan("");
  EXPECT_THROW(validate_params(p, "sim"), Error);
}

TEST(Params, DidYouMean) {
  EXPECT_EQ(did_you_mean("camrea", {"camera", "lights", "assets"}), "camera");
  EXPECT_EQ(did_you_mean("zzzzzz", {"camera", "lights"}), "");
  EXPECT_EQ(edit_distance("kitten", "sitting"), 3u);
}

TEST(AtomicFile, WritesWholeFileOrNothing) {
  auto dir = test::scratch_dir("atomic");
  auto p = dir / "a.txt";
  write_file_atomically(p, "hello");
  EXPECT_EQ(read_file(p), "hello");
  EXPECT_THROW(write_atomically(p,
                                [](const std::filesystem::path& tmp) {
                                  std::ofstream(tmp) << "partial";
                                  throw Error("simulated failure");
                                }),
               Error);
  EXPECT_EQ(read_file(p), "hello");  // untouched
  for (auto& e : std::filesystem::directory_iterator(dir))
    EXPECT_EQ(e.path().filename(), "a.txt") << "temp file left behind";
  EXPECT_THROW(read_file(dir / "missing.txt"), Error);
}

TEST(AtomicFile, ReadFileReturnsEveryByteOfLargeAndUnsizedFiles) {
  auto dir = test::scratch_dir("read_file");
  std::string big(3 * 65536 + 17, '\0');
  for (std::size_t i = 0; i < big.size(); ++i) big[i] = char((i * 131 + i / 7) & 0xFF);
  write_file_atomically(dir / "big.bin", big);
  EXPECT_EQ(read_file(dir / "big.bin"), big);
  write_file_atomically(dir / "empty.bin", "");
  EXPECT_EQ(read_file(dir / "empty.bin"), "");
  // Files in /proc report a size of 0 but have content: read in chunks to the end.
  const std::string status = read_file("/proc/self/status");
  EXPECT_NE(status.find("Name:"), std::string::npos);
  EXPECT_NE(status.find("VmRSS"), std::string::npos);
  EXPECT_THROW(read_file(dir), Error);  // a folder
}

TEST(Cpu, Avx2CheckAgreesWithTheKernelsCpuFlags) {
  const bool a = follicle::cpu_has_avx2();
  EXPECT_EQ(a, follicle::cpu_has_avx2());  // evaluated once, stable
  // On Linux the kernel lists the CPU's features in /proc/cpuinfo ("flags : ... avx2 ...").
  std::ifstream in("/proc/cpuinfo");
  if (!in) GTEST_SKIP() << "no /proc/cpuinfo";
  std::string line;
  bool listed = false, found = false;
  while (std::getline(in, line) && !found) {
    if (line.rfind("flags", 0) != 0) continue;
    found = true;
    std::istringstream words(line.substr(line.find(':') + 1));
    for (std::string w; words >> w;) listed |= w == "avx2";
  }
  if (!found) GTEST_SKIP() << "no flags line (not x86)";
  EXPECT_EQ(a, listed);
}

TEST(Context, LibraryProgressBarsAreOffUnlessTheProgramAsks) {
  Context ctx(1);
  EXPECT_FALSE(ctx.progress());  // a program linking Follicle draws nothing unasked
  ctx.set_progress(true);
  EXPECT_TRUE(ctx.progress());
}
