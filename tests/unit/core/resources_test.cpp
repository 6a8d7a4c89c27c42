#include "follicle/core/resources.hpp"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "follicle/core/error.hpp"

using namespace follicle;

TEST(Resources, BytesAndCountsAreFormattedWithThreeSignificantDigits) {
  EXPECT_EQ(format_bytes(17), "17 B");
  EXPECT_EQ(format_bytes(40'000), "40.0 KB");
  EXPECT_EQ(format_bytes(512e6), "512 MB");
  EXPECT_EQ(format_bytes(12.34e9), "12.3 GB");
  EXPECT_EQ(format_bytes(8.589934592e9), "8.59 GB");
  EXPECT_EQ(format_count(800), "800");
  EXPECT_EQ(format_count(12'500), "12.5 k");
  EXPECT_EQ(format_count(6.9e6), "6.90 M");
  EXPECT_EQ(format_count(std::numeric_limits<double>::infinity()), "infinitely many");
}

TEST(Resources, AnEstimateAboveTheAvailableMemoryIsRefusedWithTheNumbersAndTheHint) {
  EXPECT_NO_THROW(check_memory("x", "a buffer", 1e9, "", uint64_t(2e9)));
  try {
    check_memory("hair.density", "growing 6.90 M strands", 11e9, "lower hair.density",
                 uint64_t(7.1e9));
    FAIL() << "accepted";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(),
                 "hair.density: growing 6.90 M strands needs about 11.0 GB but this machine has "
                 "7.10 GB available; lower hair.density");
    EXPECT_EQ(e.where(), "hair.density");
  }
  // A non-finite estimate (an overflowing product) is refused, never taken as "fits".
  EXPECT_THROW(check_memory("x", "y", std::nan(""), "", uint64_t(1e12)), Error);
  EXPECT_THROW(check_memory("x", "y", std::numeric_limits<double>::infinity(), "", 1), Error);
}

TEST(Resources, TheSystemFigureIsPositiveAndNoMoreThanTheAddressSpaceLimit) {
  const uint64_t avail = available_memory_bytes();
  EXPECT_GT(avail, uint64_t(0));  // Linux has /proc/meminfo
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "an address-space limit cannot be set under AddressSanitizer's shadow memory";
#else
  // In a child: cap the address space at 3 GB, the figure must follow.
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    rlimit cap{};
    cap.rlim_cur = cap.rlim_max = rlim_t(3) << 30;
    if (setrlimit(RLIMIT_AS, &cap) != 0) _exit(2);
    _exit(available_memory_bytes() <= (uint64_t(3) << 30) ? 0 : 1);
  }
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
#endif
}

#if defined(__GLIBC__) && !defined(__SANITIZE_ADDRESS__)  // ASan brings its own allocator
// keep_freed_heap_memory: a freed 8 MB block stays in the heap (the next frame reuses it)
// instead of going back to the system. Without the policy glibc maps 8 MB on its own (above the
// 128 KB start of its mmap threshold) and unmaps it at free.
TEST(Resources, KeepFreedHeapMemoryKeepsAFreedFrameBufferInTheHeap) {
  ASSERT_TRUE(follicle::keep_freed_heap_memory());
  const std::size_t n = std::size_t(8) << 20;
  const auto before = mallinfo2();
  {
    std::vector<char> frame(n, 1);
    const auto during = mallinfo2();
    EXPECT_EQ(during.hblkhd, before.hblkhd) << "an 8 MB block was mapped on its own";
    EXPECT_GE(std::size_t(during.uordblks), std::size_t(before.uordblks) + n);
  }
  const auto after = mallinfo2();
  EXPECT_GE(std::size_t(after.fordblks), n) << "the freed block went back to the system";
}
#endif
