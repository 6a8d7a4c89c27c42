// libFuzzer target: OBJ meshes (geom::load_mesh on a .obj file; tinyobjloader + Follicle checks).
#include "follicle/geom/mesh_io.hpp"
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto path = follicle::fuzz::write_input(data, size, ".obj");
  follicle::fuzz::expect_ok_or_error(
      [&] { (void)follicle::geom::load_mesh(path, follicle::LengthUnit::m); });
  return 0;
}
