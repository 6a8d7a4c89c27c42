#include "testing/testing.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>

namespace follicle::test {

std::filesystem::path source_dir() {
  if (const char* s = std::getenv("FOLLICLE_SOURCE_DIR"); s && *s) return s;
  return FOLLICLE_SOURCE_DIR;
}

std::filesystem::path shared_data_dir() {
  if (const char* s = std::getenv("FOLLICLE_SHARED_DATA"); s && *s) {
    return std::filesystem::exists(s) ? std::filesystem::path(s) : std::filesystem::path();
  }
  auto d = source_dir().parent_path() / "shared" / "data";
  return std::filesystem::exists(d) ? d : std::filesystem::path();
}

bool gl_required() {
  const char* s = std::getenv("FOLLICLE_REQUIRE_GL");
  return s != nullptr && *s != '\0' && std::string(s) != "0";
}

std::filesystem::path scratch_dir(const std::string& name) {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string test = info ? std::string(info->test_suite_name()) + "." + info->name() : "x";
  auto d = std::filesystem::temp_directory_path() /
           ("follicle-test-" + std::to_string(::getpid()) + "-" + test + "-" + name);
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

}  // namespace follicle::test
