#pragma once
// Waters (1987) facial muscles as used by Bando 2002 §2.5.2 to animate the face: linear muscles
// (angular zone, fall-off start/end, cosine fall-offs), elliptical sphincter muscles and a jaw
// rotation. Every muscle's displacement is linear in its contraction k, so a MuscleField
// precomputes per-vertex influence lists once and an update is a sparse sum.
#include <map>
#include <string>
#include <vector>

#include "follicle/core/context.hpp"
#include "follicle/core/params.hpp"
#include "follicle/core/types.hpp"

namespace follicle::skin {

/// Linear muscle (Waters 1987; the formula of Waters' SimpleFace `activate_muscle`): for a vertex
/// at v = p - origin with cos(angle(insertion - origin, v)) >= cos(zone) and |v| <= falloff_end,
///   delta = k * (1 - cos/cos(zone)) * R(|v|) * v,  R = 1 below falloff_start, else
///   cos(((|v| - fs)/(fe - fs)) * 90 deg).
/// Inside the zone (1 - cos/cos zone) <= 0, so k > 0 pulls the vertex toward the bony origin.
/// That is Waters' profile ("waters"): it reaches 0 at the zone edge and at falloff_end, but with
/// a non-zero slope, so the strain jumps there (a visible crease under strong contraction).
/// Profile "smooth" keeps Waters' structure (zone cone, fs/fe, delta proportional to v) with C1
/// fall-offs that reach 0 with zero slope:
///   t = (cos - cos zone)/(1 - cos zone), A = t^2 (3 - 2t),
///   R = 1 below fs, (1 + cos(pi (|v| - fs)/(fe - fs)))/2 up to fe,
///   delta = -k A R v,
/// so k is the compression strain on the muscle axis inside fs (k = 0.2: 20 % shortening).
struct LinearMuscle {
  std::string name;
  Vec3 origin = Vec3::Zero();             // bony attachment; vertices move toward it [m]
  Vec3 insertion = Vec3::UnitZ() * 0.01;  // skin insertion [m]
  double falloff_start = 0.001;           // fs [m]
  double falloff_end = 0.04;              // fe [m]
  double zone = 0.7853981633974483;       // angular zone half-angle [rad]
  std::string profile = "waters";         // "waters" (Waters 1987/SimpleFace) or "smooth" (C1)
  template <class V>
  void visit(V&& v) {
    v("name", name, ParamInfo{"muscle name", ""});
    v("profile", profile, ParamInfo{"fall-off profile: waters | smooth", ""});
    v("origin", origin, ParamInfo{"bony origin (vertices move toward it)", "m", -10.0, 10.0});
    v("insertion", insertion, ParamInfo{"skin insertion", "m", -10.0, 10.0});
    v("falloff_start", falloff_start, ParamInfo{"radial fall-off start", "m", 0.0, 10.0});
    v("falloff_end", falloff_end, ParamInfo{"radial fall-off end (zone radius)", "m", 1e-6, 10.0});
    v("zone", zone, ParamInfo{"angular zone half-angle", "rad", 1e-3, 1.5});
  }
  void validate() const;
  static constexpr const char* kRequired[] = {"name", "origin", "insertion"};
};

/// Sphincter muscle (elliptical, Waters 1987): pulls vertices inside the ellipse toward its
/// centre within the ellipse plane: delta = k * F(rho) * G(z) * (c - p)_plane with
/// rho = sqrt((x/a)^2 + (y/b)^2), F = 1 for rho <= falloff_start, (1 + cos(pi (rho - fs)/(1 -
/// fs)))/2 up to rho = 1, 0 outside, and G = 1 - smoothstep((|z| - depth/2) / (depth/2)) across the
/// ellipse plane (z = distance along its normal). F and G reach 0 with zero slope: no crease at
/// the ellipse outline or at the depth limit.
struct SphincterMuscle {
  std::string name;
  Vec3 center = Vec3::Zero();               // [m]
  Vec3 semi_axis_a = Vec3::UnitX() * 0.03;  // first semi-axis (direction and length) [m]
  Vec3 semi_axis_b = Vec3::UnitY() * 0.02;  // second semi-axis [m]
  double falloff_start = 0.3;               // fraction of the elliptic radius
  double depth = 0.03;                      // influence half-depth along the ellipse normal [m]
  template <class V>
  void visit(V&& v) {
    v("name", name, ParamInfo{"muscle name", ""});
    v("center", center, ParamInfo{"ellipse centre", "m", -10.0, 10.0});
    v("semi_axis_a", semi_axis_a, ParamInfo{"first semi-axis vector", "m", -10.0, 10.0});
    v("semi_axis_b", semi_axis_b, ParamInfo{"second semi-axis vector", "m", -10.0, 10.0});
    v("falloff_start", falloff_start,
      ParamInfo{"fall-off start (fraction of radius)", "", 0.0, 0.999});
    v("depth", depth, ParamInfo{"influence half-depth along the normal", "m", 1e-6, 10.0});
  }
  void validate() const;
  static constexpr const char* kRequired[] = {"name", "center", "semi_axis_a", "semi_axis_b"};
};

/// Jaw: rotation by the pose's jaw angle about `axis` through `pivot`, weighted per vertex by a
/// smooth step across the plane through `pivot` + offset * plane_normal:
/// w = smoothstep(((p - pivot).n - offset) / blend_width) (n points into the jaw).
struct JawParams {
  bool enabled = false;
  Vec3 pivot = Vec3::Zero();           // [m]
  Vec3 axis = Vec3::UnitX();           // rotation axis; positive angle opens the mouth
  Vec3 plane_normal = -Vec3::UnitY();  // points into the moving jaw region
  double offset = 0.0;                 // [m]
  double blend_width = 0.01;           // [m]
  double max_angle = 0.5;              // [rad] bound for poses
  template <class V>
  void visit(V&& v) {
    v("enabled", enabled, ParamInfo{"has a jaw", ""});
    v("pivot", pivot, ParamInfo{"rotation pivot", "m", -10.0, 10.0});
    v("axis", axis, ParamInfo{"rotation axis", "", -1e3, 1e3});
    v("plane_normal", plane_normal, ParamInfo{"normal into the jaw region", "", -1e3, 1e3});
    v("offset", offset, ParamInfo{"plane offset along the normal", "m", -10.0, 10.0});
    v("blend_width", blend_width, ParamInfo{"weight blend width", "m", 1e-6, 10.0});
    v("max_angle", max_angle, ParamInfo{"largest jaw angle", "rad", 0.0, 1.5});
  }
  void validate() const;
};

/// A named expression: contractions by muscle name plus a jaw angle.
struct Expression {
  std::string name;
  std::map<std::string, double> contractions;
  double jaw_angle = 0;  // [rad]
  template <class V>
  void visit(V&& v) {
    v("name", name, ParamInfo{"expression name", ""});
    v("contractions", contractions, ParamInfo{"muscle contraction by name", "", -10.0, 10.0});
    v("jaw_angle", jaw_angle, ParamInfo{"jaw opening", "rad", -1.5, 1.5});
  }
  void validate() const { validate_params(*this, "expression"); }
  static constexpr const char* kRequired[] = {"name"};
};

/// The muscles of one face (Waters' 18 linear muscles, or an authored set) with expressions.
struct MuscleSet {
  std::vector<LinearMuscle> linear;
  std::vector<SphincterMuscle> sphincter;
  JawParams jaw;
  std::vector<Expression> expressions;
  template <class V>
  void visit(V&& v) {
    v("linear", linear, ParamInfo{"linear muscles", ""});
    v("sphincter", sphincter, ParamInfo{"sphincter muscles", ""});
    v("jaw", jaw, ParamInfo{"jaw rotation", ""});
    v("expressions", expressions, ParamInfo{"named expressions", ""});
  }
  /// Checks every muscle and that names are unique and expressions name existing muscles.
  void validate() const;
  std::size_t num_muscles() const { return linear.size() + sphincter.size(); }
  /// Linear muscles first, then sphincters.
  std::vector<std::string> muscle_names() const;
  /// Index into muscle_names(); throws follicle::Error with a did-you-mean when unknown.
  int muscle_index(const std::string& name) const;
  const Expression& expression(const std::string& name) const;
};

/// A pose: one contraction per muscle (MuscleSet order) and a jaw angle, plus the weights of the
/// rig's blendshape targets (skin/blendshapes.hpp, target order; empty: none).
struct MusclePose {
  std::vector<double> contractions;
  double jaw_angle = 0;  // [rad]
  std::vector<double> shape_weights;
};

/// Pose of an expression scaled by `weight` (0 = neutral, 1 = full).
MusclePose pose_from_expression(const MuscleSet& set, const Expression& e, double weight = 1.0);
/// Linear blend of two poses (for contraction tracks): (1-t) a + t b (shape weights too; a pose
/// without them counts as all zero).
MusclePose blend_poses(const MusclePose& a, const MusclePose& b, double t);

/// Scalar influence of one linear muscle on a point (the factor multiplying k * (p - origin));
/// 0 outside the zone.
double linear_muscle_factor(const LinearMuscle& m, const Vec3& p);

/// Precomputed influence of a muscle set on a rest mesh.
class MuscleField {
 public:
  MuscleField(const MuscleSet& set, const std::vector<Vec3>& rest);
  /// out[i] = rest[i] + sum_m k_m D_im, then the jaw rotation. out is resized.
  void apply(const Context& ctx, const MusclePose& pose, const std::vector<Vec3>& rest,
             std::vector<Vec3>& out) const;
  std::size_t num_vertices() const { return m_offsets.empty() ? 0 : m_offsets.size() - 1; }
  std::size_t num_muscles() const { return m_num_muscles; }
  std::size_t num_entries() const { return m_entries.size(); }
  /// Vertices a muscle moves (for tests and tools).
  std::vector<int> influenced_vertices(int muscle) const;

 private:
  struct Entry {
    int muscle;
    Vec3 d;  // displacement per unit contraction
  };
  std::size_t m_num_muscles = 0;
  std::vector<std::size_t> m_offsets;  // CSR over vertices
  std::vector<Entry> m_entries;
  JawParams m_jaw;
  std::vector<std::pair<int, double>> m_jaw_weights;  // vertices with w > 0
};

}  // namespace follicle::skin
