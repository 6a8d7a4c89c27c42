// follicle render SCENE [-o out.png] [--width W --height H --frame N]
#include <fmt/format.h>

#include <cctype>
#include <filesystem>

#include "commands.hpp"
#include "follicle/core/atomic_file.hpp"
#include "follicle/core/log.hpp"
#include "follicle/core/progress.hpp"
#include "follicle/image/image_io.hpp"
#include "follicle/render/renderer.hpp"
#include "follicle/scene/session.hpp"

namespace follicle::cli {

namespace {

void require_png(const std::string& path, const char* what) {
  auto ext = std::filesystem::path(path).extension().string();
  for (auto& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (ext != ".png") throw UsageError(fmt::format("{} must end in .png, got '{}'", what, path));
}

}  // namespace

int run_render(const GlobalOptions& g, const RenderArgs& a) {
  auto ctx = make_context(g);
  if (a.frame < 0) throw UsageError(fmt::format("--frame must be >= 0, got {}", a.frame));
  if (!a.output.empty()) require_png(a.output, "-o");

  // Everything that can fail (scene, assets, renderer) happens before any output is touched;
  // the PNG writer is atomic (temp file + rename), so a failure never leaves a partial file.
  auto session = scene::Session::load(a.scene, *ctx);
  if (a.width > 0) session.scene().render.width = a.width;
  if (a.height > 0) session.scene().render.height = a.height;
  session.validate();

  std::vector<std::filesystem::path> outputs;
  if (!a.output.empty()) {
    outputs.emplace_back(a.output);
  } else {
    for (const auto& o : session.scene().outputs)
      if (o.type == scene::OutputType::Image) outputs.emplace_back(o.path);
  }
  if (outputs.empty())
    throw UsageError(fmt::format("{} lists no outputs: give -o FILE.png", a.scene));
  for (const auto& out : outputs) check_output_writable(out);  // before the work, not after

  Progress progress("render", 2 + outputs.size(), !g.quiet);
  const auto rs = session.render_scene(a.frame);
  progress.tick();
  auto renderer = render::Renderer::create_headless(*ctx);
  ctx->log().info("renderer: {}", renderer->device_description());
  const auto img = renderer->render(rs, session.render_settings());
  progress.tick();
  for (const auto& out : outputs) {
    image::write_png(out, img);
    progress.tick();
  }
  progress.finish();
  if (!g.quiet)
    for (const auto& out : outputs)
      fmt::print("wrote {} ({}x{})\n", out.string(), img.width(), img.height());
  return 0;
}

}  // namespace follicle::cli
