#include <gtest/gtest.h>

#include <fstream>

#include "follicle/core/context.hpp"
#include "follicle/skin/forehead_validation.hpp"
#include "follicle/skin/muscles_waters1987.hpp"
#include "follicle/skin/waters_geoface.hpp"
#include "testing/testing.hpp"

using namespace follicle;
using namespace follicle::skin;

TEST(WatersMuscle, ContractionMovesTowardOriginInsideZoneOnly) {
  Context ctx(1);
  const geom::TriMesh m = make_cylinder_patch(0.08, 0.08, 0.0, 0.002);
  MuscleSet set;
  LinearMuscle lm;
  lm.name = "test";
  lm.origin = Vec3(0, 0.03, 0);
  lm.insertion = Vec3(0, -0.01, 0);
  lm.falloff_start = 0.01;
  lm.falloff_end = 0.05;
  lm.zone = 0.5;
  set.linear.push_back(lm);
  MuscleField field(set, m.positions);
  MusclePose pose{{0.8}, 0.0, {}};
  std::vector<Vec3> out;
  field.apply(ctx, pose, m.positions, out);
  int inside = 0;
  for (std::size_t i = 0; i < out.size(); ++i) {
    const Vec3 v = m.positions[i] - lm.origin;
    const double cosa = v.normalized().dot((lm.insertion - lm.origin).normalized());
    const bool in_zone = v.norm() < lm.falloff_end && cosa > std::cos(lm.zone) + 1e-9;
    const Vec3 d = out[i] - m.positions[i];
    if (in_zone) {
      ++inside;
      EXPECT_LT((out[i] - lm.origin).norm(), v.norm()) << i;  // closer to the origin
      EXPECT_LT(d.normalized().dot(-v.normalized()), 1.0 + 1e-9);
      EXPECT_GT(d.normalized().dot(-v.normalized()), 1.0 - 1e-9);  // along the line to the origin
    } else if (cosa < std::cos(lm.zone) - 1e-9 || v.norm() > lm.falloff_end + 1e-12) {
      EXPECT_EQ(d.norm(), 0.0) << i;
    }
  }
  EXPECT_GT(inside, 50);
  // Linear in the contraction.
  std::vector<Vec3> half;
  field.apply(ctx, MusclePose{{0.4}, 0.0, {}}, m.positions, half);
  for (std::size_t i = 0; i < out.size(); ++i)
    EXPECT_LT(((out[i] - m.positions[i]) - 2 * (half[i] - m.positions[i])).norm(), 1e-15);
}

TEST(WatersMuscle, JawRotatesOnlyJawRegion) {
  Context ctx(1);
  const geom::TriMesh m = make_cylinder_patch(0.08, 0.08, 0.0, 0.004);
  MuscleSet set;
  set.jaw.enabled = true;
  set.jaw.pivot = Vec3(0, 0, -0.05);
  set.jaw.axis = Vec3(1, 0, 0);
  set.jaw.plane_normal = Vec3(0, -1, 0);
  set.jaw.offset = 0.01;
  set.jaw.blend_width = 0.01;
  MuscleField field(set, m.positions);
  std::vector<Vec3> out;
  field.apply(ctx, MusclePose{{}, 0.2, {}}, m.positions, out);
  for (std::size_t i = 0; i < out.size(); ++i) {
    const double y = m.positions[i].y();
    if (y > -0.01) {
      EXPECT_EQ((out[i] - m.positions[i]).norm(), 0.0);
    }
    if (y < -0.021) {
      EXPECT_GT((out[i] - m.positions[i]).norm(), 1e-3);
    }
  }
}

TEST(WatersGeoface, LoadsMirroredFaceMusclesAndExpressions) {
  FOLLICLE_REQUIRE_SHARED("waters-geoface/simpleface-1998/muscle.dat");
  const auto dir = test::shared_data_dir() / "waters-geoface";
  const WatersFace glut = load_waters_geoface(dir / "glut-3.7.6");
  EXPECT_EQ(glut.mesh.positions.size(), 478u);
  EXPECT_EQ(glut.mesh.faces.size(), 876u);
  const WatersFace f = load_waters_geoface(dir / "simpleface-1998");
  EXPECT_EQ(f.mesh.positions.size(), 478u);
  EXPECT_EQ(f.muscles.linear.size(), 18u);
  EXPECT_EQ(f.muscles.expressions.size(), 6u);
  // Front faces are counter-clockwise: normals near the nose tip point +z.
  double nz = 0;
  for (std::size_t i = 0; i < f.mesh.faces.size(); ++i)
    nz += f.mesh.face_normal(i).z() * f.mesh.face_area(i);
  EXPECT_GT(nz, 0.0);
  // Anger raises the corrugators; happiness pulls the mouth corners toward the zygomatic origins.
  const Expression& happy = f.muscles.expression("Happiness");
  EXPECT_DOUBLE_EQ(happy.contractions.at("Left_Zygomatic_Major"), 1.1);
  EXPECT_DOUBLE_EQ(f.muscles.expression("Anger").contractions.at("Right_Lateral_Corigator"), 1.3);
  Context ctx(2);
  MuscleField field(f.muscles, f.mesh.positions);
  std::vector<Vec3> out;
  field.apply(ctx, pose_from_expression(f.muscles, happy), f.mesh.positions, out);
  const LinearMuscle& zl = f.muscles.linear[0];
  std::size_t moved = 0;
  double closer = 0;
  for (int i : field.influenced_vertices(0)) {
    ++moved;
    closer += (f.mesh.positions[std::size_t(i)] - zl.origin).norm() -
              (out[std::size_t(i)] - zl.origin).norm();
  }
  EXPECT_GT(moved, 5u);
  EXPECT_GT(closer, 0.0);
  // Symmetric muscles: the left zygomatic moves only x <= 0 vertices near the mouth.
  for (int i : field.influenced_vertices(0)) EXPECT_LT(f.mesh.positions[std::size_t(i)].x(), 0.01);
  // Every expression deforms the face, neutral leaves it.
  for (const auto& e : f.muscles.expressions) {
    field.apply(ctx, pose_from_expression(f.muscles, e), f.mesh.positions, out);
    double maxd = 0;
    for (std::size_t i = 0; i < out.size(); ++i)
      maxd = std::max(maxd, (out[i] - f.mesh.positions[i]).norm());
    EXPECT_GT(maxd, 1e-3) << e.name;
    EXPECT_LT(maxd, 0.05) << e.name;
  }
}

TEST(WatersGeoface, MissingOrBrokenFilesFailCleanly) {
  const auto dir = test::scratch_dir("waters_bad");
  EXPECT_THROW(load_waters_geoface(dir), Error);
  FOLLICLE_REQUIRE_SHARED("waters-geoface/simpleface-1998/muscle.dat");
  const auto src = test::shared_data_dir() / "waters-geoface" / "simpleface-1998";
  for (const char* f : {"faceline.dat", "index.dat"}) std::filesystem::copy_file(src / f, dir / f);
  {
    std::ofstream m(dir / "muscle.dat");
    m << "1\nBroken\n0 0 0\n1 1 x\n";
  }
  try {
    load_waters_geoface(dir);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("muscle.dat"), std::string::npos) << e.what();
  }
}
