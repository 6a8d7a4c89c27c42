// A wrinkle belongs to one UV island. Scanned heads (ICT FaceKit) lay several islands on top of
// each other in texture space (eyes, teeth, the back of the head over the face); the furrow must
// touch only the skin of the island its curve lies on, and its texture scale (metres per
// texture unit) must be that island's, not a mix. Before the fix the layer took every vertex
// within reach in texture space, whatever its island, and averaged their scales.
#include <gtest/gtest.h>

#include <algorithm>

#include "follicle/geom/uv_locator.hpp"
#include "follicle/skin/forehead_validation.hpp"
#include "follicle/skin/large_wrinkles_bando2002.hpp"

using namespace follicle;
using namespace follicle::skin;

namespace {

// Appends `b` to `a` as a separate UV island (its own UV indices) moved by `offset`.
geom::TriMesh join(geom::TriMesh a, const geom::TriMesh& b, const Vec3& offset) {
  const int nv = int(a.positions.size()), nt = int(a.uvs.size());
  for (const auto& p : b.positions) a.positions.push_back(p + offset);
  for (const auto& t : b.uvs) a.uvs.push_back(t);
  for (const auto& f : b.faces) a.faces.push_back(f + Vec3i::Constant(nv));
  for (const auto& f : b.uv_faces) a.uv_faces.push_back(f + Vec3i::Constant(nt));
  return a;
}

LargeWrinkle furrow() {
  LargeWrinkle w;
  w.control = {Vec2(0.2, 0.4), Vec2(0.4, 0.42), Vec2(0.6, 0.38), Vec2(0.8, 0.4)};
  w.depth = 0.002;
  w.width = 0.002;
  return w;
}

}  // namespace

TEST(WrinkleIslands, AFurrowStaysOnTheIslandItsCurveLiesOn) {
  // The skin: 6 cm patch. Laid over it in texture space: a 1.5 cm patch (an "eye" island) with
  // the same UV square, 4x finer in metres per texture unit, far away in 3D.
  const geom::TriMesh skin = make_cylinder_patch(0.06, 0.06, 0.09, 0.003);
  const geom::TriMesh eye = make_cylinder_patch(0.015, 0.015, 0.0, 0.001);
  for (bool eye_first : {false, true}) {
    const geom::TriMesh both =
        eye_first ? join(eye, skin, Vec3(0, 0, 0.2)) : join(skin, eye, Vec3(0, 0, 0.2));
    const int skin_first = eye_first ? int(eye.positions.size()) : 0;
    const int skin_end = skin_first + int(skin.positions.size());
    const std::vector<int> islands = geom::uv_islands(both);
    ASSERT_EQ(*std::max_element(islands.begin(), islands.end()), 1);

    const WrinkleLayer alone(skin, {furrow()});
    const WrinkleLayer layer(both, {furrow()});
    const auto& a = alone.influence(0);
    const auto& b = layer.influence(0);
    ASSERT_FALSE(a.entries.empty());
    // Same vertices (shifted), same texture scale, same profile: the eye island is not touched.
    EXPECT_NEAR(b.texture_scale, a.texture_scale, 1e-12 * a.texture_scale) << eye_first;
    ASSERT_EQ(b.entries.size(), a.entries.size()) << eye_first;
    for (std::size_t k = 0; k < a.entries.size(); ++k) {
      EXPECT_GE(b.entries[k].vertex, skin_first);
      EXPECT_LT(b.entries[k].vertex, skin_end);
      EXPECT_EQ(b.entries[k].vertex - skin_first, a.entries[k].vertex);
      EXPECT_NEAR(b.entries[k].shape, a.entries[k].shape, 1e-15);
      EXPECT_EQ(b.entries[k].nsides, a.entries[k].nsides);
    }
    // Heights of the squeezed pair: only skin vertices move.
    std::vector<Vec3> squeezed = both.positions;
    for (auto& p : squeezed) p.y() *= 0.8;
    std::vector<double> h;
    layer.heights(Context(1), squeezed, h);
    for (int v = 0; v < int(h.size()); ++v) {
      if (v < skin_first || v >= skin_end) {
        ASSERT_EQ(h[std::size_t(v)], 0.0) << v;
      }
    }
  }
}

TEST(WrinkleIslands, TheLargerIslandWinsWhenTwoHoldTheWholeCurve) {
  // Same UV square, skin 6 cm vs 1.5 cm: the curve lies on both; the one with more skin under
  // it is the face.
  const geom::TriMesh big = make_cylinder_patch(0.06, 0.06, 0.0, 0.003);
  const geom::TriMesh small = make_cylinder_patch(0.015, 0.015, 0.0, 0.001);
  const geom::TriMesh both = join(small, big, Vec3(0, 0, 0.1));
  const WrinkleLayer layer(both, {furrow()});
  EXPECT_EQ(layer.influence(0).island, 1);
  EXPECT_NEAR(layer.influence(0).texture_scale, 0.06, 1e-9);  // isometric UVs of a 6 cm patch
}

TEST(WrinkleIslands, ACurveOnNoIslandFallsBackToTheWholeTextureSpace) {
  // A curve in the gap between two islands side by side still reaches both borders (as before).
  geom::TriMesh left = make_cylinder_patch(0.03, 0.03, 0.0, 0.002);
  geom::TriMesh right = left;
  for (auto& t : right.uvs) t.x() += 1.2;  // u in [1.2, 2.2]
  const geom::TriMesh both = join(left, right, Vec3(0.05, 0, 0));
  LargeWrinkle w = furrow();
  w.control = {Vec2(1.1, 0.2), Vec2(1.1, 0.4), Vec2(1.1, 0.6), Vec2(1.1, 0.8)};
  w.width = 0.001;
  const WrinkleLayer layer(both, {w});
  EXPECT_EQ(layer.influence(0).island, -1);
  bool l = false, r = false;
  for (const auto& e : layer.influence(0).entries)
    (e.vertex < int(left.positions.size()) ? l : r) = true;
  EXPECT_TRUE(l && r);
}
