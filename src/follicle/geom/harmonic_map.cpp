#include "follicle/geom/harmonic_map.hpp"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <unordered_map>

#include "follicle/core/error.hpp"

namespace follicle::geom {

namespace {

double cot_at(const Vec3& apex, const Vec3& a, const Vec3& b) {
  const Vec3 u = a - apex, v = b - apex;
  const double s = u.cross(v).norm();
  return s > 1e-300 ? u.dot(v) / s : 0.0;
}

uint64_t edge_key(int a, int b) {
  if (a > b) std::swap(a, b);
  return (uint64_t(uint32_t(a)) << 32) | uint32_t(b);
}

}  // namespace

std::vector<SpringEdge> harmonic_spring_weights(const TriMesh& mesh) {
  // Eck et al. 1995: k_ij = (cot a + cot b)/2 (their (L^2 + L^2 - L^2)/A form is 2x this).
  std::unordered_map<uint64_t, double> w;
  w.reserve(mesh.faces.size() * 2);
  double total = 0;
  for (const Vec3i& f : mesh.faces) {
    for (int k = 0; k < 3; ++k) {
      const int a = f[(k + 1) % 3], b = f[(k + 2) % 3];
      const double c = 0.5 * cot_at(mesh.positions[std::size_t(f[k])],
                                    mesh.positions[std::size_t(a)], mesh.positions[std::size_t(b)]);
      w[edge_key(a, b)] += c;
      total += std::abs(c);
    }
  }
  std::vector<SpringEdge> out;
  out.reserve(w.size());
  // Floor: negative (obtuse) constants would break the maximum principle; clamp them.
  const double floor = 1e-6 * (w.empty() ? 1.0 : total / double(w.size()));
  for (const auto& [key, k] : w)
    out.push_back({int(key >> 32), int(key & 0xffffffffu), std::max(k, floor)});
  std::sort(out.begin(), out.end(), [](const SpringEdge& x, const SpringEdge& y) {
    return x.i != y.i ? x.i < y.i : x.j < y.j;
  });
  return out;
}

struct HarmonicSolver::Impl {
  int n = 0;
  std::vector<int> fixed;       // fixed vertex ids in the caller's order
  std::vector<int> free_index;  // vertex -> row in the free system, -1 fixed or unreachable
  std::vector<int> fixed_slot;  // vertex -> position in `fixed`, -1 otherwise
  int nfree = 0;
  Eigen::SparseMatrix<double> Lff;  // free-free block (SPD)
  Eigen::SparseMatrix<double> Lfb;  // free-fixed coupling (weights, positive)
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::AMDOrdering<int>> ldlt;
};

HarmonicSolver::HarmonicSolver(const TriMesh& mesh, const std::vector<int>& fixed_vertices)
    : m(std::make_unique<Impl>()) {
  m->n = int(mesh.positions.size());
  m->fixed = fixed_vertices;
  m->fixed_slot.assign(std::size_t(m->n), -1);
  for (std::size_t s = 0; s < fixed_vertices.size(); ++s) {
    const int v = fixed_vertices[s];
    if (v < 0 || v >= m->n)
      fail("harmonic map: fixed vertex {} out of range, expected an index in [0, {})", v, m->n);
    if (m->fixed_slot[std::size_t(v)] >= 0)
      fail("harmonic map: vertex {} is listed twice as fixed", v);
    m->fixed_slot[std::size_t(v)] = int(s);
  }
  for (const Vec3i& f : mesh.faces)
    for (int k = 0; k < 3; ++k)
      if (f[k] < 0 || f[k] >= m->n)
        fail("harmonic map: face references vertex {} of {}", f[k], m->n);
  const auto edges = harmonic_spring_weights(mesh);
  // Free vertices reachable from a fixed vertex (others would make the system singular).
  std::vector<std::vector<int>> adj(std::size_t(m->n));
  for (const auto& e : edges) {
    adj[std::size_t(e.i)].push_back(e.j);
    adj[std::size_t(e.j)].push_back(e.i);
  }
  std::vector<char> reach(std::size_t(m->n), 0);
  std::vector<int> stack(fixed_vertices.begin(), fixed_vertices.end());
  for (int v : stack) reach[std::size_t(v)] = 1;
  while (!stack.empty()) {
    const int v = stack.back();
    stack.pop_back();
    for (int u : adj[std::size_t(v)])
      if (!reach[std::size_t(u)]) {
        reach[std::size_t(u)] = 1;
        stack.push_back(u);
      }
  }
  m->free_index.assign(std::size_t(m->n), -1);
  for (int v = 0; v < m->n; ++v)
    if (reach[std::size_t(v)] && m->fixed_slot[std::size_t(v)] < 0)
      m->free_index[std::size_t(v)] = m->nfree++;
  std::vector<Eigen::Triplet<double>> tff, tfb;
  tff.reserve(edges.size() * 2 + std::size_t(m->nfree));
  std::vector<double> diag(std::size_t(m->nfree), 0.0);
  for (const auto& e : edges) {
    const int fi = m->free_index[std::size_t(e.i)], fj = m->free_index[std::size_t(e.j)];
    const int si = m->fixed_slot[std::size_t(e.i)], sj = m->fixed_slot[std::size_t(e.j)];
    if (fi >= 0) diag[std::size_t(fi)] += e.k;
    if (fj >= 0) diag[std::size_t(fj)] += e.k;
    if (fi >= 0 && fj >= 0) {
      tff.emplace_back(std::max(fi, fj), std::min(fi, fj), -e.k);  // lower triangle only
    } else if (fi >= 0 && sj >= 0) {
      tfb.emplace_back(fi, sj, e.k);
    } else if (fj >= 0 && si >= 0) {
      tfb.emplace_back(fj, si, e.k);
    }
  }
  for (int i = 0; i < m->nfree; ++i) tff.emplace_back(i, i, diag[std::size_t(i)]);
  m->Lff.resize(m->nfree, m->nfree);
  m->Lff.setFromTriplets(tff.begin(), tff.end());
  m->Lfb.resize(m->nfree, Eigen::Index(fixed_vertices.size()));
  m->Lfb.setFromTriplets(tfb.begin(), tfb.end());
  if (m->nfree > 0) {
    m->ldlt.analyzePattern(m->Lff);  // AMD ordering, once
    m->ldlt.factorize(m->Lff);
    if (m->ldlt.info() != Eigen::Success) fail("harmonic map: sparse factorization failed");
  }
}

HarmonicSolver::~HarmonicSolver() = default;
HarmonicSolver::HarmonicSolver(HarmonicSolver&&) noexcept = default;
HarmonicSolver& HarmonicSolver::operator=(HarmonicSolver&&) noexcept = default;

Eigen::MatrixXd HarmonicSolver::solve(const Eigen::MatrixXd& fixed_values) const {
  if (fixed_values.rows() != Eigen::Index(m->fixed.size()))
    fail("harmonic map: {} fixed values for {} fixed vertices", fixed_values.rows(),
         m->fixed.size());
  if (!fixed_values.allFinite()) fail("harmonic map: fixed values are not all finite");
  const Eigen::Index cols = fixed_values.cols();
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(m->n, cols);
  for (std::size_t s = 0; s < m->fixed.size(); ++s)
    out.row(m->fixed[s]) = fixed_values.row(Eigen::Index(s));
  if (m->nfree == 0) return out;
  const Eigen::MatrixXd rhs = m->Lfb * fixed_values;  // sum_j k_ij x_j over fixed neighbours
  const Eigen::MatrixXd x = m->ldlt.solve(rhs);
  for (int v = 0; v < m->n; ++v)
    if (m->free_index[std::size_t(v)] >= 0) out.row(v) = x.row(m->free_index[std::size_t(v)]);
  return out;
}

Eigen::MatrixXd harmonic_interpolate(const TriMesh& mesh, const std::vector<int>& fixed_vertices,
                                     const Eigen::MatrixXd& fixed_values) {
  if (fixed_values.rows() != Eigen::Index(fixed_vertices.size()))
    fail("harmonic_interpolate: {} value rows for {} fixed vertices", fixed_values.rows(),
         fixed_vertices.size());
  HarmonicSolver solver(mesh, fixed_vertices);
  return solver.solve(fixed_values);
}

std::vector<Vec2> per_vertex_uvs(const TriMesh& mesh, double tolerance) {
  if (!mesh.has_uvs()) return {};
  std::vector<Vec2> uv(mesh.positions.size(),
                       Vec2::Constant(std::numeric_limits<double>::quiet_NaN()));
  for (std::size_t f = 0; f < mesh.faces.size(); ++f)
    for (int k = 0; k < 3; ++k) {
      const auto v = std::size_t(mesh.faces[f][k]);
      const Vec2& t = mesh.uvs[std::size_t(mesh.uv_faces[f][k])];
      if (std::isnan(uv[v].x())) {
        uv[v] = t;
      } else if ((uv[v] - t).norm() > tolerance) {
        return {};
      }
    }
  for (auto& t : uv)
    if (std::isnan(t.x())) t.setZero();  // unreferenced vertex
  return uv;
}

double uv_stretch(const Vec3& p0, const Vec3& p1, const Vec3& p2, const Vec2& t0, const Vec2& t1,
                  const Vec2& t2) {
  // Jacobian of the affine map from the triangle's 3D frame to UV.
  const Vec3 x1 = p1 - p0, x2 = p2 - p0;
  const Vec3 ex = x1.normalized();
  const Vec3 ey = (x2 - x2.dot(ex) * ex).normalized();
  Eigen::Matrix2d P, U;
  P << x1.dot(ex), x2.dot(ex), 0.0, x2.dot(ey);
  U.col(0) = t1 - t0;
  U.col(1) = t2 - t0;
  const Eigen::JacobiSVD<Eigen::Matrix2d> svd(U * P.inverse());
  const double s0 = svd.singularValues()[0], s1 = svd.singularValues()[1];
  return s1 > 0 ? s0 / s1 : std::numeric_limits<double>::infinity();
}

UvQuality evaluate_uv_quality(const TriMesh& mesh, const std::vector<Vec2>& uv) {
  UvQuality q;
  if (uv.size() != mesh.positions.size())
    fail("uv quality: {} UVs for {} vertices", uv.size(), mesh.positions.size());
  const std::size_t nf = mesh.faces.size();
  std::vector<double> sa(nf), a3(nf);
  double pos = 0, neg = 0, sum_uv = 0, sum_3d = 0;
  for (std::size_t f = 0; f < nf; ++f) {
    const Vec3i& t = mesh.faces[f];
    const Vec2 e1 = uv[std::size_t(t[1])] - uv[std::size_t(t[0])];
    const Vec2 e2 = uv[std::size_t(t[2])] - uv[std::size_t(t[0])];
    sa[f] = 0.5 * (e1.x() * e2.y() - e1.y() * e2.x());
    a3[f] = mesh.face_area(f);
    (sa[f] >= 0 ? pos : neg) += std::abs(sa[f]);
    sum_uv += std::abs(sa[f]);
    sum_3d += a3[f];
  }
  const double sign = pos >= neg ? 1.0 : -1.0;
  const double global = sum_3d > 0 ? sum_uv / sum_3d : 1.0;
  double wsum = 0;
  for (std::size_t f = 0; f < nf; ++f) {
    const double s = sa[f] * sign;
    if (std::abs(s) <= 1e-18 * std::max(1.0, global)) {
      ++q.degenerate;
      continue;
    }
    if (s < 0) ++q.flipped;
    if (a3[f] <= 0) continue;
    const Vec3i& t = mesh.faces[f];
    const double stretch =
        uv_stretch(mesh.positions[std::size_t(t[0])], mesh.positions[std::size_t(t[1])],
                   mesh.positions[std::size_t(t[2])], uv[std::size_t(t[0])], uv[std::size_t(t[1])],
                   uv[std::size_t(t[2])]);
    q.stretch_mean += a3[f] * stretch;
    q.stretch_max = std::max(q.stretch_max, stretch);
    q.area_distortion += a3[f] * std::abs(std::log(std::abs(sa[f]) / a3[f] / global));
    wsum += a3[f];
  }
  if (wsum > 0) {
    q.stretch_mean /= wsum;
    q.area_distortion /= wsum;
  }
  return q;
}

std::vector<std::vector<int>> boundary_loops(const TriMesh& mesh) {
  std::unordered_map<uint64_t, int> count;
  for (const Vec3i& f : mesh.faces)
    for (int k = 0; k < 3; ++k) ++count[edge_key(f[k], f[(k + 1) % 3])];
  std::multimap<int, int> next;  // directed boundary half-edges a -> b
  for (const Vec3i& f : mesh.faces)
    for (int k = 0; k < 3; ++k)
      if (count[edge_key(f[k], f[(k + 1) % 3])] == 1) next.emplace(f[k], f[(k + 1) % 3]);
  std::vector<std::vector<int>> loops;
  while (!next.empty()) {
    std::vector<int> loop;
    const int start = next.begin()->first;
    int v = start;
    while (true) {
      auto it = next.find(v);
      if (it == next.end()) break;
      loop.push_back(v);
      const int w = it->second;
      next.erase(it);
      v = w;
      if (v == start) break;
    }
    if (loop.size() >= 3) loops.push_back(std::move(loop));
  }
  auto len = [&](const std::vector<int>& l) {
    double s = 0;
    for (std::size_t i = 0; i < l.size(); ++i)
      s += (mesh.positions[std::size_t(l[(i + 1) % l.size()])] - mesh.positions[std::size_t(l[i])])
               .norm();
    return s;
  };
  std::stable_sort(loops.begin(), loops.end(),
                   [&](const auto& a, const auto& b) { return len(a) > len(b); });
  return loops;
}

namespace {

double cross2(const Vec2& a, const Vec2& b) {
  return a.x() * b.y() - a.y() * b.x();
}

// Boundary relaxation (§2.4: "we move some vertices so that the boundary becomes less concave"):
// reflex vertices of the outer loop move toward the midpoint of their loop neighbours.
int relax_boundary(std::vector<Vec2>& uv, const std::vector<int>& loop, int iterations,
                   double step) {
  const std::size_t n = loop.size();
  if (n < 4) return 0;
  double area2 = 0;
  for (std::size_t i = 0; i < n; ++i)
    area2 += cross2(uv[std::size_t(loop[i])], uv[std::size_t(loop[(i + 1) % n])]);
  const double orient = area2 >= 0 ? 1.0 : -1.0;
  std::vector<char> moved(n, 0);
  for (int it = 0; it < iterations; ++it) {
    bool any = false;
    for (std::size_t i = 0; i < n; ++i) {
      const Vec2 a = uv[std::size_t(loop[(i + n - 1) % n])], c = uv[std::size_t(loop[(i + 1) % n])];
      Vec2& b = uv[std::size_t(loop[i])];
      const double turn = cross2(b - a, c - b) * orient;
      if (turn < -1e-12 * (c - a).squaredNorm()) {  // reflex (concave) vertex
        b += step * (0.5 * (a + c) - b);
        moved[i] = 1;
        any = true;
      }
    }
    if (!any) break;
  }
  return int(std::count(moved.begin(), moved.end(), 1));
}

void fit_unit_square(std::vector<Vec2>& uv) {
  if (uv.empty()) return;
  Eigen::AlignedBox2d box;
  for (const auto& t : uv) box.extend(t);
  const double s = std::max(box.sizes().x(), box.sizes().y());
  if (s <= 0) return;
  for (auto& t : uv) t = (t - box.min()) / s;
}

}  // namespace

std::vector<Vec2> harmonic_parameterize(const TriMesh& mesh, const std::vector<Vec2>& initial_uv,
                                        const HarmonicMapParams& params,
                                        HarmonicMapReport* report) {
  params.validate();
  if (initial_uv.size() != mesh.positions.size())
    fail("harmonic map: {} initial UVs for {} vertices", initial_uv.size(), mesh.positions.size());
  HarmonicMapReport rep;
  rep.before = evaluate_uv_quality(mesh, initial_uv);
  std::vector<Vec2> uv = initial_uv;
  const auto loops = boundary_loops(mesh);
  if (loops.empty())
    fail("harmonic map: the mesh has no boundary (a closed surface needs cutting)");
  // A boundary that touches itself (two holes meeting at a vertex, a cut through a pole) visits
  // a vertex twice: it is fixed once, at its first visit.
  std::vector<int> outer;
  {
    std::vector<char> seen(mesh.positions.size(), 0);
    for (int v : loops.front())
      if (!seen[std::size_t(v)]) {
        seen[std::size_t(v)] = 1;
        outer.push_back(v);
      }
  }
  if (params.circle_boundary) {
    double total = 0;
    std::vector<double> acc(outer.size(), 0.0);
    for (std::size_t i = 1; i < outer.size(); ++i)
      acc[i] = total +=
          (mesh.positions[std::size_t(outer[i])] - mesh.positions[std::size_t(outer[i - 1])])
              .norm();
    total +=
        (mesh.positions[std::size_t(outer.front())] - mesh.positions[std::size_t(outer.back())])
            .norm();
    for (std::size_t i = 0; i < outer.size(); ++i) {
      const double a = 2 * kPi * acc[i] / total;
      uv[std::size_t(outer[i])] = Vec2(0.5 + 0.5 * std::cos(a), 0.5 + 0.5 * std::sin(a));
    }
  } else {
    rep.relaxed_vertices = relax_boundary(uv, outer, params.relax_iterations, params.relax_step);
  }
  Eigen::MatrixXd fixed(Eigen::Index(outer.size()), 2);
  for (std::size_t i = 0; i < outer.size(); ++i)
    fixed.row(Eigen::Index(i)) = uv[std::size_t(outer[i])].transpose();
  const Eigen::MatrixXd x = harmonic_interpolate(mesh, outer, fixed);
  for (std::size_t v = 0; v < uv.size(); ++v) uv[v] = x.row(Eigen::Index(v)).transpose();
  if (params.fit_unit_square) fit_unit_square(uv);
  rep.after = evaluate_uv_quality(mesh, uv);
  if (report) *report = rep;
  return uv;
}

HarmonicMapReport make_texture_space(TriMesh& mesh, const std::vector<Vec2>& projection,
                                     const HarmonicMapParams& params) {
  HarmonicMapReport rep;
  if (params.keep_own_uvs && mesh.has_uvs()) {
    const auto own = per_vertex_uvs(mesh);
    if (!own.empty()) {
      const UvQuality q = evaluate_uv_quality(mesh, own);
      if (q.flipped == 0 && q.degenerate == 0) {
        rep.kept_own_uvs = true;
        rep.before = rep.after = q;
        return rep;
      }
    }
  }
  const auto uv = harmonic_parameterize(mesh, projection, params, &rep);
  mesh.uvs = uv;
  mesh.uv_faces = mesh.faces;
  return rep;
}

}  // namespace follicle::geom
