// Cylindrical radius tables (Daldegan et al. 1993 §3.2, Fig. 3): tables of analytic shapes,
// inside/outside, the nearest-point approximation, azimuth wrap-around, gaps, any orientation,
// the automatic head/neck/trunk split and bad parameters.
#include <gtest/gtest.h>

#include <cmath>

#include "follicle/core/context.hpp"
#include "follicle/core/error.hpp"
#include "follicle/core/rng.hpp"
#include "follicle/sim/cylinder_table_daldegan1993.hpp"

using namespace follicle;
using follicle::sim::CylinderAxis;
using follicle::sim::CylinderBody;
using follicle::sim::CylinderBodyParams;
using follicle::sim::CylinderTable;

namespace {

void append(geom::TriMesh& dst, const geom::TriMesh& src) {
  const int base = int(dst.positions.size());
  dst.positions.insert(dst.positions.end(), src.positions.begin(), src.positions.end());
  for (const Vec3i& f : src.faces) dst.faces.push_back(f + Vec3i::Constant(base));
}

// UV sphere about y (no normals: the table uses face normals).
geom::TriMesh sphere(const Vec3& c, double r, int nu = 96, int nv = 48) {
  geom::TriMesh m;
  for (int j = 0; j <= nv; ++j) {
    const double th = kPi * j / nv;
    for (int i = 0; i < nu; ++i) {
      const double ph = 2 * kPi * i / nu;
      m.positions.push_back(
          c + r * Vec3(std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph)));
    }
  }
  auto id = [&](int i, int j) { return j * nu + (i % nu); };
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      m.faces.emplace_back(id(i, j), id(i + 1, j), id(i + 1, j + 1));
      m.faces.emplace_back(id(i, j), id(i + 1, j + 1), id(i, j + 1));
    }
  return m;
}

// Elliptic tube about y from y = ya to yb with semi-axes (ax along x, az along z) centred at c;
// faces with azimuth (from +x towards +z) in [gap0, gap1) are left out; caps optional.
geom::TriMesh tube(const Vec3& c, double ax, double az, double ya, double yb, int nu = 128,
                   int nh = 8, bool caps = true, double gap0 = 0, double gap1 = 0) {
  geom::TriMesh m;
  for (int j = 0; j <= nh; ++j)
    for (int i = 0; i < nu; ++i) {
      const double ph = 2 * kPi * i / nu;
      m.positions.push_back(c +
                            Vec3(ax * std::cos(ph), ya + (yb - ya) * j / nh, az * std::sin(ph)));
    }
  auto id = [&](int i, int j) { return j * nu + (i % nu); };
  for (int j = 0; j < nh; ++j)
    for (int i = 0; i < nu; ++i) {
      const double mid = 2 * kPi * (i + 0.5) / nu;
      if (mid >= gap0 && mid < gap1) continue;
      m.faces.emplace_back(id(i, j), id(i, j + 1), id(i + 1, j + 1));
      m.faces.emplace_back(id(i, j), id(i + 1, j + 1), id(i + 1, j));
    }
  if (caps) {
    const int b = int(m.positions.size());
    m.positions.push_back(c + Vec3(0, ya, 0));
    m.positions.push_back(c + Vec3(0, yb, 0));
    for (int i = 0; i < nu; ++i) {
      m.faces.emplace_back(b, id(i + 1, 0), id(i, 0));
      m.faces.emplace_back(b + 1, id(i, nh), id(i + 1, nh));
    }
  }
  return m;
}

CylinderAxis y_axis(const Vec3& o, double y0, double y1) {
  CylinderAxis a;
  a.origin = o;
  a.up = Vec3::UnitY();
  a.reference = Vec3::UnitX();
  a.y0 = y0;
  a.y1 = y1;
  return a;
}

}  // namespace

TEST(CylinderTable, SphereRadiiAndNormals) {
  Context ctx(2, 1);
  const Vec3 c(0.01, 1.6, -0.02);
  const double R = 0.1;
  const geom::TriMesh m = sphere(c, R);
  const CylinderTable t = CylinderTable::build(ctx, m, y_axis(c, -0.095, 0.095), 64, 33);
  // Tessellation error of a 96 × 48 sphere: R (1 - cos(π/48)) ≈ 2e-4 R; more near the poles.
  for (int j = 0; j < t.height_samples(); ++j) {
    const double y = t.sample_height(j);
    const double expect = std::sqrt(R * R - y * y);
    for (int i = 0; i < t.azimuth_samples(); ++i) {
      EXPECT_NEAR(t.radius(i, j), expect, 2e-3 * R + 3e-3 * (R - expect)) << i << " " << j;
      const Vec3 p = t.sample_point(i, j);
      EXPECT_NEAR((p - c).norm(), R, 2.5e-3 * R);
      EXPECT_GT(t.normal(i, j).dot((p - c).normalized()), std::cos(5.0 * kPi / 180.0));
    }
  }
  EXPECT_DOUBLE_EQ(t.coverage(), 1.0);
  EXPECT_NEAR(t.max_radius(), R, 1e-3 * R);
}

TEST(CylinderTable, SphereInsideOutsideAndNearestPoint) {
  Context ctx(2, 1);
  const Vec3 c(0, 0, 0);
  const double R = 0.1;
  geom::TriMesh m = sphere(c, R);
  m.compute_normals();  // smooth normals, interpolated at the ray hits
  const CylinderTable t = CylinderTable::build(ctx, m, y_axis(c, -0.09, 0.09), 128, 129);
  Rng rng(7);
  int checked = 0;
  for (int k = 0; k < 4000; ++k) {
    const Vec3 p(rng.uniform(-0.12, 0.12), rng.uniform(-0.085, 0.085), rng.uniform(-0.12, 0.12));
    const double d = p.norm() - R;
    if (std::abs(d) < 2e-3) continue;  // tessellation + interpolation band
    const sim::CylinderQuery q = t.query(p);
    ASSERT_TRUE(q.over_body);
    EXPECT_EQ(q.inside, d < 0) << p.transpose();
    EXPECT_EQ(t.inside(p), d < 0);
    sim::CylinderContactF cf;
    EXPECT_EQ(t.contact(float(p.x()), float(p.y()), float(p.z()), 0.0f, cf), d < 0);
    // Nearest point T (tangent-plane projection) vs the sphere's true nearest point.
    // N is the sphere's normal at Q; T, the projection onto the tangent plane at Q, is the
    // true nearest point to second order in the depth.
    if (d < 0 && std::abs(p.y()) < 0.07) {
      EXPECT_NEAR((q.surface - c).norm(), R, 1e-3);
      EXPECT_GT(q.normal.dot((q.surface - c).normalized()), std::cos(2.0 * kPi / 180.0));
    }
    if (d < 0 && d > -0.005 && std::abs(p.y()) < 0.07) {
      const Vec3 truth = c + R * p.normalized();
      EXPECT_LT((q.closest - truth).norm(), 1e-3) << p.transpose();
      EXPECT_NEAR(q.distance, d, 5e-4);
      ++checked;
    }
  }
  EXPECT_GT(checked, 50);
  // Outside the height range: never inside, even on the axis.
  EXPECT_FALSE(t.query(Vec3(0, 0.095, 0)).inside);
  EXPECT_FALSE(t.query(Vec3(0, -0.095, 0)).over_body);
  EXPECT_TRUE(t.query(Vec3(0, 0.0, 0)).inside);
  // NaN is outside, not a crash.
  EXPECT_FALSE(t.query(Vec3(std::nan(""), 0, 0)).inside);
}

TEST(CylinderTable, CylinderRadiusMarginAndHeightRange) {
  Context ctx(1, 1);
  const double R = 0.05;
  const geom::TriMesh m = tube(Vec3(0.3, 0, 0.2), R, R, 0.0, 0.4);
  const CylinderTable t =
      CylinderTable::build(ctx, m, y_axis(Vec3(0.3, 0, 0.2), 0.01, 0.39), 48, 16, 0.004);
  for (int j = 0; j < t.height_samples(); ++j)
    for (int i = 0; i < t.azimuth_samples(); ++i)
      EXPECT_NEAR(t.radius(i, j), R, R * (1 - std::cos(kPi / 128)) + 1e-6);
  const Vec3 o(0.3, 0.2, 0.2);
  const Vec3 dir = Vec3(1, 0, 1).normalized();
  EXPECT_TRUE(t.inside(o + 0.040 * dir));
  EXPECT_TRUE(t.inside(o + 0.052 * dir));          // within the 4 mm margin
  EXPECT_FALSE(t.inside(o + 0.0545 * dir));        // beyond it
  EXPECT_TRUE(t.inside(o + 0.0545 * dir, 0.001));  // widened by `extra`
  const sim::CylinderQuery q = t.query(o + 0.045 * dir);
  EXPECT_NEAR(q.distance, -0.009, 2e-4);  // (P - Q)·N, Q at R + margin
  EXPECT_NEAR((q.surface - (o + 0.054 * dir)).norm(), 0.0, 2e-4);
  EXPECT_NEAR(q.r_q, R, 2e-4);
  // Beyond the height range nothing is inside although the radius is small.
  EXPECT_FALSE(t.inside(Vec3(0.3, 0.395, 0.2)));
  EXPECT_FALSE(t.inside(Vec3(0.3, 0.005, 0.2)));
  EXPECT_TRUE(t.inside(Vec3(0.3, 0.385, 0.2)));
}

TEST(CylinderTable, RotatedMeshGivesTheSameTable) {
  Context ctx(2, 1);
  // An elliptic tube (so the azimuth matters) rotated and moved arbitrarily; up and reference
  // rotate with it.
  const geom::TriMesh base = tube(Vec3::Zero(), 0.06, 0.035, -0.1, 0.1);
  const Mat3 Rm = Eigen::AngleAxisd(1.1, Vec3(0.3, -0.5, 0.8).normalized()).toRotationMatrix();
  const Vec3 shift(0.4, -1.2, 2.0);
  geom::TriMesh rot = base;
  for (Vec3& p : rot.positions) p = Rm * p + shift;
  CylinderAxis a = y_axis(Vec3::Zero(), -0.09, 0.09);
  const CylinderTable t0 = CylinderTable::build(ctx, base, a, 40, 12);
  a.origin = shift;
  a.up = Rm * Vec3::UnitY();
  a.reference = Rm * Vec3::UnitX() + 0.3 * a.up;  // not orthogonal: orthogonalised
  const CylinderTable t1 = CylinderTable::build(ctx, rot, a, 40, 12);
  for (int j = 0; j < 12; ++j)
    for (int i = 0; i < 40; ++i) {
      EXPECT_NEAR(t0.radius(i, j), t1.radius(i, j), 1e-6);
      EXPECT_GT((Rm * t0.normal(i, j)).dot(t1.normal(i, j)),
                std::cos(6.0 * kPi / 180.0));  // edge hits may pick either face
    }
  // Analytic radius of the ellipse at the sample azimuths (polygon error ~ 3e-4 of the axis).
  for (int i = 0; i < 40; ++i) {
    const double th = t0.sample_azimuth(i);
    const double r = 1.0 / std::hypot(std::cos(th) / 0.06, std::sin(th) / 0.035);
    EXPECT_NEAR(t0.radius(i, 5), r, 3e-4 * 0.06);
  }
  Rng rng(11);
  for (int k = 0; k < 2000; ++k) {
    const Vec3 p(rng.uniform(-0.08, 0.08), rng.uniform(-0.12, 0.12), rng.uniform(-0.08, 0.08));
    const sim::CylinderQuery q0 = t0.query(p), q1 = t1.query(Rm * p + shift);
    if (std::abs(q0.r_p - q0.r_q) < 1e-4) continue;  // float rounding of the moved point
    EXPECT_EQ(q0.inside, q1.inside);
    EXPECT_NEAR(q0.r_q, q1.r_q, 1e-5);
  }
}

TEST(CylinderTable, AzimuthWrapAroundIsContinuous) {
  Context ctx(1, 1);
  // Off-centre elliptic tube: the radius about the axis varies with azimuth, also across 0.
  const geom::TriMesh m = tube(Vec3(0.01, 0, 0.015), 0.07, 0.04, -0.1, 0.1, 180);
  const CylinderTable t = CylinderTable::build(ctx, m, y_axis(Vec3::Zero(), -0.05, 0.05), 24, 6);
  const int M = t.azimuth_samples();
  // The table's azimuth runs from `reference` towards up × reference.
  const Vec3 ra = t.axis().reference, rb = t.axis().up.cross(ra);
  auto at = [&](double th, double y) {
    return 1e-3 * (std::cos(th) * ra + std::sin(th) * rb) + y * Vec3::UnitY();
  };
  EXPECT_GT(std::abs(t.radius(M - 1, 2) - t.radius(0, 2)), 1e-3);  // a real jump to bridge
  double prev = -1;
  for (int k = -200; k <= 200; ++k) {
    const double th = 2 * kPi / M * k / 200.0;  // from the last cell across 0 into the first
    const Vec3 p = at(th, 0.01);
    const sim::CylinderQuery q = t.query(p);
    ASSERT_TRUE(q.inside);
    if (prev >= 0) {
      EXPECT_LT(std::abs(q.r_q - prev), 2e-4) << th;
    }
    prev = q.r_q;
  }
  // In the last cell the radius is the linear interpolation of column M-1 and column 0.
  const double y = t.sample_height(2);
  const double th = 2 * kPi * (M - 0.25) / M;
  const sim::CylinderQuery q = t.query(at(th, y));
  EXPECT_NEAR(q.r_q, 0.25 * t.radius(M - 1, 2) + 0.75 * t.radius(0, 2), 1e-5);
}

TEST(CylinderTable, GapNeverReportsInside) {
  Context ctx(1, 1);
  // Open tube with the wedge of azimuth [0, π/2) missing (no caps): lines there meet nothing.
  const double R = 0.05;
  const geom::TriMesh m = tube(Vec3::Zero(), R, R, -0.1, 0.1, 64, 4, false, 0.0, kPi / 2);
  const CylinderTable t = CylinderTable::build(ctx, m, y_axis(Vec3::Zero(), -0.08, 0.08), 32, 9);
  // The table's azimuth runs from +x towards up × x = -z: the tube's angle 3·11.25° (in the gap)
  // is column 32 - 3.
  EXPECT_EQ(t.radius(29, 4), 0.0);
  EXPECT_NEAR(t.radius(3, 4), R, 1e-3);
  EXPECT_NEAR(t.radius(16, 4), R, 1e-3);
  EXPECT_LT(t.coverage(), 0.8);
  Rng rng(5);
  for (int k = 0; k < 3000; ++k) {
    const double th = rng.uniform(0.0, 2 * kPi), r = rng.uniform(0.0, 0.9 * R);
    const Vec3 p(r * std::cos(th), rng.uniform(-0.07, 0.07), r * std::sin(th));
    const sim::CylinderQuery q = t.query(p);
    // Samples at 0 and π/2 (columns 0 and 8) are hits on the gap's edge faces or misses; the gap
    // interior (one cell away from its edges) never reports inside; the far side always does.
    if (th > 2 * kPi / 32 * 1.5 && th < kPi / 2 - 2 * kPi / 32 * 1.5) {
      EXPECT_FALSE(q.inside) << th;
      EXPECT_FALSE(q.over_body);
    }
    if (th > kPi / 2 + 2 * kPi / 32 && th < 2 * kPi - 2 * kPi / 32) {
      EXPECT_TRUE(q.inside) << th;
    }
  }
}

TEST(CylinderTable, BadParameters) {
  Context ctx(1, 1);
  const geom::TriMesh m = sphere(Vec3::Zero(), 0.1, 16, 8);
  const CylinderAxis ok = y_axis(Vec3::Zero(), -0.05, 0.05);
  EXPECT_THROW(CylinderTable::build(ctx, m, ok, 2, 8), Error);
  EXPECT_THROW(CylinderTable::build(ctx, m, ok, 8, 1), Error);
  EXPECT_THROW(CylinderTable::build(ctx, m, ok, 8, 8, -1.0), Error);
  CylinderAxis a = ok;
  a.up = Vec3::Zero();
  EXPECT_THROW(CylinderTable::build(ctx, m, a, 8, 8), Error);
  a = ok;
  a.reference = Vec3(0, 2, 0);
  EXPECT_THROW(CylinderTable::build(ctx, m, a, 8, 8), Error);
  a = ok;
  a.y1 = a.y0;
  EXPECT_THROW(CylinderTable::build(ctx, m, a, 8, 8), Error);
  a = ok;
  a.origin.x() = std::nan("");
  EXPECT_THROW(CylinderTable::build(ctx, m, a, 8, 8), Error);
  EXPECT_THROW(CylinderTable::build(ctx, geom::TriMesh{}, ok, 8, 8), Error);

  CylinderBodyParams p;
  EXPECT_NO_THROW(p.validate());
  p.azimuth_samples = 2;
  try {
    p.validate();
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("cylinder_body.azimuth_samples"), std::string::npos);
  }
  p = {};
  p.margin = -0.01;
  EXPECT_THROW(p.validate(), Error);
  p = {};
  p.parts.push_back({"head", 0.7, 0.6});
  try {
    p.validate();
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("cylinder_body.parts[0]"), std::string::npos);
  }
  p = {};
  p.parts.push_back({"head", 0.5, 1.5});
  EXPECT_THROW(p.validate(), Error);
  EXPECT_THROW(sim::build_cylinder_body(ctx, m, Vec3::UnitY(), Vec3::UnitY(), {}), Error);
  EXPECT_THROW(sim::build_cylinder_body(ctx, m, Vec3::Zero(), Vec3::UnitZ(), {}), Error);
  EXPECT_THROW(sim::build_cylinder_body(ctx, geom::TriMesh{}, Vec3::UnitY(), Vec3::UnitZ(), {}),
               Error);
}

namespace {

// A snowman bust: head sphere (r 0.1 at y 0.45), neck tube (r 0.05, y 0.25..0.40), trunk
// elliptic tube (0.2 × 0.1, y 0..0.27).
geom::TriMesh snowman() {
  geom::TriMesh m = sphere(Vec3(0, 0.45, 0), 0.1, 64, 32);
  append(m, tube(Vec3::Zero(), 0.05, 0.05, 0.25, 0.37, 64, 6));
  append(m, tube(Vec3::Zero(), 0.2, 0.1, 0.0, 0.27, 96, 8));
  return m;
}

}  // namespace

TEST(CylinderBody, AutomaticHeadNeckTrunkSplit) {
  Context ctx(2, 1);
  const geom::TriMesh m = snowman();
  const auto parts = sim::auto_cylinder_parts(m, Vec3::UnitY(), Vec3::UnitZ(), 0.03);
  ASSERT_EQ(parts.size(), 3u);
  EXPECT_EQ(parts[0].name, "head");
  EXPECT_EQ(parts[1].name, "neck");
  EXPECT_EQ(parts[2].name, "trunk");
  const double H = 0.55;
  // The neck's narrowest slices lie between the trunk top (0.27) and the head bottom (0.35).
  EXPECT_GT(parts[0].bottom * H, 0.24);
  EXPECT_LT(parts[0].bottom * H, 0.37);
  EXPECT_GT(parts[2].top * H, 0.25);
  EXPECT_LT(parts[2].top * H, 0.33);
  const CylinderBody body = sim::build_cylinder_body(ctx, m, Vec3::UnitY(), Vec3::UnitZ(), {});
  ASSERT_EQ(body.num_parts(), 3u);
  auto part_of = [&](const Vec3& p) {
    const sim::CylinderQuery q = body.query(p);
    return q.inside ? body.part_name(std::size_t(q.part)) : std::string("none");
  };
  EXPECT_EQ(part_of(Vec3(0.0, 0.45, 0.05)), "head");
  EXPECT_EQ(part_of(Vec3(0.15, 0.1, 0.0)), "trunk");
  EXPECT_EQ(part_of(Vec3(0.0, 0.45, 0.11)), "none");
  EXPECT_EQ(part_of(Vec3(0.1, 0.32, 0.0)), "none");   // beside the neck, above the shoulders
  EXPECT_NE(part_of(Vec3(0.0, 0.31, 0.03)), "none");  // in the neck
  EXPECT_TRUE(body.inside(Vec3(0.19, 0.2, 0.0)));
  EXPECT_FALSE(body.inside(Vec3(0.21, 0.2, 0.0)));
  // Explicit bands and a body built from a rotated mesh agree with the upright one.
  const Mat3 Rm = Eigen::AngleAxisd(0.7, Vec3(1, 0.2, -0.4).normalized()).toRotationMatrix();
  geom::TriMesh rot = m;
  for (Vec3& p : rot.positions) p = Rm * p;
  const CylinderBody body_r =
      sim::build_cylinder_body(ctx, rot, Rm * Vec3::UnitY(), Rm * Vec3::UnitZ(), {});
  ASSERT_EQ(body_r.num_parts(), 3u);
  Rng rng(3);
  int agree = 0, total = 0;
  for (int k = 0; k < 2000; ++k) {
    const Vec3 p(rng.uniform(-0.25, 0.25), rng.uniform(0.0, 0.55), rng.uniform(-0.15, 0.15));
    const sim::CylinderQuery a = body.query(p), b = body_r.query(Rm * p);
    if (a.inside && std::abs(a.distance) < 1e-4) continue;
    ++total;
    agree += a.inside == b.inside ? 1 : 0;
  }
  EXPECT_GE(agree, total - 2);  // single-precision rounding on the surface only
}

TEST(CylinderBody, DeepestPartInAnOverlap) {
  Context ctx(1, 1);
  // Two overlapping bands of a sphere with explicit fractions: a point in the overlap is
  // reported by the part where it is deepest, and both agree on inside.
  const geom::TriMesh m = sphere(Vec3::Zero(), 0.1, 64, 32);
  CylinderBodyParams p;
  p.parts = {{"lower", 0.0, 0.6}, {"upper", 0.4, 1.0}};
  const CylinderBody body = sim::build_cylinder_body(ctx, m, Vec3::UnitY(), Vec3::UnitX(), p);
  ASSERT_EQ(body.num_parts(), 2u);
  const sim::CylinderQuery q = body.query(Vec3(0.02, 0.0, 0.0));
  ASSERT_TRUE(q.inside);
  const sim::CylinderQuery q0 = body.part(0).query(Vec3(0.02, 0.0, 0.0));
  const sim::CylinderQuery q1 = body.part(1).query(Vec3(0.02, 0.0, 0.0));
  EXPECT_DOUBLE_EQ(q.distance, std::min(q0.distance, q1.distance));
  EXPECT_TRUE(body.query(Vec3(0.0, 0.08, 0.0)).inside);
  EXPECT_EQ(body.part_name(std::size_t(body.query(Vec3(0.0, 0.08, 0.0)).part)), "upper");
  EXPECT_EQ(body.query(Vec3(0.5, 0.0, 0.0)).inside, false);
  EXPECT_EQ(body.query(Vec3(0.0, 0.5, 0.0)).part, -1);
}
