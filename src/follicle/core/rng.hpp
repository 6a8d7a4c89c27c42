#pragma once
// Seeded, portable random numbers. std::uniform_real_distribution and friends are
// implementation-defined, so Follicle draws its own variates: the same seed gives the same
// numbers with every compiler and standard library. Independent streams (one per strand,
// particle or furrow) come from Rng::stream(seed, index), which makes results independent of
// how work is split across threads.
#include <cstdint>

namespace follicle {

class Rng {
 public:
  explicit Rng(uint64_t seed = 0x9E3779B97F4A7C15ull);
  /// Independent stream number `index` derived from `seed` (SplitMix64 mixing).
  static Rng stream(uint64_t seed, uint64_t index);

  uint64_t next_u64();  // xoshiro256**
  double uniform();     // [0, 1), 53 random bits
  double uniform(double lo, double hi);
  uint32_t below(uint32_t n);  // [0, n), unbiased
  double normal();             // standard normal (Box-Muller, no cached second value)
  double normal(double mean, double sigma) { return mean + sigma * normal(); }

 private:
  uint64_t m_s[4];
};

}  // namespace follicle
