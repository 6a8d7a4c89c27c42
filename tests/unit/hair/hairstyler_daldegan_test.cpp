// HairStyler (Daldegan et al. 1993 §2): curves, regions and their selectors, smooth parameters,
// growing (counts, determinism, per-triangle independence, roots, orientation), the tangent
// correction on deformed triangles, and the presets on the Lee Perry-Smith head.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>
#include <set>

#include "follicle/core/rng.hpp"
#include "follicle/geom/adjacency.hpp"
#include "follicle/geom/mesh_io.hpp"
#include "follicle/hair/hairstyler_daldegan1993.hpp"
#include "follicle/image/image_io.hpp"
#include "testing/testing.hpp"

using namespace follicle;
using namespace follicle::hair;

namespace {

const geom::TriMesh& head() {
  static const geom::TriMesh m = [] {
    auto h = geom::load_mesh(
        test::source_dir() / "data" / "meshes" / "lee_perry_smith" / "head.obj", LengthUnit::mm);
    if (!h.has_normals()) h.compute_normals();
    return h;
  }();
  return m;
}

// n x n quads in the x-z plane (y = 0, normal +y), side `size` [m], UV = (x, z) / size.
geom::TriMesh grid(int n, double size, bool uvs = true) {
  geom::TriMesh m;
  auto id = [&](int i, int j) { return i * (n + 1) + j; };
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      m.positions.emplace_back(size * i / n, 0.0, size * j / n);
      if (uvs) m.uvs.emplace_back(double(i) / n, double(j) / n);
    }
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      m.faces.emplace_back(id(i, j), id(i, j + 1), id(i + 1, j + 1));
      m.faces.emplace_back(id(i, j), id(i + 1, j + 1), id(i + 1, j));
    }
  if (uvs) m.uv_faces = m.faces;
  m.compute_normals();
  return m;
}

Vec3 centroid(const geom::TriMesh& m, std::size_t f) {
  const Vec3i& t = m.faces[f];
  return (m.positions[std::size_t(t[0])] + m.positions[std::size_t(t[1])] +
          m.positions[std::size_t(t[2])]) /
         3.0;
}

// A style that grows nowhere except on the region `r` (which re-includes its selection).
HairStylerParams only(HairRegion r) {
  HairStylerParams p;
  HairRegion none;
  none.exclude = true;
  p.regions.push_back(none);
  r.exclude = false;
  p.regions.push_back(r);
  return p;
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

void write_text(const std::filesystem::path& p, const std::string& s) {
  std::ofstream(p) << s;
}

// Strands of each face, as raw point lists (for comparing growths face by face).
std::map<int, std::vector<Vec3f>> points_by_face(const Groom& g) {
  std::map<int, std::vector<Vec3f>> out;
  for (std::size_t s = 0; s < g.num_strands(); ++s) {
    auto& v = out[g.roots[s].face];
    for (uint32_t k = g.strands.offsets[s]; k < g.strands.offsets[s + 1]; ++k)
      v.push_back(g.strands.points[k]);
  }
  return out;
}

}  // namespace

// ---- curves ----------------------------------------------------------------------------------

TEST(HairStylerCurves, BuiltinsHaveUnitLengthEqualSegmentsAndLeaveTheSurface) {
  for (const std::string& name : builtin_curve_names()) {
    for (std::size_t n : {2u, 7u, 20u, 64u}) {
      const auto pts = sample_curve(builtin_curve(name), n, name);
      ASSERT_EQ(pts.size(), n) << name;
      EXPECT_EQ(pts[0], Vec3::Zero()) << name;
      double len = 0.0, lo = 1e9, hi = 0.0;
      for (std::size_t i = 1; i < n; ++i) {
        const double d = (pts[i] - pts[i - 1]).norm();
        len += d;
        lo = std::min(lo, d);
        hi = std::max(hi, d);
      }
      EXPECT_NEAR(len, 1.0, 1e-12) << name << " n=" << n;
      // Equal arc length: chords of equal arcs differ only by the curvature's chord error.
      if (n >= 20) {
        EXPECT_LT(hi / lo, 1.05) << name << " n=" << n;
      }
      EXPECT_GT(pts[1].y(), 0.0) << name << ": the hair must leave the surface";
    }
  }
  // Shapes the names promise.
  const auto straight = sample_curve(builtin_curve("straight"), 11, "s");
  for (std::size_t i = 0; i < straight.size(); ++i)
    EXPECT_LT((straight[i] - Vec3(0.0, i / 10.0, 0.0)).norm(), 1e-12);
  const auto eyebrow = sample_curve(builtin_curve("eyebrow"), 20, "e");
  EXPECT_GT(eyebrow.back().x(), 0.9);  // lies almost flat along the tangent
  const auto beard = sample_curve(builtin_curve("beard"), 20, "b");
  EXPECT_GT(beard[1].y(), 3.0 * beard[1].x());       // leaves nearly along the normal...
  EXPECT_LT(beard.back().y() - beard[18].y(), 0.0);  // ...and ends going down the tangent
  EXPECT_THROW(builtin_curve("spiral"), Error);
}

TEST(HairStylerCurves, UserCurvesAreScaleFreeCatmullRomAndChecked) {
  HairCurve c{"hook", {Vec3(0, 0, 0), Vec3(0, 1, 0), Vec3(1, 1, 0)}};
  HairCurve big{"hook", {Vec3(0, 0, 0), Vec3(0, 5, 0), Vec3(5, 5, 0)}};
  const auto a = sample_curve(c, 20, "c"), b = sample_curve(big, 20, "c");
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_LT((a[i] - b[i]).norm(), 1e-12);
  // The spline interpolates its control points: scaled to unit length, the tip (1, 1, 0) lands
  // at (1, 1, 0) / L and the middle control point at (0, 1, 0) / L.
  const auto dense = sample_curve(c, 2001, "c");
  EXPECT_NEAR(dense.back().x(), dense.back().y(), 1e-12);
  const double L = 1.0 / dense.back().x();
  EXPECT_GT(L, std::sqrt(2.0));  // longer than the chord
  double dmin = 1e9;
  for (const Vec3& p : dense) dmin = std::min(dmin, (p - Vec3(0, 1, 0) / L).norm());
  EXPECT_LT(dmin, 1e-3);

  EXPECT_NE(error_of([] {
              sample_curve(HairCurve{"x", {Vec3(0, 0, 0)}}, 10, "curves[0]");
            }).find("curves[0].points"),
            std::string::npos);
  EXPECT_NE(error_of([] {
              sample_curve(HairCurve{"down", {Vec3(0, 0, 0), Vec3(1, -0.2, 0)}}, 10, "curves[1]");
            }).find("leave the surface"),
            std::string::npos);
  HairStylerParams p;
  p.curves.push_back(HairCurve{"down", {Vec3(0, 0, 0), Vec3(1, -0.2, 0)}});
  EXPECT_NE(error_of([&] { p.validate(); }).find("curves[0].points"), std::string::npos);
}

// ---- regions ---------------------------------------------------------------------------------

TEST(HairStylerRegions, LaterRegionsOverrideEarlierOnes) {
  const auto m = grid(10, 0.1);
  HairRegion all;
  all.scale = 0.05;
  HairRegion ball;
  ball.select = RegionSelect::Sphere;
  ball.centre = Vec3(0.0, 0.0, 0.0);
  ball.radius = 0.05;
  ball.scale = 0.2;
  HairStylerParams p;
  p.regions = {all, ball};
  const HairStyler s(m, p);
  p.regions = {ball, all};
  const HairStyler r(m, p);
  int inside = 0;
  for (std::size_t f = 0; f < m.faces.size(); ++f) {
    const bool in = centroid(m, f).norm() <= 0.05;
    inside += in;
    EXPECT_EQ(s.triangle_params(f).scale, in ? 0.2 : 0.05);
    EXPECT_EQ(r.triangle_params(f).scale, 0.05);
  }
  EXPECT_GT(inside, 10);
}

TEST(HairStylerRegions, PartialOverrideKeepsTheOtherKeys) {
  const auto m = grid(4, 0.1);
  HairStylerParams p;
  p.defaults.curve = "wavy";
  p.defaults.jitter = 0.3;
  p.defaults.tangent = Vec3(1, 0, 0);
  p.defaults.angle_deg = 10;
  p.defaults.angle_variation_deg = 5;
  p.defaults.scale = 0.07;
  p.defaults.scale_variation = 0.2;
  p.defaults.density = 1e5;
  p.defaults.seed = 9;
  p.materials.push_back(HairMaterial{"grey", Vec3(0.5, 0.5, 0.5)});
  HairRegion r;
  r.density = 3e5;
  r.material = "grey";
  p.regions.push_back(r);
  const HairStyler s(m, p);
  for (std::size_t f = 0; f < m.faces.size(); ++f) {
    const auto q = s.triangle_params(f);
    EXPECT_EQ(q.density, 3e5);
    EXPECT_EQ(q.material, "grey");
    EXPECT_EQ(q.curve, "wavy");
    EXPECT_EQ(q.jitter, 0.3);
    EXPECT_EQ(q.tangent, Vec3(1, 0, 0));
    EXPECT_EQ(q.angle_deg, 10);
    EXPECT_EQ(q.angle_variation_deg, 5);
    EXPECT_EQ(q.scale, 0.07);
    EXPECT_EQ(q.scale_variation, 0.2);
    EXPECT_EQ(q.seed, 9u);
  }
  // The material index reaches the groom.
  p.defaults.density = 0;
  p.regions[0].density = 2e4;
  const Groom g = HairStyler(m, p).grow(Context(1));
  ASSERT_GT(g.num_strands(), 0u);
  for (uint16_t k : g.material) EXPECT_EQ(k, 1);
  EXPECT_EQ(g.strands.color.front(), Vec3f(0.5f, 0.5f, 0.5f));
}

TEST(HairStylerRegions, GeometricSelectorsSelectByCentroid) {
  const auto m = grid(12, 0.12);
  auto check = [&](HairRegion r, const std::function<bool(const Vec3&)>& expect) {
    const HairStyler s(m, only(r));
    int n = 0;
    for (std::size_t f = 0; f < m.faces.size(); ++f) {
      EXPECT_EQ(s.grows(f), expect(centroid(m, f))) << to_string(r.select) << " face " << f;
      n += s.grows(f);
    }
    EXPECT_GT(n, 0) << to_string(r.select);
    EXPECT_LT(n, int(m.faces.size())) << to_string(r.select);
    // invert selects the complement
    r.invert = true;
    const HairStyler t(m, only(r));
    for (std::size_t f = 0; f < m.faces.size(); ++f)
      EXPECT_EQ(t.grows(f), !expect(centroid(m, f))) << to_string(r.select) << " inverted";
  };
  HairRegion sphere;
  sphere.select = RegionSelect::Sphere;
  sphere.centre = Vec3(0.06, 0.0, 0.06);
  sphere.radius = 0.03;
  check(sphere, [](const Vec3& c) { return (c - Vec3(0.06, 0, 0.06)).norm() <= 0.03; });
  HairRegion box;
  box.select = RegionSelect::Box;
  box.min = Vec3(0.01, -1, 0.05);
  box.max = Vec3(0.04, 1, 0.11);
  check(box, [](const Vec3& c) {
    return c.x() >= 0.01 && c.x() <= 0.04 && c.z() >= 0.05 && c.z() <= 0.11;
  });
  HairRegion hs;
  hs.select = RegionSelect::HalfSpace;
  hs.point = Vec3(0.05, 0, 0.05);
  hs.normal = Vec3(1, 0, -2);
  check(hs, [](const Vec3& c) { return (c - Vec3(0.05, 0, 0.05)).dot(Vec3(1, 0, -2)) >= 0; });
}

TEST(HairStylerRegions, IndexFilesAndInlineIndices) {
  const auto m = grid(6, 0.06);
  const auto dir = test::scratch_dir("hairstyler_index");
  write_text(dir / "tris.txt", "# scalp triangles\n3, 5\n\n7 11 # trailing\n3\n");
  HairRegion r;
  r.select = RegionSelect::Triangles;
  r.triangles = "tris.txt";
  HairStylerParams p = only(r);
  const auto resolve = [&](const std::string& s) { return dir / s; };
  const HairStyler s(m, p, load_styler_inputs(p, resolve));
  const std::set<std::size_t> want{3, 5, 7, 11};
  for (std::size_t f = 0; f < m.faces.size(); ++f) EXPECT_EQ(s.grows(f), want.count(f) == 1);

  // Inline indices select the same.
  HairRegion ri;
  ri.select = RegionSelect::Triangles;
  ri.indices = std::vector<int64_t>{3, 5, 7, 11};
  const HairStyler si(m, only(ri));
  for (std::size_t f = 0; f < m.faces.size(); ++f) EXPECT_EQ(si.grows(f), want.count(f) == 1);

  // Vertices: the triangles whose three vertices are all listed. Vertices 0, 1, 8 and 7 are the
  // corners of the first quad of the 6x6 grid (ids i*7 + j): both its triangles.
  write_text(dir / "verts.txt", "0 1 8\n7\n");
  HairRegion rv;
  rv.select = RegionSelect::Vertices;
  rv.vertices = "verts.txt";
  HairStylerParams pv = only(rv);
  const HairStyler sv(m, pv, load_styler_inputs(pv, resolve));
  for (std::size_t f = 0; f < m.faces.size(); ++f) {
    const Vec3i& t = m.faces[f];
    const std::set<int> v{0, 1, 7, 8};
    const bool all = v.count(t[0]) && v.count(t[1]) && v.count(t[2]);
    EXPECT_EQ(sv.grows(f), all) << f;
  }
  EXPECT_TRUE(sv.grows(0));
  EXPECT_TRUE(sv.grows(1));
}

TEST(HairStylerRegions, MaskSelectsInTextureSpace) {
  const auto m = grid(10, 0.1);
  const auto dir = test::scratch_dir("hairstyler_mask");
  // Top half of the image white: v > 0.5 (OBJ convention, v up); an RGB image with a
  // left-to-right grey ramp in the bottom half below the threshold.
  image::ImageRGB8 img(64, 64);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x)
      for (int c = 0; c < 3; ++c) img.at(x, y, c) = y < 32 ? 255 : uint8_t(x);
  image::write_png(dir / "mask.png", img);
  HairRegion r;
  r.select = RegionSelect::Mask;
  r.mask = "mask.png";
  HairStylerParams p = only(r);
  const auto resolve = [&](const std::string& s) { return dir / s; };
  const HairStyler s(m, p, load_styler_inputs(p, resolve));
  int n = 0;
  for (std::size_t f = 0; f < m.faces.size(); ++f) {
    const double v = centroid(m, f).z() / 0.1;
    if (std::abs(v - 0.5) < 0.02) continue;
    EXPECT_EQ(s.grows(f), v > 0.5) << f;
    n += s.grows(f);
  }
  EXPECT_GT(n, 50);
  // The value can also weight the density.
  r.mask_scales_density = true;
  r.density = 1e6;
  HairStylerParams pd = only(r);
  const HairStyler sd(m, pd, load_styler_inputs(pd, resolve));
  for (std::size_t f = 0; f < m.faces.size(); ++f)
    if (centroid(m, f).z() / 0.1 > 0.55) {
      EXPECT_NEAR(sd.triangle_params(f).density, 1e6, 1e-6);
    }
}

TEST(HairStylerRegions, BadInputsFailNamingWhere) {
  const auto m = grid(4, 0.04);
  const auto nouv = grid(4, 0.04, false);
  const auto dir = test::scratch_dir("hairstyler_bad");
  const auto resolve = [&](const std::string& s) { return dir / s; };
  image::write_png(dir / "m.png", image::ImageGray8(8, 8, 255));

  // A mask on a mesh without UVs.
  HairRegion mask;
  mask.select = RegionSelect::Mask;
  mask.mask = "m.png";
  HairStylerParams pm = only(mask);
  const auto in = load_styler_inputs(pm, resolve);
  const std::string e1 = error_of([&] { HairStyler(nouv, pm, in); });
  EXPECT_NE(e1.find("regions[1].mask"), std::string::npos) << e1;
  EXPECT_NE(e1.find("texture coordinates"), std::string::npos) << e1;
  // A missing mask image.
  pm.regions[1].mask = "nope.png";
  const std::string e2 = error_of([&] { load_styler_inputs(pm, resolve); });
  EXPECT_NE(e2.find("regions[1].mask"), std::string::npos) << e2;
  EXPECT_NE(e2.find("nope.png"), std::string::npos) << e2;

  // A bad token in an index file: file:line.
  write_text(dir / "bad.txt", "1 2\n3\n4 x5 6\n");
  HairRegion tri;
  tri.select = RegionSelect::Triangles;
  tri.triangles = "bad.txt";
  HairStylerParams pt = only(tri);
  const std::string e3 = error_of([&] { load_styler_inputs(pt, resolve); });
  EXPECT_NE(e3.find("bad.txt:3"), std::string::npos) << e3;
  EXPECT_NE(e3.find("x5"), std::string::npos) << e3;
  EXPECT_NE(e3.find("regions[1].triangles"), std::string::npos) << e3;
  // Negative indices are bad tokens too.
  write_text(dir / "neg.txt", "1\n-2\n");
  pt.regions[1].triangles = "neg.txt";
  EXPECT_NE(error_of([&] { load_styler_inputs(pt, resolve); }).find("neg.txt:2"),
            std::string::npos);
  // An index out of range for the mesh: file:line and the mesh's size.
  write_text(dir / "range.txt", "1\n2\n\n32\n");
  pt.regions[1].triangles = "range.txt";
  const auto rin = load_styler_inputs(pt, resolve);
  const std::string e4 = error_of([&] { HairStyler(m, pt, rin); });
  EXPECT_NE(e4.find("range.txt:4"), std::string::npos) << e4;
  EXPECT_NE(e4.find("32 triangles"), std::string::npos) << e4;
  // A missing index file.
  pt.regions[1].triangles = "missing.txt";
  const std::string e5 = error_of([&] { load_styler_inputs(pt, resolve); });
  EXPECT_NE(e5.find("regions[1].triangles"), std::string::npos) << e5;
  EXPECT_NE(e5.find("missing.txt"), std::string::npos) << e5;
  // Inline vertex index out of range.
  HairRegion v;
  v.select = RegionSelect::Vertices;
  v.indices = std::vector<int64_t>{0, 25};
  const std::string e6 = error_of([&] { HairStyler(m, only(v)); });
  EXPECT_NE(e6.find("regions[1].indices[1]"), std::string::npos) << e6;
  // An index file region without loaded inputs.
  pt.regions[1].triangles = "range.txt";
  EXPECT_NE(error_of([&] { HairStyler(m, pt); }).find("load_styler_inputs"), std::string::npos);

  // Selector arguments: missing, or given to another kind.
  HairRegion s;
  s.select = RegionSelect::Sphere;
  s.centre = Vec3::Zero();
  EXPECT_NE(error_of([&] { only(s).validate(); }).find("needs \"radius\""), std::string::npos);
  s.radius = 0.1;
  s.normal = Vec3(0, 1, 0);
  const std::string e7 = error_of([&] { only(s).validate(); });
  EXPECT_NE(e7.find("regions[1].normal"), std::string::npos) << e7;
  EXPECT_NE(e7.find("half_space"), std::string::npos) << e7;
  // Unknown curve / material names, with a suggestion.
  HairRegion c;
  c.curve = "swep";
  const std::string e8 = error_of([&] { only(c).validate(); });
  EXPECT_NE(e8.find("regions[1].curve"), std::string::npos) << e8;
  EXPECT_NE(e8.find("did you mean \"swept\""), std::string::npos) << e8;
  HairRegion mt;
  mt.material = "blond";
  EXPECT_NE(error_of([&] { only(mt).validate(); }).find("regions[1].material"), std::string::npos);
  // Ranges of optional overrides.
  HairRegion j;
  j.jitter = 2.0;
  EXPECT_NE(error_of([&] { only(j).validate(); }).find("regions[1].jitter"), std::string::npos);
}

// ---- smooth parameters -----------------------------------------------------------------------

TEST(HairStylerSmooth, ParametersAreContinuousAcrossEveryEdge) {
  const auto& m = head();
  HairStylerParams p;
  p.defaults.density = 1e5;
  auto ball = [](Vec3 c, double r) {
    HairRegion g;
    g.select = RegionSelect::Sphere;
    g.centre = c;
    g.radius = r;
    return g;
  };
  HairRegion a = ball(Vec3(0.0, 0.15, 0.0), 0.08);
  a.scale = 0.3;
  a.jitter = 0.2;
  a.angle_deg = 40;
  a.density = 3e5;
  a.tangent = Vec3(0, 0, -1);
  HairRegion b = ball(Vec3(0.05, 0.1, 0.05), 0.05);
  b.scale_variation = 0.5;
  b.angle_variation_deg = 30;
  b.curve = "curl";
  b.density = 0;  // no hairs, the neighbours fade
  HairRegion c = ball(Vec3(-0.05, 0.1, 0.05), 0.04);
  c.exclude = true;
  p.regions = {a, b, c};
  const HairStyler s(m, p);
  const auto adj = geom::build_adjacency(m);
  Rng rng(7);
  int checked = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const std::size_t f = rng.below(uint32_t(m.faces.size()));
    const int e = int(rng.below(3));
    const int g = adj.face_neighbours[f][e];
    if (g < 0 || !s.grows(f) || !s.grows(std::size_t(g))) continue;
    const int va = m.faces[f][e], vb = m.faces[f][(e + 1) % 3];
    const double t = rng.uniform();
    Vec3 bf = Vec3::Zero(), bg = Vec3::Zero();
    bf[e] = 1 - t;
    bf[(e + 1) % 3] = t;
    for (int k = 0; k < 3; ++k) {
      if (m.faces[std::size_t(g)][k] == va) bg[k] = 1 - t;
      if (m.faces[std::size_t(g)][k] == vb) bg[k] = t;
    }
    ASSERT_NEAR(bg.sum(), 1.0, 1e-15);
    const auto x = s.params_at(f, bf), y = s.params_at(std::size_t(g), bg);
    EXPECT_NEAR(x.jitter, y.jitter, 1e-12);
    EXPECT_NEAR(x.angle_deg, y.angle_deg, 1e-10);
    EXPECT_NEAR(x.angle_variation_deg, y.angle_variation_deg, 1e-10);
    EXPECT_NEAR(x.scale, y.scale, 1e-12);
    EXPECT_NEAR(x.scale_variation, y.scale_variation, 1e-12);
    EXPECT_NEAR(x.density, y.density, 1e-6);
    EXPECT_LT((x.tangent - y.tangent).norm(), 1e-9);
    EXPECT_LT((s.normal_at(f, bf) - s.normal_at(std::size_t(g), bg)).norm(), 1e-12);
    EXPECT_NEAR(x.tangent.dot(s.normal_at(f, bf)), 0.0, 1e-12);
    ++checked;
  }
  EXPECT_GT(checked, 1000);
  // The regions did vary the parameters (the test is not trivially passing).
  double lo = 1e9, hi = 0;
  for (std::size_t f = 0; f < m.faces.size(); ++f)
    if (s.grows(f)) {
      const double sc = s.params_at(f, Vec3(1, 1, 1) / 3).scale;
      lo = std::min(lo, sc);
      hi = std::max(hi, sc);
    }
  EXPECT_NEAR(lo, 0.1, 1e-9);
  EXPECT_NEAR(hi, 0.3, 1e-9);
  // Without smoothing the parameters are the triangle's own.
  p.smooth = false;
  const HairStyler r(m, p);
  for (std::size_t f = 0; f < m.faces.size(); f += 97)
    EXPECT_EQ(r.params_at(f, Vec3(0.2, 0.3, 0.5)).scale, r.triangle_params(f).scale);
}

// ---- growing ---------------------------------------------------------------------------------

TEST(HairStylerGrow, CountIsDensityTimesAreaWithinStatistics) {
  const auto m = grid(20, 0.2);  // 0.04 m²
  HairStylerParams p;
  p.defaults.density = 2.5e5;  // 10,000 hairs expected
  p.points_per_hair = 5;
  const HairStyler s(m, p);
  EXPECT_NEAR(s.expected_total(), 2.5e5 * 0.04, 1e-6);
  double var = 0.0;
  for (std::size_t f = 0; f < m.faces.size(); ++f) {
    const double e = s.expected_hairs(f), fr = e - std::floor(e);
    var += fr * (1 - fr);
  }
  const Groom g = s.grow(Context(2));
  g.check("grid");
  EXPECT_LE(std::abs(double(g.num_strands()) - 1e4), 5.0 * std::sqrt(var) + 1.0);
  // Per face: stochastic rounding gives floor or ceil of the expectation.
  const auto counts = s.hair_counts(Context(1));
  for (std::size_t f = 0; f < m.faces.size(); ++f) {
    const double e = s.expected_hairs(f);
    EXPECT_TRUE(counts[f] == uint32_t(std::floor(e)) || counts[f] == uint32_t(std::ceil(e)));
  }
  // A low, non-integer expectation per face: the total follows the density statistically.
  p.defaults.density = 1.3e4;  // 0.65 per face
  const HairStyler low(m, p);
  double vlow = 0.0;
  for (std::size_t f = 0; f < m.faces.size(); ++f) {
    const double e = low.expected_hairs(f), fr = e - std::floor(e);
    vlow += fr * (1 - fr);
  }
  const Groom gl = low.grow(Context(1));
  EXPECT_LE(std::abs(double(gl.num_strands()) - 1.3e4 * 0.04), 5.0 * std::sqrt(vlow));
  // density_scale and the budget.
  p.defaults.density = 2.5e5;
  p.density_scale = 0.1;
  EXPECT_NEAR(HairStyler(m, p).expected_total(), 1e3, 1e-6);
  p.density_scale = 1.0;
  p.max_hairs = 5000;
  const std::string err = error_of([&] { HairStyler(m, p).grow(Context(1)); });
  EXPECT_NE(err.find("about 10000 hairs"), std::string::npos) << err;
  EXPECT_NE(err.find("max_hairs = 5000"), std::string::npos) << err;
}

TEST(HairStylerGrow, RootsLieUniformlyInEachTriangleAndJitterZeroIsALattice) {
  const auto m = grid(1, 1.0);  // two triangles of 0.5 m²
  HairStylerParams p;
  p.defaults.density = 4000;
  p.points_per_hair = 2;
  const Groom g = HairStyler(m, p).grow(Context(1));
  // Area-uniform: the mean of the barycentric weights is (1/3, 1/3, 1/3).
  Vec3 mean = Vec3::Zero();
  for (const auto& r : g.roots) mean += r.bary.cast<double>();
  mean /= double(g.roots.size());
  EXPECT_LT((mean - Vec3(1, 1, 1) / 3).norm(), 0.02);
  // jitter 0: the same lattice for every seed; jitter 1: not.
  p.defaults.jitter = 0.0;
  const Groom a = HairStyler(m, p).grow(Context(1));
  p.seed = 99;
  const Groom b = HairStyler(m, p).grow(Context(1));
  ASSERT_EQ(a.num_strands(), b.num_strands());
  for (std::size_t s = 0; s < a.num_strands(); ++s) EXPECT_EQ(a.roots[s].bary, b.roots[s].bary);
  p.defaults.jitter = 1.0;
  const Groom c = HairStyler(m, p).grow(Context(1));
  int same = 0;
  for (std::size_t s = 0; s < std::min(a.num_strands(), c.num_strands()); ++s)
    same += a.roots[s].bary == c.roots[s].bary;
  EXPECT_LT(same, 5);
}

TEST(HairStylerGrow, DeterministicForAnyThreadCount) {
  const auto& m = head();
  HairStylerParams p;
  p.defaults.density = 2e5;
  p.defaults.angle_variation_deg = 20;
  p.defaults.scale_variation = 0.3;
  HairRegion r;
  r.select = RegionSelect::HalfSpace;
  r.point = Vec3(0, 0.1, 0);
  r.normal = Vec3(0, 1, 0);
  r.curve = "curl";
  p.regions.push_back(r);
  const HairStyler s(m, p);
  const Groom a = s.grow(Context(1)), b = s.grow(Context(2)), c = s.grow(Context(3));
  ASSERT_GT(a.num_strands(), 10000u);
  for (const Groom* o : {&b, &c}) {
    EXPECT_EQ(a.strands.offsets, o->strands.offsets);
    EXPECT_EQ(a.strands.points, o->strands.points);
    EXPECT_EQ(a.material, o->material);
    ASSERT_EQ(a.roots.size(), o->roots.size());
    for (std::size_t i = 0; i < a.roots.size(); ++i) {
      EXPECT_EQ(a.roots[i].face, o->roots[i].face);
      EXPECT_EQ(a.roots[i].bary, o->roots[i].bary);
    }
  }
  p.seed = 2;
  const Groom d = HairStyler(m, p).grow(Context(2));
  EXPECT_NE(a.strands.points, d.strands.points);
}

TEST(HairStylerGrow, EditingOneTriangleLeavesTheOthersHairsAlone) {
  const auto& m = head();
  const auto adj = geom::build_adjacency(m);
  HairStylerParams p;
  p.defaults.density = 3e5;
  p.defaults.angle_variation_deg = 15;
  p.defaults.scale_variation = 0.2;
  // An edited triangle with plenty of hairs.
  HairStyler base(m, p);
  std::size_t f0 = 0;
  for (std::size_t f = 0; f < m.faces.size(); ++f)
    if (base.expected_hairs(f) > base.expected_hairs(f0)) f0 = f;
  std::set<std::size_t> ring;  // faces sharing a vertex with f0
  for (int k = 0; k < 3; ++k)
    for (uint32_t g : adj.vertex_faces(std::size_t(m.faces[f0][k]))) ring.insert(g);
  for (bool smooth : {false, true}) {
    p.smooth = smooth;
    p.regions.clear();
    const auto before = points_by_face(HairStyler(m, p).grow(Context(2)));
    HairRegion edit;
    edit.select = RegionSelect::Triangles;
    edit.indices = std::vector<int64_t>{int64_t(f0)};
    edit.scale = 0.25;
    edit.density = 6e5;
    edit.angle_deg = 90;
    p.regions = {edit};
    const auto after = points_by_face(HairStyler(m, p).grow(Context(2)));
    EXPECT_NE(before.at(int(f0)), after.at(int(f0)));
    std::size_t same = 0, changed_ring = 0;
    for (const auto& [f, pts] : before) {
      if (std::size_t(f) == f0) continue;
      const bool near = ring.count(std::size_t(f)) > 0;
      if (!smooth || !near) {
        ASSERT_TRUE(after.count(f));
        EXPECT_EQ(pts, after.at(f)) << "face " << f << " smooth " << smooth;
        ++same;
      } else {
        changed_ring += after.count(f) && pts != after.at(f);
      }
    }
    EXPECT_GT(same, 10000u);
    if (smooth) {
      EXPECT_GT(changed_ring, 0u);
    }  // smoothing reaches the one-ring only
    // A new seed redraws that triangle only (with smoothing too).
    edit = HairRegion{};
    edit.select = RegionSelect::Triangles;
    edit.indices = std::vector<int64_t>{int64_t(f0)};
    edit.seed = 12345;
    p.regions = {edit};
    const auto reseeded = points_by_face(HairStyler(m, p).grow(Context(1)));
    for (const auto& [f, pts] : before)
      if (std::size_t(f) != f0) {
        EXPECT_EQ(pts, reseeded.at(f));
      }
    EXPECT_NE(before.at(int(f0)), reseeded.at(int(f0)));
  }
}

TEST(HairStylerGrow, HairsLeaveTheSurfaceAndRootsMatchTheirBindings) {
  const auto& m = head();
  for (const char* curve : {"straight", "swept", "eyebrow", "fur", "curl", "beard", "wavy"}) {
    HairStylerParams p;
    p.defaults.curve = curve;
    p.defaults.density = 1e5;
    p.defaults.angle_variation_deg = 45;
    HairRegion r;  // a second curve in half the head: blended shapes at the border
    r.select = RegionSelect::HalfSpace;
    r.point = Vec3::Zero();
    r.normal = Vec3(1, 0, 0);
    r.curve = "eyebrow";
    p.regions.push_back(r);
    const Groom g = HairStyler(m, p).grow(Context(2));
    g.check(curve);
    ASSERT_GT(g.num_strands(), 1000u);
    const auto roots = bound_root_positions(g, m);
    const auto normals = bound_root_normals(g, m);
    double worst = 0;
    std::size_t inward = 0;
    for (std::size_t s = 0; s < g.num_strands(); ++s) {
      const uint32_t b = g.strands.offsets[s];
      worst = std::max(worst, (g.strands.points[b].cast<double>() - roots[s]).norm());
      const Vec3 d = (g.strands.points[b + 1] - g.strands.points[b]).cast<double>();
      inward += !(d.dot(normals[s]) > 0.0);
      EXPECT_NEAR(strand_length(g.strands, s) / 0.1, 1.0, 1e-4);
    }
    EXPECT_LT(worst, 1e-6) << curve;
    EXPECT_EQ(inward, 0u) << curve;
  }
}

TEST(HairStylerGrow, AngleRotatesAboutTheNormal) {
  const auto m = grid(4, 0.04);
  HairStylerParams p;
  p.defaults.curve = "eyebrow";
  p.defaults.tangent = Vec3(1, 0, 0);
  p.defaults.density = 1e5;
  p.defaults.angle_deg = 90;  // counter-clockwise seen from +y: +x -> -z
  p.points_per_hair = 4;
  const Groom g = HairStyler(m, p).grow(Context(1));
  ASSERT_GT(g.num_strands(), 50u);
  for (std::size_t s = 0; s < g.num_strands(); ++s) {
    const uint32_t b = g.strands.offsets[s];
    const Vec3 d = (g.strands.points[b + 3] - g.strands.points[b]).cast<double>();
    EXPECT_LT(d.z(), -0.09 * 0.1);
    EXPECT_NEAR(d.x(), 0.0, 1e-6);
  }
}

// ---- deformation -----------------------------------------------------------------------------

TEST(HairStylerDeform, TangentCorrectionIsPerpendicularToTheNewNormal) {
  Rng rng(3);
  for (int i = 0; i < 1000; ++i) {
    const Vec3 t(rng.normal(), rng.normal(), rng.normal());
    const Vec3 n = Vec3(rng.normal(), rng.normal(), rng.normal()).normalized();
    const Vec3 c = correct_tangent(t, n);
    EXPECT_NEAR(c.norm(), 1.0, 1e-12);
    EXPECT_NEAR(c.dot(n), 0.0, 1e-12);
    // It is t's projection: same direction within the new tangent plane.
    const Vec3 proj = t - t.dot(n) * n;
    EXPECT_LT((c - proj.normalized()).norm(), 1e-9);
  }
  // A tangent already perpendicular is kept; one along the normal gets some perpendicular.
  EXPECT_LT((correct_tangent(Vec3(2, 0, 0), Vec3(0, 1, 0)) - Vec3(1, 0, 0)).norm(), 1e-15);
  EXPECT_NEAR(correct_tangent(Vec3(0, 3, 0), Vec3(0, 1, 0)).dot(Vec3(0, 1, 0)), 0.0, 1e-15);
}

TEST(HairStylerDeform, GrowingOnADeformedMeshKeepsCountsAndFollowsTheSurface) {
  const auto& m = head();
  HairStylerParams p;
  p.defaults.density = 1e5;
  p.defaults.curve = "eyebrow";
  p.defaults.angle_variation_deg = 10;
  const HairStyler s(m, p);
  const Groom rest = s.grow(Context(2));

  // A bulge: the surface moves along its normals by a smooth amount (triangles change shape).
  geom::TriMesh def = m;
  for (std::size_t v = 0; v < def.positions.size(); ++v)
    def.positions[v] += 0.01 * std::sin(30.0 * m.positions[v].y()) * m.normals[v];
  def.compute_normals();
  for (bool transport : {true, false}) {
    p.transport_tangent = transport;
    const Groom g = HairStyler(m, p).grow(Context(2), def);
    // Same hairs: counts, bindings and lengths (no redraw: the drawing-order problem of §2).
    ASSERT_EQ(g.num_strands(), rest.num_strands());
    const auto roots = bound_root_positions(g, def);
    const auto normals = bound_root_normals(g, def);
    for (std::size_t i = 0; i < g.num_strands(); ++i) {
      ASSERT_EQ(g.roots[i].face, rest.roots[i].face);
      ASSERT_EQ(g.roots[i].bary, rest.roots[i].bary);
      const uint32_t b = g.strands.offsets[i];
      EXPECT_LT((g.strands.points[b].cast<double>() - roots[i]).norm(), 1e-6);
      // The eyebrow curve starts 20° above the tangent plane; the frame is orthonormal with the
      // deformed normal: the first segment's normal component is sin(~19°) of its length.
      const Vec3 d = (g.strands.points[b + 1] - g.strands.points[b]).cast<double>();
      EXPECT_NEAR(d.normalized().dot(normals[i]), std::sin(19.5 * kPi / 180.0), 0.01);
      EXPECT_NEAR(strand_length(g.strands, i), strand_length(rest.strands, i), 1e-6);
    }
  }
  // A rigid rotation of the mesh rotates the hairs (tangent carried with the triangles).
  p.transport_tangent = true;
  const Affine3 R(Eigen::AngleAxisd(0.7, Vec3(0.3, 1.0, -0.2).normalized()));
  geom::TriMesh rot = m;
  rot.transform(R);
  const Groom gr = HairStyler(m, p).grow(Context(1), rot);
  double worst = 0.0;
  for (std::size_t k = 0; k < gr.strands.points.size(); ++k)
    worst = std::max(
        worst,
        (gr.strands.points[k].cast<double>() - R * rest.strands.points[k].cast<double>()).norm());
  EXPECT_LT(worst, 1e-5);
  // Topology must match.
  geom::TriMesh other = grid(3, 0.1);
  EXPECT_THROW(s.grow(Context(1), other), Error);
}

// ---- presets ---------------------------------------------------------------------------------

TEST(HairStylerPresets, LandOnPlausiblePartsOfTheDefaultHead) {
  const auto& m = head();  // face towards +z, up +y: nose tip y ~ 0.05, mouth y ~ 0, brows ~ 0.1
  const HeadLandmarks L = head_landmarks(m);
  EXPECT_NEAR(L.nose_tip.y(), 0.05, 0.01);
  EXPECT_NEAR(L.nose_tip.z(), 0.12, 0.01);
  EXPECT_NEAR(L.top.y(), 0.185, 0.005);
  EXPECT_GT(L.left_ear.x(), 0.06);
  EXPECT_LT(L.right_ear.x(), -0.06);
  std::map<std::string, Groom> g;
  for (const auto& name : styler_preset_names()) {
    const HairStylerParams p = styler_preset(name, m);
    g[name] = HairStyler(m, p).grow(Context(2));
    g[name].check(name);
  }
  auto roots = [&](const std::string& n) { return bound_root_positions(g[n], m); };
  // Scalp: 100,000-150,000 hairs (§2); down to the nape at the back; in front of the ears above
  // the eyes (temples), on the forehead above the brows.
  EXPECT_GT(g["long"].num_strands(), 80000u);
  EXPECT_LT(g["long"].num_strands(), 160000u);
  for (const Vec3& r : roots("long")) {
    EXPECT_GT(r.y(), 0.0) << r.transpose();
    if (r.z() > 0.03) {
      EXPECT_GT(r.y(), 0.09) << r.transpose();
    }
    if (r.z() > 0.03 && std::abs(r.x()) < 0.045) {
      EXPECT_GT(r.y(), 0.13) << r.transpose();
    }
  }
  // Beard: below the ears' height (sideburns), on the face below the nose tip, near the midline
  // below the mouth, not behind the ears.
  EXPECT_GT(g["beard"].num_strands(), 3000u);
  for (const Vec3& r : roots("beard")) {
    EXPECT_LT(r.y(), 0.07) << r.transpose();
    if (r.z() > 0.06) {
      EXPECT_LT(r.y(), 0.045) << r.transpose();
    }
    if (std::abs(r.x()) < 0.02 && r.z() > 0.06) {
      EXPECT_LT(r.y(), 0.0) << r.transpose();
    }
    EXPECT_GT(r.z(), -0.03) << r.transpose();
  }
  // Moustache: upper lip between mouth and nose.
  EXPECT_GT(g["moustache"].num_strands(), 300u);
  for (const Vec3& r : roots("moustache")) {
    EXPECT_GT(r.y(), 0.0) << r.transpose();
    EXPECT_LT(r.y(), 0.045) << r.transpose();
    EXPECT_LT(std::abs(r.x()), 0.05) << r.transpose();
    EXPECT_GT(r.z(), 0.07) << r.transpose();
  }
  // Eyebrows: two brows above the eyes, below the forehead.
  std::size_t left = 0, right = 0;
  for (const Vec3& r : roots("eyebrows")) {
    EXPECT_GT(r.y(), 0.085) << r.transpose();
    EXPECT_LT(r.y(), 0.12) << r.transpose();
    EXPECT_GT(r.z(), 0.06) << r.transpose();
    EXPECT_GT(std::abs(r.x()), 0.005) << r.transpose();
    left += r.x() > 0;
    right += r.x() < 0;
  }
  EXPECT_GT(left, 200u);
  EXPECT_GT(right, 200u);
  EXPECT_NEAR(double(left) / double(right), 1.0, 0.3);
  // Beard and moustache hairs go down; fur covers the mesh.
  for (const char* n : {"beard", "moustache"}) {
    double down = 0;
    const Groom& b = g[n];
    for (std::size_t s = 0; s < b.num_strands(); ++s)
      down += b.strands.points[b.strands.offsets[s + 1] - 1].y() -
              b.strands.points[b.strands.offsets[s]].y();
    EXPECT_LT(down / double(b.num_strands()), 0.0) << n;
  }
  EXPECT_GT(g["fur"].num_strands(), 50000u);
  EXPECT_THROW(styler_preset("mohawk", m), Error);
}

TEST(HairStylerPresets, FollowTheGivenUpAndFrontDirections) {
  // The same head turned: the presets computed with the turned axes select the same triangles.
  const auto& m = head();
  const Affine3 R(Eigen::AngleAxisd(1.2, Vec3(1.0, 0.4, 0.1).normalized()));
  geom::TriMesh t = m;
  t.transform(R);
  for (const auto& name : styler_preset_names()) {
    const HairStyler a(m, styler_preset(name, m));
    const HairStyler b(
        t, styler_preset(name, t, R.linear() * Vec3::UnitY(), R.linear() * Vec3::UnitZ()));
    std::size_t differ = 0, grow = 0;
    for (std::size_t f = 0; f < m.faces.size(); ++f) {
      differ += a.grows(f) != b.grows(f);
      grow += a.grows(f);
    }
    EXPECT_LE(double(differ), 0.01 * double(grow) + 2) << name;
  }
}
