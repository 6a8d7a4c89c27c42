#include "follicle/sim/voxel_planes.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "follicle/core/error.hpp"
#include "follicle/core/rng.hpp"

using namespace follicle;
using follicle::sim::BodyPlane;
using follicle::sim::VoxelPlanes;
using follicle::sim::VoxelPlanesParams;

namespace {

// UV sphere, faces counter-clockwise seen from outside.
geom::TriMesh sphere(const Vec3& centre, double radius, int nlat = 32, int nlon = 64) {
  geom::TriMesh m;
  for (int i = 0; i <= nlat; ++i)
    for (int j = 0; j < nlon; ++j) {
      const double th = kPi * i / nlat, ph = 2 * kPi * j / nlon;
      m.positions.push_back(centre + radius * Vec3(std::sin(th) * std::cos(ph), std::cos(th),
                                                   std::sin(th) * std::sin(ph)));
    }
  auto id = [&](int i, int j) { return i * nlon + (j % nlon); };
  for (int i = 0; i < nlat; ++i)
    for (int j = 0; j < nlon; ++j) {
      m.faces.push_back({id(i, j), id(i, j + 1), id(i + 1, j)});
      m.faces.push_back({id(i, j + 1), id(i + 1, j + 1), id(i + 1, j)});
    }
  return m;
}

// Points on the sphere surface.
std::vector<Vec3> surface_points(const Vec3& centre, double radius, int n, uint64_t seed) {
  Rng rng = Rng::stream(seed, 7);
  std::vector<Vec3> out;
  for (int k = 0; k < n; ++k) {
    const double z = 2 * rng.uniform() - 1, ph = 2 * kPi * rng.uniform();
    const double s = std::sqrt(std::max(0.0, 1 - z * z));
    out.push_back(centre + radius * Vec3(s * std::cos(ph), z, s * std::sin(ph)));
  }
  return out;
}

}  // namespace

TEST(VoxelPlanes, PlanesApproximateTheSphereSurface) {
  // §3.5: per voxel, the mean sample position lies on the surface (within the chord sag of a
  // voxel) and the mean normal points outward along the radius.
  const Vec3 c(0.01, -0.02, 0.03);
  const double R = 0.1;
  const geom::TriMesh m = sphere(c, R);
  VoxelPlanesParams p;
  p.voxel_size = 0.01;
  const VoxelPlanes vp = VoxelPlanes::build({&m}, p, 1);
  ASSERT_GT(vp.num_planes(), 100u);
  for (const BodyPlane& pl : vp.planes()) {
    EXPECT_NEAR((pl.p - c).norm(), R, 2e-3);
    EXPECT_GT(pl.n.dot((pl.p - c).normalized()), 0.95);
  }
  // Surface points find a plane (all but those in voxels the surface only grazes, which drew no
  // sample), at a signed distance within the voxel's curvature sag.
  int found = 0;
  const auto pts = surface_points(c, R, 2000, 3);
  for (const Vec3& x : pts)
    if (vp.find(x)) {
      ++found;
      EXPECT_LT(std::abs(vp.distance(x)), 2e-3);
    }
  EXPECT_GT(found, int(0.95 * double(pts.size())));
  // Inside (1 cm below the surface) the distance is negative; far away there is no plane.
  for (const Vec3& x : surface_points(c, R, 200, 4)) {
    const Vec3 in = c + (x - c) * (R - 0.004) / R;
    if (vp.find(in)) {
      EXPECT_LT(vp.distance(in), 0.0);
    }
  }
  EXPECT_EQ(vp.find(c), nullptr);
  EXPECT_EQ(vp.find(Vec3(5, 5, 5)), nullptr);
  EXPECT_TRUE(std::isinf(vp.distance(Vec3(-5, 0, 0))));
}

TEST(VoxelPlanes, LookupIsExactOnVoxelBoundariesAndSafeForBadPoints) {
  // A point exactly on a voxel face belongs to the voxel above it (floor), like every point a
  // little inside that voxel; a point a little below belongs to the voxel below.
  const geom::TriMesh m = sphere(Vec3::Zero(), 0.1);
  VoxelPlanesParams p;
  p.voxel_size = 1.0 / 64;  // a power of two: k * size and (k * size) / size are exact
  const VoxelPlanes vp = VoxelPlanes::build({&m}, p, 2);
  int checked = 0;
  for (int i = -10; i <= 10; ++i)
    for (int j = -10; j <= 10; ++j)
      for (int k = -10; k <= 10; ++k) {
        const Vec3 x = p.voxel_size * Vec3(i, j, k);
        const BodyPlane* here = vp.find(x);
        const double eps = 1e-6;
        EXPECT_EQ(here, vp.find(x + Vec3(eps, eps, eps))) << x.transpose();
        if (here) {
          ++checked;
          // The voxel below along x is a different voxel: a different plane (or none).
          EXPECT_NE(here, vp.find(x - Vec3(eps, 0, 0))) << x.transpose();
        }
      }
  EXPECT_GT(checked, 50);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(vp.find(Vec3(nan, 0, 0)), nullptr);
  EXPECT_EQ(vp.find(Vec3(0.1, inf, 0)), nullptr);
  EXPECT_EQ(vp.find(Vec3(-inf, -inf, -inf)), nullptr);
  EXPECT_EQ(vp.find(Vec3(1e300, 0, 0)), nullptr);
  EXPECT_TRUE(std::isinf(vp.distance(Vec3(nan, nan, nan))));
}

TEST(VoxelPlanes, SparseBodyOverAHugeBoxStillFindsItsPlanes) {
  // Two small spheres 200 m apart: the occupied voxels span far more cells than a dense index
  // may hold, so lookups go through the hash; both bodies are found, the gap is empty.
  const Vec3 c1(-100, 0, 0), c2(100, 0, 0);
  const geom::TriMesh a = sphere(c1, 0.05, 16, 32), b = sphere(c2, 0.05, 16, 32);
  VoxelPlanesParams p;
  p.voxel_size = 0.01;
  const VoxelPlanes vp = VoxelPlanes::build({&a, &b}, p, 5);
  for (const Vec3& c : {c1, c2}) {
    int found = 0;
    for (const Vec3& x : surface_points(c, 0.05, 300, 6))
      if (vp.find(x)) {
        ++found;
        EXPECT_LT(std::abs(vp.distance(x)), 2e-3);
      }
    EXPECT_GT(found, 270);
  }
  EXPECT_EQ(vp.find(Vec3(0, 0, 0)), nullptr);
  EXPECT_EQ(vp.find(Vec3(std::numeric_limits<double>::quiet_NaN(), 0, 0)), nullptr);
}

TEST(VoxelPlanes, DenseAndHashedLookupsAgree) {
  // The same sphere alone (a small box: dense index) and with a far speck added (a huge box:
  // hash lookups). The sphere's samples come first from the same seed, so its planes are the
  // same; every lookup around it must return the same plane (or none) both ways.
  const geom::TriMesh a = sphere(Vec3(0.003, -0.01, 0.02), 0.1);
  const geom::TriMesh speck = sphere(Vec3(300, 0, 0), 0.01, 4, 8);
  VoxelPlanesParams p;
  p.voxel_size = 0.01;
  const VoxelPlanes dense = VoxelPlanes::build({&a}, p, 9);
  const VoxelPlanes hashed = VoxelPlanes::build({&a, &speck}, p, 9);
  Rng rng = Rng::stream(11, 1);
  int hits = 0;
  for (int k = 0; k < 20000; ++k) {
    Vec3 x(rng.uniform(-0.13, 0.13), rng.uniform(-0.13, 0.13), rng.uniform(-0.13, 0.13));
    if (k % 4 == 0) x = p.voxel_size * (x / p.voxel_size).array().round().matrix();  // on faces
    const BodyPlane* u = dense.find(x);
    const BodyPlane* v = hashed.find(x);
    ASSERT_EQ(u == nullptr, v == nullptr) << x.transpose();
    if (!u) continue;
    ++hits;
    EXPECT_EQ(u->p, v->p) << x.transpose();
    EXPECT_EQ(u->n, v->n) << x.transpose();
  }
  EXPECT_GT(hits, 1000);
}

TEST(VoxelPlanes, BadMeshesFailCleanly) {
  VoxelPlanesParams p;
  EXPECT_THROW(VoxelPlanes::build({}, p, 1), Error);
  geom::TriMesh empty;
  EXPECT_THROW(VoxelPlanes::build({&empty}, p, 1), Error);
  geom::TriMesh bad = sphere(Vec3::Zero(), 0.1, 4, 8);
  bad.faces[3] = Vec3i(0, 1, 9999);
  try {
    VoxelPlanes::build({&bad}, p, 1);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("out of range"), std::string::npos) << e.what();
  }
  p.voxel_size = -1;
  EXPECT_THROW(VoxelPlanes::build({&bad}, p, 1), Error);
}

TEST(VoxelPlanes, ABodyTooLargeForTheSampleBudgetIsRefusedBeforeSampling) {
  // A 10 m sphere head at 1.3 cm voxels asked for 178 M samples and ran for minutes.
  const geom::TriMesh big = sphere(Vec3::Zero(), 10.0, 8, 16);
  VoxelPlanesParams p;
  p.voxel_size = 0.013;
  try {
    (void)VoxelPlanes::build({&big}, p, 1);
    FAIL() << "accepted";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_EQ(e.where(), "voxel_planes.max_samples");
    EXPECT_NE(msg.find("needs 1"), std::string::npos) << msg;  // 1xx M samples
    EXPECT_NE(msg.find(" M samples, more than the budget of 20.0 M"), std::string::npos) << msg;
  }
  // The same at head size builds.
  const geom::TriMesh head = sphere(Vec3::Zero(), 0.1, 8, 16);
  EXPECT_GT(VoxelPlanes::build({&head}, p, 1).num_planes(), 0u);
}
