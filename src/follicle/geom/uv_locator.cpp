#include "follicle/geom/uv_locator.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "follicle/core/error.hpp"

namespace follicle::geom {

UvLocator::UvLocator(const TriMesh& mesh) {
  if (!mesh.has_uvs() || mesh.uv_faces.empty())
    fail("uv locator: the mesh has no texture coordinates");
  const std::size_t nf = mesh.uv_faces.size();
  m_tris.reserve(nf);
  Eigen::AlignedBox2d box;
  for (const auto& f : mesh.uv_faces) {
    Tri t{mesh.uvs.at(std::size_t(f[0])), mesh.uvs.at(std::size_t(f[1])),
          mesh.uvs.at(std::size_t(f[2]))};
    if (!t.a.allFinite() || !t.b.allFinite() || !t.c.allFinite())
      fail("uv locator: a texture coordinate is not finite");
    box.extend(t.a);
    box.extend(t.b);
    box.extend(t.c);
    m_tris.push_back(t);
  }
  const Vec2 ext = (box.max() - box.min()).cwiseMax(1e-12);
  const double side = std::sqrt(ext.x() * ext.y() / double(nf));
  m_nx = std::clamp(int(std::ceil(ext.x() / side)), 1, 4096);
  m_ny = std::clamp(int(std::ceil(ext.y() / side)), 1, 4096);
  m_lo = box.min();
  m_cell = Vec2(ext.x() / m_nx, ext.y() / m_ny);
  auto range = [&](const Tri& t, int& x0, int& x1, int& y0, int& y1) {
    const Vec2 lo = (t.a.cwiseMin(t.b).cwiseMin(t.c) - m_lo).cwiseQuotient(m_cell);
    const Vec2 hi = (t.a.cwiseMax(t.b).cwiseMax(t.c) - m_lo).cwiseQuotient(m_cell);
    x0 = std::clamp(int(std::floor(lo.x())), 0, m_nx - 1);
    x1 = std::clamp(int(std::floor(hi.x())), 0, m_nx - 1);
    y0 = std::clamp(int(std::floor(lo.y())), 0, m_ny - 1);
    y1 = std::clamp(int(std::floor(hi.y())), 0, m_ny - 1);
  };
  const std::size_t cells = std::size_t(m_nx) * std::size_t(m_ny);
  std::vector<std::size_t> count(cells + 1, 0);
  for (const Tri& t : m_tris) {
    int x0, x1, y0, y1;
    range(t, x0, x1, y0, y1);
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) ++count[std::size_t(y) * std::size_t(m_nx) + std::size_t(x)];
  }
  m_offsets.assign(cells + 1, 0);
  for (std::size_t c = 0; c < cells; ++c) m_offsets[c + 1] = m_offsets[c] + count[c];
  m_faces.resize(m_offsets.back());
  std::vector<std::size_t> fill(m_offsets.begin(), m_offsets.end() - 1);
  for (std::size_t f = 0; f < nf; ++f) {
    int x0, x1, y0, y1;
    range(m_tris[f], x0, x1, y0, y1);
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x)
        m_faces[fill[std::size_t(y) * std::size_t(m_nx) + std::size_t(x)]++] = int(f);
  }
}

UvHit UvLocator::locate(const Vec2& q, double tolerance) const {
  UvHit hit;
  if (!q.allFinite()) return hit;
  const Vec2 g = (q - m_lo).cwiseQuotient(m_cell);
  // A point up to `tolerance` outside the layout's box still finds the border faces.
  const int cx = int(std::floor(g.x())), cy = int(std::floor(g.y()));
  if (cx < -1 || cy < -1 || cx > m_nx || cy > m_ny) return hit;
  const std::size_t cell = std::size_t(std::clamp(cy, 0, m_ny - 1)) * std::size_t(m_nx) +
                           std::size_t(std::clamp(cx, 0, m_nx - 1));
  double best = tolerance;
  for (std::size_t k = m_offsets[cell]; k < m_offsets[cell + 1]; ++k) {
    const int f = m_faces[k];
    const Tri& t = m_tris[std::size_t(f)];
    const Vec2 e1 = t.b - t.a, e2 = t.c - t.a, d = q - t.a;
    const double det = e1.x() * e2.y() - e1.y() * e2.x();
    const double scale = e1.squaredNorm() + e2.squaredNorm();
    if (!(std::abs(det) > 1e-14 * scale)) continue;
    const double l1 = (d.x() * e2.y() - d.y() * e2.x()) / det;
    const double l2 = (e1.x() * d.y() - e1.y() * d.x()) / det;
    const double l0 = 1 - l1 - l2;
    const double out = std::max({0.0, -l0, -l1, -l2});
    if (out < best || (out == 0 && hit.face < 0)) {
      best = out;
      hit.face = f;
      hit.bary = Vec3(l0, l1, l2).cwiseMax(0.0);
      hit.bary /= hit.bary.sum();
      if (out == 0) break;
    }
  }
  return hit;
}

Eigen::Matrix<double, 3, 2> uv_jacobian(const TriMesh& mesh, std::size_t face) {
  const Vec3i& f = mesh.faces.at(face);
  const Vec3i& t = mesh.uv_faces.at(face);
  Eigen::Matrix<double, 3, 2> e;
  e.col(0) = mesh.positions[std::size_t(f[1])] - mesh.positions[std::size_t(f[0])];
  e.col(1) = mesh.positions[std::size_t(f[2])] - mesh.positions[std::size_t(f[0])];
  Eigen::Matrix2d u;
  u.col(0) = mesh.uvs[std::size_t(t[1])] - mesh.uvs[std::size_t(t[0])];
  u.col(1) = mesh.uvs[std::size_t(t[2])] - mesh.uvs[std::size_t(t[0])];
  const double det = u.determinant();
  if (!(std::abs(det) > 1e-14 * u.squaredNorm())) return Eigen::Matrix<double, 3, 2>::Zero();
  return e * u.inverse();
}

std::vector<int> uv_islands(const TriMesh& mesh) {
  std::vector<int> parent(mesh.uvs.size());
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int x) {
    while (parent[std::size_t(x)] != x)
      x = parent[std::size_t(x)] = parent[std::size_t(parent[std::size_t(x)])];
    return x;
  };
  for (const auto& f : mesh.uv_faces) {
    parent[std::size_t(find(f[0]))] = find(f[1]);
    parent[std::size_t(find(f[1]))] = find(f[2]);
  }
  std::vector<int> label(mesh.uvs.size(), -1), out;
  out.reserve(mesh.uv_faces.size());
  int next = 0;
  for (const auto& f : mesh.uv_faces) {
    int& l = label[std::size_t(find(f[0]))];
    if (l < 0) l = next++;
    out.push_back(l);
  }
  return out;
}

}  // namespace follicle::geom
