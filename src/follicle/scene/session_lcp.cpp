// Session: loosely connected particle hair (Bando, Chen & Nishita 2003; thesis ch. 3) through
// hair::LcpScenario (back hair on a mesh head named by lcp.mesh or on a sphere, optional head
// shake and SPH wind). The
// simulation starts at frame 0 and advances steps_per_frame steps of 1 / (fps steps_per_frame)
// per frame; consecutive frames continue from the kept state, an earlier frame restarts from
// frame 0, so any frame is the same whatever was rendered before it. The particles are drawn as
// hair splats (render::ParticleShading::HairSplat, §3.4) aligned with t_i.
#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <optional>

#include "follicle/core/error.hpp"
#include "follicle/core/log.hpp"
#include "follicle/image/image_io.hpp"
#include "follicle/scene/hand_runtime.hpp"
#include "follicle/scene/session.hpp"

namespace follicle::scene {

std::size_t Session::lcp_steps() const {
  return m_lcp ? m_lcp->steps : 0;
}

std::shared_ptr<const geom::ParticleSet> Session::lcp_particles(int frame) {
  if (!m_scene.lcp) fail_at(m_source, "the scene has no \"lcp\" section");
  if (frame < 0) fail("frame {} is negative", frame);
  const LcpSpec& spec = *m_scene.lcp;
  if (!m_lcp) m_lcp = std::make_shared<LcpRuntime>();
  LcpRuntime& rt = *m_lcp;
  if (rt.last && rt.last_frame == frame) return rt.last;
  if (!rt.ctx) {
    rt.ctx = std::make_unique<Context>(m_ctx->threads(), spec.seed, m_ctx->logger_ptr());
    rt.ctx->set_progress(m_ctx->progress());
  }
  const Context& ctx = *rt.ctx;
  if (!m_scene.animation && frame > 0)
    fail_at(m_source, "frame {} of a still scene (add an \"animation\" section)", frame);

  if (!rt.sim || rt.state_frame > frame) {  // (re)start deterministically at frame 0
    // A mesh head in scene coordinates at rest (the asset transform applied): the head frame.
    std::optional<geom::TriMesh> head_mesh;
    if (!spec.mesh.empty()) {
      const std::size_t mi = mesh_index(spec.mesh);
      head_mesh = *mesh(mi);
      head_mesh->transform(m_scene.assets.meshes[mi].transform.matrix());
    }
    image::ImageF length_map;
    if (!spec.length_map.empty()) {
      const auto file = resolve(spec.length_map);
      if (!std::filesystem::is_regular_file(file))
        fail_at(m_source, "lcp.length_map: image not found: {}", file.string());
      length_map = image::read_gray_map(file);
    }
    try {
      rt.sim = std::make_unique<hair::LcpScenario>(ctx, spec.scenario, spec.dynamics,
                                                   head_mesh ? &*head_mesh : nullptr,
                                                   length_map.empty() ? nullptr : &length_map);
    } catch (const Error& e) {
      fail_at(m_source, "lcp: {}", e.what());
    }
    rt.head = std::make_shared<const geom::TriMesh>(rt.sim->head());
    rt.state_frame = 0;
    ctx.log().info("lcp: {} particles, {} connections", rt.sim->solver().model().size(),
                   rt.sim->solver().model().num_pairs());
  }
  const double dt =
      m_scene.animation ? 1.0 / (m_scene.animation->fps * double(spec.steps_per_frame)) : 0.0;
  while (rt.state_frame < frame) {
    const int f = rt.state_frame + 1;
    for (int k = 0; k < spec.steps_per_frame; ++k) {
      const std::vector<Vec3>* extra = nullptr;
      if (spec.part) {  // back hair with the parting force (Fig. 3.7), world frame
        const auto& model = rt.sim->solver().model();
        const auto& st = rt.sim->state();
        const double a = spec.part->at(st.time);
        rt.force.assign(model.size(), Vec3::Zero());
        for (std::size_t i = 0; i < model.size(); ++i) {
          if (model.root[i]) continue;
          const double side = st.x[i].x() >= spec.part->centre_x ? 1.0 : -1.0;
          rt.force[i] = Vec3(side * a * model.mass[i], 0.0, 0.0);
        }
        extra = &rt.force;
      }
      const hair::LcpStepReport rep = rt.sim->step(ctx, dt, extra);
      ++rt.steps;
      if (!rep.ok)
        fail_at(m_source,
                "lcp: the simulation failed at frame {} (t = {:.4f} s): {}; try more "
                "lcp.dynamics.substeps or lcp.steps_per_frame",
                f, rt.sim->time(), rep.message);
    }
    rt.state_frame = f;
  }
  std::vector<Vec3> x, t;
  rt.sim->world(x, &t);
  auto ps = std::make_shared<geom::ParticleSet>();
  ps->positions.reserve(x.size());
  ps->directions.reserve(t.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    ps->positions.push_back(x[i].cast<float>());
    ps->directions.push_back(t[i].cast<float>());
  }
  rt.last = std::move(ps);
  rt.last_frame = frame;
  rt.last_head = rt.sim->head_pose().transform();
  rt.last_air.reset();
  if (const auto* air = rt.sim->air(); air && spec.render.show_air) {
    auto ap = std::make_shared<geom::ParticleSet>();
    for (const auto& p : air->positions()) ap->positions.push_back(p.cast<float>());
    rt.last_air = std::move(ap);
  }
  return rt.last;
}

void Session::add_lcp_items(render::RenderScene& rs, int frame) {
  if (!m_scene.lcp) return;
  const LcpSpec& spec = *m_scene.lcp;
  auto particles = lcp_particles(frame);
  const LcpRuntime& rt = *m_lcp;
  if (!spec.mesh.empty()) {
    // The asset's mesh item (drawn by render_scene with its material) follows the head pose.
    const auto head_mesh = mesh(mesh_index(spec.mesh));
    for (auto& item : rs.meshes)
      if (item.mesh == head_mesh) item.transform = rt.last_head * item.transform;
  } else if (spec.render.show_head) {
    render::MeshItem head;
    head.mesh = rt.head;
    head.transform = rt.last_head;
    head.material.base_color = spec.render.head_color;
    head.material.specular = 0.1;
    head.material.ambient = 0.2;
    rs.meshes.push_back(std::move(head));
  }
  render::ParticleItem item;
  item.particles = std::move(particles);
  item.shading = render::ParticleShading::HairSplat;
  item.color = spec.render.color;
  item.radius = spec.render.radius;
  item.opacity = spec.render.opacity;
  item.splat = spec.render.splat;
  rs.particles.push_back(std::move(item));
  if (rt.last_air) {
    render::ParticleItem air;
    air.particles = rt.last_air;
    air.shading = render::ParticleShading::Flat;
    air.color = Vec3(0.55, 0.75, 1.0);
    air.radius = spec.render.air_radius;
    air.opacity = 0.5;
    rs.particles.push_back(std::move(air));
  }
}

}  // namespace follicle::scene
