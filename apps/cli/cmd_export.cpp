// follicle export SCENE --hair out.EXT [--frame N] [--units U]: the scene's hair (every group,
// concatenated) at a frame, as Cem Yuksel .hair, TressFX .tfx, USD ASCII .usda or OBJ polylines
// (by extension). Written atomically.
#include <fmt/format.h>

#include <cctype>
#include <filesystem>

#include "commands.hpp"
#include "follicle/core/atomic_file.hpp"
#include "follicle/core/units.hpp"
#include "follicle/geom/strand_io.hpp"
#include "follicle/scene/session.hpp"

namespace follicle::cli {

int run_export(const GlobalOptions& g, const ExportArgs& a) {
  if (a.hair.empty() && a.maps.empty() && a.mesh.empty())
    throw UsageError(
        "nothing to export: give --hair out.hair|.tfx|.usda|.obj, --maps DIR or --mesh "
        "out.obj|.ply|.glb");
  if (!a.frames.empty() && a.maps.empty()) throw UsageError("--frames applies to --maps only");
  if (!a.rig.empty() && a.mesh.empty()) throw UsageError("--rig applies to --mesh only");
  if (!a.mesh.empty()) {
    run_export_mesh(g, a);  // cmd_export_mesh.cpp
    if (a.hair.empty() && a.maps.empty()) return 0;
  }
  if (!a.maps.empty()) {
    run_export_maps(g, a);
    if (a.hair.empty()) return 0;
  }
  auto ctx = make_context(g);
  auto ext = std::filesystem::path(a.hair).extension().string();
  for (auto& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (ext != ".hair" && ext != ".tfx" && ext != ".usda" && ext != ".obj")
    throw UsageError(
        fmt::format("--hair must end in .hair, .tfx, .usda or .obj, got '{}'", a.hair));
  if (a.frame < 0) throw UsageError(fmt::format("--frame must be >= 0, got {}", a.frame));
  const LengthUnit unit = parse_length_unit(a.units);

  auto session = scene::Session::load(a.scene, *ctx);
  if (session.scene().hair.empty()) fail_at(a.scene, "the scene has no \"hair\" groups to export");
  if (a.frame >= session.frame_count())
    throw UsageError(fmt::format("--frame {} is past the scene's last frame {}", a.frame,
                                 session.frame_count() - 1));
  if (!a.cache.empty()) session.set_strand_cache(a.cache);
  check_output_writable(a.hair);  // before the simulation, not after
  const geom::StrandSet hair = session.all_hair(a.frame);
  geom::save_strands(hair, a.hair, unit);  // atomic (temp file + rename)
  if (!g.quiet)
    fmt::print("wrote {} ({} strands, {} points, frame {})\n", a.hair, hair.num_strands(),
               hair.num_points(), a.frame);
  return 0;
}

}  // namespace follicle::cli
