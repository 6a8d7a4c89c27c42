#include "follicle/hair/cantilever_anjyo1992.hpp"

#include <cmath>
#include <vector>

#include "follicle/core/error.hpp"
#include "follicle/core/params.hpp"

namespace follicle::hair {

void CantileverParams::validate() const {
  validate_params(*this, "cantilever");
}

namespace {

Vec3 any_perpendicular(const Vec3& a) {
  const Vec3 t = std::abs(a.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  return a.cross(t).normalized();
}

}  // namespace

Vec3 avoid_hull_in_plane(const sim::Ellipsoid& hull, const Vec3& p_prev2, const Vec3& p_prev,
                         const Vec3& p) {
  if (hull.value(p) >= 0.0) return p;
  const Vec3 seg = p - p_prev;
  const double d = seg.norm();
  if (d <= 0.0) return hull.push_out(p);
  const Vec3 u = seg / d;
  Vec3 a = p_prev - p_prev2;
  if (a.norm() <= 1e-12 * d) a = u;
  const Vec3 grad = hull.gradient(p);
  // The rotation plane: p_{i-2}, p_{i-1}, p_i; degenerate (collinear) -> the plane holding
  // p_{i-2}, p_{i-1} and the outward normal at p_i; doubly degenerate -> any plane holding a.
  Vec3 nrm = a.cross(u);
  if (nrm.norm() <= 1e-6 * a.norm()) nrm = a.cross(grad);
  if (nrm.norm() <= 1e-9 * a.norm() * grad.norm()) nrm = any_perpendicular(a);
  nrm.normalize();
  Vec3 w = nrm.cross(u);  // in-plane, perpendicular to u
  if (w.dot(grad) < 0) w = -w;
  w.normalize();
  auto at = [&](double c, double sn) { return Vec3(p_prev + d * (c * u + sn * w)); };
  // The point rotated by the angle whose half-angle tangent is t (a rational map: no sine).
  auto at_t = [&](double t) {
    const double inv = 1.0 / (1.0 + t * t);
    return at((1.0 - t * t) * inv, 2.0 * t * inv);
  };
  // Smallest rotation angle that gets out: a coarse scan, then the Illinois variant of regula
  // falsi in t = tan(angle / 2) on the hull's implicit value, which keeps the bracket (the
  // returned point is always outside) and converges in a few evaluations where a bisection to
  // the same 1e-9 needed 22. The scan rotates (cos t, sin t) by a fixed step (no trigonometric
  // call per sample).
  constexpr int kSteps = 48;
  const double cstep = std::cos(kPi / kSteps), sstep = std::sin(kPi / kSteps);
  double c = 1.0, sn = 0.0;
  double f_prev = hull.value(p);  // < 0: p is inside
  for (int s = 1; s <= kSteps; ++s) {
    const double clo = c, slo = sn;
    const double c2 = c * cstep - sn * sstep;
    sn = sn * cstep + c * sstep;
    c = c2;
    const double f = hull.value(at(c, sn));
    if (f >= 0.0) {
      double ta = slo / (1.0 + clo), tb = sn / (1.0 + c), fa = f_prev, fb = f;
      int side = 0;
      for (int it = 0; it < 40 && tb - ta > 1e-10; ++it) {
        double tm = (ta * fb - tb * fa) / (fb - fa);
        if (!(tm > ta && tm < tb)) tm = 0.5 * (ta + tb);
        const double fm = hull.value(at_t(tm));
        if (fm >= 0.0) {
          tb = tm;
          fb = fm;
          if (side == -1) fa *= 0.5;
          side = -1;
        } else {
          ta = tm;
          fa = fm;
          if (side == 1) fb *= 0.5;
          side = 1;
        }
        if (fb < 1e-12) break;  // on the surface
      }
      return at_t(tb);
    }
    f_prev = f;
  }
  return hull.push_out(p);
}

void bend_strand(const CantileverParams& prm, const sim::Ellipsoid* hull, const Vec3& root,
                 const Vec3& dir, double length, const SegmentLoadFn& extra, Vec3* nodes,
                 const ClosestPointFn& scalp) {
  const int k = prm.segments;
  const double d = length / k;
  const double seg_mass = prm.linear_density * d;
  const Vec3 n = dir.normalized();
  const sim::Ellipsoid grown = hull ? hull->grown(prm.collision_margin) : sim::Ellipsoid{};
  // Pass 0 configuration: the straight radial beam (Fig. 4a).
  for (int i = 0; i <= k; ++i) nodes[i] = root + (i * d) * n;
  // Small fixed-size scratch on the stack for the usual k <= 64.
  Vec3 g[65], T[66];
  for (int pass = 0; pass < prm.load_iterations; ++pass) {
    // Segment-averaged concentrated loads g_j [N] (Fig. 1a), at the segment midpoints.
    for (int j = 1; j <= k; ++j) {
      const Vec3 mid = 0.5 * (nodes[j - 1] + nodes[j]);
      Vec3 acc = prm.gravity;
      if (extra) acc += extra(j, mid);
      g[j] = seg_mass * acc;
    }
    // (2) bending moment on segment s_i: M_i = sum_{j>=i} g_j * lever (j - i + 1/2) d, which for
    // a uniform load equals the paper's ||g|| d (k-i+1)^2 / 2. As a vector (direction of the
    // load): T_i = g_i/2 + T_{i+1} + S_{i+1} with S the suffix sum of loads.
    Vec3 S = Vec3::Zero();
    T[k + 1] = Vec3::Zero();
    for (int i = k; i >= 1; --i) {
      T[i] = 0.5 * g[i] + T[i + 1] + S;
      S += g[i];
    }
    for (int i = 1; i <= k; ++i) {
      const Vec3 Mvec = d * T[i];  // [N m]
      // a0 along p_{i-2}p_{i-1}; for i = 1 the clamped root direction.
      const Vec3 a0 = i == 1 ? n : Vec3((nodes[i - 1] - nodes[i - 2]).normalized());
      // a1 perpendicular to a0 in the plane of a0 and a reference point (here: the load
      // direction, else any), a2 = a0 x a1 (Fig. 2).
      Vec3 perp = Mvec - Mvec.dot(a0) * a0;
      const Vec3 a1 = perp.norm() > 1e-300 ? Vec3(perp.normalized()) : any_perpendicular(a0);
      const Vec3 a2 = a0.cross(a1);
      // (3) y_i = -(1/2) M_i d^2 / (E I), per component along a1 and a2. The recurrence
      // continues along the previous chord, so the chord turns by twice the (3) offset of a
      // constant-curvature arc; euler_bernoulli uses the full M d / EI (half at the clamped
      // root segment, whose chord turns by half its end slope), which converges to the
      // Euler-Bernoulli deflection (tests/physics/hair).
      const double f = prm.euler_bernoulli ? (i == 1 ? 0.5 : 1.0) : 0.5;
      const double y1 = f * Mvec.dot(a1) * d * d / prm.flexural_rigidity;
      const double y2 = f * Mvec.dot(a2) * d * d / prm.flexural_rigidity;
      const Vec3 e = d * a0 + y1 * a1 + y2 * a2;  // e_i = p_{i-2}p_{i-1} (scaled to d) + y_i
      Vec3 p = nodes[i - 1] + (d / e.norm()) * e;
      if (hull) {
        const Vec3 prev2 = i == 1 ? Vec3(nodes[0] - d * n) : nodes[i - 2];
        p = avoid_hull_in_plane(grown, prev2, nodes[i - 1], p);
      }
      if (prm.avoid_mesh && scalp) {
        const SurfaceHit h = scalp(p);
        if ((p - h.point).dot(h.normal) < prm.collision_margin) {
          const Vec3 q = h.point + prm.collision_margin * h.normal;
          const Vec3 s = q - nodes[i - 1];
          p = s.norm() > 0 ? Vec3(nodes[i - 1] + d * s.normalized()) : q;
        }
      }
      nodes[i] = p;
    }
  }
}

}  // namespace follicle::hair
