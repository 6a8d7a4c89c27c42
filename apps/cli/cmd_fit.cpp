// follicle fit HEAD --units U -o DIR [--up X Y Z --front X Y Z]: the bundled template's face
// setup fitted to another head (scene/head_fit), with the registration's residual printed.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <filesystem>

#include "commands.hpp"
#include "follicle/core/log.hpp"
#include "follicle/core/progress.hpp"
#include "follicle/core/units.hpp"
#include "follicle/geom/mesh_io.hpp"
#include "follicle/scene/head_fit.hpp"
#include "workloads/data_path.hpp"

namespace follicle::cli {

int run_fit(const GlobalOptions& g, const FitArgs& a) {
  auto ctx = make_context(g);
  const LengthUnit units = parse_length_unit(a.units);
  if (!a.units_given)
    ctx->log().warn("{}: no --units given; the head is assumed to be in metres", a.head);
  std::optional<Vec3> up, front;
  if (!a.up.empty()) up = Vec3(a.up[0], a.up[1], a.up[2]);
  if (!a.front.empty()) front = Vec3(a.front[0], a.front[1], a.front[2]);
  if (up.has_value() != front.has_value())
    throw UsageError("give both --up and --front, or neither (then both are found)");

  Progress progress("fit", 4, !g.quiet);
  const auto head = geom::load_mesh(a.head, units);
  const auto tpl = scene::load_head_template(
      workloads::find_data("meshes/lee_perry_smith/head.obj"), LengthUnit::mm,
      workloads::find_data("muscles/lee_perry_smith.json"));
  progress.tick();
  const double size = head.bounds().diagonal().norm();
  if (size < 0.05 || size > 2.0)
    ctx->log().warn(
        "{}: the head is {:.3g} m across in {} — implausible for a head; is --units right?", a.head,
        size, to_string(units));
  const auto fit = scene::fit_head(*ctx, tpl, head, up, front);
  progress.tick();
  const auto out = scene::write_head_fit(*ctx, fit, a.head, units, scene::fit_mapping(fit, head),
                                         a.output, a.image_size);
  progress.tick();
  progress.finish();
  const auto& s = fit.setup;
  fmt::print("orientation: up [{:.3f}, {:.3f}, {:.3f}], front [{:.3f}, {:.3f}, {:.3f}] ({})\n",
             s.up.x(), s.up.y(), s.up.z(), s.front.x(), s.front.y(), s.front.z(),
             fit.orientation_given ? "given" : "found");
  fmt::print(
      "scale: template x {:.4f}; rigid residual {:.2f} mm (overlap: {:.0f} % of the "
      "template, {:.0f} % of the head)\n",
      fit.rigid.s, fit.rigid_residual * 1e3, 100 * fit.overlap_template, 100 * fit.overlap_head);
  fmt::print(
      "registration residual: RMS {:.2f} mm, 95th percentile {:.2f} mm over {:.0f} % of "
      "the template's vertices\n",
      fit.residual_rms * 1e3, fit.residual_p95 * 1e3, 100 * fit.matched_fraction);
  for (const auto& l : fit.landmarks)
    fmt::print("  {:<9} [{:.4f}, {:.4f}, {:.4f}] m ({})\n", l.name, l.position.x(), l.position.y(),
               l.position.z(), l.detected ? "found on the mesh" : "registered");
  if (!fit.whole_head())
    fmt::print(
        "a face mask (it covers {:.0f} % of the template's head): no scalp, so "
        "scene.json has no hair\n",
        100 * fit.overlap_template);
  if (!fit.dropped_wrinkles.empty())
    fmt::print("wrinkles left out (mostly beyond the head's surface): {}\n",
               fmt::join(fit.dropped_wrinkles, ", "));
  fmt::print("wrote {}, {}, {}\n", out.setup.string(), out.scene.string(), out.image.string());
  return 0;
}

}  // namespace follicle::cli
