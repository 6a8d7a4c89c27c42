// Hair splat rendering (Bando 2003 §3.4): "lcp-render" renders the synthetic sphere head with
// 2,000 hair particles, self-shadowing on (light-view pass, shadow map, light map), headless.
// The light pass is the exact per-particle CPU pass (ADR 0005) unless gpu_light_pass=1; the
// view pass and the resolve run on the CPU (ADR 0007) unless gpu_view_pass=1.
#include "follicle/render/renderer.hpp"
#include "follicle/render/splat_bando2003.hpp"
#include "workloads/workload.hpp"

namespace follicle::workloads {
namespace {

class LcpRender final : public WorkloadInstance {
 public:
  LcpRender(const Context& ctx, const Sizes& sz) {
    m_settings.width = int(sz.at("width"));
    m_settings.height = int(sz.at("height"));
    m_settings.supersample = int(sz.at("supersample"));
    m_settings.shadow_map_size = int(sz.at("shadow_map_size"));
    m_settings.hair_light_map_size = int(sz.at("light_map_size"));
    m_settings.hair_light_pass = sz.at("gpu_light_pass") != 0 ? "gpu" : "cpu";
    m_settings.hair_light_slices = int(sz.at("slices"));  // the "gpu" pass only
    m_settings.hair_view_pass = sz.at("gpu_view_pass") != 0 ? "gpu" : "cpu";
    m_settings.validate();
    m_scene = render::make_hair_sheet_scene(int(sz.at("particles")));
    m_scene.particles.at(0).splat.self_shadow = sz.at("self_shadow") != 0;
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

void add_splat_workloads(std::vector<Workload>& out) {
  out.push_back(Workload{
      "lcp-render",
      "render 2,000 hair particles as self-shadowed splats (Bando 2003 §3.4) on a sphere head, "
      "headless",
      {{"particles", 2000},
       {"width", 512},
       {"height", 512},
       {"supersample", 1},
       {"shadow_map_size", 1024},
       {"light_map_size", 512},
       {"gpu_light_pass", 0},  // 1: the sliced GPU light pass (ADR 0003) instead of the CPU one
       {"slices", 128},
       {"gpu_view_pass", 0},  // 1: the GL view pass and resolve instead of the CPU ones
       {"self_shadow", 1}},
      "frames/s",
      [](const Context& ctx, const Sizes& sz) -> std::unique_ptr<WorkloadInstance> {
        return std::make_unique<LcpRender>(ctx, sz);
      }});
}

}  // namespace follicle::workloads
