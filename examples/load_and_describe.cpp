// load_and_describe FILE [--units mm|cm|dm|m]: the smallest program on the installed Follicle
// package. A mesh (.obj, .ply, .gltf, .glb) prints its vertex and triangle counts and bounds in the
// file's unit; a scene (.json) prints what `follicle info` prints for it.
#include <cstdio>
#include <filesystem>
#include <follicle/core/context.hpp>
#include <follicle/core/error.hpp>
#include <follicle/core/units.hpp>
#include <follicle/geom/mesh_io.hpp>
#include <follicle/scene/session.hpp>
#include <string>

namespace {

void describe_mesh(const std::filesystem::path& path, follicle::LengthUnit unit) {
  const follicle::geom::TriMesh mesh = follicle::geom::load_mesh(path, unit);  // in metres
  const double k = 1.0 / follicle::unit_to_metres(unit);
  const std::string u = follicle::to_string(unit);
  std::printf("mesh: %s\n", path.string().c_str());
  std::printf("vertices: %zu\n", mesh.num_vertices());
  std::printf("triangles: %zu\n", mesh.num_faces());
  if (mesh.num_vertices() == 0) return;
  const Eigen::AlignedBox3d box = mesh.bounds();
  const Eigen::Vector3d lo = box.min() * k, hi = box.max() * k;
  std::printf("bounds min: %.6g %.6g %.6g %s\n", lo.x(), lo.y(), lo.z(), u.c_str());
  std::printf("bounds max: %.6g %.6g %.6g %s\n", hi.x(), hi.y(), hi.z(), u.c_str());
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2 && !(argc == 4 && std::string(argv[2]) == "--units")) {
    std::fprintf(stderr, "usage: %s FILE [--units mm|cm|dm|m]\n", argv[0]);
    return 2;
  }
  try {
    const std::filesystem::path path = argv[1];
    const auto unit = follicle::parse_length_unit(argc == 4 ? argv[3] : "m");
    if (path.extension() == ".json") {
      const follicle::Context ctx(/*threads=*/1);
      std::printf("%s", follicle::scene::Session::load(path, ctx).summary().c_str());
    } else {
      describe_mesh(path, unit);
    }
  } catch (const follicle::Error& e) {
    std::fprintf(stderr, "load_and_describe: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
