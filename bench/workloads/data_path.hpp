#pragma once
// Where workloads find shipped data: $FOLLICLE_DATA_DIR, then the compile-time source tree, then
// a `data` folder in the working directory or one of its parents.
#include <filesystem>

namespace follicle::workloads {

/// Path of `data/<rel>`; throws follicle::Error naming what was searched when it is missing.
std::filesystem::path find_data(const std::filesystem::path& rel);

}  // namespace follicle::workloads
