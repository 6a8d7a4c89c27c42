#include <gtest/gtest.h>

#include <cmath>

#include "follicle/core/error.hpp"
#include "follicle/geom/mesh_io.hpp"
#include "follicle/geom/texture_mapping_bando2002.hpp"
#include "testing/testing.hpp"

using namespace follicle;
using namespace follicle::geom;

namespace {

// Latitude-longitude sphere (closed), counter-clockwise seen from outside.
TriMesh sphere(int nu, int nv, double r, const Vec3& c = Vec3::Zero()) {
  TriMesh m;
  m.positions.push_back(c + Vec3(0, r, 0));
  for (int j = 1; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const double th = kPi * j / nv, ph = 2 * kPi * i / nu;
      m.positions.push_back(
          c + r * Vec3(std::sin(th) * std::sin(ph), std::cos(th), std::sin(th) * std::cos(ph)));
    }
  const int south = int(m.positions.size());
  m.positions.push_back(c + Vec3(0, -r, 0));
  auto id = [&](int i, int j) { return 1 + (j - 1) * nu + (i % nu); };
  for (int i = 0; i < nu; ++i) m.faces.emplace_back(0, id(i, 1), id(i + 1, 1));
  for (int j = 1; j < nv - 1; ++j)
    for (int i = 0; i < nu; ++i) {
      m.faces.emplace_back(id(i, j), id(i, j + 1), id(i + 1, j + 1));
      m.faces.emplace_back(id(i, j), id(i + 1, j + 1), id(i + 1, j));
    }
  for (int i = 0; i < nu; ++i) m.faces.emplace_back(south, id(i + 1, nv - 1), id(i, nv - 1));
  return m;
}

// A flat face mask facing +z: a disk with two eye holes.
TriMesh mask(int n) {
  TriMesh m;
  std::vector<int> index((n + 1) * (n + 1), -1);
  auto inside = [](double x, double y) {
    const bool eye = std::hypot(x - 0.3, y - 0.6) < 0.12 || std::hypot(x - 0.7, y - 0.6) < 0.12;
    return std::hypot(x - 0.5, y - 0.5) < 0.5 && !eye;
  };
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      index[std::size_t(j * (n + 1) + i)] = int(m.positions.size());
      m.positions.emplace_back(0.2 * i / n, 0.2 * j / n, 0.0);
    }
  auto id = [&](int i, int j) { return index[std::size_t(j * (n + 1) + i)]; };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      if (!inside((i + 0.5) / n, (j + 0.5) / n)) continue;
      m.faces.emplace_back(id(i, j), id(i + 1, j), id(i + 1, j + 1));
      m.faces.emplace_back(id(i, j), id(i + 1, j + 1), id(i, j + 1));
    }
  return m;
}

void expect_in_unit_square(const TriMesh& m) {
  for (const auto& t : m.uvs) {
    EXPECT_GE(t.x(), -1e-9);
    EXPECT_LE(t.x(), 1 + 1e-9);
    EXPECT_GE(t.y(), -1e-9);
    EXPECT_LE(t.y(), 1 + 1e-9);
  }
}

TriMesh strip_uvs(TriMesh m) {
  m.uvs.clear();
  m.uv_faces.clear();
  return m;
}

}  // namespace

TEST(TextureMapping, ClosedSphereIsCutCylindricallyWithoutFolds) {
  const TriMesh s = sphere(48, 24, 0.1);
  TextureMappingReport rep;
  const TriMesh m = map_to_texture_space(s, {}, &rep);
  EXPECT_EQ(rep.charts, 1);
  EXPECT_EQ(rep.cylindrical_charts, 1);
  EXPECT_EQ(rep.flipped, 0);
  EXPECT_EQ(rep.degenerate, 0);
  EXPECT_EQ(count_uv_folds(m).flipped, 0);
  ASSERT_EQ(m.uv_faces.size(), s.faces.size());
  EXPECT_GT(m.uvs.size(), s.positions.size());  // split along the seam
  EXPECT_EQ(m.positions, s.positions);
  expect_in_unit_square(m);
}

TEST(TextureMapping, FlatMaskKeepsItsShapeAndHoles) {
  // A flat part maps by planar projection; the harmonic map of a flat mesh with its projected
  // boundary fixed is the projection itself (linear precision), so the stretch stays ~1.
  // Without boundary relaxation: the staircase rim of this grid mask is concave everywhere.
  const TriMesh s = mask(40);
  TextureMappingParams p;
  p.relax_iterations = 0;
  TextureMappingReport rep;
  const TriMesh m = map_to_texture_space(s, p, &rep);
  EXPECT_EQ(rep.planar_charts, 1);
  EXPECT_EQ(rep.flipped, 0);
  // Close to the projection (the holes' virtual fans clamp a few obtuse weights, so linear
  // precision is not exact): under 1 % of the area stretched beyond 4:1.
  EXPECT_LT(rep.stretch_mean, 1.6);
  EXPECT_LT(rep.stretched_area, 0.01);
  EXPECT_NEAR(rep.metres_per_unit, 0.2, 0.02);
  // u grows to the right (+x), v up (+y) seen from the front.
  const auto& f = s.faces[0];
  const auto& t = m.uv_faces[0];
  const Vec3 d3 = s.positions[std::size_t(f[1])] - s.positions[std::size_t(f[0])];
  const Vec2 d2 = m.uvs[std::size_t(t[1])] - m.uvs[std::size_t(t[0])];
  EXPECT_GT(d3.x() * d2.x(), 0);
}

TEST(TextureMapping, PartsBecomeSeparateChartsThatDoNotOverlap) {
  TriMesh a = sphere(32, 16, 0.1), b = sphere(16, 8, 0.02, Vec3(0.3, 0, 0));
  const int off = int(a.positions.size());
  for (const auto& p : b.positions) a.positions.push_back(p);
  for (const auto& f : b.faces) a.faces.push_back(f + Vec3i::Constant(off));
  TextureMappingReport rep;
  const TriMesh m = map_to_texture_space(a, {}, &rep);
  EXPECT_EQ(rep.charts, 2);
  EXPECT_EQ(rep.flipped, 0);
  Eigen::AlignedBox2d big, small;
  for (std::size_t f = 0; f < m.faces.size(); ++f)
    for (int c = 0; c < 3; ++c)
      (m.faces[f][c] < off ? big : small).extend(m.uvs[std::size_t(m.uv_faces[f][c])]);
  EXPECT_FALSE(big.intersects(small));
  // One texel density: the small sphere's chart is about (0.02 / 0.1)^2 of the big one's area.
  EXPECT_LT(small.volume(), 0.1 * big.volume());
  expect_in_unit_square(m);
}

TEST(TextureMapping, ProjectionAloneAndBadInput) {
  const TriMesh s = sphere(24, 12, 0.1);
  TextureMappingParams p;
  p.method = MappingMethod::Uv;
  EXPECT_THROW(map_to_texture_space(s, p), Error);
  p.method = MappingMethod::Cylindrical;
  p.front = Vec3(0, 1, 0);
  EXPECT_THROW(map_to_texture_space(s, p), Error);
  p.front = Vec3::UnitZ();
  p.harmonic = false;
  TextureMappingReport rep;
  const TriMesh m = map_to_texture_space(s, p, &rep);
  EXPECT_EQ(rep.cylindrical_charts, 1);
  EXPECT_EQ(m.uv_faces.size(), s.faces.size());
  EXPECT_THROW(map_to_texture_space(TriMesh{}, {}), Error);
}

TEST(TextureMapping, MeshWithUvsKeepsThemUnderAuto) {
  const TriMesh head =
      load_mesh(test::source_dir() / "data/meshes/lee_perry_smith/head.obj", LengthUnit::mm);
  TextureMappingReport rep;
  const TriMesh m = map_to_texture_space(head, {}, &rep);
  EXPECT_EQ(rep.method, MappingMethod::Uv);
  EXPECT_EQ(m.uvs, head.uvs);
}

// The bundled head without its UVs, as a scan would come: one chart, no folds, in any rigid
// orientation and mirrored when up and front say where the head looks.
TEST(TextureMapping, HeadScanWithoutUvsInAnyOrientation) {
  const TriMesh head = strip_uvs(
      load_mesh(test::source_dir() / "data/meshes/lee_perry_smith/head.obj", LengthUnit::mm));
  const Eigen::AngleAxisd rot(1.1, Vec3(0.3, 0.8, -0.5).normalized());
  for (int variant = 0; variant < 3; ++variant) {
    TriMesh m = head;
    TextureMappingParams p;
    if (variant == 1) {
      for (auto& x : m.positions) x = rot * x;
      p.up = rot * Vec3::UnitY();
      p.front = rot * Vec3::UnitZ();
    } else if (variant == 2) {  // mirrored (x -> -x), faces reversed to stay outward
      for (auto& x : m.positions) x.x() = -x.x();
      for (auto& f : m.faces) std::swap(f[1], f[2]);
    }
    TextureMappingReport rep;
    const TriMesh out = map_to_texture_space(m, p, &rep);
    SCOPED_TRACE(variant);
    EXPECT_EQ(rep.cylindrical_charts, 1) << rep.summary();
    EXPECT_EQ(rep.flipped, 0) << rep.summary();
    // The cylinder's crushed crown (the circle fallback) leaves at most a few zero-area slivers.
    EXPECT_LE(rep.degenerate, 3) << rep.summary();
    EXPECT_LT(rep.stretched_area, 0.05) << rep.summary();
    expect_in_unit_square(out);
    // Upright: the chin (lowest point along up) lies below the forehead's top in v.
    const Vec3 upv = p.up.normalized();
    std::size_t lo = 0, hi = 0;
    for (std::size_t v = 0; v < m.positions.size(); ++v) {
      const Vec3 d = m.positions[v];
      if (d.dot(upv) < m.positions[lo].dot(upv)) lo = v;
      if (d.dot(upv) > m.positions[hi].dot(upv)) hi = v;
    }
    auto uv_of = [&](std::size_t v) {
      for (std::size_t f = 0; f < out.faces.size(); ++f)
        for (int c = 0; c < 3; ++c)
          if (std::size_t(out.faces[f][c]) == v) return out.uvs[std::size_t(out.uv_faces[f][c])];
      return Vec2(0, 0);
    };
    EXPECT_LT(uv_of(lo).y(), uv_of(hi).y());
  }
}

TEST(TextureMapping, SintelBustHasNoUvsAndMapsWithoutFolds) {
  const TriMesh m = load_mesh(test::source_dir() / "data/meshes/sintel/sintel.obj", LengthUnit::m);
  ASSERT_FALSE(m.has_uvs());
  TextureMappingReport rep;
  const TriMesh out = map_to_texture_space(m, {}, &rep);
  EXPECT_EQ(rep.flipped, 0) << rep.summary();
  EXPECT_EQ(rep.degenerate, 0) << rep.summary();
  expect_in_unit_square(out);
}

// Held-out heads from ../shared/data, their own UVs dropped.
TEST(TextureMapping, SharedHeadsWithoutUvsMapWithoutFolds) {
  struct Case {
    const char* path;
    LengthUnit unit;
  };
  for (const Case c : {Case{"ict-facekit/generic_neutral_mesh.obj", LengthUnit::cm},
                       Case{"mediapipe-face/canonical_face_model.obj", LengthUnit::cm},
                       Case{"makehuman-base/base.obj", LengthUnit::dm}}) {
    const auto dir = test::shared_data_dir();
    if (dir.empty() || !std::filesystem::exists(dir / c.path)) GTEST_SKIP() << c.path;
    const TriMesh m = strip_uvs(load_mesh(dir / c.path, c.unit));
    TextureMappingReport rep;
    const TriMesh out = map_to_texture_space(m, {}, &rep);
    SCOPED_TRACE(c.path);
    // Known limit: ICT's many small parts (eyes, teeth, lashes: 56 charts) leave 12 of 26k
    // triangles folded (0.05 %); the face chart itself is fold-free. Bound it, do not hide it.
    EXPECT_LE(rep.flipped, int(m.faces.size() / 1000)) << rep.summary();
    expect_in_unit_square(out);
  }
}
