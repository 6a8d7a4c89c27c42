#include "follicle/geom/mesh_sdf.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

#include "follicle/core/error.hpp"
#include "follicle/core/parallel.hpp"

namespace follicle::geom {

namespace {

// Surface crossings of the ray p + t dir, t > 0 (each hit counted once; the next search starts
// just past it).
int crossings(const MeshQuery& q, const Vec3& p, const Vec3& dir, std::vector<double>* ts) {
  int n = 0;
  double t = 0.0;
  for (int guard = 0; guard < 100000; ++guard) {
    const RayHit h = q.intersect(p, dir, t);
    if (!h.hit) break;
    ++n;
    if (ts) ts->push_back(h.distance);
    t = h.distance + 1e-6;  // past this hit (Embree's float tnear needs a real step)
  }
  return n;
}

}  // namespace

bool MeshSignedDistance::inside(const Vec3& p) const {
  // Majority of three rays (a ray grazing an edge may count a crossing twice or not at all).
  static const Vec3 dirs[3] = {Vec3(0.5771, 0.5774, 0.5777), Vec3(-0.7071, 0.0013, 0.7071),
                               Vec3(0.0019, -0.8944, -0.4472)};
  int odd = 0;
  for (const auto& d : dirs) odd += crossings(*m_query, p, d, nullptr) % 2;
  return odd >= 2;
}

MeshSignedDistance::MeshSignedDistance(const TriMesh& mesh) : m_mesh(mesh) {
  m_query = std::make_unique<MeshQuery>(m_mesh);  // checks the mesh
  const std::size_t F = m_mesh.faces.size();
  m_face_n.resize(F);
  m_vertex_n.assign(m_mesh.positions.size(), Vec3::Zero());
  m_edge_n.assign(3 * F, Vec3::Zero());
  std::unordered_map<uint64_t, Vec3> edge_sum;
  edge_sum.reserve(3 * F);
  auto key = [](int a, int b) {
    if (a > b) std::swap(a, b);
    return (uint64_t(uint32_t(a)) << 32) | uint64_t(uint32_t(b));
  };
  for (std::size_t f = 0; f < F; ++f) {
    const Vec3i& t = m_mesh.faces[f];
    const Vec3 n = m_mesh.face_normal(f);
    m_face_n[f] = n;
    for (int k = 0; k < 3; ++k) {
      const Vec3& p = m_mesh.positions[std::size_t(t[k])];
      const Vec3 e1 = m_mesh.positions[std::size_t(t[(k + 1) % 3])] - p;
      const Vec3 e2 = m_mesh.positions[std::size_t(t[(k + 2) % 3])] - p;
      const double den = e1.norm() * e2.norm();
      const double ang = den > 0 ? std::acos(std::clamp(e1.dot(e2) / den, -1.0, 1.0)) : 0.0;
      m_vertex_n[std::size_t(t[k])] += ang * n;
      edge_sum[key(t[(k + 1) % 3], t[(k + 2) % 3])] += n;
    }
  }
  for (std::size_t f = 0; f < F; ++f) {
    const Vec3i& t = m_mesh.faces[f];
    for (int k = 0; k < 3; ++k)
      m_edge_n[3 * f + std::size_t(k)] = edge_sum[key(t[(k + 1) % 3], t[(k + 2) % 3])];
  }
}

MeshSignedDistance::~MeshSignedDistance() = default;
MeshSignedDistance::MeshSignedDistance(MeshSignedDistance&&) noexcept = default;
MeshSignedDistance& MeshSignedDistance::operator=(MeshSignedDistance&&) noexcept = default;

double MeshSignedDistance::signed_distance(const Vec3& p, double max_distance, bool* known) const {
  const ClosestPoint c = m_query->closest_point(p, max_distance);
  if (known) *known = c.face >= 0;
  if (c.face < 0) return max_distance;
  // Pseudo-normal of the feature the closest point lies on (Bærentzen & Aanæs 2005).
  constexpr double tiny = 1e-9;
  int zeros = 0, zk = -1, one = -1;
  for (int k = 0; k < 3; ++k) {
    if (c.bary[k] <= tiny) {
      ++zeros;
      zk = k;
    } else {
      one = k;
    }
  }
  const std::size_t f = std::size_t(c.face);
  Vec3 n = m_face_n[f];
  if (zeros == 1)
    n = m_edge_n[3 * f + std::size_t(zk)];
  else if (zeros >= 2 && one >= 0)
    n = m_vertex_n[std::size_t(m_mesh.faces[f][one])];
  const double s = (p - c.point).dot(n);
  return s < 0 ? -c.distance : c.distance;
}

double MeshSignedDistance::signed_distance(const Vec3& p) const {
  const ClosestPoint c = m_query->closest_point(p);
  return inside(p) ? -c.distance : c.distance;
}

SignedDistanceGrid::SignedDistanceGrid(const Context& ctx, const MeshSignedDistance& sd,
                                       const Vec3& lo, const Vec3& hi,
                                       const SignedDistanceGridParams& params) {
  if (!(params.cell > 0) || !(params.band > 0) || params.block < 1)
    fail("signed distance grid: cell ({}) and band ({}) must be positive, block ({}) >= 1",
         params.cell, params.band, params.block);
  if (!(hi.array() > lo.array()).all()) fail("signed distance grid: empty box");
  const double h = params.cell;
  for (int a = 0; a < 3; ++a) {
    const double n = std::ceil((hi[a] - lo[a]) / h) + 1;
    if (n > 4096) fail("signed distance grid: {} nodes along axis {} (cell too small)", n, a);
    m_dim[a] = int(n);
    m_origin[a] = float(lo[a]);
  }
  m_cell = float(h);
  m_inv_cell = float(1.0 / h);
  m_band = float(params.band);
  const std::size_t nx = std::size_t(m_dim[0]), ny = std::size_t(m_dim[1]),
                    nz = std::size_t(m_dim[2]);
  const std::size_t total = nx * ny * nz;
  m_value.assign(total, 0.0f);
  // Sign: parity of the surface crossings of one ray along each grid row (x), cast from outside
  // the box; magnitude: closest point within the band (beyond it, clamped to the band).
  const Vec3 o(m_origin[0], m_origin[1], m_origin[2]);
  const Vec3 dir(1.0, 1.3e-7, 2.9e-7);
  const double x_min =
      sd.mesh().bounds().min().x();  // off the grid planes: no row runs along an edge
  parallel_for(
      ctx, 0, nz * ny,
      [&](std::size_t row) {
        const std::size_t k = row / ny, j = row % ny;
        // From outside the mesh's bounds (the mesh may reach beyond the box, e.g. shoulders).
        const double lead = h + std::max(0.0, o.x() - x_min);
        const Vec3 start = o + Vec3(-lead, h * double(j), h * double(k));
        std::vector<double> ts;
        crossings(sd.query(), start, dir, &ts);
        std::size_t passed = 0;
        for (std::size_t i = 0; i < nx; ++i) {
          const double ti = lead + double(i) * h;
          while (passed < ts.size() && ts[passed] < ti) ++passed;
          const bool in = passed % 2 == 1;
          const Vec3 p = start + ti * dir;
          const ClosestPoint c = sd.query().closest_point(p, params.band);
          const double d = c.face >= 0 ? std::min(c.distance, params.band) : params.band;
          m_value[row * nx + i] = float(in ? -d : d);
        }
      },
      4);
  // Coarse blocks: the minimum over the nodes a point in the block interpolates from.
  const int B = params.block;
  m_inv_block = float(1.0 / (h * B));
  for (int a = 0; a < 3; ++a) m_bdim[a] = (m_dim[a] - 1 + B - 1) / B;
  m_block_min.assign(std::size_t(m_bdim[0]) * std::size_t(m_bdim[1]) * std::size_t(m_bdim[2]),
                     m_band);
  for (int bk = 0; bk < m_bdim[2]; ++bk)
    for (int bj = 0; bj < m_bdim[1]; ++bj)
      for (int bi = 0; bi < m_bdim[0]; ++bi) {
        float m = m_band;
        for (int k = bk * B; k <= std::min(bk * B + B, m_dim[2] - 1); ++k)
          for (int j = bj * B; j <= std::min(bj * B + B, m_dim[1] - 1); ++j)
            for (int i = bi * B; i <= std::min(bi * B + B, m_dim[0] - 1); ++i)
              m = std::min(m, node(i, j, k));
        m_block_min[(std::size_t(bk) * std::size_t(m_bdim[1]) + std::size_t(bj)) *
                        std::size_t(m_bdim[0]) +
                    std::size_t(bi)] = m;
      }
}

float SignedDistanceGrid::value(float x, float y, float z) const {
  float g[3];
  return value_gradient(x, y, z, g);
}

float SignedDistanceGrid::value_gradient(float x, float y, float z, float g[3]) const {
  g[0] = g[1] = g[2] = 0.0f;
  if (m_value.empty()) return m_band;
  const float fx = (x - m_origin[0]) * m_inv_cell, fy = (y - m_origin[1]) * m_inv_cell,
              fz = (z - m_origin[2]) * m_inv_cell;
  if (!(fx >= 0.0f && fy >= 0.0f && fz >= 0.0f && fx < float(m_dim[0] - 1) &&
        fy < float(m_dim[1] - 1) && fz < float(m_dim[2] - 1)))
    return m_band;
  const int i = int(fx), j = int(fy), k = int(fz);
  const float u = fx - float(i), v = fy - float(j), w = fz - float(k);
  const float c000 = node(i, j, k), c100 = node(i + 1, j, k), c010 = node(i, j + 1, k),
              c110 = node(i + 1, j + 1, k), c001 = node(i, j, k + 1), c101 = node(i + 1, j, k + 1),
              c011 = node(i, j + 1, k + 1), c111 = node(i + 1, j + 1, k + 1);
  const float c00 = c000 + u * (c100 - c000), c10 = c010 + u * (c110 - c010),
              c01 = c001 + u * (c101 - c001), c11 = c011 + u * (c111 - c011);
  const float c0 = c00 + v * (c10 - c00), c1 = c01 + v * (c11 - c01);
  const float dx0 = (c100 - c000) + v * ((c110 - c010) - (c100 - c000));
  const float dx1 = (c101 - c001) + v * ((c111 - c011) - (c101 - c001));
  g[0] = (dx0 + w * (dx1 - dx0)) * m_inv_cell;
  g[1] = ((c10 - c00) + w * ((c11 - c01) - (c10 - c00))) * m_inv_cell;
  g[2] = (c1 - c0) * m_inv_cell;
  return c0 + w * (c1 - c0);
}

}  // namespace follicle::geom
