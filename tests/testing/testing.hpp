#pragma once
// Helpers shared by the tests: where the source tree and the shared data live, scratch dirs.
#include <filesystem>
#include <string>

namespace follicle::test {

/// The repository root (compiled in; $FOLLICLE_SOURCE_DIR overrides).
std::filesystem::path source_dir();
/// ../shared/data next to the repository, or $FOLLICLE_SHARED_DATA; empty path when absent.
std::filesystem::path shared_data_dir();
/// True when $FOLLICLE_REQUIRE_GL is set (tools/test.sh sets it): GL tests must then fail
/// instead of skipping when no OpenGL context can be made.
bool gl_required();
/// A fresh, empty directory under the system temp dir, unique to this test.
std::filesystem::path scratch_dir(const std::string& name);

}  // namespace follicle::test

/// Skips the current test when the shared data folder (or a file inside it) is missing.
#define FOLLICLE_REQUIRE_SHARED(relpath)                          \
  do {                                                            \
    auto _d = ::follicle::test::shared_data_dir();                \
    if (_d.empty() || !std::filesystem::exists(_d / (relpath)))   \
      GTEST_SKIP() << "shared data not available: " << (relpath); \
  } while (0)
