#pragma once
// follicle-viewer: a GLFW window (OpenGL 3.3 core) showing a scene through the shared GL
// renderer, with an orbit camera and a Dear ImGui side panel. See README "Viewer".
#include <filesystem>
#include <string>
#include <vector>

namespace follicle::viewer {

struct ViewerOptions {
  std::filesystem::path scene;       // scene JSON file
  std::filesystem::path screenshot;  // batch mode when set: render `frames` frames, save, exit
  int frames = 3;                    // frames drawn in batch mode before the screenshot
  bool screenshot_ui = false;        // batch screenshot of the whole window (panel included)
  int width = 1280;                  // window size [screen coordinates]
  int height = 900;
  int threads = 0;  // CPU threads for scene work (0 = all)
  // Edits applied after loading, as the panel would make them: "PATH=VALUE" with a JSON path
  // (hair[0].density_scale) and a JSON value (a string when it does not parse as JSON).
  std::vector<std::string> sets;
  std::filesystem::path save;  // batch mode: write the (edited) scene here before exiting
  bool preview = false;        // draw every frame as while the camera moves (batch checks)
  int frame = 0;               // timeline frame to open at, as if the slider were moved there
};

/// Runs the viewer until the window closes (or the batch screenshot is written). Returns the
/// process exit code: 0, or 1 when batch mode could not load/render the scene. Throws
/// follicle::Error when no window/GL 3.3 context can be made.
int run_viewer(const ViewerOptions& opt);

}  // namespace follicle::viewer
