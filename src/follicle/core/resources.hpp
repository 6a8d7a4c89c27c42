#pragma once
// Resource guards (issue 24 item 5): work whose size would exhaust the machine is refused before
// it allocates, with the reason and the likely fix, instead of running for minutes and dying in
// the allocator or the GL driver. Callers estimate the bytes they are about to allocate and ask
// check_memory(); count budgets (strands, particles, triangles, pixels) live in the parameter
// structs of the code that grows them.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

namespace follicle {

/// Bytes the system can still give this process without swapping: MemAvailable of
/// /proc/meminfo, capped by what is left under RLIMIT_AS / RLIMIT_DATA when they are set (ulimit
/// -v), less what the process already maps. 0 when unknown (then no check is made).
uint64_t available_memory_bytes();

/// "12.3 GB", "512 MB", "40 KB", "17 B": decimal units, three significant digits.
std::string format_bytes(double bytes);

/// "6.9 M", "12.5 k", "800": a count in the same style.
std::string format_count(double count);

/// Throws follicle::Error at `where` when an estimate of `bytes` about to be allocated for `what`
/// exceeds the available memory: "<what> needs about 12.3 GB but this machine has 7.10 GB
/// available; <hint>". `available` overrides the system's figure (tests; 0 = ask the system).
/// Estimates below kAlwaysAffordableBytes return at once without asking the system: the guard
/// is for allocations that could exhaust a machine, and reading /proc for every small GPU
/// buffer of every frame cost more than the upload.
constexpr double kAlwaysAffordableBytes = 16.0 * 1024 * 1024;
void check_memory(const std::string& where, std::string_view what, double bytes,
                  std::string_view hint, uint64_t available = 0);

/// Process-wide allocator policy for programs that draw frame after frame (the CLI, the viewer,
/// the benchmarks); call once from main(). glibc returns the top of its heaps to the system as
/// soon as more than 128 KB there is free; a software GL (Mesa llvmpipe) frees and re-allocates
/// its per-frame binning memory every frame, so each frame faulted the same pages in again:
/// a quarter of the time of a hair frame in the viewer went to the kernel's page-fault handler
/// (anjyo_ponytail 190 ms per frame, 88 ms with this policy). Keeps up to `keep_bytes` free at
/// the top of a heap and serves allocations below 32 MB from the heaps rather than from fresh
/// mappings. No effect where the C library is not glibc. Returns whether the policy was set.
bool keep_freed_heap_memory(std::size_t keep_bytes = std::size_t(256) << 20);

}  // namespace follicle
