// follicle export SCENE --mesh out.obj|.ply|.gltf|.glb [--rig NAME] [--frame N] [--units U]: the
// deformed, wrinkled mesh of one face rig of the scene's "skin" section (the first, or the rig on
// mesh asset NAME) at a frame: muscles, tissue and large-scale wrinkles applied to the adaptively
// refined mesh (Bando 2002 §2.5). Coordinates are the mesh file's own (the asset transform is not
// applied), written in --units. Written atomically (temp file + rename).
#include <fmt/format.h>

#include <cctype>
#include <filesystem>

#include "commands.hpp"
#include "follicle/core/atomic_file.hpp"
#include "follicle/core/error.hpp"
#include "follicle/core/units.hpp"
#include "follicle/geom/mesh_io.hpp"
#include "follicle/scene/session.hpp"

namespace follicle::cli {

int run_export_mesh(const GlobalOptions& g, const ExportArgs& a) {
  auto ext = std::filesystem::path(a.mesh).extension().string();
  for (auto& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (ext != ".obj" && ext != ".ply" && ext != ".gltf" && ext != ".glb")
    throw UsageError(fmt::format("--mesh must end in .obj, .ply, .gltf or .glb, got '{}'", a.mesh));
  if (a.frame < 0) throw UsageError(fmt::format("--frame must be >= 0, got {}", a.frame));
  const LengthUnit unit = parse_length_unit(a.units);
  if ((ext == ".gltf" || ext == ".glb") && unit != LengthUnit::m)
    throw UsageError(fmt::format(
        "--mesh {}: glTF stores metres by specification; use --units m (not {})", a.mesh, a.units));

  auto ctx = make_context(g);
  auto session = scene::Session::load(a.scene, *ctx);
  check_output_writable(a.mesh);  // before the face rig is built, not after
  const auto& skin = session.scene().skin;
  if (skin.empty())
    fail_at(a.scene, "the scene has no \"skin\" face rigs; --mesh exports a deformed face");
  std::size_t ri = 0;
  if (!a.rig.empty()) {
    std::vector<std::string> names;
    bool found = false;
    for (std::size_t i = 0; i < skin.size(); ++i) {
      names.push_back(skin[i].mesh);
      if (skin[i].mesh == a.rig) {
        ri = i;
        found = true;
      }
    }
    if (!found) {
      std::string list;
      for (const auto& n : names) list += (list.empty() ? "\"" : ", \"") + n + "\"";
      const std::string hint = did_you_mean(a.rig, names);
      throw UsageError(
          fmt::format("--rig '{}': the scene has no face rig on that mesh{}; rigs: {}", a.rig,
                      hint.empty() ? "" : fmt::format(" (did you mean '{}'?)", hint), list));
    }
  }
  if (a.frame >= session.frame_count())
    throw UsageError(fmt::format("--frame {} is past the scene's last frame {}", a.frame,
                                 session.frame_count() - 1));
  const auto mesh = session.skin_mesh(ri, a.frame);  // errors name the scene and JSON path
  geom::save_mesh(*mesh, a.mesh, unit);              // atomic (temp file + rename)
  if (!g.quiet)
    fmt::print(
        "wrote {} (face rig on mesh \"{}\", {} vertices, {} faces, frame {}, wrinkles {}, "
        "{})\n",
        a.mesh, skin[ri].mesh, mesh->num_vertices(), mesh->num_faces(), a.frame,
        skin[ri].wrinkles ? "on" : "off", to_string(unit));
  return 0;
}

}  // namespace follicle::cli
