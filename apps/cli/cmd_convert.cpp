// follicle convert IN OUT [--in-units U --out-units U] [--ascii] [--tfx-verts N]: converts a mesh
// (OBJ, PLY, glTF) or a hair strand file (.hair, .tfx, .usda, .obj polylines) by extension. An
// .obj input with `l` polylines and no faces is strands; with faces it is a mesh.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>

#include "commands.hpp"
#include "follicle/core/error.hpp"
#include "follicle/geom/mesh_io.hpp"
#include "follicle/geom/strand_io.hpp"

namespace follicle::cli {

namespace {

std::string lower_ext(const std::string& path) {
  auto ext = std::filesystem::path(path).extension().string();
  for (auto& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

// "cm", or "0.0254 m" for a USD metersPerUnit that is not one of ours.
std::string unit_label(double metres_per_unit) {
  for (LengthUnit u : {LengthUnit::mm, LengthUnit::cm, LengthUnit::dm, LengthUnit::m})
    if (std::abs(unit_to_metres(u) - metres_per_unit) <= 1e-12 * metres_per_unit)
      return to_string(u);
  return fmt::format("{} m", metres_per_unit);
}

int convert_strands(const GlobalOptions& g, const ConvertArgs& a, Context& ctx, LengthUnit in,
                    LengthUnit out) {
  const std::string ext = lower_ext(a.output);
  if (!geom::is_strand_extension(a.output))
    fail_at(a.output,
            "cannot write hair strands as '{}': strand outputs are .hair, .tfx, .usda or .obj",
            ext);
  const long long tv = a.tfx_verts;
  if (ext == ".tfx" && (tv < 4 || tv > 64 || (tv & (tv - 1)) != 0))
    throw UsageError(fmt::format("--tfx-verts must be a power of two in [4, 64], got {}", tv));
  const uint32_t tfx_verts = ext == ".tfx" ? uint32_t(tv) : 32;
  if (a.ascii) ctx.log().warn("--ascii applies to PLY meshes only; ignored for hair strands");
  geom::StrandFileInfo info;
  const geom::StrandSet s = geom::load_strands(a.input, in, &info);  // metres inside
  if (info.unit_from_file && unit_label(info.metres_per_unit) != to_string(in))
    ctx.log().warn("{} declares metersPerUnit = {}: the file's unit ({}) overrides --in-units {}",
                   a.input, info.metres_per_unit, unit_label(info.metres_per_unit), to_string(in));
  for (const auto& n : info.notes) ctx.log().info("{}: {}", a.input, n);
  std::size_t points = s.num_points();
  if (ext == ".tfx") {
    std::size_t resampled = 0;
    for (std::size_t h = 0; h < s.num_strands(); ++h) resampled += s.strand_size(h) != tfx_verts;
    if (resampled)
      ctx.log().warn(
          ".tfx stores exactly {} vertices per strand: resampling all {} strands by arc length "
          "({} of them differ; {} -> {} points); set the count with --tfx-verts",
          tfx_verts, s.num_strands(), resampled, s.num_points(), s.num_strands() * tfx_verts);
    points = s.num_strands() * tfx_verts;
  }
  geom::save_strands(s, a.output, out, tfx_verts);  // atomic (temp file + rename)
  if (!g.quiet)
    fmt::print("wrote {} ({} strands, {} points, {} -> {})\n", a.output, s.num_strands(), points,
               unit_label(info.metres_per_unit), to_string(out));
  return 0;
}

}  // namespace

int run_convert(const GlobalOptions& g, const ConvertArgs& a) {
  auto ctx = make_context(g);
  const LengthUnit in = parse_length_unit(a.in_units), out = parse_length_unit(a.out_units);
  if (geom::is_strand_file(a.input)) return convert_strands(g, a, *ctx, in, out);
  const std::string ext = lower_ext(a.output);
  if (ext != ".obj" && geom::is_strand_extension(a.output))
    fail_at(a.input,
            "is a mesh; it cannot be written as hair strands ('{}'): mesh outputs are .obj, .ply, "
            ".gltf or .glb",
            ext);
  const auto mesh = geom::load_mesh(a.input, in);  // metres inside
  geom::save_mesh(mesh, a.output, out, a.ascii);   // atomic
  if (!g.quiet)
    fmt::print("wrote {} ({} vertices, {} faces, {} -> {})\n", a.output, mesh.num_vertices(),
               mesh.num_faces(), to_string(in), to_string(out));
  return 0;
}

}  // namespace follicle::cli
