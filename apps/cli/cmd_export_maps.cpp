// follicle export SCENE --maps DIR [--frames A-B]: the fine-wrinkle relief of the scene's hand
// and of every skin rig with "fine" as height, normal and displacement maps (float EXR + 8-bit
// PNG, skin::export_wrinkle_maps) for the rest state (DIR/hand_rest_*, DIR/skinR_rest_*) and
// every frame of the range (DIR/hand_frame_NNNN_*, DIR/skinR_frame_NNNN_*). Every file is
// written atomically (temp file + rename).
#include <fmt/format.h>

#include <cctype>
#include <filesystem>

#include "commands.hpp"
#include "follicle/core/atomic_file.hpp"
#include "follicle/core/error.hpp"
#include "follicle/core/progress.hpp"
#include "follicle/scene/session.hpp"

namespace follicle::cli {

int run_export_maps(const GlobalOptions& g, const ExportArgs& a) {
  auto ctx = make_context(g);
  int first = -1, last = -1;
  parse_frames(a.frames, first, last);
  auto session = scene::Session::load(a.scene, *ctx);
  if (!session.has_wrinkle_maps())
    fail_at(a.scene,
            "the scene has no fine-wrinkle source for --maps (a \"hand\" section or \"fine\" "
            "in a skin rig); nothing to export");
  const int count = session.frame_count();
  if (first < 0) {
    first = 0;
    last = count - 1;
  }
  if (last >= count)
    throw UsageError(
        fmt::format("--frames {}-{}: the scene has frames 0-{}", first, last, count - 1));
  const std::filesystem::path dir(a.maps);
  check_output_folder(dir);
  Progress progress("maps", std::size_t(last - first + 2), !g.quiet);
  session.export_wrinkle_maps(dir, -1);  // rest state
  progress.tick();
  for (int f = first; f <= last; ++f) {
    session.export_wrinkle_maps(dir, f);
    progress.tick();
  }
  progress.finish();
  if (!g.quiet)
    fmt::print(
        "wrote height, normal and displacement maps (EXR + PNG) of the rest state and "
        "frames {}-{} to {}\n",
        first, last, dir.string());
  return 0;
}

}  // namespace follicle::cli
