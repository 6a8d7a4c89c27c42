// follicle info FILE: a summary of a scene or mesh file (hair files come with the hair module).
#include <fmt/format.h>

#include <cctype>
#include <filesystem>

#include "commands.hpp"
#include "follicle/geom/mesh_io.hpp"
#include "follicle/scene/session.hpp"

namespace follicle::cli {

namespace {

std::string lower_ext(const std::string& path) {
  auto ext = std::filesystem::path(path).extension().string();
  for (auto& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

void mesh_info(const std::string& path, LengthUnit unit) {
  const auto mesh = geom::load_mesh(path, unit);
  const double k = 1.0 / unit_to_metres(unit);
  const auto box = mesh.bounds();
  double area = 0.0;
  for (std::size_t f = 0; f < mesh.num_faces(); ++f) area += mesh.face_area(f);
  fmt::print("mesh: {}\n", path);
  fmt::print("units: {} (as declared with --units)\n", to_string(unit));
  fmt::print("vertices: {}\n", mesh.num_vertices());
  fmt::print("faces: {}\n", mesh.num_faces());
  fmt::print("uvs: {}\n", mesh.has_uvs() ? fmt::format("yes ({})", mesh.uvs.size()) : "no");
  fmt::print("normals: {}\n", mesh.has_normals() ? "yes" : "no");
  if (mesh.num_vertices() > 0) {
    const Vec3 lo = box.min() * k, hi = box.max() * k, ext = (box.max() - box.min()) * k;
    fmt::print("bounds min: [{:.6g}, {:.6g}, {:.6g}] {}\n", lo.x(), lo.y(), lo.z(),
               to_string(unit));
    fmt::print("bounds max: [{:.6g}, {:.6g}, {:.6g}] {}\n", hi.x(), hi.y(), hi.z(),
               to_string(unit));
    fmt::print("extent: [{:.6g}, {:.6g}, {:.6g}] {}\n", ext.x(), ext.y(), ext.z(), to_string(unit));
  }
  fmt::print("surface area: {:.6g} m^2\n", area);
}

}  // namespace

int run_info(const GlobalOptions& g, const InfoArgs& a) {
  auto ctx = make_context(g);
  const auto ext = lower_ext(a.file);
  if (ext == ".json") {
    const auto session = scene::Session::load(a.file, *ctx);
    fmt::print("{}", session.summary());
    return 0;
  }
  if (ext == ".obj" || ext == ".ply" || ext == ".gltf" || ext == ".glb") {
    mesh_info(a.file, parse_length_unit(a.units));
    return 0;
  }
  fail_at(a.file,
          "unknown file type '{}': expected a scene (.json) or a mesh (.obj, .ply, "
          ".gltf, .glb)",
          ext);
}

}  // namespace follicle::cli
