#include "follicle/skin/face_rig.hpp"

#include "follicle/core/error.hpp"
#include "follicle/core/parallel.hpp"

namespace follicle::skin {

void compute_vertex_normals(const Context& ctx, const geom::TriMesh& topo,
                            const TextureSpaceMesh& tex, const std::vector<Vec3>& p,
                            std::vector<Vec3>& face_n, std::vector<double>& face_area,
                            std::vector<Vec3>& normals) {
  const std::size_t nf = topo.faces.size(), nv = p.size();
  face_n.resize(nf);
  face_area.resize(nf);
  parallel_for(
      ctx, 0, nf,
      [&](std::size_t f) {
        const Vec3i& t = topo.faces[f];
        const Vec3 c = (p[std::size_t(t[1])] - p[std::size_t(t[0])])
                           .cross(p[std::size_t(t[2])] - p[std::size_t(t[0])]);
        face_n[f] = c;  // |c| = 2 area: area weighting for free
        face_area[f] = 0.5 * c.norm();
      },
      2048);
  normals.resize(nv);
  parallel_for(
      ctx, 0, nv,
      [&](std::size_t v) {
        Vec3 n = Vec3::Zero();
        for (std::size_t k = tex.vf_offsets[v]; k < tex.vf_offsets[v + 1]; ++k)
          n += face_n[std::size_t(tex.vf_faces[k])];
        const double len = n.norm();
        normals[v] = len > 0 ? Vec3(n / len) : Vec3(0, 0, 1);
      },
      2048);
}

FaceRig::FaceRig(const geom::TriMesh& base, MuscleSet muscles, std::vector<LargeWrinkle> wrinkles,
                 const FaceRigParams& params, const image::ImageF* thickness_map)
    : m_params(params), m_muscles(std::move(muscles)) {
  m_params.validate();
  m_muscles.validate();
  m_refined = refine_around_wrinkles(base, wrinkles, m_params.refine);
  m_wrinkles = std::make_unique<WrinkleLayer>(m_refined.mesh, std::move(wrinkles),
                                              m_params.wrinkle_cutoff_widths);
  m_field = std::make_unique<MuscleField>(m_muscles, m_refined.mesh.positions);
  m_tissue = std::make_unique<SubcutaneousTissue>(
      m_refined.mesh, m_wrinkles->texture_mesh(),
      initial_thickness(m_wrinkles->texture_mesh(), thickness_map, m_params.tissue));
}

FaceRig::~FaceRig() = default;

MusclePose FaceRig::neutral_pose() const {
  MusclePose p;
  p.contractions.assign(m_muscles.num_muscles(), 0.0);
  return p;
}

MusclePose FaceRig::expression_pose(const std::string& name, double weight) const {
  return pose_from_expression(m_muscles, m_muscles.expression(name), weight);
}

void FaceRig::set_blendshapes(const Blendshapes& on_base) {
  m_shapes = on_base.empty() ? Blendshapes{} : on_base.refined(m_refined);
}

void FaceRig::update(const Context& ctx, const MusclePose& pose, FaceState& s) const {
  const auto& rest = m_refined.mesh;
  const auto& tex = m_wrinkles->texture_mesh();
  const std::size_t nv = rest.positions.size();
  if (!pose.shape_weights.empty() && pose.shape_weights.size() != m_shapes.size())
    fail("face rig: the pose has {} shape weights and the rig {} blendshape targets",
         pose.shape_weights.size(), m_shapes.size());
  // 1. Waters muscles and jaw, then the blendshape offsets (a sum: both deform the rest mesh).
  m_field->apply(ctx, pose, rest.positions, s.muscle_pos);
  m_shapes.accumulate(ctx, pose.shape_weights, s.muscle_pos);
  // 2. Subcutaneous tissue: h0/e - h0 along the normals of the muscle-deformed surface.
  compute_vertex_normals(ctx, rest, tex, s.muscle_pos, s.face_n, s.face_area, s.normals);
  s.animated.resize(nv);
  if (m_params.tissue.enabled) {
    m_tissue->offsets(ctx, s.face_area, s.offsets);
    parallel_for(
        ctx, 0, nv,
        [&](std::size_t i) { s.animated[i] = s.muscle_pos[i] + s.offsets[i] * s.normals[i]; },
        2048);
    compute_vertex_normals(ctx, rest, tex, s.animated, s.face_n, s.face_area, s.normals);
  } else {
    s.animated = s.muscle_pos;
  }
  // 3. Large-scale wrinkles with shrinkage-driven amplitude, along the animated normals.
  s.positions.resize(nv);
  if (m_params.wrinkles_enabled && m_wrinkles->num_wrinkles() > 0) {
    m_wrinkles->heights(ctx, s.animated, s.wrinkle_height);
    parallel_for(
        ctx, 0, nv,
        [&](std::size_t i) { s.positions[i] = s.animated[i] + s.wrinkle_height[i] * s.normals[i]; },
        2048);
    compute_vertex_normals(ctx, rest, tex, s.positions, s.face_n, s.face_area, s.normals);
  } else {
    s.wrinkle_height.assign(nv, 0.0);
    s.positions = s.animated;
  }
}

geom::TriMesh FaceRig::deformed_mesh(const FaceState& s) const {
  geom::TriMesh m = m_refined.mesh;
  if (s.positions.size() != m.positions.size())
    fail("deformed_mesh: state has {} vertices, rig {}", s.positions.size(), m.positions.size());
  m.positions = s.positions;
  m.normals = s.normals;
  return m;
}

}  // namespace follicle::skin
