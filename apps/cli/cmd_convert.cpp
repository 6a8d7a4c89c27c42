// follicle convert IN OUT [--in-units U --out-units U] [--ascii]: mesh format conversion.
#include <fmt/format.h>

#include "commands.hpp"
#include "follicle/geom/mesh_io.hpp"

namespace follicle::cli {

int run_convert(const GlobalOptions& g, const ConvertArgs& a) {
  auto ctx = make_context(g);
  const LengthUnit in = parse_length_unit(a.in_units), out = parse_length_unit(a.out_units);
  const auto mesh = geom::load_mesh(a.input, in);  // metres inside
  geom::save_mesh(mesh, a.output, out, a.ascii);   // atomic
  if (!g.quiet)
    fmt::print("wrote {} ({} vertices, {} faces, {} -> {})\n", a.output, mesh.num_vertices(),
               mesh.num_faces(), to_string(in), to_string(out));
  return 0;
}

}  // namespace follicle::cli
