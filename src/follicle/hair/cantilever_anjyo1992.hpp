#pragma once
// Cantilever beam hair bending, Anjyo, Usami, Kurihara 1992 §2.1 (eqs. 1-3) with collision
// avoidance against the ellipsoidal hull while the nodes are generated.
#include <functional>

#include "follicle/core/types.hpp"
#include "follicle/hair/scalp.hpp"
#include "follicle/sim/ellipsoid.hpp"

namespace follicle::hair {

struct CantileverParams {
  int segments = 20;                // k: segments per strand (all of the same length d = L/k)
  double flexural_rigidity = 4e-8;  // E*I [N m²] (human hair: ~1e-8)
  double linear_density = 6.5e-6;   // ρ [kg/m] (human hair: 6.5e-6)
  Vec3 gravity{0.0, -9.81, 0.0};    // [m/s²] world
  bool euler_bernoulli = true;      // true: chord rotation M d/EI per node, which converges to
                                    // the Euler-Bernoulli deflection; false: eq. (3) literally
                                    // (half that bending)
  int load_iterations = 2;          // position-dependent loads are evaluated on the previous
                                    // pass (pass 0: the straight radial beam of Fig. 4a)
  double collision_margin = 0.002;  // [m] nodes are kept this far outside the hull
  bool avoid_mesh = false;          // also push nodes out of the real head (needs a scalp query)

  template <class V>
  void visit(V&& v) {
    v("segments", segments, {"segments per strand (k)", "", 1, 64});
    v("flexural_rigidity", flexural_rigidity, {"E*I of a hair", "N m^2", 1e-15, 1.0});
    v("linear_density", linear_density, {"mass per length", "kg/m", 1e-9, 1.0});
    v("gravity", gravity, {"gravity acceleration", "m/s^2", -100.0, 100.0});
    v("euler_bernoulli", euler_bernoulli, {"consistent bending (else eq. 3 literally)"});
    v("load_iterations", load_iterations, {"passes for position-dependent loads", "", 1, 8});
    v("collision_margin", collision_margin, {"clearance outside the hull", "m", 0.0, 0.05});
    v("avoid_mesh", avoid_mesh, {"also avoid the real head mesh"});
  }
  void validate() const;
};

/// Extra load on segment j (1-based) whose midpoint is `mid` (world), as an acceleration
/// [m/s²] (multiplied by the segment's mass ρ d). Gravity is added by the beam itself.
using SegmentLoadFn = std::function<Vec3(int j, const Vec3& mid)>;

/// Generates the nodes p_0 .. p_k of one hair (`nodes` must hold k+1 entries): root p_0, initial
/// direction `dir` (unit), length `length`. With `hull`, every new node is moved out of the hull
/// within the plane of p_{i-2}, p_{i-1}, p_i (§2.1, last paragraph); with params.avoid_mesh and
/// `scalp`, also out of the real head.
void bend_strand(const CantileverParams& params, const sim::Ellipsoid* hull, const Vec3& root,
                 const Vec3& dir, double length, const SegmentLoadFn& extra, Vec3* nodes,
                 const ClosestPointFn& scalp = {});

/// Moves p (end of the segment p_prev -> p of length d) out of `hull` (already grown by the
/// margin) by rotating the segment about p_prev within the plane of p_prev2, p_prev, p; when
/// the three points are collinear, within the plane of p_prev2, p_prev and the hull normal at p.
/// Returns p when it is outside. Falls back to the radial push-out when no rotation gets out
/// (p_prev itself deep inside).
Vec3 avoid_hull_in_plane(const sim::Ellipsoid& hull, const Vec3& p_prev2, const Vec3& p_prev,
                         const Vec3& p);

}  // namespace follicle::hair
