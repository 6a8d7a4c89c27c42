#pragma once
// CPU feature checks for the kernels that carry an AVX2 variant besides their portable one
// (ADR 0004: the Anjyo projective kernel; ADR 0008: the LCP pair, spring, geometry and air
// kernels; the particle grid's distance filter). One place, so every dispatcher asks the same
// question the same way.

namespace follicle {

/// Whether the CPU running this process has AVX2 (always false where the check is not available:
/// other architectures or compilers). Evaluated once per process.
inline bool cpu_has_avx2() {
#if (defined(__x86_64__) || defined(__i386__)) && defined(__GNUC__)
  static const bool yes = __builtin_cpu_supports("avx2");
  return yes;
#else
  return false;
#endif
}

}  // namespace follicle
