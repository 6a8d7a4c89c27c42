// libFuzzer target: PLY meshes, ASCII and binary (geom::load_mesh on a .ply file).
#include "follicle/geom/mesh_io.hpp"
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto path = follicle::fuzz::write_input(data, size, ".ply");
  follicle::fuzz::expect_ok_or_error(
      [&] { (void)follicle::geom::load_mesh(path, follicle::LengthUnit::mm); });
  return 0;
}
