// render::PreviewReducer (issue 25 item 2): the scene an interactive view draws while moving.
#include "follicle/render/preview_scene.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <utility>

#include "follicle/core/error.hpp"

using namespace follicle;
using namespace follicle::render;

namespace {
std::shared_ptr<const geom::StrandSet> strands(int n, int pts) {
  auto s = std::make_shared<geom::StrandSet>();
  for (int i = 0; i < n; ++i) {
    for (int k = 0; k < pts; ++k) {
      s->points.push_back(Vec3f(float(i), float(k), 0));
      s->color.push_back(Vec3f(float(i) / n, 0, 0));
    }
    s->offsets.push_back(uint32_t(s->points.size()));
  }
  return s;
}
}  // namespace

TEST(PreviewScene, EveryKthStrandKeepsWholeStrandsWithTheirColours) {
  const auto s = strands(10, 4);
  const geom::StrandSet r = every_kth_strand(*s, 3);  // strands 0, 3, 6, 9
  ASSERT_EQ(r.num_strands(), 4u);
  EXPECT_NO_THROW(r.check("reduced"));
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(r.strand_size(i), 4u);
    EXPECT_EQ(r.points[r.offsets[i]].x(), float(3 * i));
    EXPECT_EQ(r.color[r.offsets[i]].x(), float(3 * i) / 10);
  }
  EXPECT_EQ(every_kth_strand(*s, 1).points, s->points);
}

TEST(PreviewScene, EveryMthPointKeepsTheRootAndTheTip) {
  const auto s = strands(4, 11);
  const geom::StrandSet r = every_kth_strand(*s, 2, 3);  // strands 0, 2; points 0 3 6 9 10
  ASSERT_EQ(r.num_strands(), 2u);
  EXPECT_NO_THROW(r.check("reduced"));
  for (std::size_t i = 0; i < 2; ++i) {
    ASSERT_EQ(r.strand_size(i), 5u);
    const uint32_t b = r.offsets[i];
    EXPECT_EQ(r.points[b].y(), 0.0f);       // root
    EXPECT_EQ(r.points[b + 3].y(), 9.0f);   // every third
    EXPECT_EQ(r.points[b + 4].y(), 10.0f);  // tip
    EXPECT_EQ(r.color[b].x(), float(2 * i) / 4);
  }
  // The tip is not repeated when the stride lands on it.
  EXPECT_EQ(every_kth_strand(*strands(1, 10), 1, 3).points.size(), 4u);  // 0 3 6 9
}

TEST(PreviewScene, ReduceCapsThePointsDrawnAlongLongStrands) {
  RenderScene rs;
  StrandItem si;
  si.strands = strands(5000, 40);  // 200,000 points in few strands
  rs.strands.push_back(si);
  RenderSettings s;
  PreviewParams p;
  PreviewReducer red;
  red.reduce(rs, s, p);
  const auto& r = *rs.strands[0].strands;
  EXPECT_EQ(r.num_strands(), 5000u);  // under max_strands: all strands stay
  EXPECT_LE(r.points.size(), std::size_t(p.max_points) + r.num_strands());  // + the tips
  EXPECT_GE(r.points.size(), std::size_t(p.max_points) / 2);
  EXPECT_EQ(r.points[r.offsets[1] - 1].y(), 39.0f);  // the tip stays
}

TEST(PreviewScene, AnEmptyStrandSetKeepsItsWidth) {
  // An item without strands is left as it is: same set, same width (the strides are at least 1;
  // before the review they relied on an unsigned wrap-around to come out 0 here).
  RenderScene rs;
  StrandItem si;
  si.strands = std::make_shared<geom::StrandSet>();
  si.material.width_px = 1.5;
  rs.strands.push_back(si);
  RenderSettings s;
  PreviewReducer red;
  red.reduce(rs, s, PreviewParams{});
  EXPECT_EQ(rs.strands[0].material.width_px, 1.5);
  EXPECT_EQ(rs.strands[0].strands.get(), si.strands.get());
}

TEST(PreviewScene, ReduceCapsStrandsAndParticlesAndLowersTheSettings) {
  RenderScene rs;
  StrandItem si;
  si.strands = strands(100000, 3);
  rs.strands.push_back(si);
  ParticleItem pi;
  auto ps = std::make_shared<geom::ParticleSet>();
  for (int i = 0; i < 50000; ++i) {
    ps->positions.push_back(Vec3f(float(i), 0, 0));
    ps->radius.push_back(0.001f);
  }
  pi.particles = ps;
  rs.particles.push_back(pi);
  RenderSettings s;
  s.width = 880;
  s.height = 800;
  s.supersample = 2;
  s.shadow_map_size = 4096;
  PreviewParams p;
  PreviewReducer red;
  RenderScene a = rs;
  RenderSettings sa = s;
  red.reduce(a, sa, p);
  EXPECT_LE(a.strands[0].strands->num_strands(), std::size_t(p.max_strands));
  EXPECT_GE(a.strands[0].strands->num_strands(), std::size_t(p.max_strands) / 2);
  EXPECT_GT(a.strands[0].material.width_px, rs.strands[0].material.width_px);  // drawn wider
  EXPECT_LE(a.particles[0].particles->size(), std::size_t(p.max_particles));
  EXPECT_EQ(sa.width, 440);
  EXPECT_EQ(sa.height, 400);
  EXPECT_EQ(sa.supersample, 1);
  EXPECT_EQ(sa.shadow_map_size, p.shadow_map_size);
  // The same source set again: the reduced set is reused, not rebuilt.
  RenderScene b = rs;
  RenderSettings sb = s;
  red.reduce(b, sb, p);
  EXPECT_EQ(a.strands[0].strands.get(), b.strands[0].strands.get());
  // A small scene is left whole.
  RenderScene c;
  StrandItem small;
  small.strands = strands(10, 3);
  c.strands.push_back(small);
  RenderSettings sc = s;
  red.reduce(c, sc, p);
  EXPECT_EQ(c.strands[0].strands.get(), small.strands.get());
  // Bad parameters are refused with the key.
  p.scale = 0;
  RenderScene d = rs;
  RenderSettings sd = s;
  try {
    red.reduce(d, sd, p);
    FAIL() << "scale 0 accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("preview.scale"), std::string::npos) << e.what();
  }
}

namespace {
// A latitude-longitude sphere of radius r: positions shared across the UV seam at u = 0 / 1,
// whose UVs are split there (as in an OBJ), poles included.
std::shared_ptr<geom::TriMesh> uv_sphere(int nu, int nv, double r) {
  auto m = std::make_shared<geom::TriMesh>();
  auto pos = [&](int i, int j) {  // i around (mod nu), j from pole to pole
    const double th = kPi * j / nv, ph = 2 * kPi * (i % nu) / nu;
    return Vec3(r * std::sin(th) * std::cos(ph), r * std::cos(th), r * std::sin(th) * std::sin(ph));
  };
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i < nu; ++i) m->positions.push_back(pos(i, j));
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i <= nu; ++i) m->uvs.push_back(Vec2(double(i) / nu, 1.0 - double(j) / nv));
  auto P = [&](int i, int j) { return j * nu + (i % nu); };
  auto T = [&](int i, int j) { return j * (nu + 1) + i; };
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      if (j > 0) {
        m->faces.push_back(Vec3i(P(i, j), P(i + 1, j), P(i, j + 1)));
        m->uv_faces.push_back(Vec3i(T(i, j), T(i + 1, j), T(i, j + 1)));
      }
      if (j < nv - 1) {
        m->faces.push_back(Vec3i(P(i + 1, j), P(i + 1, j + 1), P(i, j + 1)));
        m->uv_faces.push_back(Vec3i(T(i + 1, j), T(i + 1, j + 1), T(i, j + 1)));
      }
    }
  m->compute_normals();
  return m;
}
}  // namespace

TEST(PreviewScene, SimplifiedMeshKeepsTheShapeTheVerticesAndTheUvSeam) {
  const auto m = uv_sphere(128, 64, 0.1);  // 16,128 faces
  m->check("sphere");
  const geom::TriMesh s = simplified_mesh(*m, 2000);
  EXPECT_NO_THROW(s.check("simplified"));
  EXPECT_LE(s.faces.size(), 2000u);
  EXPECT_GE(s.faces.size(), 500u);
  // The faces index the original vertices, which stay as they were.
  EXPECT_EQ(s.positions, m->positions);
  EXPECT_EQ(s.normals, m->normals);
  EXPECT_EQ(s.uvs, m->uvs);
  ASSERT_EQ(s.uv_faces.size(), s.faces.size());
  // Every corner keeps a (position, UV) pair of the original mesh: no texture smeared across the
  // seam; and the surface stays within 1 % of the radius of the sphere (face centroids).
  std::set<std::pair<int, int>> pairs;
  for (std::size_t f = 0; f < m->faces.size(); ++f)
    for (int c = 0; c < 3; ++c) pairs.insert({m->faces[f][c], m->uv_faces[f][c]});
  double area = 0, worst = 0;
  for (std::size_t f = 0; f < s.faces.size(); ++f) {
    for (int c = 0; c < 3; ++c)
      EXPECT_TRUE(pairs.count({s.faces[f][c], s.uv_faces[f][c]})) << "face " << f;
    const Vec3 g =
        (s.positions[std::size_t(s.faces[f][0])] + s.positions[std::size_t(s.faces[f][1])] +
         s.positions[std::size_t(s.faces[f][2])]) /
        3;
    worst = std::max(worst, 0.1 - g.norm());
    area += s.face_area(f);
  }
  EXPECT_LT(worst, 0.1 * 0.03);
  // No holes: the area stays close to the sphere's (a cracked seam or lost cap would show).
  EXPECT_NEAR(area, 4 * kPi * 0.01, 4 * kPi * 0.01 * 0.03);
  // A mesh within the budget is returned whole.
  EXPECT_EQ(simplified_mesh(*m, 20000).faces, m->faces);
  // Without UVs (and normals) as well: a scan straight from the scanner.
  geom::TriMesh bare = *m;
  bare.uvs.clear();
  bare.uv_faces.clear();
  bare.normals.clear();
  const geom::TriMesh sb = simplified_mesh(bare, 2000);
  EXPECT_NO_THROW(sb.check("simplified without UVs"));
  EXPECT_LE(sb.faces.size(), 2000u);
  EXPECT_TRUE(sb.uv_faces.empty());
  EXPECT_TRUE(sb.has_normals());
}

TEST(PreviewScene, ReduceSimplifiesABigMeshOnceForItsTopology) {
  const auto m = uv_sphere(128, 64, 0.1);
  RenderSettings s;
  PreviewParams p;
  p.max_triangles = 2000;
  PreviewReducer red;
  RenderScene a;
  MeshItem mi;
  mi.mesh = m;
  a.meshes.push_back(mi);
  red.reduce(a, s, p);
  const auto first = a.meshes[0].mesh;
  EXPECT_LE(first->faces.size(), 2000u);
  RenderScene b;
  b.meshes.push_back(mi);
  red.reduce(b, s, p);
  EXPECT_EQ(b.meshes[0].mesh.get(), first.get());  // the same mesh again: reused
  // The next frame of an animation: a new mesh object, same faces, moved vertices. The faces
  // simplified before are reused; the new positions are drawn.
  auto moved = std::make_shared<geom::TriMesh>(*m);
  for (auto& q : moved->positions) q *= 1.5;
  RenderScene c;
  MeshItem mc;
  mc.mesh = moved;
  c.meshes.push_back(mc);
  red.reduce(c, s, p);
  EXPECT_EQ(c.meshes[0].mesh->faces, first->faces);
  EXPECT_EQ(c.meshes[0].mesh->positions, moved->positions);
  // Under the budget: the mesh itself.
  p.max_triangles = 100000;
  RenderScene d;
  d.meshes.push_back(mi);
  red.reduce(d, s, p);
  EXPECT_EQ(d.meshes[0].mesh.get(), m.get());
}
