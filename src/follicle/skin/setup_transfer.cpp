#include "follicle/skin/setup_transfer.hpp"

#include <cmath>

#include "follicle/core/error.hpp"
#include "follicle/geom/spatial_embree.hpp"

namespace follicle::skin {

struct HeadMap::Impl {
  geom::MeshQuery region_query;
  geom::MeshQuery target_query;
  Impl(const geom::TriMesh& region, const geom::TriMesh& target)
      : region_query(region), target_query(target) {}
};

HeadMap::HeadMap(const geom::TriMesh& region, std::vector<Vec3> deformed,
                 const geom::Similarity& rigid, const geom::TriMesh& target)
    : m_region(region),
      m_deformed(std::move(deformed)),
      m_rigid(rigid),
      m_target(target),
      m_impl(std::make_unique<Impl>(region, target)) {
  if (m_deformed.size() != region.num_vertices())
    fail("head map: {} deformed vertices for a template region of {}", m_deformed.size(),
         region.num_vertices());
}

HeadMap::~HeadMap() = default;
HeadMap::HeadMap(HeadMap&&) noexcept = default;

Vec3 HeadMap::skin_point(const Vec3& p, double* gap) const {
  if (gap) *gap = 0;
  const auto cp = m_impl->region_query.closest_point(p);
  if (cp.face < 0) return inner_point(p);
  const auto& f = m_region.faces[std::size_t(cp.face)];
  const Vec3 n0 = m_region.face_normal(std::size_t(cp.face));
  const double height = (p - cp.point).dot(n0);  // signed, over the template's skin
  Vec3 q = Vec3::Zero();
  for (int k = 0; k < 3; ++k) q += cp.bary[k] * m_deformed[std::size_t(f[k])];
  const auto on = m_impl->target_query.closest_point(q);
  if (on.face < 0) return q;
  if (gap) *gap = on.distance;
  Vec3 n1 = m_target.face_normal(std::size_t(on.face));
  // Keep the side: the template's outward normal turned by the map (a target with the other
  // winding has face normals pointing in).
  if (n1.dot(m_rigid.R * n0) < 0) n1 = -n1;
  return on.point + m_rigid.s * height * n1;
}

Vec3 HeadMap::inner_point(const Vec3& p) const {
  // Gaussian-weighted displacement of the template vertices around p, sigma 2 cm of the
  // template (a bony origin lies 1-4 cm under the skin), cut at 3 sigma.
  constexpr double sigma = 0.02;
  Vec3 disp = Vec3::Zero();
  double wsum = 0;
  for (std::size_t i = 0; i < m_region.num_vertices(); ++i) {
    const double d2 = (m_region.positions[i] - p).squaredNorm();
    if (d2 > 9 * sigma * sigma) continue;
    const double w = std::exp(-d2 / (sigma * sigma));
    disp += w * (m_deformed[i] - m_rigid.apply(m_region.positions[i]));
    wsum += w;
  }
  const Vec3 base = m_rigid.apply(p);
  return wsum > 1e-12 ? Vec3(base + disp / wsum) : base;
}

FaceSetup transfer_face_setup(const FaceSetup& setup, const geom::TriMesh& template_mesh,
                              const HeadMap& map, const std::string& where, double edge_gap,
                              std::vector<std::string>* dropped) {
  FaceSetup out;
  out.follicle_face = setup.follicle_face;
  out.muscles.expressions = setup.muscles.expressions;
  for (const auto& m : setup.muscles.linear) {
    LinearMuscle n = m;
    n.origin = map.inner_point(m.origin);
    n.insertion = map.skin_point(m.insertion);
    n.falloff_start = map.length(m.falloff_start);
    n.falloff_end = map.length(m.falloff_end);
    out.muscles.linear.push_back(n);
  }
  for (const auto& m : setup.muscles.sphincter) {
    SphincterMuscle n = m;
    n.center = map.skin_point(m.center);
    n.semi_axis_a = map.length(1.0) * map.direction(m.semi_axis_a);
    n.semi_axis_b = map.length(1.0) * map.direction(m.semi_axis_b);
    n.depth = map.length(m.depth);
    out.muscles.sphincter.push_back(n);
  }
  out.muscles.jaw = setup.muscles.jaw;
  if (setup.muscles.jaw.enabled) {
    const auto& j = setup.muscles.jaw;
    auto& o = out.muscles.jaw;
    o.pivot = map.inner_point(j.pivot);
    o.axis = map.direction(j.axis);
    o.plane_normal = map.direction(j.plane_normal);
    // The plane (x - pivot) . n = offset: carry the point of the plane in front of the pivot.
    const Vec3 n0 = j.plane_normal.normalized();
    const Vec3 on_plane = map.inner_point(j.pivot + j.offset * n0);
    o.offset = (on_plane - o.pivot).dot(o.plane_normal.normalized());
    o.blend_width = map.length(j.blend_width);
  }

  std::vector<SurfaceWrinkle> lifted = setup.surface_wrinkles;
  if (!setup.wrinkles.empty()) {
    auto w = lift_wrinkles_to_surface(template_mesh, setup.wrinkles, where);
    lifted.insert(lifted.end(), w.begin(), w.end());
  }
  for (auto w : lifted) {
    // The longest run of points on the new head's surface.
    std::size_t best_begin = 0, best_len = 0, begin = 0;
    std::vector<Vec3> moved;
    for (std::size_t i = 0; i < w.points.size(); ++i) {
      double gap = 0;
      moved.push_back(map.skin_point(w.points[i], &gap));
      if (gap > edge_gap) {
        begin = i + 1;
      } else if (i + 1 - begin > best_len) {
        best_begin = begin;
        best_len = i + 1 - begin;
      }
    }
    if (2 * best_len < w.points.size() || best_len < 2) {
      if (dropped) dropped->push_back(w.name);
      continue;
    }
    w.points.assign(moved.begin() + std::ptrdiff_t(best_begin),
                    moved.begin() + std::ptrdiff_t(best_begin + best_len));
    w.depth = map.length(w.depth);
    w.width = map.length(w.width);
    out.surface_wrinkles.push_back(std::move(w));
  }
  out.up = map.direction(setup.up.normalized()).normalized();
  out.front = map.direction(setup.front.normalized()).normalized();
  out.muscles.validate();
  return out;
}

}  // namespace follicle::skin
