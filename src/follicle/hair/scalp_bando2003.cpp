#include "follicle/hair/scalp_bando2003.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>

#include "follicle/core/error.hpp"
#include "follicle/geom/curves.hpp"
#include "follicle/geom/harmonic_map.hpp"

namespace follicle::hair {

namespace {

bool inside_polygon(const std::vector<Vec2>& poly, const Vec2& p) {
  bool in = false;
  for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    const Vec2 &a = poly[i], &b = poly[j];
    if ((a.y() > p.y()) != (b.y() > p.y()) &&
        p.x() < (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y()) + a.x())
      in = !in;
  }
  return in;
}

Vec2 square_point(int curve, double t) {
  switch (curve) {
    case 0: return {t, 0.0};
    case 1: return {1.0, t};
    case 2: return {1.0 - t, 1.0};
    default: return {0.0, 1.0 - t};
  }
}

/// Component id per face (-1 outside the face set) and face count per component.
struct FaceComponents {
  std::vector<int> id;
  std::vector<int> size;
  int largest() const {
    return size.empty() ? -1 : int(std::max_element(size.begin(), size.end()) - size.begin());
  }
};

using EdgeFaces = std::map<std::pair<int, int>, std::vector<uint32_t>>;

/// Undirected edge -> the faces that have it, for every face of the mesh.
EdgeFaces edge_faces_of(const geom::TriMesh& m) {
  EdgeFaces edge_faces;
  for (std::size_t f = 0; f < m.faces.size(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = m.faces[f][k], b = m.faces[f][(k + 1) % 3];
      edge_faces[{std::min(a, b), std::max(a, b)}].push_back(uint32_t(f));
    }
  return edge_faces;
}

/// Edge-connected components of the faces with member[f] != 0 (id -1 for the others).
FaceComponents face_components(const geom::TriMesh& m, const EdgeFaces& edge_faces,
                               const std::vector<char>& member) {
  const std::size_t nf = m.faces.size();
  FaceComponents c;
  c.id.assign(nf, -1);
  for (std::size_t f0 = 0; f0 < nf; ++f0) {
    if (!member[f0] || c.id[f0] >= 0) continue;
    const int id = int(c.size.size());
    int size = 0;
    std::vector<uint32_t> stack{uint32_t(f0)};
    c.id[f0] = id;
    while (!stack.empty()) {
      const uint32_t f = stack.back();
      stack.pop_back();
      ++size;
      for (int k = 0; k < 3; ++k) {
        const int a = m.faces[f][k], b = m.faces[f][(k + 1) % 3];
        for (uint32_t g : edge_faces.at({std::min(a, b), std::max(a, b)}))
          if (member[g] && c.id[g] < 0) {
            c.id[g] = id;
            stack.push_back(g);
          }
      }
    }
    c.size.push_back(size);
  }
  return c;
}

}  // namespace

Scalp Scalp::trim(const geom::TriMesh& head, const ScalpCurves& curves, const ScalpParams& p) {
  p.validate();
  head.check("scalp head mesh");
  if (head.faces.empty()) fail_at("scalp", "head mesh has no faces");
  for (int k = 0; k < 4; ++k) {
    if (curves[k].size() < 2)
      fail_at(fmt::format("scalp.curves[{}]", k), "needs at least 2 control points, got {}",
              curves[k].size());
    for (std::size_t i = 0; i < curves[k].size(); ++i)
      if (!curves[k][i].allFinite())
        fail_at(fmt::format("scalp.curves[{}][{}]", k, i), "control point is not finite");
  }
  // 1. Sample the closed boundary loop.
  const int M = p.curve_samples;
  std::vector<Vec3> loop;
  std::vector<std::pair<int, double>> loop_param;
  for (int k = 0; k < 4; ++k) {
    // Uniform open Catmull-Rom through the control points (phantom ends by reflection).
    const geom::CatmullRom3 cr(curves[k], 0.0, false);
    for (int i = 0; i < M; ++i) {
      const double t = double(i) / M;
      loop.push_back(cr.eval(t * double(cr.num_segments())));
      loop_param.emplace_back(k, t);
    }
  }
  // 2. Plane of the loop (Newell normal), oriented away from the head's centre.
  Vec3 c = Vec3::Zero(), nrm = Vec3::Zero();
  for (std::size_t i = 0; i < loop.size(); ++i) {
    c += loop[i];
    const Vec3 &a = loop[i], &b = loop[(i + 1) % loop.size()];
    nrm += Vec3((a.y() - b.y()) * (a.z() + b.z()), (a.z() - b.z()) * (a.x() + b.x()),
                (a.x() - b.x()) * (a.y() + b.y()));
  }
  c /= double(loop.size());
  if (nrm.norm() < 1e-12) fail_at("scalp.curves", "the four curves enclose no area");
  nrm.normalize();
  Vec3 head_c = Vec3::Zero();
  for (const auto& v : head.positions) head_c += v;
  head_c /= double(head.positions.size());
  if (nrm.dot(c - head_c) < 0) nrm = -nrm;
  const Vec3 e1 = nrm.unitOrthogonal(), e2 = nrm.cross(e1);
  auto proj = [&](const Vec3& x) { return Vec2((x - c).dot(e1), (x - c).dot(e2)); };
  std::vector<Vec2> poly;
  for (const auto& x : loop) poly.push_back(proj(x));

  // Faces farther behind the loop's plane than every loop point (by a tenth of the loop's
  // size) are on the far side of the head.
  double loop_radius = 0, behind = 0;
  for (const auto& x : loop) {
    loop_radius = std::max(loop_radius, (x - c).norm());
    behind = std::min(behind, (x - c).dot(nrm));
  }
  const double min_offset = behind - 0.1 * loop_radius;
  // 3. Faces inside the loop (projected) and facing the loop's side.
  const std::size_t nf = head.faces.size();
  std::vector<char> sel(nf, 0);
  for (std::size_t f = 0; f < nf; ++f) {
    const Vec3i& fc = head.faces[f];
    const Vec3 cen = (head.positions[fc[0]] + head.positions[fc[1]] + head.positions[fc[2]]) / 3;
    // Also on the outer side of the loop's plane (the scalp bulges away from the head's centre):
    // keeps out the far side of the head (mouth, face) that projects into the loop too.
    if (head.face_normal(f).dot(nrm) > 0 && (cen - c).dot(nrm) > min_offset &&
        inside_polygon(poly, proj(cen)))
      sel[f] = 1;
  }
  // 3b. On a scan mesh the jagged selection can touch itself at a vertex (a boundary vertex of
  // degree 4) or leave single unselected faces inside; grow it there (all faces around such a
  // vertex, every face whose three edges border the selection) until the boundary is manifold.
  for (int pass = 0; pass < 8; ++pass) {
    std::map<std::pair<int, int>, int> used;
    for (std::size_t f = 0; f < nf; ++f)
      if (sel[f])
        for (int k = 0; k < 3; ++k) {
          const int a = head.faces[f][k], b = head.faces[f][(k + 1) % 3];
          used[{std::min(a, b), std::max(a, b)}]++;
        }
    std::map<int, int> deg;
    for (const auto& [e, n] : used)
      if (n == 1) {
        deg[e.first]++;
        deg[e.second]++;
      }
    std::vector<char> bad(head.positions.size(), 0);
    bool any = false;
    for (const auto& [v, d] : deg)
      if (d != 2) bad[std::size_t(v)] = any = 1;
    bool grown = false;
    for (std::size_t f = 0; f < nf; ++f) {
      if (sel[f]) continue;
      int bordering = 0;
      bool at_bad = false;
      for (int k = 0; k < 3; ++k) {
        const int a = head.faces[f][k], b = head.faces[f][(k + 1) % 3];
        const auto it = used.find({std::min(a, b), std::max(a, b)});
        if (it != used.end() && it->second == 1) ++bordering;
        at_bad = at_bad || bad[std::size_t(a)];
      }
      if (bordering == 3 || (any && at_bad)) sel[f] = grown = 1;
    }
    if (!grown) break;
  }
  // 4. Keep the largest edge-connected component.
  const EdgeFaces edge_faces = edge_faces_of(head);
  const FaceComponents in = face_components(head, edge_faces, sel);
  const int best = in.largest();
  if (best < 0 || in.size[std::size_t(best)] < 2)
    fail_at("scalp.curves", "the curves enclose no faces of the head mesh");
  std::vector<int> comp = in.id;
  // 4b. Fill holes: a scalp reaching the hairline bends through more than the loop's plane can
  // see, and faces there that turn away from the plane's normal leave islands inside the
  // selection. Every edge-connected group of the other faces except the largest (the rest of
  // the head) is a hole and joins the scalp.
  std::vector<char> rest(nf, 0);
  for (std::size_t f = 0; f < nf; ++f) rest[f] = comp[f] != best;
  const FaceComponents out = face_components(head, edge_faces, rest);
  const int outside = out.largest();
  for (std::size_t f = 0; f < nf; ++f)
    if (out.id[f] >= 0 && out.id[f] != outside) comp[f] = best;

  Scalp s;
  s.m_params = p;
  std::vector<int> remap(head.positions.size(), -1);
  for (std::size_t f = 0; f < nf; ++f) {
    if (comp[f] != best) continue;
    Vec3i nfc;
    for (int k = 0; k < 3; ++k) {
      int& r = remap[head.faces[f][k]];
      if (r < 0) {
        r = int(s.m_mesh.positions.size());
        s.m_mesh.positions.push_back(head.positions[head.faces[f][k]]);
        s.m_source.push_back(head.faces[f][k]);
      }
      nfc[k] = r;
    }
    s.m_mesh.faces.push_back(nfc);
  }
  s.m_mesh.name = "scalp";
  // 5. Boundary: edges used once; must form one loop (a disk).
  std::map<std::pair<int, int>, int> ecount;
  for (const auto& f : s.m_mesh.faces)
    for (int k = 0; k < 3; ++k) {
      int a = f[k], b = f[(k + 1) % 3];
      ecount[{std::min(a, b), std::max(a, b)}]++;
    }
  std::vector<int> bverts;
  std::map<int, int> bdeg;
  int nbedges = 0;
  for (const auto& [e, n] : ecount)
    if (n == 1) {
      bdeg[e.first]++;
      bdeg[e.second]++;
      ++nbedges;
    }
  for (const auto& [v, d] : bdeg) {
    if (d != 2) fail_at("scalp.curves", "the trimmed scalp boundary is not a simple loop");
    bverts.push_back(v);
  }
  const int nv = int(s.m_mesh.positions.size());
  const int euler = nv - int(ecount.size()) + int(s.m_mesh.faces.size());
  if (euler != 1 || nbedges != int(bverts.size()) || bverts.size() < 4)
    fail_at("scalp.curves", "the trimmed scalp is not a disk (Euler characteristic {})", euler);
  // 6. Boundary vertices to the square by the nearest point of the loop.
  Eigen::MatrixXd fixed(bverts.size(), 2);
  for (std::size_t i = 0; i < bverts.size(); ++i) {
    const Vec2 q = proj(s.m_mesh.positions[bverts[i]]);
    double bd = 1e300;
    Vec2 uv(0, 0);
    for (std::size_t k = 0; k < poly.size(); ++k) {
      const Vec2 &a = poly[k], &b = poly[(k + 1) % poly.size()];
      const Vec2 ab = b - a;
      const double t = std::clamp((q - a).dot(ab) / std::max(ab.squaredNorm(), 1e-300), 0.0, 1.0);
      const double d = (a + t * ab - q).squaredNorm();
      if (d < bd) {
        bd = d;
        const auto [curve, t0] = loop_param[k];
        uv = square_point(curve, t0 + t / M);
      }
    }
    fixed.row(Eigen::Index(i)) = uv.transpose();
  }
  // 7. Harmonic embedding (Eck et al. weights) of the interior.
  const Eigen::MatrixXd uv = geom::harmonic_interpolate(s.m_mesh, bverts, fixed);
  s.m_mesh.uvs.resize(std::size_t(nv));
  for (int v = 0; v < nv; ++v)
    s.m_mesh.uvs[std::size_t(v)] = Vec2(uv(v, 0), uv(v, 1)).cwiseMax(0.0).cwiseMin(1.0);
  s.m_mesh.uv_faces = s.m_mesh.faces;
  s.m_mesh.compute_normals();
  s.build_lookup();
  return s;
}

void Scalp::build_lookup() {
  const std::size_t nf = m_mesh.faces.size();
  m_cum_area.resize(nf);
  double acc = 0;
  for (std::size_t f = 0; f < nf; ++f) {
    acc += m_mesh.face_area(f);
    m_cum_area[f] = acc;
  }
  m_area = acc;
  m_grid = std::max(1, int(std::sqrt(double(nf))));
  m_cells.assign(std::size_t(m_grid * m_grid), {});
  for (std::size_t f = 0; f < nf; ++f) {
    Vec2 lo(1, 1), hi(0, 0);
    for (int k = 0; k < 3; ++k) {
      lo = lo.cwiseMin(m_mesh.uvs[m_mesh.faces[f][k]]);
      hi = hi.cwiseMax(m_mesh.uvs[m_mesh.faces[f][k]]);
    }
    const int x0 = std::clamp(int(lo.x() * m_grid), 0, m_grid - 1);
    const int x1 = std::clamp(int(hi.x() * m_grid), 0, m_grid - 1);
    const int y0 = std::clamp(int(lo.y() * m_grid), 0, m_grid - 1);
    const int y1 = std::clamp(int(hi.y() * m_grid), 0, m_grid - 1);
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) m_cells[std::size_t(y * m_grid + x)].push_back(uint32_t(f));
  }
}

ScalpPoint Scalp::point(const Vec2& uv_in) const {
  const Vec2 uv = uv_in.cwiseMax(0.0).cwiseMin(1.0);
  const int cx = std::clamp(int(uv.x() * m_grid), 0, m_grid - 1);
  const int cy = std::clamp(int(uv.y() * m_grid), 0, m_grid - 1);
  // Barycentric coordinates in the face whose uv triangle contains uv; the least-outside face
  // when none does (points on the border of D, rounding).
  double best_out = 1e300;
  uint32_t best_f = 0;
  Vec3 best_b(1, 0, 0);
  for (uint32_t f : m_cells[std::size_t(cy * m_grid + cx)]) {
    const Vec3i& fc = m_mesh.faces[f];
    const Vec2 &a = m_mesh.uvs[fc[0]], &b = m_mesh.uvs[fc[1]], &c = m_mesh.uvs[fc[2]];
    const double det = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
    if (std::abs(det) < 1e-300) continue;
    const Vec2 d = uv - a;
    const double l1 = (d.x() * (c - a).y() - d.y() * (c - a).x()) / det;
    const double l2 = ((b - a).x() * d.y() - (b - a).y() * d.x()) / det;
    const double l0 = 1 - l1 - l2;
    const double out = std::max({0.0, -l0, -l1, -l2});
    if (out < best_out) {
      best_out = out;
      best_f = f;
      best_b = Vec3(l0, l1, l2);
    }
    if (out == 0) break;
  }
  best_b = best_b.cwiseMax(0.0);
  best_b /= best_b.sum();
  const Vec3i& fc = m_mesh.faces[best_f];
  ScalpPoint sp;
  sp.position = best_b[0] * m_mesh.positions[fc[0]] + best_b[1] * m_mesh.positions[fc[1]] +
                best_b[2] * m_mesh.positions[fc[2]];
  const Vec3 n = best_b[0] * m_mesh.normals[fc[0]] + best_b[1] * m_mesh.normals[fc[1]] +
                 best_b[2] * m_mesh.normals[fc[2]];
  sp.normal = n.norm() > 0 ? Vec3(n.normalized()) : m_mesh.face_normal(best_f);
  return sp;
}

void Scalp::set_length_map(const image::ImageF& map) {
  for (std::size_t i = 0; i < map.storage().size(); ++i) {
    const float v = map.storage()[i];
    if (!(v >= 0.f && v <= 1.f))
      fail_at("scalp.length_map", "pixel {} has value {}, expected a value in [0, 1]", i, v);
  }
  m_length_map = map;
}

double Scalp::length(const Vec2& uv_in) const {
  if (m_length_map.empty()) return m_params.max_length;
  const Vec2 uv = uv_in.cwiseMax(0.0).cwiseMin(1.0);
  const int w = m_length_map.width(), h = m_length_map.height();
  const double x = uv.x() * (w - 1), y = (1.0 - uv.y()) * (h - 1);
  const int x0 = std::min(int(x), std::max(w - 2, 0)), y0 = std::min(int(y), std::max(h - 2, 0));
  const int x1 = std::min(x0 + 1, w - 1), y1 = std::min(y0 + 1, h - 1);
  const double fx = std::clamp(x - x0, 0.0, 1.0), fy = std::clamp(y - y0, 0.0, 1.0);
  const double v = (1 - fy) * ((1 - fx) * m_length_map.at(x0, y0) + fx * m_length_map.at(x1, y0)) +
                   fy * ((1 - fx) * m_length_map.at(x0, y1) + fx * m_length_map.at(x1, y1));
  return v * m_params.max_length;
}

Vec2 Scalp::sample_uv(Rng& rng) const {
  const double r = rng.uniform() * m_area;
  const std::size_t f = std::min<std::size_t>(
      std::size_t(std::lower_bound(m_cum_area.begin(), m_cum_area.end(), r) - m_cum_area.begin()),
      m_cum_area.size() - 1);
  double r1 = rng.uniform(), r2 = rng.uniform();
  if (r1 + r2 > 1) {
    r1 = 1 - r1;
    r2 = 1 - r2;
  }
  const Vec3i& fc = m_mesh.faces[f];
  const Vec2 &a = m_mesh.uvs[fc[0]], &b = m_mesh.uvs[fc[1]], &c = m_mesh.uvs[fc[2]];
  return a + r1 * (b - a) + r2 * (c - a);
}

Vec2 Scalp::nearest_uv(const Vec3& p) const {
  std::size_t best = 0;
  double bd = 1e300;
  for (std::size_t v = 0; v < m_mesh.positions.size(); ++v) {
    const double d = (m_mesh.positions[v] - p).squaredNorm();
    if (d < bd) {
      bd = d;
      best = v;
    }
  }
  return m_mesh.uvs[best];
}

}  // namespace follicle::hair
