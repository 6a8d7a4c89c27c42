#include "follicle/core/resources.hpp"

#include <sys/resource.h>
#include <unistd.h>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include <algorithm>
#include <cmath>
#include <fstream>
#include <string>
#include <utility>

#include "follicle/core/error.hpp"

namespace follicle {

uint64_t available_memory_bytes() {
  uint64_t avail = 0;
  std::ifstream in("/proc/meminfo");
  std::string key;
  uint64_t value = 0;
  std::string unit;
  while (in >> key >> value) {
    std::getline(in, unit);
    if (key == "MemAvailable:") {
      avail = value * 1024;  // the kernel reports kB
      break;
    }
  }
  // What the process already uses counts against its limits: /proc/self/statm gives the total
  // virtual size (field 1, for RLIMIT_AS) and the data + stack size (field 6, for RLIMIT_DATA)
  // in pages.
  uint64_t vm_pages = 0, data_pages = 0;
  {
    std::ifstream statm("/proc/self/statm");
    uint64_t f[7] = {};
    for (auto& v : f) statm >> v;
    if (statm) {
      vm_pages = f[0];
      data_pages = f[5];
    }
  }
  const uint64_t page = uint64_t(sysconf(_SC_PAGESIZE));
  const std::pair<int, uint64_t> limits[] = {{RLIMIT_AS, vm_pages * page},
                                             {RLIMIT_DATA, data_pages * page}};
  for (const auto& [res, used] : limits) {
    rlimit lim{};
    if (getrlimit(res, &lim) == 0 && lim.rlim_cur != RLIM_INFINITY) {
      const uint64_t cap = uint64_t(lim.rlim_cur) > used ? uint64_t(lim.rlim_cur) - used : 1;
      avail = avail == 0 ? cap : std::min(avail, cap);
    }
  }
  return avail;
}

namespace {
std::string format_scaled(double v, const char* const* units, int n, double step) {
  if (!std::isfinite(v)) return "infinitely many";
  int k = 0;
  while (k + 1 < n && std::abs(v) >= step) {
    v /= step;
    ++k;
  }
  if (k == 0) return fmt::format("{:.0f}{}", v, units[0]);
  const int decimals = std::abs(v) >= 100 ? 0 : std::abs(v) >= 10 ? 1 : 2;
  return fmt::format("{:.{}f}{}", v, decimals, units[k]);
}
}  // namespace

std::string format_bytes(double bytes) {
  static constexpr const char* kUnits[] = {" B", " KB", " MB", " GB", " TB", " PB", " EB"};
  return format_scaled(bytes, kUnits, 7, 1000.0);
}

std::string format_count(double count) {
  static constexpr const char* kUnits[] = {"", " k", " M", " G", " T"};
  return format_scaled(count, kUnits, 5, 1000.0);
}

void check_memory(const std::string& where, std::string_view what, double bytes,
                  std::string_view hint, uint64_t available) {
  if (available == 0 && std::isfinite(bytes) && bytes < kAlwaysAffordableBytes) return;
  if (available == 0) available = available_memory_bytes();
  if (available == 0) return;  // unknown: nothing to compare with
  if (std::isfinite(bytes) && bytes <= double(available)) return;
  fail_at(where, "{} needs about {} but this machine has {} available{}{}", what,
          format_bytes(bytes), format_bytes(double(available)), hint.empty() ? "" : "; ", hint);
}

bool keep_freed_heap_memory(std::size_t keep_bytes) {
#if defined(__GLIBC__)
  const int keep = int(std::min<std::size_t>(keep_bytes, std::size_t(1) << 30));
  // M_MMAP_THRESHOLD: glibc's own upper bound for its dynamic threshold (32 MB on 64-bit);
  // setting M_TRIM_THRESHOLD alone would freeze the threshold at its 128 KB start.
  return mallopt(M_TRIM_THRESHOLD, keep) == 1 && mallopt(M_TOP_PAD, 16 << 20) == 1 &&
         mallopt(M_MMAP_THRESHOLD, 32 << 20) == 1;
#else
  (void)keep_bytes;
  return false;
#endif
}

}  // namespace follicle
