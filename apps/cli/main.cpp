// follicle: the command-line front end. This is the only file that includes CLI11 (slow to
// compile); each subcommand's work is in cmd_*.cpp.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <string>

#include "commands.hpp"
#include "follicle/core/error.hpp"
#include "follicle/core/interrupt.hpp"
#include "follicle/core/resources.hpp"

namespace {

// One line on stderr: "follicle: error: <message>" (newlines folded so scripts can grep it).
int report(const std::string& msg, int code) {
  std::string one = msg;
  for (auto& c : one)
    if (c == '\n' || c == '\r') c = ' ';
  while (!one.empty() && one.back() == ' ') one.pop_back();
  std::fprintf(stderr, "follicle: error: %s\n", one.c_str());
  return code;
}

// Output paths must name something: `-o ''` used to fall back silently to the scene's outputs.
CLI::Validator non_empty_path() {
  return CLI::Validator(
      [](std::string& v) { return v.empty() ? std::string("an empty path names no file") : ""; },
      "PATH", "non-empty path");
}

}  // namespace

int main(int argc, char** argv) {
  using namespace follicle::cli;
  // SIGINT / SIGTERM remove the temporary file of an output being written and stop ffmpeg.
  follicle::install_interrupt_handlers();
  // Frames and simulation steps free and re-allocate the same memory (keep_freed_heap_memory).
  follicle::keep_freed_heap_memory();
  CLI::App app{"follicle: model, animate and render virtual heads (skin wrinkles and hair)",
               "follicle"};
  app.require_subcommand(1);
  app.fallthrough();  // global flags may also follow the subcommand
  GlobalOptions g;
  app.add_option("--threads", g.threads, "worker threads (0 = all hardware threads)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--seed", g.seed, "base random seed");
  auto* quiet = app.add_flag("-q,--quiet", g.quiet, "print only errors");
  app.add_flag("-v,--verbose", g.verbose, "log what is being done")->excludes(quiet);
  app.set_version_flag("--version", "follicle 0.1.0");

  RenderArgs ra;
  auto* render = app.add_subcommand("render", "render a scene to PNG");
  render->add_option("scene", ra.scene, "scene file (.json)")->required();
  render->add_option("-o,--output", ra.output, "output PNG (default: the scene's outputs)")
      ->check(non_empty_path());
  render->add_option("--width", ra.width, "image width in pixels (overrides the scene)")
      ->check(CLI::Range(1, 16384));
  render->add_option("--height", ra.height, "image height in pixels (overrides the scene)")
      ->check(CLI::Range(1, 16384));
  render->add_option("--frame", ra.frame, "frame number to render")->check(CLI::NonNegativeNumber);

  FitArgs fa;
  auto* fit = app.add_subcommand(
      "fit", "fit the bundled face setup to another head: setup.json, scene.json, fit.png");
  fit->add_option("head", fa.head, "head mesh (.obj, .ply, .gltf, .glb)")->required();
  auto* fit_units =
      fit->add_option("--units", fa.units, "length unit of the head file: mm, cm, dm, m")
          ->capture_default_str();
  fit->add_option("-o,--output", fa.output, "output folder")->required();
  fit->add_option("--up", fa.up, "the head's up direction X Y Z in the file (else found)")
      ->expected(3);
  fit->add_option("--front", fa.front, "the direction the face looks, X Y Z (else found)")
      ->expected(3);
  fit->add_option("--image-size", fa.image_size, "fit.png width and height in pixels")
      ->check(CLI::Range(64, 4096))
      ->capture_default_str();

  ValidateArgs va;
  auto* validate =
      app.add_subcommand("validate", "check scene files strictly and load their assets");
  validate->add_option("scenes", va.scenes, "scene files (.json)")->required();

  InfoArgs ia;
  auto* info = app.add_subcommand("info", "summarize a scene, mesh or hair file");
  info->add_option("file", ia.file,
                   "scene (.json), mesh (.obj, .ply, .gltf, .glb) or hair (.hair, .tfx, .usda, "
                   ".obj lines)")
      ->required();
  auto* info_units =
      info->add_option("--units", ia.units, "length unit of a mesh or hair file: mm, cm, dm, m")
          ->capture_default_str();

  ConvertArgs ca;
  auto* convert = app.add_subcommand(
      "convert", "convert a mesh (OBJ, PLY, glTF) or hair strands (.hair, .tfx, .usda, OBJ lines)");
  convert->add_option("input", ca.input, "input mesh or strand file")->required();
  convert->add_option("output", ca.output, "output file (format from the extension)")->required();
  convert
      ->add_option("--in-units", ca.in_units,
                   "length unit of the input: mm, cm, dm, m (a .usda's metersPerUnit wins)")
      ->capture_default_str();
  convert->add_option("--out-units", ca.out_units, "length unit to write: mm, cm, dm, m")
      ->capture_default_str();
  convert->add_flag("--ascii", ca.ascii, "write PLY as ASCII instead of binary");
  convert
      ->add_option("--tfx-verts", ca.tfx_verts,
                   "vertices per strand of a .tfx output (power of two, 4..64; resampled)")
      ->capture_default_str();

  BenchArgs ba;
  auto* bench = app.add_subcommand("bench", "run benchmark workloads, one JSON line each");
  bench->add_option("workloads", ba.workloads, "workload names (see --list)");
  bench->add_option("--size", ba.sizes, "KEY=VALUE size override (repeatable)");
  bench->add_flag("--list", ba.list, "list the workloads with their default sizes");
  bench->add_option("--min-seconds", ba.min_seconds, "minimum timed duration per workload")
      ->capture_default_str();

  ExportArgs ea;
  auto* exp = app.add_subcommand(
      "export",
      "write a scene's hair to a strand file, its wrinkle maps to images or its deformed face "
      "mesh");
  exp->add_option("scene", ea.scene, "scene file (.json)")->required();
  exp->add_option("--hair", ea.hair, "output strand file: .hair, .tfx, .usda or .obj")
      ->check(non_empty_path());
  exp->add_option("--maps", ea.maps,
                  "folder for height, normal and displacement maps (EXR + PNG) of the rest "
                  "state and each frame");
  exp->add_option("--frames", ea.frames, "frame range A-B of --maps (default: every frame)");
  exp->add_option("--frame", ea.frame, "frame of the animation")->check(CLI::NonNegativeNumber);
  exp->add_option("--units", ea.units, "length unit written to the file: mm, cm, dm, m")
      ->capture_default_str();
  exp->add_option("--cache", ea.cache, "strand cache folder (reuse simulated frames)");
  exp->add_option("--mesh", ea.mesh,
                  "output mesh of the deformed, wrinkled face (.obj, .ply, .gltf, .glb), in the "
                  "mesh file's coordinates");
  exp->add_option("--rig", ea.rig, "face rig of --mesh by mesh asset name (default: the first)");

  CompareArgs cma;
  auto* compare = app.add_subcommand(
      "compare", "distances between two meshes (mean, RMS, p95, max) and an error render");
  compare->add_option("a", cma.a, "first mesh (.obj, .ply, .gltf, .glb)")->required();
  compare->add_option("b", cma.b, "second mesh")->required();
  compare
      ->add_option("-o,--output", cma.output,
                   "PNG of A coloured by its distance to B (blue 0 .. red max)")
      ->check(non_empty_path());
  compare->add_option("--units", cma.units, "length unit of both files and of the printed numbers")
      ->capture_default_str();
  compare->add_option("--width", cma.width, "width of the error render")
      ->check(CLI::Range(16, 16384))
      ->capture_default_str();
  compare->add_option("--height", cma.height, "height of the error render")
      ->check(CLI::Range(16, 16384))
      ->capture_default_str();
  compare->add_option("--samples", cma.samples, "area-uniform samples per mesh")
      ->check(CLI::Range(uint64_t(1), uint64_t(1000000000)))
      ->capture_default_str();

  AnimateArgs aa;
  auto* animate = app.add_subcommand("animate", "render an animation to numbered PNGs and an MP4");
  animate->add_option("scene", aa.scene, "scene file (.json) with an \"animation\" section")
      ->required();
  animate->add_option("--frames", aa.frames, "frame range A-B (default: every frame)");
  animate->add_option("-o,--output", aa.output_dir, "output folder for frame_NNNN.png")
      ->required()
      ->check(non_empty_path());
  animate->add_option("--mp4", aa.mp4, "MP4 file (default: DIR/<scene>.mp4)")
      ->check(non_empty_path());
  animate->add_option("--cache", aa.cache, "strand cache folder: re-render without re-simulating");
  animate->add_flag("--no-video", aa.no_video, "write only the PNG frames");
  animate->add_option("--width", aa.width, "image width in pixels (overrides the scene)")
      ->check(CLI::Range(1, 16384));
  animate->add_option("--height", aa.height, "image height in pixels (overrides the scene)")
      ->check(CLI::Range(1, 16384));

  HarnessArgs ha;
  auto* harness = app.add_subcommand(
      "harness",
      "run every hair model on a scene's groom under the same motion; report stretch, "
      "penetration, root drift, energy and speed (JSON) and a comparison sheet (PNG)");
  harness->add_option("scene", ha.scene, "scene file (.json) with \"hair\" and \"animation\"")
      ->required();
  harness->add_option("--frames", ha.frames, "frame range A-B (default: every frame)");
  harness->add_option("--models", ha.models, "hair models m1,m2,... (default: all)");
  harness->add_option("--group", ha.group, "hair group by index or name (default: 0)");
  harness->add_option("--sheet-frames", ha.sheet_frames,
                      "frames pictured on the sheet f1,f2,... (default: first, middle, last)");
  harness->add_option("--thumb-size", ha.thumb_size, "width of each picture in pixels")
      ->capture_default_str();
  harness->add_option("--json", ha.json, "report file (.json)")->check(non_empty_path());
  harness->add_option("--sheet", ha.sheet, "comparison sheet (.png)")->check(non_empty_path());

  DocsArgs da;
  auto* docs = app.add_subcommand("docs", "");  // hidden: an empty group hides it from --help
  docs->group("");
  docs->add_option("topic", da.topic, "scene-format or face-setup")->required();
  docs->add_option("--write", da.write, "markdown file whose generated tables to refresh");
  docs->add_flag("--check", da.check, "fail when the file is out of date (with --write)");

  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {
    return app.exit(e);  // --help / --version (CallForHelp derives from Success)
  } catch (const CLI::ParseError& e) {
    return report(std::string(e.what()) + " (run 'follicle --help')", 2);
  }

  try {
    if (*render) return run_render(g, ra);
    if (*validate) return run_validate(g, va);
    if (*info) {
      ia.units_given = info_units->count() > 0;
      return run_info(g, ia);
    }
    if (*convert) return run_convert(g, ca);
    if (*fit) {
      fa.units_given = fit_units->count() > 0;
      return run_fit(g, fa);
    }
    if (*bench) return run_bench(g, ba);
    if (*docs) return run_docs(g, da);
    if (*exp) return run_export(g, ea);
    if (*animate) return run_animate(g, aa);
    if (*compare) return run_compare(g, cma);
    if (*harness) return run_harness(g, ha);
    return report("no command given (run 'follicle --help')", 2);
  } catch (const UsageError& e) {
    return report(e.what(), 2);
  } catch (const follicle::Error& e) {
    return report(e.what(), 1);
  } catch (const std::exception& e) {
    return report(std::string("unexpected: ") + e.what(), 1);
  }
}
