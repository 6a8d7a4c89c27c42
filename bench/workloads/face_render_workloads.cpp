// Face rendering workload (issue 4): "face-render" draws the wrinkled default head of
// data/scenes/skin_troubled.json (muscles + tissue + large-scale wrinkles on the adaptively
// refined mesh, Lafortune skin BRDF, shadow-mapped key light + fill + rim) through the headless
// renderer at 640x480. With update=1 every iteration also re-runs the face update (muscles,
// tissue, wrinkles) and rebuilds the deformed mesh, i.e. a full animated frame.
#include <memory>

#include "follicle/core/error.hpp"
#include "follicle/render/renderer.hpp"
#include "follicle/scene/session.hpp"
#include "follicle/skin/face_rig.hpp"
#include "workloads/data_path.hpp"
#include "workloads/workload.hpp"

namespace follicle::workloads {
namespace {

class FaceRender final : public WorkloadInstance {
 public:
  FaceRender(const Context& ctx, const Sizes& sz)
      : m_ctx(ctx),
        m_session(scene::Session::load(find_data("scenes/skin_troubled.json"), ctx)),
        m_update(sz.at("update") != 0) {
    auto& r = m_session.scene().render;
    r.width = int(sz.at("width"));
    r.height = int(sz.at("height"));
    r.supersample = int(sz.at("supersample"));
    m_session.validate();
    m_settings = m_session.render_settings();
    m_scene = m_session.render_scene(0);  // builds the face rig and the wrinkled mesh (untimed)
    if (m_scene.meshes.size() != 1 ||
        m_scene.meshes[0].material.shading != render::MeshShading::LafortuneSkin)
      fail("face-render: expected one Lafortune-shaded face mesh in skin_troubled.json");
    m_pose = m_session.skin_pose(0, 0);
    m_renderer = render::Renderer::create_headless(ctx);
    (void)m_renderer->render(m_scene, m_settings);  // warm-up: shaders, targets, textures
  }
  void run_once() override {
    if (m_update) {
      const skin::FaceRig& rig = m_session.face_rig(0);
      rig.update(m_ctx, m_pose, m_state);
      m_scene.meshes[0].mesh = std::make_shared<const geom::TriMesh>(rig.deformed_mesh(m_state));
    }
    (void)m_renderer->render(m_scene, m_settings);
  }
  double items_per_iter() const override { return 1.0; }

 private:
  const Context& m_ctx;
  scene::Session m_session;
  bool m_update;
  render::RenderScene m_scene;
  render::RenderSettings m_settings;
  skin::MusclePose m_pose;
  skin::FaceState m_state;
  std::unique_ptr<render::Renderer> m_renderer;
};

}  // namespace

void add_face_render_workloads(std::vector<Workload>& out) {
  out.push_back(Workload{
      "face-render",
      "render the wrinkled default head ('troubled', Lafortune skin BRDF, shadow map) headless; "
      "update=1 also re-deforms the face every frame",
      {{"width", 640}, {"height", 480}, {"supersample", 1}, {"update", 0}},
      "frames/s",
      [](const Context& ctx, const Sizes& sz) -> std::unique_ptr<WorkloadInstance> {
        return std::make_unique<FaceRender>(ctx, sz);
      }});
}

}  // namespace follicle::workloads
