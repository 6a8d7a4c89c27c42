// Rendering workloads: "render-head" renders the textured default head at 1024^2 headless.
#include <cstdlib>
#include <filesystem>

#include "follicle/core/error.hpp"
#include "follicle/render/framing.hpp"
#include "follicle/render/renderer.hpp"
#include "workloads/data_path.hpp"
#include "workloads/workload.hpp"

namespace follicle::workloads {
namespace {

std::filesystem::path find_head_dir() {
  return find_data("meshes/lee_perry_smith");
}

class RenderHead final : public WorkloadInstance {
 public:
  RenderHead(const Context& ctx, const Sizes& sz) {
    m_settings.width = int(sz.at("width"));
    m_settings.height = int(sz.at("height"));
    m_settings.supersample = int(sz.at("supersample"));
    m_settings.validate();
    m_scene = render::make_head_scene(find_head_dir(), sz.at("lafortune") != 0);
    m_renderer = render::Renderer::create_headless(ctx);
    (void)m_renderer->render(m_scene, m_settings);  // warm-up: shaders, targets, textures
  }
  void run_once() override { (void)m_renderer->render(m_scene, m_settings); }
  double items_per_iter() const override { return 1.0; }

 private:
  render::RenderScene m_scene;
  render::RenderSettings m_settings;
  std::unique_ptr<render::Renderer> m_renderer;
};

}  // namespace

void add_render_workloads(std::vector<Workload>& out) {
  out.push_back(Workload{
      "render-head",
      "render the textured default head (Lee Perry-Smith, 8.8k triangles, shadow map) headless",
      {{"width", 1024}, {"height", 1024}, {"supersample", 2}, {"lafortune", 0}},
      "frames/s",
      [](const Context& ctx, const Sizes& sz) -> std::unique_ptr<WorkloadInstance> {
        return std::make_unique<RenderHead>(ctx, sz);
      }});
}

}  // namespace follicle::workloads
