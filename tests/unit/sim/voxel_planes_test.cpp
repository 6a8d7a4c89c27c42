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

// (3.20)-(3.24) and the speculative form of ADR 0016 on the plane y = 0 (normal +y), band 5 mm.
TEST(BodyContact, SpeculativeContactStopsAFastParticleAtTheBandsEdge) {
  using sim::body_contact_accel;
  using sim::body_contact_accel_speculative;
  sim::BodyContactParams cp;  // threshold 5 mm, mu 0.3, k_r 4000
  const BodyPlane pl{Vec3::Zero(), Vec3::UnitY()};
  const Vec3 g(0, -9.81, 0);
  const double dt = 0.01;
  // 3 cm above, falling at 4 m/s: the step would carry it 1 cm into the body. The rule of the
  // paper sees nothing outside the band; the speculative one ends the step on the band's edge.
  const Vec3 x(0, 0.03, 0), v(1.0, -4.0, 0);
  EXPECT_EQ(body_contact_accel(pl, x, v, g, dt, cp), Vec3::Zero());
  const Vec3 a = g + body_contact_accel_speculative(pl, x, v, g, dt, cp);
  const Vec3 v1 = v + a * dt, x1 = x + v1 * dt;
  EXPECT_NEAR(x1.y(), cp.threshold, 1e-12);
  // Coulomb sliding on the normal impulse beyond the edge: (4 + 9.81 dt - 2.5) m/s of approach
  // stopped, mu times that taken off the tangential 1 m/s.
  const double stopped = 4.0 + 9.81 * dt - (0.03 - cp.threshold) / dt;
  EXPECT_NEAR(v1.x(), 1.0 - cp.mu * stopped, 1e-12);
  // Sticking when the tangential speed is below mu times the stopped one.
  const Vec3 slow(0.1, -4.0, 0);
  const Vec3 as = g + body_contact_accel_speculative(pl, x, slow, g, dt, cp);
  EXPECT_NEAR((slow + as * dt).x(), 0.0, 1e-12);
  // A particle that does not reach the band, or moves away, is left alone.
  EXPECT_EQ(body_contact_accel_speculative(pl, x, Vec3(0, -1.0, 0), g, dt, cp), Vec3::Zero());
  EXPECT_EQ(body_contact_accel_speculative(pl, x, Vec3(0, 3.0, 0), g, dt, cp), Vec3::Zero());
  // Within the band it is the paper's rule, repulsion (3.24) included.
  for (const double y : {0.004, 0.0, -0.002}) {
    const Vec3 xb(0, y, 0), vb(0.5, -0.3, 0.2);
    EXPECT_EQ(body_contact_accel_speculative(pl, xb, vb, g, dt, cp),
              body_contact_accel(pl, xb, vb, g, dt, cp))
        << y;
  }
  // Short steps, as the leapfrog takes them: the particle crosses into the band before any step
  // would carry it past the edge, and both rules give the same trajectory.
  Vec3 xa = x, va = v, xs = x, vs = v;
  for (int k = 0; k < 400; ++k) {
    const double h = 1e-4;
    const Vec3 aa = g + body_contact_accel(pl, xa, va, g, h, cp);
    const Vec3 as2 = g + body_contact_accel_speculative(pl, xs, vs, g, h, cp);
    va += aa * h, xa += va * h;
    vs += as2 * h, xs += vs * h;
  }
  EXPECT_LT((xa - xs).norm(), 5e-4);  // about one short step's displacement apart
  EXPECT_GT(xs.y(), cp.threshold - 5e-4);
}

// A voxel the surface only clips at a corner may draw no sample; before the fill such holes let
// a strand's tip into a sphere head 8.5 mm deep. Every point of the surface now finds a plane,
// within the sampled planes' accuracy, even at a sparse sampling.
TEST(VoxelPlanes, EveryVoxelTheSurfaceCrossesHasAPlane) {
  const Vec3 c(0.003, -0.002, 0.001);
  const geom::TriMesh m = sphere(c, 0.1, 48, 96);
  VoxelPlanesParams p;
  p.voxel_size = 0.01;
  p.samples_per_voxel = 4;
  const VoxelPlanes vp = VoxelPlanes::build({&m}, p, 3);
  std::size_t missing = 0;
  double worst = 0;
  for (const Vec3& x : surface_points(c, 0.1, 20000, 5)) {
    const BodyPlane* pl = vp.find(x);
    if (!pl) {
      ++missing;
      continue;
    }
    worst = std::max(worst, std::abs((x - pl->p).dot(pl->n)));
  }
  EXPECT_EQ(missing, 0u);
  EXPECT_LT(worst, 0.003);  // a plane per voxel: the sagitta of a 1-2 cm patch of r = 10 cm
  // Far from the surface there is still no plane.
  EXPECT_EQ(vp.find(c), nullptr);
  EXPECT_EQ(vp.find(c + Vec3(0.13, 0, 0)), nullptr);
}
