#pragma once
// CPU feature checks for the kernels that carry an AVX2 variant besides their portable one
// (ADR 0004: the Anjyo projective kernel; ADR 0008: the LCP pair, spring, geometry and air
// kernels; the particle grid's distance filter). One place, so every dispatcher asks the same
// question the same way.

// FOLLICLE_AVX2_BEGIN ... FOLLICLE_AVX2_END: the functions in between are compiled for AVX2
// (no FMA), for g++ by `#pragma GCC target` and for clang, which ignores that pragma, by
// `#pragma clang attribute` (the fuzz build, tools/fuzz.sh). Callers dispatch on cpu_has_avx2().
#if defined(__clang__)
#define FOLLICLE_AVX2_BEGIN \
  _Pragma("clang attribute push(__attribute__((target(\"avx2\"))), apply_to = function)")
#define FOLLICLE_AVX2_END _Pragma("clang attribute pop")
#else
#define FOLLICLE_AVX2_BEGIN _Pragma("GCC push_options") _Pragma("GCC target(\"avx2\")")
#define FOLLICLE_AVX2_END _Pragma("GCC pop_options")
#endif

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
