// Scalp trimming (Bando 2003 §3.3.1): the four Catmull-Rom curves cut a disk out of the head
// mesh. A scalp that reaches the hairline bends further than the loop's plane can see, so faces
// there turn away from the plane's normal; such islands inside the loop are holes and must be
// filled, or the harmonic embedding has no disk to map. Also the hair length map L(u, v).
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "follicle/geom/mesh_io.hpp"
#include "follicle/hair/lcp_bando2003.hpp"
#include "follicle/hair/scalp_bando2003.hpp"
#include "lcp_test_scenes.hpp"
#include "testing/testing.hpp"

using namespace follicle;
using namespace follicle::hair;

namespace {

int euler_characteristic(const geom::TriMesh& m) {
  std::set<std::pair<int, int>> edges;
  for (const auto& f : m.faces)
    for (int k = 0; k < 3; ++k)
      edges.insert({std::min(f[k], f[(k + 1) % 3]), std::max(f[k], f[(k + 1) % 3])});
  return int(m.positions.size()) - int(edges.size()) + int(m.faces.size());
}

}  // namespace

TEST(ScalpTrim, IslandsOfFacesTurnedAwayInsideTheLoopAreFilled) {
  auto head = test::lcp_sphere(0.1, 24, 48);
  // Turn a patch of faces inside the cap inside out (as a fold of a scanned mesh would look to
  // the loop's plane): they fail the facing test and leave a hole in the selection.
  int flipped = 0;
  for (std::size_t f = 0; f < head.faces.size(); ++f) {
    const Vec3i& F = head.faces[f];
    const Vec3 c = (head.positions[F[0]] + head.positions[F[1]] + head.positions[F[2]]) / 3;
    const Vec3 d = c.normalized();
    if (d.y() > 0.8 && d.y() < 0.93 && d.x() > 0.1) {
      std::swap(head.faces[f][1], head.faces[f][2]);
      ++flipped;
    }
  }
  ASSERT_GT(flipped, 4);
  const Scalp s = Scalp::trim(head, test::lcp_cap_curves(0.1, 1.1), ScalpParams{});
  EXPECT_EQ(euler_characteristic(s.mesh()), 1);
  // The flipped patch is part of the scalp.
  int inside = 0;
  for (const auto& v : s.mesh().positions)
    if (v.normalized().y() > 0.8 && v.normalized().y() < 0.93 && v.x() > 0.1 * 0.1) ++inside;
  EXPECT_GT(inside, 3);
  // The cap (polar angle 1.1) holds about its share of the sphere's area.
  const double cap = 2 * kPi * 0.1 * 0.1 * (1 - std::cos(1.1));
  EXPECT_NEAR(s.area(), cap, 0.25 * cap);
}

TEST(ScalpTrim, FullScalpOfTheHeadReachesTheHairlineAndLeavesTheFace) {
  const auto path = test::source_dir() / "data/meshes/lee_perry_smith/head.obj";
  const auto head = geom::load_mesh(path, LengthUnit::mm);
  // The curves of data/scenes/lcp_*.json: nape, behind and over the ears, front hairline.
  ScalpCurves c;
  c[0] = {{0.055, 0.03, -0.062},
          {0.03, 0.012, -0.068},
          {0.0, 0.008, -0.068},
          {-0.03, 0.012, -0.068},
          {-0.055, 0.03, -0.062}};
  c[1] = {
      {-0.055, 0.03, -0.062}, {-0.066, 0.08, -0.05}, {-0.068, 0.125, -0.01}, {-0.055, 0.145, 0.05}};
  c[2] = {{-0.055, 0.145, 0.05},
          {-0.03, 0.157, 0.07},
          {0.0, 0.16, 0.076},
          {0.03, 0.157, 0.07},
          {0.055, 0.145, 0.05}};
  c[3] = {{0.055, 0.145, 0.05}, {0.068, 0.125, -0.01}, {0.066, 0.08, -0.05}, {0.055, 0.03, -0.062}};
  const Scalp s = Scalp::trim(head, c, ScalpParams{});
  EXPECT_EQ(euler_characteristic(s.mesh()), 1);
  double to_hairline = 1e9, to_crown = 1e9;
  bool face = false;
  for (const auto& v : s.mesh().positions) {
    to_hairline = std::min(to_hairline, (v - Vec3(0, 0.155, 0.075)).norm());
    to_crown = std::min(to_crown, (v - Vec3(0, 0.185, 0.0)).norm());
    face = face || (v.y() < 0.12 && v.z() > 0.06);  // forehead, eyes, nose
  }
  EXPECT_LT(to_hairline, 0.012);
  EXPECT_LT(to_crown, 0.012);
  EXPECT_FALSE(face);
}

TEST(ScalpLengthMap, ShortHairWhereTheMapIsDark) {
  // §3.3.1: L(u, v) = max_length * map(u, v). Left half of the map 0.25, right half 1: the
  // particles of the pillar (u, v, s) stop at s <= L(u, v) on each side.
  const auto head = test::lcp_sphere(0.1, 24, 48);
  ScalpParams sp;
  sp.max_length = 0.12;
  sp.root_depth = 0.01;
  Scalp scalp = Scalp::trim(head, test::lcp_cap_curves(0.1, 1.1), sp);
  image::ImageF map(16, 16, 1.0f);
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 8; ++x) map.at(x, y) = 0.25f;
  scalp.set_length_map(map);
  EXPECT_NEAR(scalp.length(Vec2(0.1, 0.5)), 0.25 * 0.12, 1e-9);
  EXPECT_NEAR(scalp.length(Vec2(0.9, 0.3)), 0.12, 1e-9);
  Context ctx(1, 5);
  LcpInitParams ip;
  ip.spacing = 0.012;
  ip.whirl_point = Vec3(0, 0.1, 0.02);
  const LcpInit init = initialize_lcp(ctx, scalp, ip);
  double left_max = 0, right_max = 0;
  int left = 0, right = 0;
  for (const Vec3& q : init.model.uvs) {
    if (q.x() < 0.4) {
      left_max = std::max(left_max, q.z());
      ++left;
    } else if (q.x() > 0.6) {
      right_max = std::max(right_max, q.z());
      ++right;
    }
  }
  ASSERT_GT(left, 10);
  ASSERT_GT(right, 10);
  EXPECT_LE(left_max, 0.25 * 0.12 + 1e-9);
  EXPECT_GT(right_max, 0.6 * 0.12);
  EXPECT_GT(right, 2 * left);  // longer hair, more particles per unit of scalp
}
