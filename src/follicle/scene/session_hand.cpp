// Session: the skeleton-animated MakeHuman hand (Bando 2002 §2.7, Figs. 2.16, 2.17). The rig is
// built once (skinning weights, joint wrinkles, both fine height fields); every frame is a pure
// function of the finger flexion (skinning + joint wrinkles + per-frame shrinkage modulation of
// the fine relief), so frames can be rendered in any order with identical results.
#include <fmt/format.h>

#include <algorithm>

#include "follicle/core/error.hpp"
#include "follicle/core/log.hpp"
#include "follicle/scene/hand_runtime.hpp"
#include "follicle/scene/session.hpp"
#include "follicle/scene/skin_runtime.hpp"
#include "follicle/skin/wrinkle_maps.hpp"

namespace follicle::scene {

namespace {

HandRuntime& hand_rt(std::shared_ptr<HandRuntime>& p, const Scene& s, const std::string& source,
                     const std::filesystem::path& dir, const Context& ctx) {
  if (!s.hand) fail_at(source, "the scene has no \"hand\" section");
  if (!p) p = std::make_shared<HandRuntime>();
  if (!p->rig) {
    const auto mh = dir;
    if (!std::filesystem::is_directory(mh))
      fail_at(source, "hand.makehuman: folder not found: {}", mh.string());
    try {
      p->rig = skin::HandRig::load(ctx, mh, s.hand->rig);
    } catch (const Error& e) {
      fail_at(source, "hand: {}", e.what());
    }
    const auto& m = p->rig->rest_mesh();
    Vec3 lo = Vec3::Constant(1e30), hi = Vec3::Constant(-1e30);
    for (const auto& x : m.positions) {
      lo = lo.cwiseMin(x.cast<double>());
      hi = hi.cwiseMax(x.cast<double>());
    }
    ctx.log().info(
        "hand: {} vertices, {} faces, bounds ({:.4f} {:.4f} {:.4f})-({:.4f} {:.4f} {:.4f}) m",
        m.positions.size(), m.faces.size(), lo.x(), lo.y(), lo.z(), hi.x(), hi.y(), hi.z());
  }
  return *p;
}

}  // namespace

double Session::hand_flexion(int frame) const {
  if (!m_scene.hand) fail_at(m_source, "the scene has no \"hand\" section");
  const auto& h = *m_scene.hand;
  if (h.flexion) return *h.flexion;
  if (!m_hand || !m_hand->rig) fail("hand_flexion: the hand rig is not built yet");
  return std::clamp(m_hand->rig->flexion_track().value(frame_time(frame) * h.track_speed), 0.0,
                    1.0);
}

skin::HandFrame Session::hand_frame(int frame) {
  if (frame < 0) fail("frame {} is negative", frame);
  auto& rt = hand_rt(m_hand, m_scene, m_source,
                     resolve(m_scene.hand ? m_scene.hand->makehuman : ""), *m_ctx);
  if (rt.last && rt.last_frame == frame) return *rt.last;
  rt.last = rt.rig->frame_at_flexion(*m_ctx, hand_flexion(frame), m_scene.hand->wrinkles);
  rt.last_frame = frame;
  return *rt.last;
}

void Session::add_hand_items(render::RenderScene& rs, int frame) {
  if (!m_scene.hand) return;
  const auto& h = *m_scene.hand;
  const skin::HandFrame f = hand_frame(frame);
  render::MeshItem item;
  item.mesh = f.mesh;
  item.cast_shadow = h.cast_shadow;
  auto& mat = item.material;
  mat.shading = render::MeshShading::BlinnPhong;
  mat.base_color = h.material.base_color;
  mat.specular = h.material.specular;
  mat.shininess = h.material.shininess;
  mat.ambient = h.material.ambient;
  mat.height_map = f.height_m;
  mat.bump_strength = f.bump_strength;
  rs.meshes.push_back(std::move(item));
}

bool Session::has_wrinkle_maps() const {
  if (m_scene.hand) return true;
  return std::any_of(m_scene.skin.begin(), m_scene.skin.end(),
                     [](const SkinSpec& s) { return s.fine.has_value(); });
}

std::vector<std::string> Session::export_wrinkle_maps(const std::filesystem::path& dir, int frame) {
  if (!has_wrinkle_maps())
    fail_at(m_source,
            "the scene has no fine-wrinkle source to export maps from (add a \"hand\" section "
            "or \"fine\" to a skin rig)");
  if (frame >= frame_count())
    fail_at(m_source, "frame {} is past the scene's last frame {}", frame, frame_count() - 1);
  auto suffix = [&] {
    return frame < 0 ? std::string("rest") : fmt::format("frame_{:04d}", frame);
  };
  std::vector<std::string> stems;
  if (m_scene.hand) {
    auto& rt = hand_rt(m_hand, m_scene, m_source, resolve(m_scene.hand->makehuman), *m_ctx);
    const skin::HandRig& rig = *rt.rig;
    image::ImageF relief;
    if (frame < 0) {
      rig.fine_animator().rest_relief(*m_ctx, relief);
    } else {
      skin::HandState s;
      rig.update(*m_ctx, hand_flexion(frame), s, skin::HandUpdateOptions{});
      relief = std::move(s.relief);
    }
    skin::MapExportInfo info;
    info.depth_m = rig.relief_depth_m();
    info.metres_per_texel = rig.fine_animator().metres_per_texel();
    info.strength = rig.params().bump_strength;
    stems.push_back("hand_" + suffix());
    skin::export_wrinkle_maps(*m_ctx, dir, stems.back(), relief, info);
  }
  for (std::size_t ri = 0; ri < m_scene.skin.size(); ++ri) {
    const SkinSpec& spec = m_scene.skin[ri];
    if (!spec.fine) continue;
    // The relief in units of depth_m. skin_fine_relief builds the fields and, for a frame,
    // measures the shrinkage (2.3) of that frame into r.fine_s; the rest relief is M = r
    // everywhere (no deformation), as is every frame's without modulation.
    (void)skin_fine_relief(ri, std::max(frame, 0));
    const auto& r = skin_runtime().rigs[ri];
    image::ImageF relief;
    if (frame >= 0 && spec.fine->modulate)
      r.fine->modulate(*m_ctx, r.fine_s, relief);  // (2.4)
    else
      r.fine->rest_relief(*m_ctx, relief);
    skin::MapExportInfo info;
    info.depth_m = r.fine_depth_m;
    info.metres_per_texel = r.fine->metres_per_texel();
    info.strength = spec.fine->bump_strength;
    stems.push_back(fmt::format("skin{}_{}", ri, suffix()));
    skin::export_wrinkle_maps(*m_ctx, dir, stems.back(), relief, info);
  }
  return stems;
}

}  // namespace follicle::scene
