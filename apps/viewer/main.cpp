// follicle-viewer SCENE [--frame F] [--screenshot out.png [--frames N] [--with-ui]]
//                 [--width W --height H] [--set PATH=VALUE ...] [--save edited.json] [--preview]
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>

#include "follicle/core/error.hpp"
#include "follicle/core/resources.hpp"
#include "viewer_app.hpp"

int main(int argc, char** argv) {
  // Every frame frees and re-allocates the GL driver's memory (keep_freed_heap_memory).
  follicle::keep_freed_heap_memory();
  follicle::viewer::ViewerOptions opt;
  CLI::App app{"follicle-viewer: interactive viewer for Follicle scene files", "follicle-viewer"};
  std::string scene, screenshot;
  app.add_option("scene", scene, "scene file (JSON)")->required()->check(CLI::ExistingFile);
  app.add_option("--screenshot", screenshot,
                 "batch mode: draw --frames frames, save the view to this PNG and exit");
  app.add_option("--frames", opt.frames, "frames to draw before the batch screenshot")
      ->check(CLI::Range(1, 100000));
  app.add_option("--frame", opt.frame,
                 "open at this timeline frame of an animated scene (as the panel's frame slider)")
      ->check(CLI::Range(0, 10000000));
  app.add_flag("--with-ui", opt.screenshot_ui,
               "batch screenshot of the whole window with the panel");
  app.add_option("--width", opt.width, "window width")->check(CLI::Range(400, 16384));
  app.add_option("--height", opt.height, "window height")->check(CLI::Range(200, 16384));
  app.add_option("-j,--threads", opt.threads, "CPU threads (0 = all)")->check(CLI::Range(0, 1024));
  app.add_option("--set", opt.sets,
                 "edit the scene after loading, as the panel does: PATH=VALUE with a JSON path "
                 "(hair[0].density_scale=0.5) and a JSON value (repeatable)");
  std::string save;
  app.add_option("--save", save,
                 "write the (edited) scene to this JSON file, as the panel's Save does (asset "
                 "paths made relative to its folder)");
  app.add_flag("--preview", opt.preview,
               "draw as while the camera moves (smaller image, fewer strands; see the panel's "
               "'preview while moving')");
  CLI11_PARSE(app, argc, argv);
  opt.save = save;
  opt.scene = scene;
  opt.screenshot = screenshot;
  if (!screenshot.empty() && !screenshot.ends_with(".png") && !screenshot.ends_with(".PNG")) {
    fmt::print(stderr, "follicle-viewer: --screenshot must end in .png, got '{}'\n", screenshot);
    return 2;
  }
  try {
    return follicle::viewer::run_viewer(opt);
  } catch (const std::exception& e) {
    fmt::print(stderr, "follicle-viewer: {}\n", e.what());
    return 1;
  }
}
