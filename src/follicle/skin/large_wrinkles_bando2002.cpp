#include "follicle/skin/large_wrinkles_bando2002.hpp"

#include <algorithm>
#include <bitset>
#include <cmath>
#include <map>

#include "follicle/core/error.hpp"
#include "follicle/core/parallel.hpp"
#include "follicle/geom/uv_locator.hpp"

namespace follicle::skin {

BezierDistance::BezierDistance(const CubicBezier2& c, int samples) : m_c(c) {
  samples = std::max(samples, 2);
  for (int i = 0; i <= samples; ++i) {
    const double t = double(i) / samples;
    m_ts.push_back(t);
    m_pts.push_back(c.eval(t));
    m_box.extend(m_pts.back());
    if (i > 0) m_length += (m_pts[std::size_t(i)] - m_pts[std::size_t(i - 1)]).norm();
  }
}

CurveProjection BezierDistance::project(const Vec2& q) const {
  double best = 1e300, bt = 0;
  for (std::size_t i = 0; i + 1 < m_pts.size(); ++i) {
    const Vec2 a = m_pts[i], d = m_pts[i + 1] - a;
    const double dd = d.squaredNorm();
    const double u = dd > 0 ? std::clamp((q - a).dot(d) / dd, 0.0, 1.0) : 0.0;
    const double dist = (a + u * d - q).squaredNorm();
    if (dist < best) {
      best = dist;
      bt = m_ts[i] + u * (m_ts[i + 1] - m_ts[i]);
    }
  }
  // Newton refinement of (B(t) - q) . B'(t) = 0 on the true curve.
  for (int it = 0; it < 3; ++it) {
    const Vec2 b = m_c.eval(bt), d1 = m_c.tangent(bt);
    const double u = 1 - bt;
    const Vec2 d2 = 6 * u * (m_c.p[2] - 2 * m_c.p[1] + m_c.p[0]) +
                    6 * bt * (m_c.p[3] - 2 * m_c.p[2] + m_c.p[1]);
    const double f = (b - q).dot(d1), fp = d1.dot(d1) + (b - q).dot(d2);
    if (std::abs(fp) < 1e-300) break;
    bt = std::clamp(bt - f / fp, 0.0, 1.0);
  }
  CurveProjection r;
  r.t = bt;
  r.point = m_c.eval(bt);
  r.distance = (r.point - q).norm();
  Vec2 tg = m_c.tangent(bt);
  if (tg.norm() < 1e-300) tg = m_c.p[3] - m_c.p[0];
  r.tangent = tg.norm() > 0 ? Vec2(tg.normalized()) : Vec2::UnitX();
  return r;
}

TextureSpaceMesh TextureSpaceMesh::build(const geom::TriMesh& mesh) {
  if (!mesh.has_uvs())
    fail("wrinkles: the mesh has no texture coordinates (map it to texture space first)");
  TextureSpaceMesh t;
  const std::size_t nv = mesh.positions.size(), nf = mesh.faces.size();
  t.vertex_uv.assign(nv, Vec2::Zero());
  std::vector<char> seen(nv, 0);
  t.face_uv.resize(nf);
  t.vf_offsets.assign(nv + 1, 0);
  for (std::size_t f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) {
      const auto v = std::size_t(mesh.faces[f][k]);
      const Vec2 uv = mesh.uvs[std::size_t(mesh.uv_faces[f][k])];
      t.face_uv[f][std::size_t(k)] = uv;
      if (!seen[v]) {
        seen[v] = 1;
        t.vertex_uv[v] = uv;
      }
      ++t.vf_offsets[v + 1];
    }
  for (std::size_t v = 0; v < nv; ++v) t.vf_offsets[v + 1] += t.vf_offsets[v];
  t.vf_faces.resize(t.vf_offsets.back());
  t.vf_corner.resize(t.vf_offsets.back());
  std::vector<std::size_t> fill(t.vf_offsets.begin(), t.vf_offsets.end() - 1);
  for (std::size_t f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) {
      const auto v = std::size_t(mesh.faces[f][k]);
      t.vf_faces[fill[v]] = int(f);
      t.vf_corner[fill[v]] = char(k);
      ++fill[v];
    }
  return t;
}

double texture_scale(const geom::TriMesh& mesh, const TextureSpaceMesh& tex,
                     const std::vector<int>& faces) {
  double a3 = 0, auv = 0;
  for (int f : faces) {
    a3 += mesh.face_area(std::size_t(f));
    const auto& uv = tex.face_uv[std::size_t(f)];
    const Vec2 e1 = uv[1] - uv[0], e2 = uv[2] - uv[0];
    auv += 0.5 * std::abs(e1.x() * e2.y() - e1.y() * e2.x());
  }
  return auv > 0 ? std::sqrt(a3 / auv) : 1.0;
}

WrinkleLayer::WrinkleLayer(const geom::TriMesh& rest, std::vector<LargeWrinkle> wrinkles,
                           double cutoff_widths, ShrinkageMethod method)
    : m_rest(rest),
      m_tex(TextureSpaceMesh::build(rest)),
      m_wrinkles(std::move(wrinkles)),
      m_cutoff(cutoff_widths),
      m_method(method) {
  m_face_island = geom::uv_islands(m_rest);
  std::vector<int> all(rest.faces.size());
  for (std::size_t f = 0; f < all.size(); ++f) all[f] = int(f);
  m_global_scale = texture_scale(m_rest, m_tex, all);
  m_infl.resize(m_wrinkles.size());
  for (std::size_t i = 0; i < m_wrinkles.size(); ++i) {
    m_wrinkles[i].validate();
    build(i);
  }
  build_vertex_index();
}

void WrinkleLayer::build_vertex_index() {
  const std::size_t nv = m_rest.positions.size();
  std::vector<std::size_t> count(nv + 1, 0);
  for (const auto& infl : m_infl)
    for (const auto& e : infl.entries) ++count[std::size_t(e.vertex) + 1];
  m_vtx.clear();
  m_vtx_offsets.assign(1, 0);
  std::vector<std::size_t> slot(nv, 0);
  for (std::size_t v = 0; v < nv; ++v)
    if (count[v + 1] > 0) {
      slot[v] = m_vtx_offsets.back();
      m_vtx.push_back(int(v));
      m_vtx_offsets.push_back(m_vtx_offsets.back() + count[v + 1]);
    }
  m_vtx_refs.resize(m_vtx_offsets.back());
  for (std::size_t i = 0; i < m_infl.size(); ++i)  // wrinkle order within each vertex
    for (std::size_t k = 0; k < m_infl[i].entries.size(); ++k)
      m_vtx_refs[slot[std::size_t(m_infl[i].entries[k].vertex)]++] = {int(i), int(k)};
}

std::size_t WrinkleLayer::set_wrinkle(std::size_t i, const LargeWrinkle& w) {
  if (i >= m_wrinkles.size())
    fail("set_wrinkle: index {} out of range ({} wrinkles)", i, m_wrinkles.size());
  w.validate();
  const std::size_t before = m_infl[i].entries.size();
  m_wrinkles[i] = w;
  build(i);
  build_vertex_index();  // O(entries): no geometry is recomputed for the other wrinkles
  return std::max(before, m_infl[i].entries.size());
}

namespace {
double smoothstep01(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * (3 - 2 * x);
}
}  // namespace

namespace {
bool in_uv_triangle(const std::array<Vec2, 3>& t, const Vec2& q) {
  auto cross = [](const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); };
  const double d1 = cross(t[1] - t[0], q - t[0]), d2 = cross(t[2] - t[1], q - t[1]),
               d3 = cross(t[0] - t[2], q - t[2]);
  const double area = cross(t[1] - t[0], t[2] - t[0]);
  if (std::abs(area) < 1e-300) return false;
  return (d1 >= 0 && d2 >= 0 && d3 >= 0) || (d1 <= 0 && d2 <= 0 && d3 <= 0);
}
}  // namespace

int WrinkleLayer::curve_island(const BezierDistance& bd) const {
  // Texture space may hold several UV islands on top of each other (eyes, teeth, the back of a
  // scanned head laid over the face). The curve belongs to the island whose UV triangles hold
  // most of its samples; ties go to the island with more 3D area under the samples.
  constexpr int kSamples = 33;
  std::array<Vec2, kSamples> q;
  for (int k = 0; k < kSamples; ++k)
    q[std::size_t(k)] = bd.curve().eval(double(k) / (kSamples - 1));
  const Eigen::AlignedBox2d box = bd.bounds();
  // Per island: which samples its UV triangles hold, and the 3D area of those triangles.
  std::map<int, std::pair<std::bitset<kSamples>, double>> held;
  for (std::size_t f = 0; f < m_rest.faces.size(); ++f) {
    const auto& t = m_tex.face_uv[f];
    Eigen::AlignedBox2d fb(t[0]);
    fb.extend(t[1]);
    fb.extend(t[2]);
    if (!fb.intersects(box)) continue;
    std::bitset<kSamples> in;
    for (int k = 0; k < kSamples; ++k)
      in[std::size_t(k)] = fb.contains(q[std::size_t(k)]) && in_uv_triangle(t, q[std::size_t(k)]);
    if (in.none()) continue;
    auto& h = held[m_face_island[f]];
    h.first |= in;
    h.second += m_rest.face_area(f);
  }
  int best = -1;
  std::size_t best_count = 0;
  double best_area = 0;
  for (const auto& [island, h] : held) {
    const std::size_t count = h.first.count();
    if (count > best_count || (count == best_count && h.second > best_area)) {
      best = island;
      best_count = count;
      best_area = h.second;
    }
  }
  return best;
}

void WrinkleLayer::build(std::size_t i) {
  const LargeWrinkle& w = m_wrinkles[i];
  WrinkleInfluence infl;
  const BezierDistance bd(CubicBezier2{w.control});
  const std::size_t nv = m_rest.positions.size();
  const int island = curve_island(bd);
  infl.island = island;
  auto in_island = [&](std::size_t f) { return island < 0 || m_face_island[f] == island; };
  // A vertex's texture position on the wrinkle's island (a seam vertex has one per island).
  auto island_uv = [&](std::size_t v, Vec2& uv) {
    if (island < 0) {
      uv = m_tex.vertex_uv[v];
      return true;
    }
    for (std::size_t k = m_tex.vf_offsets[v]; k < m_tex.vf_offsets[v + 1]; ++k) {
      const auto f = std::size_t(m_tex.vf_faces[k]);
      if (m_face_island[f] == island) {
        uv = m_tex.face_uv[f][std::size_t(m_tex.vf_corner[k])];
        return true;
      }
    }
    return false;
  };
  // Local texture scale from the faces around the curve (first with the global scale).
  double scale = m_global_scale;
  for (int pass = 0; pass < 2; ++pass) {
    const double radius_uv = m_cutoff * w.width / scale;
    Eigen::AlignedBox2d box = bd.bounds();
    box.min().array() -= radius_uv;
    box.max().array() += radius_uv;
    std::vector<int> near;
    for (std::size_t f = 0; f < m_rest.faces.size(); ++f) {
      if (!in_island(f)) continue;
      const auto& uv = m_tex.face_uv[f];
      const Vec2 c = (uv[0] + uv[1] + uv[2]) / 3.0;
      if (box.contains(c) && bd.project(c).distance <= radius_uv) near.push_back(int(f));
    }
    if (!near.empty()) scale = texture_scale(m_rest, m_tex, near);
  }
  infl.texture_scale = scale;
  const double radius_uv = m_cutoff * w.width / scale;
  Eigen::AlignedBox2d box = bd.bounds();
  box.min().array() -= radius_uv;
  box.max().array() += radius_uv;
  for (std::size_t v = 0; v < nv; ++v) {
    Vec2 q;
    if (!island_uv(v, q) || !box.contains(q)) continue;
    const CurveProjection pr = bd.project(q);
    if (pr.distance > radius_uv) continue;
    double taper = 1.0;
    if (w.end_taper > 0) {
      taper = smoothstep01(pr.t / w.end_taper) * smoothstep01((1.0 - pr.t) / w.end_taper);
    } else if (pr.t <= 0.0 || pr.t >= 1.0) {
      taper = 0.0;  // no perpendicular foot on the curve
    }
    if (taper <= 0) continue;
    WrinkleInfluence::Entry e;
    e.vertex = int(v);
    e.l = pr.distance * scale;
    e.shape = wrinkle_shape(e.l, w.depth, w.width) * taper;  // (2.1)
    const Vec2 dp(-pr.tangent.y(), pr.tangent.x());  // perpendicular to the furrow (texture space)
    for (int sgn = 0; sgn < 2; ++sgn) {
      const Vec2 d = sgn == 0 ? dp : Vec2(-dp);
      for (std::size_t k = m_tex.vf_offsets[v]; k < m_tex.vf_offsets[v + 1]; ++k) {
        const auto f = std::size_t(m_tex.vf_faces[k]);
        if (!in_island(f)) continue;  // another island's UVs live in another chart
        const int c = m_tex.vf_corner[k];
        const auto& uv = m_tex.face_uv[f];
        const Vec2 e2 = uv[std::size_t((c + 1) % 3)] - uv[std::size_t(c)];
        const Vec2 e3 = uv[std::size_t((c + 2) % 3)] - uv[std::size_t(c)];
        Eigen::Matrix2d E;
        E.col(0) = e2;
        E.col(1) = e3;
        const double det = E.determinant();
        if (std::abs(det) < 1e-30) continue;
        const Vec2 ab = E.inverse() * d;
        const double tol = -1e-9 * (std::abs(ab.x()) + std::abs(ab.y()));
        if (ab.x() < tol || ab.y() < tol) continue;  // d_p is outside this corner's sector
        WrinkleInfluence::Side s;
        s.j2 = m_rest.faces[f][(c + 1) % 3];
        s.j3 = m_rest.faces[f][(c + 2) % 3];
        s.a = std::max(ab.x(), 0.0);
        s.b = std::max(ab.y(), 0.0);
        s.rest2 = (m_rest.positions[std::size_t(s.j2)] - m_rest.positions[v]).norm();
        s.rest3 = (m_rest.positions[std::size_t(s.j3)] - m_rest.positions[v]).norm();
        s.rest_span = (s.a * (m_rest.positions[std::size_t(s.j2)] - m_rest.positions[v]) +
                       s.b * (m_rest.positions[std::size_t(s.j3)] - m_rest.positions[v]))
                          .norm();
        if (s.rest2 <= 0 || s.rest3 <= 0 || s.a + s.b <= 0 || s.rest_span <= 0) continue;
        e.side[std::size_t(e.nsides++)] = s;
        break;
      }
    }
    infl.entries.push_back(e);
  }
  m_infl[i] = std::move(infl);
}

double WrinkleLayer::entry_shrinkage(const WrinkleInfluence::Entry& e,
                                     const std::vector<Vec3>& p) const {
  double acc = 0;
  const Vec3& p1 = p[std::size_t(e.vertex)];
  for (int j = 0; j < e.nsides; ++j) {
    const auto& sd = e.side[std::size_t(j)];
    const Vec3 x2 = p[std::size_t(sd.j2)] - p1, x3 = p[std::size_t(sd.j3)] - p1;
    if (m_method == ShrinkageMethod::edge_scaling)
      acc += triangle_shrinkage(sd.a, sd.b, x2.norm() / sd.rest2, x3.norm() / sd.rest3);  // (2.3)
    else
      acc += 1.0 - (sd.a * x2 + sd.b * x3).norm() / sd.rest_span;  // (2.3) s = 1 - L'/L
  }
  return e.nsides > 0 ? acc / e.nsides : 0.0;  // average of the +d_p and -d_p triangles
}

void WrinkleLayer::shrinkage(const Context& ctx, std::size_t i, const std::vector<Vec3>& p,
                             std::vector<double>& s) const {
  const auto& entries = m_infl[i].entries;
  s.resize(entries.size());
  parallel_for(
      ctx, 0, entries.size(), [&](std::size_t k) { s[k] = entry_shrinkage(entries[k], p); }, 512);
}

void WrinkleLayer::heights(const Context& ctx, const std::vector<Vec3>& deformed,
                           std::vector<double>& height) const {
  if (deformed.size() != m_rest.positions.size())
    fail("wrinkle heights: {} positions for a {}-vertex rest mesh", deformed.size(),
         m_rest.positions.size());
  height.assign(deformed.size(), 0.0);
  // One pass over the affected vertices; each sums its wrinkles in wrinkle order, so the result
  // is bit-identical for any thread count (and to a wrinkle-by-wrinkle accumulation).
  parallel_for(
      ctx, 0, m_vtx.size(),
      [&](std::size_t j) {
        double h = 0;
        for (std::size_t q = m_vtx_offsets[j]; q < m_vtx_offsets[j + 1]; ++q) {
          const auto [wi, k] = m_vtx_refs[q];
          const auto& e = m_infl[std::size_t(wi)].entries[std::size_t(k)];
          h += amplitude_modulation(entry_shrinkage(e, deformed), m_wrinkles[std::size_t(wi)].r) *
               e.shape;  // (2.4) M(s) S(l)
        }
        height[std::size_t(m_vtx[j])] = h;
      },
      512);
}

void WrinkleLayer::rest_heights(std::vector<double>& height) const {
  height.assign(m_rest.positions.size(), 0.0);
  for (std::size_t i = 0; i < m_wrinkles.size(); ++i)
    for (const auto& e : m_infl[i].entries)
      height[std::size_t(e.vertex)] += amplitude_modulation(0.0, m_wrinkles[i].r) * e.shape;
}

}  // namespace follicle::skin
