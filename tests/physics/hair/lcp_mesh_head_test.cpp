// LCP hair (Bando 2003 ch. 3) on the Lee Perry-Smith head mesh: the scalp trimmed by the four
// default Catmull-Rom curves (§3.3.1) covers the head from the nape to the hairline, and during a
// head shake the voxel-plane body collision (§3.5) keeps every particle outside the head (signed
// distance from the closest mesh point, Embree query, sign from the interpolated normal).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include "follicle/geom/mesh_io.hpp"
#include "follicle/geom/spatial_embree.hpp"
#include "follicle/hair/lcp_scenario_bando2003.hpp"
#include "testing/testing.hpp"

using namespace follicle;
using namespace follicle::hair;

namespace {

geom::TriMesh lee_perry_smith() {
  auto m = geom::load_mesh(test::source_dir() / "data" / "meshes" / "lee_perry_smith" / "head.obj",
                           LengthUnit::mm);
  if (!m.has_normals()) m.compute_normals();
  return m;
}

// Signed distance of x to the mesh: negative inside (against the interpolated vertex normal at
// the closest point).
double signed_distance(const geom::MeshQuery& q, const geom::TriMesh& m, const Vec3& x) {
  const geom::ClosestPoint cp = q.closest_point(x);
  const Vec3i& f = m.faces[std::size_t(cp.face)];
  const Vec3 n =
      cp.bary[0] * m.normals[f[0]] + cp.bary[1] * m.normals[f[1]] + cp.bary[2] * m.normals[f[2]];
  const double d = (x - cp.point).norm();
  return (x - cp.point).dot(n) < 0 ? -d : d;
}

struct ShakeResult {
  double deepest = 0;  // [m] deepest penetration over the run (>= 0)
  std::size_t particles = 0;
  int substeps = 0;
};

// Shakes the head for `seconds` and returns the deepest particle inside the head (cranium region
// y > 0, where the mesh is a closed surface around the particles).
ShakeResult shake(bool body_collision, double seconds, const char* integrator = "leapfrog",
                  bool speculative = true) {
  Context ctx(2, 7);
  const geom::TriMesh head = lee_perry_smith();
  const geom::MeshQuery query(head);
  LcpScenarioParams sp;
  sp.spacing = 0.02;
  sp.hair_length = 0.25;
  sp.root_normal_weight = 0.3;
  sp.shake = true;
  sp.shake_angle = 0.8;
  sp.shake_period = 0.6;
  sp.mesh_head.torso = false;
  LcpParams lp;
  lp.body_collision = body_collision;
  lp.integrator = integrator;
  lp.implicit.speculative_contact = speculative;
  LcpScenario sc(ctx, sp, lp, &head);
  ShakeResult r;
  r.particles = sc.state().x.size();
  const int frames = int(seconds * 30);
  for (int f = 0; f < frames; ++f) {
    const LcpStepReport rep = sc.step(ctx, 1.0 / 30);
    r.substeps += rep.substeps;
    EXPECT_TRUE(rep.ok) << rep.message;
    if (!rep.ok) break;
    const auto& x = sc.state().x;  // head frame = mesh frame
    for (std::size_t i = 0; i < x.size(); ++i) {
      if (sc.solver().model().root[i] || x[i].y() < 0.0) continue;
      r.deepest = std::max(r.deepest, -signed_distance(query, head, x[i]));
    }
  }
  return r;
}

}  // namespace

TEST(LcpMeshHead, ScalpCoversTheHeadFromNapeToHairline) {
  Context ctx(2, 3);
  const geom::TriMesh head = lee_perry_smith();
  LcpScenarioParams sp;
  sp.spacing = 0.02;
  LcpScenario sc(ctx, sp, {}, &head);
  const Scalp& s = sc.scalp();
  EXPECT_GT(s.area(), 0.03);  // about half of a head of radius 0.09 m
  EXPECT_LT(s.area(), 0.07);
  double front = -1;
  for (const Vec3& p : s.mesh().positions) {
    EXPECT_FALSE(p.y() < 0.13 && p.z() > 0.05);  // not the forehead or the face
    EXPECT_GT(p.y(), -0.01);                     // above the nape
    front = std::max(front, p.z());
  }
  EXPECT_GT(front, 0.065);  // reaches the front hairline
  EXPECT_GT(sc.body().num_planes(), 100u);
  // Every root lies at most s_r + spacing beneath the scalp (roots are fixed to the head).
  const geom::MeshQuery q(head);
  for (std::size_t i = 0; i < sc.state().x.size(); ++i) {
    if (sc.solver().model().root[i]) {
      EXPECT_LT(q.closest_point(sc.state().x[i]).distance, s.root_depth() + sp.spacing);
    }
  }
}

TEST(LcpMeshHead, NoParticleEndsInsideTheHeadDuringTheShake) {
  const ShakeResult with = shake(true, 1.5);
  std::printf("leapfrog shake on the scanned head: %.2f mm deep\n", with.deepest * 1e3);
  EXPECT_GT(with.particles, 100u);
  // Voxel planes approximate the surface to within a fraction of a voxel (1 cm).
  EXPECT_LT(with.deepest, 0.004);
  // Without body collision hair swings into the head: the measure can fail.
  const ShakeResult without = shake(false, 1.5);
  EXPECT_GT(without.deepest, 0.01);
}

// The implicit integrator's long sub-steps on the scanned head (ears, a concave nape): speculative
// contact (ADR 0016) keeps the hair out as the band-bounded sub-steps of ADR 0014 do, in fewer.
TEST(LcpMeshHead, ImplicitSpeculativeContactKeepsTheHairOutInFewerSubSteps) {
  const ShakeResult spec = shake(true, 1.5, "implicit", true);
  const ShakeResult band = shake(true, 1.5, "implicit", false);
  std::printf(
      "implicit shake on the scanned head: speculative %.2f mm deep in %d sub-steps, "
      "band-bounded %.2f mm in %d\n",
      spec.deepest * 1e3, spec.substeps, band.deepest * 1e3, band.substeps);
  EXPECT_LT(spec.deepest, 0.004);
  EXPECT_LT(band.deepest, 0.004);
  EXPECT_LT(spec.substeps, band.substeps);
}
