#include "follicle/geom/harmonic_map.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "follicle/geom/mesh_io.hpp"
#include "follicle/geom/projection.hpp"
#include "testing/testing.hpp"

using namespace follicle;
using namespace follicle::geom;

namespace {
// Jittered planar grid in the unit square (z = bump), boundary on the square.
TriMesh grid(int n, double bump, bool jitter = true) {
  TriMesh m;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      double x = double(i) / n, y = double(j) / n;
      if (jitter && i > 0 && i < n && j > 0 && j < n) {
        x += 0.2 / n * std::sin(7.0 * i + 3.0 * j);
        y += 0.2 / n * std::cos(5.0 * i - 2.0 * j);
      }
      m.positions.emplace_back(x, y, bump * std::sin(kPi * x) * std::sin(kPi * y));
    }
  auto id = [&](int i, int j) { return j * (n + 1) + i; };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      m.faces.emplace_back(id(i, j), id(i + 1, j), id(i + 1, j + 1));
      m.faces.emplace_back(id(i, j), id(i + 1, j + 1), id(i, j + 1));
    }
  return m;
}
}  // namespace

TEST(HarmonicInterpolate, ReproducesLinearFunctionsOnFlatMesh) {
  // Right-angled grid triangles: no negative cotangent weights to clamp, so linear precision holds
  // up to the tiny weight floor.
  const TriMesh m = grid(20, 0.0, false);
  std::vector<int> fixed;
  const auto loops = boundary_loops(m);
  for (int v : loops.front()) fixed.push_back(v);
  Eigen::MatrixXd vals(Eigen::Index(fixed.size()), 3);
  for (std::size_t k = 0; k < fixed.size(); ++k) {
    const Vec3& p = m.positions[std::size_t(fixed[k])];
    vals.row(Eigen::Index(k)) << 2 * p.x() - p.y() + 1, 3.0, p.x() + p.y();
  }
  const Eigen::MatrixXd x = harmonic_interpolate(m, fixed, vals);
  ASSERT_EQ(x.rows(), Eigen::Index(m.positions.size()));
  for (std::size_t v = 0; v < m.positions.size(); ++v) {
    const Vec3& p = m.positions[v];
    EXPECT_NEAR(x(Eigen::Index(v), 0), 2 * p.x() - p.y() + 1,
                1e-6);  // cotan weights: linear precision
    EXPECT_NEAR(x(Eigen::Index(v), 1), 3.0, 1e-12);
    EXPECT_NEAR(x(Eigen::Index(v), 2), p.x() + p.y(), 1e-6);
  }
  for (std::size_t k = 0; k < fixed.size(); ++k)
    EXPECT_EQ(x(fixed[k], 0), vals(Eigen::Index(k), 0));
}

TEST(HarmonicInterpolate, BadInputsFailCleanly) {
  const TriMesh m = grid(4, 0.0);
  Eigen::MatrixXd v(1, 2);
  v << 1, 2;
  EXPECT_THROW(harmonic_interpolate(m, {999}, v), Error);
  EXPECT_THROW(harmonic_interpolate(m, {0, 1}, v), Error);
  Eigen::MatrixXd two(2, 1);
  two << 1, 2;
  EXPECT_THROW(harmonic_interpolate(m, {3, 3}, two), Error);
  v(0, 0) = std::nan("");
  EXPECT_THROW(harmonic_interpolate(m, {0}, v), Error);
}

TEST(HarmonicMap, BumpyDiskNoFlipsAndLessDistortion) {
  const TriMesh m = grid(30, 0.6);
  PlanarProjection pp;
  pp.u_axis = Vec3(1, 0, 0);
  pp.v_axis = Vec3(0, 1, 0);
  HarmonicMapParams hp;
  HarmonicMapReport rep;
  const auto uv = harmonic_parameterize(m, project_planar(m.positions, pp), hp, &rep);
  EXPECT_EQ(rep.after.flipped, 0);
  EXPECT_EQ(rep.after.degenerate, 0);
  EXPECT_LT(rep.after.stretch_mean, rep.before.stretch_mean);
  for (const auto& t : uv) {
    EXPECT_GE(t.x(), -1e-12);
    EXPECT_LE(t.x(), 1 + 1e-12);
  }
}

TEST(HarmonicMap, ConcaveBoundaryIsRelaxed) {
  // An L-shaped (concave) region of a bumpy grid.
  TriMesh g = grid(20, 0.3), m;
  m.positions = g.positions;
  for (const auto& f : g.faces) {
    const Vec3 c = (g.positions[std::size_t(f[0])] + g.positions[std::size_t(f[1])] +
                    g.positions[std::size_t(f[2])]) /
                   3;
    if (!(c.x() > 0.5 && c.y() > 0.5)) m.faces.push_back(f);
  }
  PlanarProjection pp;
  HarmonicMapReport rep;
  harmonic_parameterize(m, project_planar(m.positions, pp), HarmonicMapParams{}, &rep);
  EXPECT_GT(rep.relaxed_vertices, 0);
  EXPECT_EQ(rep.after.flipped, 0);
}

TEST(HarmonicMap, KeepsOwnOneToOneUvs) {
  TriMesh m = grid(6, 0.1);
  std::vector<Vec2> own;
  for (const auto& p : m.positions) own.emplace_back(p.x(), p.y());
  assign_uvs(m, own, false);
  const auto rep = make_texture_space(m, own, HarmonicMapParams{});
  EXPECT_TRUE(rep.kept_own_uvs);
  // A folded UV set is replaced.
  TriMesh f = m;
  f.uvs[7] = Vec2(5, 5);
  const auto rep2 = make_texture_space(f, own, HarmonicMapParams{});
  EXPECT_FALSE(rep2.kept_own_uvs);
  EXPECT_EQ(rep2.after.flipped, 0);
}

namespace {
// The face of a head: faces whose vertices all lie in front (z > zcut) and above the chin.
TriMesh front_region(const TriMesh& head, double zcut, double ymin) {
  TriMesh out;
  std::vector<int> map(head.positions.size(), -1);
  for (const auto& f : head.faces) {
    bool keep = true;
    for (int k = 0; k < 3; ++k) {
      const Vec3& p = head.positions[std::size_t(f[k])];
      keep = keep && p.z() > zcut && p.y() > ymin;
    }
    if (!keep) continue;
    Vec3i g;
    for (int k = 0; k < 3; ++k) {
      int& id = map[std::size_t(f[k])];
      if (id < 0) {
        id = int(out.positions.size());
        out.positions.push_back(head.positions[std::size_t(f[k])]);
      }
      g[k] = id;
    }
    out.faces.push_back(g);
  }
  return out;
}
}  // namespace

TEST(HarmonicMap, DefaultHeadFaceHasNoFlips) {
  const auto path = test::source_dir() / "data/meshes/lee_perry_smith/head.obj";
  const TriMesh head = load_mesh(path, LengthUnit::mm);
  const TriMesh face = front_region(head, 0.04, -0.03);
  ASSERT_GT(face.faces.size(), 1000u);
  CylindricalProjection cp;
  cp.origin = Vec3(0, 0, 0);
  cp.height_scale = 0.2;
  HarmonicMapParams hp;
  hp.circle_boundary = true;  // convex boundary: Tutte guarantees an embedding
  HarmonicMapReport rep;
  harmonic_parameterize(face, project_cylindrical(face.positions, cp), hp, &rep);
  EXPECT_EQ(rep.after.flipped, 0);
  HarmonicMapReport rep2;
  harmonic_parameterize(face, project_cylindrical(face.positions, cp), HarmonicMapParams{}, &rep2);
  EXPECT_EQ(rep2.after.flipped, 0);  // projected + relaxed boundary
}

TEST(HarmonicMap, IctFaceHasNoFlips) {
  FOLLICLE_REQUIRE_SHARED("ict-facekit/generic_neutral_mesh.obj");
  const TriMesh head =
      load_mesh(test::shared_data_dir() / "ict-facekit/generic_neutral_mesh.obj", LengthUnit::cm);
  const auto bb = head.bounds();
  // Front part of the face.
  const TriMesh face = front_region(head, bb.center().z() + 0.25 * bb.sizes().z(),
                                    bb.min().y() + 0.2 * bb.sizes().y());
  ASSERT_GT(face.faces.size(), 500u);
  HarmonicMapParams hp;
  hp.circle_boundary = true;
  HarmonicMapReport rep;
  CylindricalProjection cp;
  cp.origin = bb.center();
  cp.height_scale = bb.sizes().y();
  harmonic_parameterize(face, project_cylindrical(face.positions, cp), hp, &rep);
  EXPECT_EQ(rep.after.flipped, 0);
}
