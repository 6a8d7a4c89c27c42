#pragma once
// Ellipsoid collider (Anjyo 1992 §2 step [α]): centre, semi-axes and a rotation whose columns are
// the ellipsoid's local axes in world coordinates. The local frame follows the head convention:
// local y up, local z towards the face, local x to the head's left.
//
// Quadric form E(p) = |q|^2 - 1 with q = R^T (p - c) ./ radii ("normalized hull coordinates":
// the hull is the unit sphere in q); E < 0 inside, E = 0 on the surface.
//
// Polar coordinates: zenith θ in [0, π] from local +y (θ = 0 at the crown), azimuth φ in (-π, π]
// measured in the local zx plane from +z (the face, φ = 0) towards +x (φ = π/2), back of the head
// at φ = ±π. They are the parametric angles: q = (sinθ sinφ, cosθ, sinθ cosφ).
#include <vector>

#include "follicle/core/types.hpp"

namespace follicle::sim {

struct Ellipsoid {
  Vec3 centre = Vec3::Zero();        // [m]
  Vec3 radii = Vec3::Ones();         // [m] semi-axes along local x, y, z
  Mat3 rotation = Mat3::Identity();  // columns: local axes in world

  /// Normalized hull coordinates q (unit sphere = hull surface).
  Vec3 normalized(const Vec3& p) const {
    return (rotation.transpose() * (p - centre)).cwiseQuotient(radii);
  }
  Vec3 from_normalized(const Vec3& q) const { return centre + rotation * q.cwiseProduct(radii); }
  /// E(p) = |q|^2 - 1: negative inside.
  double value(const Vec3& p) const { return normalized(p).squaredNorm() - 1.0; }
  bool inside(const Vec3& p) const { return value(p) < 0.0; }
  /// (E_x, E_y, E_z): gradient of the quadric form (outward, not normalized).
  Vec3 gradient(const Vec3& p) const;
  /// Outward unit normal of the level surface through p.
  Vec3 normal(const Vec3& p) const { return gradient(p).normalized(); }

  /// (azimuth φ, zenith θ) of p (see the file comment); the centre maps to (0, 0).
  Vec2 polar(const Vec3& p) const;
  /// The surface point with polar coordinates (azimuth, zenith).
  Vec3 surface_point(double azimuth, double zenith) const;
  /// Surface area element ratio dA/dΩ at the direction of q (for uniform-area sampling).
  double area_density(const Vec3& q_unit) const;

  /// Radial push-out: p itself when E(p) >= 0, else the point where the ray from the centre
  /// through p leaves the hull grown by `margin` (a few percent from the true closest point on
  /// head-like hulls, exact on a sphere). Cheap: no root finding.
  Vec3 push_out(const Vec3& p, double margin = 0.0) const;
  /// Exact closest point on the surface (Newton on the Lagrange multiplier; works inside and out).
  Vec3 closest_point(const Vec3& p) const;
  /// The hull grown by `margin` metres along every semi-axis.
  Ellipsoid grown(double margin) const {
    Ellipsoid e = *this;
    e.radii.array() += margin;
    return e;
  }
};

/// How to fit a hull to a head mesh (see fit_head_ellipsoid).
struct EllipsoidFitParams {
  double cap_depth = 0.11;  // [m] vertices within this distance below the highest one (the cranium)
  double coverage = 0.985;  // fraction of cranium vertices that must end up inside the hull
  double margin = 0.002;    // [m] added to every semi-axis afterwards
  double max_aspect = 1.6;  // semi-axes are clamped to [min_r, max_aspect * min_r] (cap fits are
                            // unconstrained below)

  template <class V>
  void visit(V&& v) {
    v("cap_depth", cap_depth, {"depth of the cranium cap used for the fit", "m", 0.01, 1.0});
    v("coverage", coverage, {"fraction of cap vertices inside the hull", "", 0.5, 1.0});
    v("margin", margin, {"extra clearance on every semi-axis", "m", 0.0, 0.1});
    v("max_aspect", max_aspect, {"largest semi-axis / smallest semi-axis", "", 1.0, 4.0});
  }
  void validate() const;
};

/// Fits an ellipsoid hull to a head (y up, face +z): takes the cranium cap (vertices within
/// cap_depth of the top), least-squares fits the axis-aligned quadric
/// A x² + B y² + C z² + D x + E y + F z = 1 to it (an algebraic fit; a cap leaves the y extent
/// weakly determined, hence the aspect clamp), then scales the semi-axes about the centre so
/// that `coverage` of the cap lies inside, and adds `margin`. Throws follicle::Error when the
/// mesh has too few vertices or the fit degenerates.
Ellipsoid fit_head_ellipsoid(const std::vector<Vec3>& positions,
                             const EllipsoidFitParams& params = {});
/// The same fit in a head frame: `frame` is a rotation whose columns are the head's left, up and
/// face directions in world; the cap is taken along its up axis and the hull gets that rotation,
/// so a head facing any way gets the hull (and every style laid out on it) it would get upright.
Ellipsoid fit_head_ellipsoid(const std::vector<Vec3>& positions, const Mat3& frame,
                             const EllipsoidFitParams& params = {});

}  // namespace follicle::sim
