// Hair rendering workload "hair-render": the bob of data/scenes/anjyo_bob.json (Anjyo 1992
// Fig. 3) grown to `strands` strands on the default head, shaded per node with eqs. (8)/(9)
// (untimed, on the CPU), then rendered headless (head + z-buffered vertex-coloured polylines)
// at width x height. Timed: one Renderer::render call (upload, draw, resolve, read-back).
#include <cmath>
#include <memory>

#include "follicle/core/error.hpp"
#include "follicle/render/renderer.hpp"
#include "follicle/scene/session.hpp"
#include "workloads/data_path.hpp"
#include "workloads/workload.hpp"

namespace follicle::workloads {
namespace {

// Keeps the first n strands of s.
void truncate_strands(geom::StrandSet& s, std::size_t n) {
  if (s.num_strands() <= n) return;
  s.offsets.resize(n + 1);
  const std::size_t np = s.offsets.back();
  s.points.resize(np);
  if (!s.color.empty()) s.color.resize(np);
  if (!s.radius.empty()) s.radius.resize(np);
}

class HairRender final : public WorkloadInstance {
 public:
  HairRender(const Context& ctx, const Sizes& sz) {
    const auto scenes = find_data("scenes");
    const std::size_t want = std::size_t(sz.at("strands"));
    if (want < 1) fail("hair-render: strands must be >= 1");
    scene::Json j = scene::parse_json_file(scenes / "anjyo_bob.json");
    // Density for the wanted count: count at a small density, scale up with 3 % slack, trim.
    j["hair"][0]["density_scale"] = 0.1;
    std::size_t n01 = 0;
    {
      auto probe = scene::Session::from_json(j, scenes, "anjyo_bob.json", ctx);
      n01 = probe.hair_strands(0, 0)->num_strands();
    }
    if (n01 == 0) fail("hair-render: the bob preset grew no strands");
    j["hair"][0]["density_scale"] = std::min(100.0, 0.1 * double(want) / double(n01) * 1.03);
    j["render"]["width"] = int(sz.at("width"));
    j["render"]["height"] = int(sz.at("height"));
    j["render"]["supersample"] = int(sz.at("supersample"));
    auto session = scene::Session::from_json(j, scenes, "anjyo_bob.json", ctx);
    m_scene = session.render_scene(0);
    auto hair = std::make_shared<geom::StrandSet>(*m_scene.strands.at(0).strands);
    truncate_strands(*hair, want);
    m_strands = hair->num_strands();
    m_scene.strands[0].strands = hair;
    m_settings = session.render_settings();
    m_renderer = render::Renderer::create_headless(ctx);
    (void)m_renderer->render(m_scene, m_settings);  // warm-up: shaders, targets, textures
  }
  void run_once() override { (void)m_renderer->render(m_scene, m_settings); }
  double items_per_iter() const override { return double(m_strands); }

 private:
  render::RenderScene m_scene;
  render::RenderSettings m_settings;
  std::unique_ptr<render::Renderer> m_renderer;
  std::size_t m_strands = 0;
};

}  // namespace

void add_hair_render_workloads(std::vector<Workload>& out) {
  out.push_back(Workload{
      "hair-render",
      "render 100,000 Anjyo-shaded hair strands (bob preset) with the default head headless",
      {{"strands", 100000}, {"width", 1024}, {"height", 1024}, {"supersample", 2}},
      "strands/s",
      [](const Context& ctx, const Sizes& sz) -> std::unique_ptr<WorkloadInstance> {
        return std::make_unique<HairRender>(ctx, sz);
      }});
}

}  // namespace follicle::workloads
