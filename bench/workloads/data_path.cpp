#include "workloads/data_path.hpp"

#include <cstdlib>

#include "follicle/core/error.hpp"

namespace follicle::workloads {

std::filesystem::path find_data(const std::filesystem::path& rel) {
  namespace fs = std::filesystem;
  if (const char* env = std::getenv("FOLLICLE_DATA_DIR"); env && *env) {
    if (fs::exists(fs::path(env) / rel)) return fs::path(env) / rel;
  }
#ifdef FOLLICLE_SOURCE_DIR
  if (fs::exists(fs::path(FOLLICLE_SOURCE_DIR) / "data" / rel))
    return fs::path(FOLLICLE_SOURCE_DIR) / "data" / rel;
#endif
  fs::path p = fs::current_path();
  for (int i = 0; i < 8; ++i) {
    if (fs::exists(p / "data" / rel)) return p / "data" / rel;
    if (!p.has_parent_path() || p.parent_path() == p) break;
    p = p.parent_path();
  }
  fail("cannot find data/{} (run from the repository or set FOLLICLE_DATA_DIR)", rel.string());
}

}  // namespace follicle::workloads
