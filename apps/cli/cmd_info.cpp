// follicle info FILE: a summary of a scene, mesh or hair strand file (.hair, .tfx, .usda, .obj
// polylines): strands, points, strand lengths and bounds.
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <filesystem>

#include "commands.hpp"
#include "follicle/geom/mesh_io.hpp"
#include "follicle/geom/strand_io.hpp"
#include "follicle/scene/session.hpp"

namespace follicle::cli {

namespace {

std::string lower_ext(const std::string& path) {
  auto ext = std::filesystem::path(path).extension().string();
  for (auto& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

// How the unit was chosen: OBJ, PLY, .hair and .tfx do not record one.
std::string unit_source(bool given) {
  return given ? "as declared with --units"
               : "assumed: no --units given, and this format does not record a unit";
}

// A head is 0.2-0.3 m across, a bust up to 0.6 m, a hand about 0.2 m, a body under 3 m: a mesh
// far outside 5 cm - 3 m in the declared unit was probably written in another one (a 34 m "head"
// from a file in cm read as m is the usual case).
void size_note(double diag_m, LengthUnit unit, bool given) {
  if (diag_m >= 0.05 && diag_m <= 3.0) return;
  // Every unit that makes it body-part-sized or body-sized: a file of 20 units may be a head in
  // cm or a whole body in dm (MakeHuman's base mesh), so neither is picked for the user.
  std::string hint;
  for (LengthUnit u : {LengthUnit::mm, LengthUnit::cm, LengthUnit::dm, LengthUnit::m}) {
    const double d = diag_m / unit_to_metres(unit) * unit_to_metres(u);
    if (u != unit && d >= 0.05 && d <= 3.0)
      hint += fmt::format("{} --units {} it is {:.2f} m across", hint.empty() ? "; with" : ", with",
                          to_string(u), d);
  }
  fmt::print("note: {:.3g} m across in {} ({}) is not the size of a head, bust, hand or body{}\n",
             diag_m, to_string(unit), given ? "declared" : "assumed", hint);
}

void mesh_info(const std::string& path, LengthUnit unit, bool unit_given) {
  const auto mesh = geom::load_mesh(path, unit);
  const double k = 1.0 / unit_to_metres(unit);
  const auto box = mesh.bounds();
  double area = 0.0;
  for (std::size_t f = 0; f < mesh.num_faces(); ++f) area += mesh.face_area(f);
  fmt::print("mesh: {}\n", path);
  const std::string file_ext = lower_ext(path);
  const bool gltf = file_ext == ".gltf" || file_ext == ".glb";
  fmt::print("units: {} ({})\n", to_string(unit),
             gltf && !unit_given ? "metres by the glTF specification" : unit_source(unit_given));
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
  if (mesh.num_vertices() > 0) size_note((box.max() - box.min()).norm(), unit, unit_given);
}

// "cm", or "0.0254 m" for a USD metersPerUnit that is not one of ours.
std::string unit_label(double metres_per_unit) {
  for (LengthUnit u : {LengthUnit::mm, LengthUnit::cm, LengthUnit::dm, LengthUnit::m})
    if (std::abs(unit_to_metres(u) - metres_per_unit) <= 1e-12 * metres_per_unit)
      return to_string(u);
  return fmt::format("{} m", metres_per_unit);
}

// Strand files: lengths and bounds in the file's unit (USD: its metersPerUnit, else --units).
void hair_info(const std::string& path, LengthUnit unit, bool unit_given) {
  geom::StrandFileInfo info;
  const auto s = geom::load_strands(path, unit, &info);
  const double k = 1.0 / info.metres_per_unit;
  const std::string label = unit_label(info.metres_per_unit);
  fmt::print("hair: {}\n", path);
  fmt::print("format: {}\n", info.format);
  if (info.unit_from_file)
    fmt::print("units: {} (metersPerUnit {} from the file; --units is ignored)\n", label,
               info.metres_per_unit);
  else
    fmt::print("units: {} ({})\n", label, unit_source(unit_given));
  fmt::print("strands: {}\n", s.num_strands());
  fmt::print("points: {}\n", s.num_points());
  fmt::print("segments: {}\n",
             s.num_points() - std::min<std::size_t>(s.num_points(), s.num_strands()));
  if (s.num_points() == 0) return;
  Eigen::AlignedBox3d box;
  for (const auto& p : s.points) box.extend(p.cast<double>());
  double lmin = 1e300, lmax = 0.0, lsum = 0.0;
  std::size_t pmin = SIZE_MAX, pmax = 0;
  for (std::size_t i = 0; i < s.num_strands(); ++i) {
    double len = 0.0;
    const uint32_t b = s.strand_begin(i), n = s.strand_size(i);
    for (uint32_t j = 1; j < n; ++j)
      len += (s.points[b + j] - s.points[b + j - 1]).cast<double>().norm();
    lmin = std::min(lmin, len);
    lmax = std::max(lmax, len);
    lsum += len;
    pmin = std::min<std::size_t>(pmin, n);
    pmax = std::max<std::size_t>(pmax, n);
  }
  const Vec3 lo = box.min() * k, hi = box.max() * k;
  fmt::print("points per strand: min {}, max {}\n", pmin, pmax);
  fmt::print("bounds min: [{:.6g}, {:.6g}, {:.6g}] {}\n", lo.x(), lo.y(), lo.z(), label);
  fmt::print("bounds max: [{:.6g}, {:.6g}, {:.6g}] {}\n", hi.x(), hi.y(), hi.z(), label);
  fmt::print("strand length: min {:.6g}, mean {:.6g}, max {:.6g} {}\n", lmin * k,
             lsum * k / double(std::max<std::size_t>(1, s.num_strands())), lmax * k, label);
  fmt::print("radius: {}, colour: {}\n", s.radius.empty() ? "no" : "per point",
             s.color.empty() ? "no" : "per point");
  for (const auto& n : info.notes) fmt::print("note: {}\n", n);
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
  // An .obj with `l` polylines and no faces holds hair strands; otherwise it is a mesh.
  if (geom::is_strand_file(a.file)) {
    hair_info(a.file, parse_length_unit(a.units), a.units_given);
    return 0;
  }
  if (ext == ".obj" || ext == ".ply" || ext == ".gltf" || ext == ".glb") {
    mesh_info(a.file, parse_length_unit(a.units), a.units_given);
    return 0;
  }
  fail_at(a.file,
          "unknown file type '{}': expected a scene (.json), a mesh (.obj, .ply, .gltf, .glb) or "
          "hair (.hair, .tfx, .usda, .usd, .obj polylines)",
          ext);
}

}  // namespace follicle::cli
