#include "follicle/geom/texture_mapping_bando2002.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "follicle/core/error.hpp"
#include "follicle/geom/projection.hpp"

namespace follicle::geom {

namespace {

// Union-find over indices (connected parts by shared vertices, UV islands by shared UV indices).
struct Dsu {
  std::vector<int> p;
  explicit Dsu(std::size_t n) : p(n) { std::iota(p.begin(), p.end(), 0); }
  int find(int x) {
    while (p[std::size_t(x)] != x) x = p[std::size_t(x)] = p[std::size_t(p[std::size_t(x)])];
    return x;
  }
  void unite(int a, int b) { p[std::size_t(find(a))] = find(b); }
};

double signed_area(const Vec2& a, const Vec2& b, const Vec2& c) {
  const Vec2 e1 = b - a, e2 = c - a;
  return 0.5 * (e1.x() * e2.y() - e1.y() * e2.x());
}

// One chart: its own vertices (one per UV, so a cut splits them), faces over them, 3D positions.
struct Chart {
  TriMesh mesh;              // positions per chart vertex, faces over them
  std::vector<int> face_of;  // chart face -> input face
  std::vector<Vec2> uv;      // per chart vertex
  MappingMethod method = MappingMethod::Planar;
  bool circle = false;
  Eigen::AlignedBox2d box;
  Vec2 offset = Vec2::Zero();
};

// Does the part wrap around the up axis (a head) or not (a face mask)? Share of 10-degree
// sectors about the axis through the centroid holding a vertex away from the axis.
bool wraps_around(const std::vector<Vec3>& pts, const Vec3& up, const Vec3& front) {
  if (pts.size() < 8) return false;
  Vec3 c = Vec3::Zero();
  for (const auto& p : pts) c += p;
  c /= double(pts.size());
  const Vec3 z = (front - front.dot(up) * up).normalized(), x = up.cross(z);
  double rmean = 0;
  for (const auto& p : pts) rmean += ((p - c) - (p - c).dot(up) * up).norm();
  rmean /= double(pts.size());
  std::array<char, 36> sector{};
  for (const auto& p : pts) {
    const Vec3 d = p - c;
    if ((d - d.dot(up) * up).norm() < 0.3 * rmean) continue;
    const double a = std::atan2(d.dot(x), d.dot(z));
    sector[std::size_t(std::clamp(int((a + kPi) / (2 * kPi) * 36), 0, 35))] = 1;
  }
  return std::count(sector.begin(), sector.end(), 1) >= 30;
}

// Chart vertices from per-face UV indices: chart vertex = UV index (cut along split UVs).
Chart make_chart(const std::vector<Vec3>& pos, const std::vector<Vec3i>& faces,
                 const std::vector<int>& face_ids, const std::vector<Vec2>& uvs,
                 const std::vector<Vec3i>& uv_faces) {
  Chart ch;
  std::vector<int> remap(uvs.size(), -1);
  for (std::size_t k = 0; k < face_ids.size(); ++k) {
    Vec3i f;
    for (int c = 0; c < 3; ++c) {
      const int t = uv_faces[k][c];
      if (remap[std::size_t(t)] < 0) {
        remap[std::size_t(t)] = int(ch.mesh.positions.size());
        ch.mesh.positions.push_back(pos[std::size_t(faces[k][c])]);
        ch.uv.push_back(uvs[std::size_t(t)]);
      }
      f[c] = remap[std::size_t(t)];
    }
    ch.mesh.faces.push_back(f);
    ch.face_of.push_back(face_ids[k]);
  }
  return ch;
}

// §2.4 on one chart: fixed (relaxed) boundary + harmonic interior, holes closed by virtual fans.
// Returns false when the chart has no boundary to fix (a closed surface that was not cut).
bool harmonic_chart(Chart& ch, const TextureMappingParams& p, bool circle) {
  const auto loops = boundary_loops(ch.mesh);
  if (loops.empty()) return false;
  TriMesh aug = ch.mesh;
  std::vector<Vec2> uv0 = ch.uv;
  for (std::size_t l = 1; l < loops.size(); ++l) {
    const auto& loop = loops[l];
    Vec3 c = Vec3::Zero();
    Vec2 cu = Vec2::Zero();
    for (int v : loop) {
      c += aug.positions[std::size_t(v)];
      cu += ch.uv[std::size_t(v)];
    }
    const int cv = int(aug.positions.size());
    aug.positions.push_back(c / double(loop.size()));
    uv0.push_back(cu / double(loop.size()));
    // Boundary half-edges run a -> b inside their face; the fan takes the twin b -> a.
    for (std::size_t i = 0; i < loop.size(); ++i)
      aug.faces.push_back(Vec3i(loop[(i + 1) % loop.size()], loop[i], cv));
  }
  HarmonicMapParams hp;
  hp.keep_own_uvs = false;
  hp.relax_iterations = p.relax_iterations;
  hp.relax_step = p.relax_step;
  hp.circle_boundary = circle;
  hp.fit_unit_square = false;
  const auto uv = harmonic_parameterize(aug, uv0, hp);
  std::copy(uv.begin(), uv.begin() + std::ptrdiff_t(ch.uv.size()), ch.uv.begin());
  ch.circle = circle;
  return true;
}

// Orientation: counter-clockwise UV triangles for faces counter-clockwise seen from outside (the
// OBJ convention); a chart whose majority is clockwise is mirrored in u.
void orient(Chart& ch) {
  double s = 0;
  for (const auto& f : ch.mesh.faces)
    s += signed_area(ch.uv[std::size_t(f[0])], ch.uv[std::size_t(f[1])], ch.uv[std::size_t(f[2])]);
  if (s < 0)
    for (auto& t : ch.uv) t.x() = -t.x();
}

// Upright charts: rotate so that the mean UV gradient of the height along `up` points along +v
// (the face reads upright in the texture whichever way the circle boundary started).
void make_upright(Chart& ch, const Vec3& up) {
  Vec2 g = Vec2::Zero();
  for (std::size_t f = 0; f < ch.mesh.faces.size(); ++f) {
    const auto& t = ch.mesh.faces[f];
    const Vec2 a = ch.uv[std::size_t(t[0])], e1 = ch.uv[std::size_t(t[1])] - a,
               e2 = ch.uv[std::size_t(t[2])] - a;
    const double h0 = ch.mesh.positions[std::size_t(t[0])].dot(up);
    Eigen::Matrix2d E;
    E << e1.x(), e1.y(), e2.x(), e2.y();
    if (std::abs(E.determinant()) < 1e-300) continue;
    const Vec2 dh(ch.mesh.positions[std::size_t(t[1])].dot(up) - h0,
                  ch.mesh.positions[std::size_t(t[2])].dot(up) - h0);
    const Vec2 grad = E.inverse() * dh;  // E grad = dh
    if (grad.allFinite()) g += ch.mesh.face_area(f) * grad.normalized();
  }
  if (g.norm() < 1e-300) return;
  const double turn = 0.5 * kPi - std::atan2(g.y(), g.x());
  const double c = std::cos(turn), s = std::sin(turn);
  for (auto& t : ch.uv) t = Vec2(c * t.x() - s * t.y(), s * t.x() + c * t.y());
}

double uv_area(const Chart& ch) {
  double a = 0;
  for (const auto& f : ch.mesh.faces)
    a += std::abs(
        signed_area(ch.uv[std::size_t(f[0])], ch.uv[std::size_t(f[1])], ch.uv[std::size_t(f[2])]));
  return a;
}

int folded(const Chart& ch, double tiny) {
  int n = 0;
  for (const auto& f : ch.mesh.faces)
    n += signed_area(ch.uv[std::size_t(f[0])], ch.uv[std::size_t(f[1])], ch.uv[std::size_t(f[2])]) <
         -tiny;
  return n;
}

}  // namespace

const char* to_string(MappingMethod m) {
  for (const auto& [v, name] : follicle_enum_names(m))
    if (v == m) return name;
  return "?";
}

void TextureMappingParams::validate() const {
  validate_params(*this, "mapping");
  if (up.norm() < 1e-9 || front.norm() < 1e-9)
    fail_at("mapping", "up and front must be non-zero directions");
  if (up.normalized().cross(front.normalized()).norm() < 0.1)
    fail_at("mapping", "up ({}, {}, {}) and front ({}, {}, {}) must not be (nearly) parallel",
            up.x(), up.y(), up.z(), front.x(), front.y(), front.z());
}

std::string TextureMappingReport::summary() const {
  if (method == MappingMethod::Uv) return "the mesh's own texture coordinates";
  std::string s = fmt::format("{} chart{} ({} cylindrical, {} planar", charts,
                              charts == 1 ? "" : "s", cylindrical_charts, planar_charts);
  if (circle_charts) s += fmt::format(", {} on a circle boundary", circle_charts);
  s += fmt::format(
      "), {:.3g} m per texture unit, mean stretch {:.2f} ({:.1f}% of the area stretched over 4:1), "
      "{} folded, {} degenerate",
      metres_per_unit, stretch_mean, 100 * stretched_area, flipped, degenerate);
  return s;
}

TriMesh map_to_texture_space(const TriMesh& mesh, const TextureMappingParams& params,
                             TextureMappingReport* report) {
  params.validate();
  if (mesh.faces.empty() || mesh.positions.empty()) fail("texture mapping: the mesh is empty");
  mesh.check("texture mapping");
  TextureMappingReport rep;
  MappingMethod method = params.method;
  if (method == MappingMethod::Auto) method = mesh.has_uvs() ? MappingMethod::Uv : method;
  if (method == MappingMethod::Uv) {
    if (!mesh.has_uvs())
      fail(
          "texture mapping 'uv': the mesh has no texture coordinates (use mapping 'auto', "
          "'cylindrical' or 'planar')");
    const UvFolds f = count_uv_folds(mesh);
    rep.method = MappingMethod::Uv;
    rep.flipped = f.flipped;
    rep.degenerate = f.degenerate;
    if (report) *report = rep;
    return mesh;
  }
  const Vec3 up = params.up.normalized();
  const Vec3 front = (params.front - params.front.dot(up) * up).normalized();

  // Connected parts (by shared vertices), largest 3D area first.
  const std::size_t nv = mesh.positions.size(), nf = mesh.faces.size();
  Dsu dsu(nv);
  for (const auto& f : mesh.faces) {
    dsu.unite(f[0], f[1]);
    dsu.unite(f[1], f[2]);
  }
  std::vector<int> root_id(nv, -1);
  std::vector<std::vector<int>> parts;
  std::vector<double> part_area;
  for (std::size_t f = 0; f < nf; ++f) {
    const int r = dsu.find(mesh.faces[f][0]);
    if (root_id[std::size_t(r)] < 0) {
      root_id[std::size_t(r)] = int(parts.size());
      parts.emplace_back();
      part_area.push_back(0);
    }
    parts[std::size_t(root_id[std::size_t(r)])].push_back(int(f));
    part_area[std::size_t(root_id[std::size_t(r)])] += mesh.face_area(f);
  }
  std::vector<std::size_t> order(parts.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return part_area[a] > part_area[b]; });

  std::vector<Chart> charts;
  std::vector<int> local(nv, -1);  // global vertex -> index in the current part
  for (std::size_t pi : order) {
    const auto& ids = parts[pi];
    std::vector<Vec3i> faces;  // in the part's own vertex indices
    std::vector<int> used;
    faces.reserve(ids.size());
    for (int f : ids) {
      Vec3i lf;
      for (int c = 0; c < 3; ++c) {
        const int v = mesh.faces[std::size_t(f)][c];
        if (local[std::size_t(v)] < 0) {
          local[std::size_t(v)] = int(used.size());
          used.push_back(v);
        }
        lf[c] = local[std::size_t(v)];
      }
      faces.push_back(lf);
    }
    for (int v : used) local[std::size_t(v)] = -1;
    std::vector<Vec3> pts;
    pts.reserve(used.size());
    for (int v : used) pts.push_back(mesh.positions[std::size_t(v)]);
    MappingMethod m = method;
    if (m == MappingMethod::Auto)
      m = wraps_around(pts, up, front) ? MappingMethod::Cylindrical : MappingMethod::Planar;
    auto build = [&](MappingMethod how) {
      TriMesh tmp;
      tmp.positions = pts;
      tmp.faces = faces;
      std::vector<Vec2> uv;
      if (how == MappingMethod::Planar) {
        uv = project_planar(pts, fit_planar_projection(pts, front, up));
        assign_uvs(tmp, uv, false);
      } else {
        Vec3 c = Vec3::Zero();
        for (const auto& p : pts) c += p;
        c /= double(pts.size());
        double r = 0;
        for (const auto& p : pts) r += ((p - c) - (p - c).dot(up) * up).norm();
        r = std::max(r / double(pts.size()), 1e-9);
        CylindricalProjection cp;
        cp.origin = c;
        cp.axis = up;
        cp.zero_dir = front;
        cp.height_scale = 2 * kPi * r;  // u and v in about the same metres per unit
        uv = project_cylindrical(pts, cp);
        assign_uvs(tmp, uv, true);  // the seam behind the face is cut
      }
      Chart ch = make_chart(pts, faces, ids, tmp.uvs, tmp.uv_faces);
      ch.method = how;
      return ch;
    };
    Chart ch = build(m);
    if (params.harmonic) {
      bool ok = harmonic_chart(ch, params, params.circle_boundary);
      if (!ok && m == MappingMethod::Planar) {
        // A closed part has no boundary to fix: cut it open cylindrically.
        ch = build(MappingMethod::Cylindrical);
        ok = harmonic_chart(ch, params, params.circle_boundary);
      }
      if (!ok)
        fail(
            "texture mapping: part {} ({} triangles) has no boundary even after the cylindrical "
            "cut",
            charts.size(), ids.size());
      orient(ch);
      if (!ch.circle && folded(ch, 1e-14 * uv_area(ch)) > 0) {
        // The relaxed projection still folds: a convex (circle) boundary cannot (Tutte).
        Chart again = build(ch.method);
        harmonic_chart(again, params, true);
        ch = std::move(again);
        orient(ch);
      }
    } else {
      orient(ch);
    }
    make_upright(ch, up);
    charts.push_back(std::move(ch));
  }

  // One texel density: each chart in metres (its 3D area over its UV area), then shelf-packed.
  double box_area = 0;
  for (auto& ch : charts) {
    double a3 = 0;
    for (std::size_t f = 0; f < ch.mesh.faces.size(); ++f) a3 += ch.mesh.face_area(f);
    const double auv = uv_area(ch);
    const double k = auv > 0 && a3 > 0 ? std::sqrt(a3 / auv) : 1.0;
    ch.box.setEmpty();
    for (auto& t : ch.uv) {
      t *= k;
      ch.box.extend(t);
    }
    box_area += ch.box.volume();
  }
  const double side = std::sqrt(std::max(box_area, 1e-300));
  const double margin = 0.01 * side;
  double shelf_width = side * 1.05;
  for (const auto& ch : charts) shelf_width = std::max(shelf_width, ch.box.sizes().x());
  std::vector<std::size_t> by_height(charts.size());
  std::iota(by_height.begin(), by_height.end(), 0);
  std::stable_sort(by_height.begin(), by_height.end(), [&](std::size_t a, std::size_t b) {
    return charts[a].box.sizes().y() > charts[b].box.sizes().y();
  });
  double x = 0, y = 0, shelf_h = 0, total_w = 0;
  for (std::size_t i : by_height) {
    auto& ch = charts[i];
    const Vec2 s = ch.box.sizes();
    if (x > 0 && x + s.x() > shelf_width) {
      y += shelf_h + margin;
      x = 0;
      shelf_h = 0;
    }
    ch.offset = Vec2(x, y) - ch.box.min();
    x += s.x() + margin;
    total_w = std::max(total_w, x - margin);
    shelf_h = std::max(shelf_h, s.y());
  }
  const double extent = std::max(total_w, y + shelf_h);
  const double scale = extent > 0 ? extent : 1.0;

  TriMesh out = mesh;
  out.uvs.clear();
  out.uv_faces.assign(nf, Vec3i::Zero());
  for (const auto& ch : charts) {
    const int base = int(out.uvs.size());
    for (const auto& t : ch.uv) out.uvs.push_back((t + ch.offset) / scale);
    for (std::size_t k = 0; k < ch.mesh.faces.size(); ++k)
      out.uv_faces[std::size_t(ch.face_of[k])] = ch.mesh.faces[k] + Vec3i::Constant(base);
  }

  rep.method = charts.front().method;
  rep.charts = int(charts.size());
  for (const auto& ch : charts) {
    (ch.method == MappingMethod::Cylindrical ? rep.cylindrical_charts : rep.planar_charts) += 1;
    rep.circle_charts += ch.circle;
  }
  rep.metres_per_unit = scale;
  // Stretch: singular-value ratio of each triangle's 3D -> UV map, area-weighted; slivers that
  // are degenerate in 3D already (scans have some) carry no area and are left out.
  double wsum = 0, a3_total = 0;
  for (std::size_t f = 0; f < nf; ++f) a3_total += mesh.face_area(f);
  for (std::size_t f = 0; f < nf; ++f) {
    const double a3 = mesh.face_area(f);
    if (!(a3 > 1e-9 * a3_total)) continue;
    const Vec3i& t = mesh.faces[f];
    const Vec3i& tu = out.uv_faces[f];
    // Capped so that one crushed sliver cannot stand for the whole map in the mean.
    const double st =
        std::min(uv_stretch(mesh.positions[std::size_t(t[0])], mesh.positions[std::size_t(t[1])],
                            mesh.positions[std::size_t(t[2])], out.uvs[std::size_t(tu[0])],
                            out.uvs[std::size_t(tu[1])], out.uvs[std::size_t(tu[2])]),
                 1e3);
    rep.stretch_mean += a3 * st;
    wsum += a3;
    if (st > 4) rep.stretched_area += a3;
  }
  if (wsum > 0) {
    rep.stretch_mean /= wsum;
    rep.stretched_area /= wsum;
  }
  const UvFolds folds = count_uv_folds(out);
  rep.flipped = folds.flipped;
  rep.degenerate = folds.degenerate;
  if (report) *report = rep;
  return out;
}

UvFolds count_uv_folds(const TriMesh& mesh) {
  UvFolds r;
  if (!mesh.has_uvs()) return r;
  const std::size_t nf = mesh.uv_faces.size();
  Dsu dsu(mesh.uvs.size());
  for (const auto& f : mesh.uv_faces) {
    dsu.unite(f[0], f[1]);
    dsu.unite(f[1], f[2]);
  }
  std::vector<double> sa(nf), pos(mesh.uvs.size(), 0.0), neg(mesh.uvs.size(), 0.0);
  double total = 0, total3 = 0;
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) total3 += mesh.face_area(f);
  for (std::size_t f = 0; f < nf; ++f) {
    const auto& t = mesh.uv_faces[f];
    sa[f] = signed_area(mesh.uvs[std::size_t(t[0])], mesh.uvs[std::size_t(t[1])],
                        mesh.uvs[std::size_t(t[2])]);
    const auto root = std::size_t(dsu.find(t[0]));
    (sa[f] >= 0 ? pos : neg)[root] += std::abs(sa[f]);
    total += std::abs(sa[f]);
  }
  const double tiny = 1e-14 * total;
  for (std::size_t f = 0; f < nf; ++f) {
    const auto root = std::size_t(dsu.find(mesh.uv_faces[f][0]));
    if (std::abs(sa[f]) <= tiny) {
      // Zero UV area counts only where the 3D triangle has area (scans carry some slivers).
      if (f < mesh.faces.size() && mesh.face_area(f) > 1e-12 * total3) ++r.degenerate;
      continue;
    }
    const bool majority_pos = pos[root] >= neg[root];
    if ((sa[f] > 0) != majority_pos) ++r.flipped;
  }
  return r;
}

}  // namespace follicle::geom
