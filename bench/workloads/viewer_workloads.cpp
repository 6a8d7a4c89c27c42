// Viewer workload "viewer-frame" (issue 25 item 2): what follicle-viewer draws per frame while
// the camera moves, headless, for the shipped scenes (data/scenes/*.json, sorted by name; size
// "scene": its index, or -1 = all of them in turn). The view is 880 x 800 (a 1280 x 800 window
// less the 400-pixel panel); each iteration orbits the camera by 2 degrees about the scene's
// target and draws frame 0 with render::PreviewReducer (size "moving" = 1) or at full quality
// ("moving" = 0). Scene construction (styling, simulation of frame 0) is untimed; the setup logs
// every scene's median frame time over 5 frames, and how many scenes reach 10 frames/s, so the
// slowest scene is visible.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "follicle/core/error.hpp"
#include "follicle/core/log.hpp"
#include "follicle/render/preview_scene.hpp"
#include "follicle/render/renderer.hpp"
#include "follicle/scene/session.hpp"
#include "workloads/data_path.hpp"
#include "workloads/workload.hpp"

namespace follicle::workloads {
namespace {

struct ViewScene {
  std::string name;
  render::RenderScene scene;
  render::RenderSettings settings;
};

class ViewerFrame final : public WorkloadInstance {
 public:
  ViewerFrame(const Context& ctx, const Sizes& sz) : m_moving(sz.at("moving") != 0) {
    namespace fs = std::filesystem;
    const fs::path dir = find_data("scenes");
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(dir))
      if (e.path().extension() == ".json") files.push_back(e.path());
    std::sort(files.begin(), files.end());
    if (files.empty()) fail("viewer-frame: no scenes in {}", dir.string());
    const double pick = sz.at("scene");
    if (pick != std::floor(pick) || pick < -1 || pick >= double(files.size()))
      fail("viewer-frame: scene must be -1 (all) or an index below {}, got {}", files.size(), pick);
    if (pick >= 0) files = {files[std::size_t(pick)]};
    m_renderer = render::Renderer::create_headless(ctx);
    for (const auto& f : files) {
      auto session = scene::Session::load(f, ctx);
      session.load_all_assets();
      ViewScene v;
      v.name = f.stem().string();
      v.scene = session.render_scene(0);
      v.settings = session.render_settings();
      v.settings.width = 880;
      v.settings.height = 800;
      if (m_moving) m_preview.reduce(v.scene, v.settings, render::PreviewParams{});
      m_scenes.push_back(std::move(v));
    }
    // Warm-up (shaders, targets, textures), then, for the log, the median of kLogFrames frames
    // per scene with the camera orbiting (one frame scattered by +-20 %).
    for (auto& v : m_scenes) (void)m_renderer->render(v.scene, v.settings);
    constexpr int kLogFrames = 5;
    std::size_t interactive = 0;
    std::string slowest;
    double slowest_ms = 0;
    for (std::size_t i = 0; i < m_scenes.size(); ++i) {
      ViewScene& v = m_scenes[i];
      std::vector<double> ms;
      for (int f = 0; f < kLogFrames; ++f) {
        const auto t0 = std::chrono::steady_clock::now();
        draw(v);
        ms.push_back(
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                .count());
      }
      std::nth_element(ms.begin(), ms.begin() + kLogFrames / 2, ms.end());
      const double med = ms[kLogFrames / 2];
      ctx.log().info("viewer-frame: {} {:.1f} ms ({:.1f} frames/s) at {}x{}{}, median of {}",
                     v.name, med, 1000.0 / med, v.settings.width, v.settings.height,
                     m_moving ? " (moving)" : "", kLogFrames);
      if (med <= 100.0) ++interactive;
      if (med > slowest_ms) {
        slowest_ms = med;
        slowest = v.name;
      }
    }
    ctx.log().info("viewer-frame: {} of {} scenes at >= 10 frames/s; slowest {} {:.1f} ms",
                   interactive, m_scenes.size(), slowest, slowest_ms);
  }
  void run_once() override { draw(m_scenes[m_next++ % m_scenes.size()]); }
  double items_per_iter() const override { return 1.0; }

 private:
  // Orbits the camera 2 degrees about the target's vertical axis and draws the frame.
  void draw(ViewScene& v) {
    auto& cam = v.scene.camera;
    const double a = 2.0 * kPi / 180.0;
    const Vec3 d = cam.eye - cam.target;
    cam.eye = cam.target + Vec3(std::cos(a) * d.x() + std::sin(a) * d.z(), d.y(),
                                -std::sin(a) * d.x() + std::cos(a) * d.z());
    (void)m_renderer->render(v.scene, v.settings);
  }

  bool m_moving = true;
  std::unique_ptr<render::Renderer> m_renderer;
  render::PreviewReducer m_preview;
  std::vector<ViewScene> m_scenes;
  std::size_t m_next = 0;
};

}  // namespace

void add_viewer_workloads(std::vector<Workload>& out) {
  out.push_back(Workload{
      "viewer-frame",
      "what follicle-viewer draws per frame while the camera moves (880x800 view of a 1280x800 "
      "window), headless, for the shipped scenes in turn (scene = index, -1 = all; moving = 0: "
      "full quality)",
      {{"scene", -1}, {"moving", 1}},
      "frames/s",
      [](const Context& ctx, const Sizes& sz) -> std::unique_ptr<WorkloadInstance> {
        return std::make_unique<ViewerFrame>(ctx, sz);
      }});
}

}  // namespace follicle::workloads
