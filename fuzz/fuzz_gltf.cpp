// libFuzzer target: glTF 2.0 meshes (geom::load_mesh; tinygltf + Follicle's accessor checks).
// Inputs starting with the GLB magic "glTF" are read as .glb, everything else as .gltf (JSON).
#include <cstring>

#include "follicle/geom/mesh_io.hpp"
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const bool glb = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
  const auto path = follicle::fuzz::write_input(data, size, glb ? ".glb" : ".gltf");
  follicle::fuzz::expect_ok_or_error(
      [&] { (void)follicle::geom::load_mesh(path, follicle::LengthUnit::m); });
  return 0;
}
