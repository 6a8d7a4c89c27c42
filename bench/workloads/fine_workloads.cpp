// Fine-scale wrinkle workloads (issue 5): "fine-wrinkles" (both height fields of the default
// head), "fine-modulation" (per-frame shrinkage + M(s) modulation of both maps) and
// "hand-update" (MakeHuman hand rig: skinning + joint wrinkles + per-vertex shrinkage of both
// fine fields; relief=1 adds the per-texel modulated relief map).
#include <cstdlib>
#include <filesystem>

#include "follicle/anim/makehuman.hpp"
#include "follicle/anim/skeleton.hpp"
#include "follicle/core/error.hpp"
#include "follicle/geom/mesh_io.hpp"
#include "follicle/skin/fine_wrinkles_bando2002.hpp"
#include "follicle/skin/hand_rig.hpp"
#include "workloads/data_path.hpp"
#include "workloads/workload.hpp"

namespace follicle::workloads {
namespace {

/// Two default fields: keys on every 40th uv vertex, field 0 along u (m = 0.5), field 1 at 70
/// degrees (m = 0.4).
std::array<std::vector<skin::DirectionKey>, 2> default_keys(const geom::TriMesh& m) {
  std::array<std::vector<skin::DirectionKey>, 2> k;
  for (std::size_t v = 0; v < m.uvs.size(); v += 40) {
    k[0].push_back({int(v), Vec2(0.5, 0.0)});
    k[1].push_back({int(v), Vec2(std::cos(1.22), std::sin(1.22)) * 0.4});
  }
  return k;
}

geom::TriMesh load_head() {
  return geom::load_mesh(find_data("meshes/lee_perry_smith/head.obj"), LengthUnit::mm);
}

class FineGen final : public WorkloadInstance {
 public:
  FineGen(const Context& ctx, const Sizes& s) : m_ctx(ctx), m_mesh(load_head()) {
    m_p.resolution = int(s.at("resolution"));
    // The (2.5) unit on the skin (the paper's unit is one pixel of a 512^2 hand texture, about
    // 0.4 mm); 0 = one texel whatever the resolution.
    m_p.unit_mm = s.at("unit_mm");
    m_keys = default_keys(m_mesh);
  }
  void run_once() override { m_w = skin::generate_fine_wrinkles(m_ctx, m_mesh, m_keys, m_p); }
  double items_per_iter() const override { return 2.0; }

 private:
  const Context& m_ctx;
  geom::TriMesh m_mesh;
  skin::FineWrinkleParams m_p;
  std::array<std::vector<skin::DirectionKey>, 2> m_keys;
  skin::FineWrinkles m_w;
};

class FineModulation final : public WorkloadInstance {
 public:
  FineModulation(const Context& ctx, const Sizes& s) : m_ctx(ctx), m_mesh(load_head()) {
    skin::FineWrinkleParams p;
    p.resolution = int(s.at("resolution"));
    const auto w = skin::generate_fine_wrinkles(ctx, m_mesh, default_keys(m_mesh), p);
    m_anim = std::make_unique<skin::FineWrinkleAnimator>(m_mesh, w);
    // A deformed frame: stretch 10% along x.
    m_x = m_mesh.positions;
    for (auto& q : m_x) q.x() *= 1.1;
  }
  void run_once() override {
    m_anim->shrinkage(m_ctx, m_x, m_s);
    m_anim->modulate(m_ctx, m_s, m_relief);
  }
  double items_per_iter() const override { return 1.0; }

 private:
  const Context& m_ctx;
  geom::TriMesh m_mesh;
  std::unique_ptr<skin::FineWrinkleAnimator> m_anim;
  std::vector<Vec3> m_x;
  std::array<std::vector<float>, 2> m_s;
  image::ImageF m_relief;
};

class HandUpdate final : public WorkloadInstance {
 public:
  HandUpdate(const Context& ctx, const Sizes& s) : m_ctx(ctx) {
    skin::HandRigParams p;
    p.fine.resolution = int(s.at("resolution"));
    m_rig = skin::HandRig::load(ctx, find_data("makehuman"), p);
    m_track = anim::finger_flexion_track(2.0);
    m_opt.fine_relief = s.at("relief") != 0;
  }
  void run_once() override {
    // One frame of the finger-flexion clip at 30 fps: LBS -> normals -> joint wrinkles
    // (shrinkage + M(s) S(l)) -> normals -> fine-wrinkle shrinkage of both fields.
    m_t = std::fmod(m_t + 1.0 / 30.0, 2.0);
    m_rig->update(m_ctx, m_track.value(m_t), m_state, m_opt);
  }
  double items_per_iter() const override { return 1.0; }

 private:
  const Context& m_ctx;
  std::unique_ptr<skin::HandRig> m_rig;
  anim::ScalarTrack m_track;
  skin::HandState m_state;
  skin::HandUpdateOptions m_opt;
  double m_t = 0;
};

}  // namespace

void add_fine_workloads(std::vector<Workload>& out) {
  out.push_back({"fine-wrinkles",
                 "both fine-wrinkle height fields of the default head",
                 {{"resolution", 2048}, {"unit_mm", 0.3}},
                 "fields/s",
                 [](const Context& c, const Sizes& s) -> std::unique_ptr<WorkloadInstance> {
                   return std::make_unique<FineGen>(c, s);
                 }});
  out.push_back({"fine-modulation",
                 "per-frame shrinkage + M(s) modulation of both maps",
                 {{"resolution", 1024}},
                 "frames/s",
                 [](const Context& c, const Sizes& s) -> std::unique_ptr<WorkloadInstance> {
                   return std::make_unique<FineModulation>(c, s);
                 }});
  out.push_back({"hand-update",
                 "MakeHuman hand rig: skinning + joint wrinkles + shrinkage of both fine fields",
                 {{"resolution", 1024}, {"relief", 0}},
                 "frames/s",
                 [](const Context& c, const Sizes& s) -> std::unique_ptr<WorkloadInstance> {
                   return std::make_unique<HandUpdate>(c, s);
                 }});
}

}  // namespace follicle::workloads
