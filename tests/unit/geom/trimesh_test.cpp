// TriMesh, StrandSet, ParticleSet and adjacency.
#include "follicle/geom/trimesh.hpp"

#include <gtest/gtest.h>

#include "follicle/core/error.hpp"
#include "follicle/geom/adjacency.hpp"
#include "follicle/geom/strands.hpp"

using namespace follicle;
using namespace follicle::geom;

namespace {
// n x n grid of unit squares in the z = 0 plane, 2 triangles each, normals +z.
TriMesh make_grid(int n, double size = 1.0) {
  TriMesh m;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) m.positions.emplace_back(size * i / n, size * j / n, 0);
  auto id = [&](int i, int j) { return j * (n + 1) + i; };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      m.faces.emplace_back(id(i, j), id(i + 1, j), id(i + 1, j + 1));
      m.faces.emplace_back(id(i, j), id(i + 1, j + 1), id(i, j + 1));
    }
  return m;
}
}  // namespace

TEST(TriMesh, NormalsAreaBoundsOfPlane) {
  TriMesh m = make_grid(4, 2.0);
  m.compute_normals();
  for (const Vec3& n : m.normals) EXPECT_NEAR((n - Vec3(0, 0, 1)).norm(), 0, 1e-12);
  double area = 0;
  for (std::size_t f = 0; f < m.num_faces(); ++f) area += m.face_area(f);
  EXPECT_NEAR(area, 4.0, 1e-12);
  EXPECT_EQ(m.face_normal(0), Vec3(0, 0, 1));
  EXPECT_EQ(m.bounds().min(), Vec3(0, 0, 0));
  EXPECT_EQ(m.bounds().max(), Vec3(2, 2, 0));
}

TEST(TriMesh, TransformRotatesNormalsAndMirrorKeepsOrientation) {
  TriMesh m = make_grid(2);
  m.compute_normals();
  Affine3 rot = Affine3::Identity();
  rot.rotate(Eigen::AngleAxisd(kPi / 2, Vec3::UnitX()));
  m.transform(rot);
  EXPECT_NEAR((m.normals[0] - Vec3(0, -1, 0)).norm(), 0, 1e-12);
  TriMesh mirrored = make_grid(2);
  mirrored.compute_normals();
  Affine3 mir = Affine3::Identity();
  mir.scale(Vec3(1, 1, -1));
  mirrored.transform(mir);
  // z-mirror of a z=0 plane keeps positions; orientation is flipped back so normals agree.
  mirrored.compute_normals();
  EXPECT_NEAR(mirrored.face_normal(0).z(), -1.0, 1e-12);
  m = make_grid(2);
  m.scale(0.001);
  EXPECT_NEAR(m.bounds().sizes().x(), 0.001, 1e-15);
}

TEST(TriMesh, CheckRejectsBadData) {
  TriMesh m = make_grid(1);
  EXPECT_NO_THROW(m.check("grid"));
  TriMesh bad = m;
  bad.faces[0][2] = 99;
  EXPECT_THROW(bad.check("grid"), Error);
  bad = m;
  bad.positions[1].x() = std::nan("");
  EXPECT_THROW(bad.check("grid"), Error);
  bad = m;
  bad.uvs = {Vec2(0, 0)};
  EXPECT_THROW(bad.check("grid"), Error);  // uv_faces missing
  try {
    bad.check("where.obj");
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("where.obj"), std::string::npos);
  }
}

TEST(Strands, AddStrandAndCheck) {
  StrandSet s;
  s.add_strand({Vec3f(0, 0, 0), Vec3f(0, 0, 1)});
  s.radius.assign(2, 1e-4f);
  s.add_strand({Vec3f(1, 0, 0), Vec3f(1, 0, 1), Vec3f(1, 0, 2)});
  EXPECT_EQ(s.num_strands(), 2u);
  EXPECT_EQ(s.strand_begin(1), 2u);
  EXPECT_EQ(s.strand_size(1), 3u);
  EXPECT_EQ(s.radius.size(), 5u);
  EXPECT_TRUE(s.color.empty());
  EXPECT_NO_THROW(s.check("s"));
  s.points[3].y() = std::numeric_limits<float>::infinity();
  EXPECT_THROW(s.check("s"), Error);
  s.points[3].y() = 0;
  s.offsets[1] = 9;
  EXPECT_THROW(s.check("s"), Error);
  ParticleSet p;
  p.positions = {Vec3f(0, 0, 0), Vec3f(1, 1, 1)};
  p.radius = {0.1f, 0.2f};
  EXPECT_NO_THROW(p.check("p"));
  p.opacity = {0.5f};
  EXPECT_THROW(p.check("p"), Error);
}

TEST(Adjacency, GridOneRingsFaceNeighboursAndBoundary) {
  const int n = 3;
  const TriMesh m = make_grid(n);
  const MeshAdjacency a = build_adjacency(m);
  // Interior vertex (1,1) = index 5: 6 neighbours and 6 faces in this triangulation.
  EXPECT_EQ(a.vertex_neighbours(5).size(), 6u);
  EXPECT_EQ(a.vertex_faces(5).size(), 6u);
  // Corner 0 touches 1 face... two faces share the diagonal at (0,0).
  EXPECT_EQ(a.vertex_faces(0).size(), 2u);
  EXPECT_TRUE(std::is_sorted(a.vertex_neighbours(5).begin(), a.vertex_neighbours(5).end()));
  // Face neighbours are symmetric.
  for (std::size_t f = 0; f < m.num_faces(); ++f)
    for (int e = 0; e < 3; ++e) {
      const int g = a.face_neighbours[f][e];
      if (g < 0) continue;
      const Vec3i& nb = a.face_neighbours[std::size_t(g)];
      EXPECT_TRUE(nb[0] == int(f) || nb[1] == int(f) || nb[2] == int(f));
    }
  // Boundary: 4n edges in one loop of 4n vertices.
  EXPECT_EQ(a.boundary_edges.size(), std::size_t(4 * n));
  ASSERT_EQ(a.boundary_loops.size(), 1u);
  EXPECT_EQ(a.boundary_loops[0].size(), std::size_t(4 * n));
  EXPECT_TRUE(a.is_boundary_vertex(0));
  EXPECT_FALSE(a.is_boundary_vertex(5));
  EXPECT_EQ(a.nonmanifold_edges, 0u);
  // Euler: V - E + F = 1 for a disc.
  const std::size_t edges = a.vv_index.size() / 2;
  EXPECT_EQ(int(m.num_vertices()) - int(edges) + int(m.num_faces()), 1);
}

TEST(Adjacency, ClosedTetrahedronHasNoBoundary) {
  TriMesh t;
  t.positions = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
  t.faces = {Vec3i(0, 2, 1), Vec3i(0, 1, 3), Vec3i(1, 2, 3), Vec3i(0, 3, 2)};
  const MeshAdjacency a = build_adjacency(t);
  EXPECT_TRUE(a.boundary_edges.empty());
  EXPECT_TRUE(a.boundary_loops.empty());
  for (const Vec3i& fn : a.face_neighbours)
    for (int e = 0; e < 3; ++e) EXPECT_GE(fn[e], 0);
  for (std::size_t v = 0; v < 4; ++v) EXPECT_EQ(a.vertex_neighbours(v).size(), 3u);
}
