#pragma once
// Registering one surface to another (issue 21, `follicle fit`): a similarity (rotation, uniform
// scale, translation) found by trimmed ICP from many starts, then a smooth non-rigid deformation
// of the source's vertices onto the target.
//
// - Rigid: iterative closest points (Besl & McKay 1992) in both directions, each pair set trimmed
//   to its best fraction chosen as in the fractional ICP of Phillips, Liu & Tomasi (2007)
//   (minimise RMS(xi) / xi^lambda), pairs whose normals disagree dropped, the similarity solved in
//   closed form (Umeyama 1991, Eigen::umeyama). Partial overlaps work both ways: a face mask
//   against a whole head, a head with shoulders against a bare head. The orientation search
//   starts from 120 rotations spread evenly over SO(3) (a super-Fibonacci spiral, Alexa 2022)
//   taken in the frame of the surfaces' principal axes, each at three scales, scored after a few
//   coarse rounds; the best dozen run on and the best three are refined. So a head in any rigid
//   orientation, or mirrored, is found without being told which way is up; a given up/front
//   replaces the search by one start.
// - Non-rigid: the displacement d of every source vertex from its rigid position minimises
//   sum_i w_i |x_i + d_i - c_i|^2 + alpha sum_edges |d_i - d_j|^2 + sum_landmarks w_l |...|^2
//   (a membrane on the displacement, as in Allen, Curless & Popovic 2003's smoothness term, with
//   the closest points c_i re-found each round and alpha lowered from stiff to soft, as in
//   Amberg, Romdhani & Vetter 2007's optimal-step schedule). w_i is 0 for a vertex whose closest
//   target point is too far, on the target's open boundary or faces another way, so unmatched
//   parts (the back of a head against a mask) follow their neighbours. Solved per schedule step
//   with a sparse Cholesky factorisation (Eigen::SimplicialLDLT).
// All distances are relative to the target's size where a threshold is needed, so a head in mm,
// cm or m, and the same head scaled, registers alike. Deterministic for any thread count.
#include <cstdint>
#include <string>
#include <vector>

#include "follicle/core/context.hpp"
#include "follicle/core/params.hpp"
#include "follicle/core/types.hpp"
#include "follicle/geom/trimesh.hpp"

namespace follicle::geom {

/// x -> s R x + t.
struct Similarity {
  Mat3 R = Mat3::Identity();
  double s = 1.0;
  Vec3 t = Vec3::Zero();
  Vec3 apply(const Vec3& x) const { return s * (R * x) + t; }
  Vec3 apply_direction(const Vec3& v) const { return R * v; }
  Vec3 inverse(const Vec3& y) const { return R.transpose() * (y - t) / s; }
};

struct RigidRegistrationParams {
  int rotations = 120;              // orientation starts (evenly spread), each at three scales
  uint64_t samples = 1500;          // area-uniform samples per surface for the search
  uint64_t fine_samples = 6000;     // for the refinement of the best start
  int iterations = 30;              // ICP rounds per start
  int fine_iterations = 40;         // ICP rounds of the refinement
  double min_overlap = 0.25;        // smallest fraction of target pairs kept
  double lambda = 2.0;              // FICP exponent of the target's pairs: larger keeps more
  double min_overlap_source = 0.1;  // the same for the source's pairs
  double lambda_source = 2.0;       // (a whole-head source covers a face mask at ~20 %)
  double inlier_distance = 0.01;    // x target size: a pair this close counts for the score
  double normal_agreement = 0.3;    // |n_a . n_b| below this drops a pair (winding-free)
  uint64_t seed = 7;
  template <class V>
  void visit(V&& v) {
    v("rotations", rotations, ParamInfo{"orientation starts of the search", "", 1, 10000});
    v("samples", samples,
      ParamInfo{"surface samples per mesh for the orientation search", "", 50, 1e6});
    v("fine_samples", fine_samples,
      ParamInfo{"surface samples per mesh for the refinement", "", 50, 1e7});
    v("iterations", iterations, ParamInfo{"ICP rounds per start", "", 1, 1000});
    v("fine_iterations", fine_iterations, ParamInfo{"ICP rounds of the refinement", "", 0, 1000});
    v("min_overlap", min_overlap,
      ParamInfo{"smallest fraction of target pairs kept", "", 0.05, 1.0});
    v("lambda", lambda, ParamInfo{"fractional-ICP exponent of the target's pairs", "", 0.0, 10.0});
    v("min_overlap_source", min_overlap_source,
      ParamInfo{"smallest fraction of source pairs kept", "", 0.01, 1.0});
    v("lambda_source", lambda_source,
      ParamInfo{"fractional-ICP exponent of the source's pairs", "", 0.0, 10.0});
    v("inlier_distance", inlier_distance,
      ParamInfo{"pair distance counted as a match / target size", "", 1e-5, 1.0});
    v("normal_agreement", normal_agreement,
      ParamInfo{"least |cos| between paired normals", "", 0.0, 1.0});
    v("seed", seed, ParamInfo{"sampling seed"});
  }
  void validate() const { validate_params(*this, "registration"); }
};

struct RigidRegistration {
  Similarity xf;              // source -> target
  double residual = 0;        // [m] trimmed RMS distance of the kept pairs, both directions
  double overlap_source = 0;  // share of source samples within the inlier distance of the target
  double overlap_target = 0;  // share of target samples within it of the source
  int start = -1;             // which orientation start won (-1: the given orientation)
  double score = 0;           // 3 - (2 x share of target samples matched + share of source samples)
  std::vector<double> start_scores;  // each start's coarse score (lower is better)
};

/// The similarity taking `source` onto `target`. With `initial_R` given (a proper rotation), only
/// that orientation is tried; otherwise the search over orientations. Throws follicle::Error for
/// an empty mesh or one with no area.
RigidRegistration register_rigid(const Context& ctx, const TriMesh& source, const TriMesh& target,
                                 const RigidRegistrationParams& params,
                                 const Mat3* initial_R = nullptr);

struct NonrigidRegistrationParams {
  double stiffness_start = 100.0;  // alpha of the first schedule step
  double stiffness_end = 1.0;      // alpha of the last (geometric in between)
  int steps = 5;                   // schedule steps
  int rounds_per_step = 2;         // closest points re-found this often per step
  double max_distance = 0.06;      // pairs farther than this x target size are dropped
  double normal_agreement = 0.5;   // least |cos| between a vertex normal and the target's
  double landmark_weight = 20.0;   // w_l relative to a vertex pair's 1
  template <class V>
  void visit(V&& v) {
    v("stiffness_start", stiffness_start,
      ParamInfo{"membrane stiffness of the first step", "", 1e-4, 1e6});
    v("stiffness_end", stiffness_end,
      ParamInfo{"membrane stiffness of the last step", "", 1e-4, 1e6});
    v("steps", steps, ParamInfo{"stiffness steps", "", 1, 100});
    v("rounds_per_step", rounds_per_step,
      ParamInfo{"closest-point rounds per stiffness step", "", 1, 100});
    v("max_distance", max_distance,
      ParamInfo{"largest pair distance / target size", "", 1e-4, 1.0});
    v("normal_agreement", normal_agreement,
      ParamInfo{"least |cos| between paired normals", "", 0.0, 1.0});
    v("landmark_weight", landmark_weight,
      ParamInfo{"landmark weight relative to a vertex pair", "", 0.0, 1e6});
  }
  void validate() const { validate_params(*this, "registration.nonrigid"); }
};

/// A source vertex that must land on a target point.
struct Landmark {
  int vertex = -1;  // source vertex
  Vec3 target = Vec3::Zero();
};

struct NonrigidRegistration {
  std::vector<Vec3> positions;   // the source's vertices deformed onto the target (target frame)
  std::vector<uint8_t> matched;  // 1 where the last round paired the vertex with the target
  double rms = 0;                // [m] over matched vertices, to the target surface
  double p95 = 0;                // [m]
  double matched_fraction = 0;   // of the source's vertices
};

/// Deforms `source` (placed by `rigid`) onto `target`. Throws follicle::Error for a bad
/// landmark vertex or a non-finite result.
NonrigidRegistration register_nonrigid(const Context& ctx, const TriMesh& source,
                                       const TriMesh& target, const Similarity& rigid,
                                       const std::vector<Landmark>& landmarks,
                                       const NonrigidRegistrationParams& params);

/// The size used for relative thresholds: the diagonal of the bounding box [m].
double mesh_size(const TriMesh& mesh);

}  // namespace follicle::geom
