#pragma once
// Hairdressing, Anjyo, Usami, Kurihara 1992 §2.2: a style is a list of separately designed parts
// (main hair, tufts, a ponytail), each with pore regions, cantilever parameters, extra force
// fields applied to regions ("combing") and cutting rules. Positions inside a style are given in
// normalized hull coordinates q (the hull is the unit sphere; q_y up, q_z towards the face, q_x
// to the head's left), so a style fits any head the hull was fitted to.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "follicle/core/context.hpp"
#include "follicle/geom/strands.hpp"
#include "follicle/hair/cantilever_anjyo1992.hpp"
#include "follicle/hair/pores.hpp"

namespace follicle::hair {

/// Pore selection by the root's hull polar coordinates (wraps through ±π when min > max).
struct PolarRange {
  double azimuth_min = -kPi, azimuth_max = kPi;  // [rad]
  double zenith_min = 0.0, zenith_max = kPi;     // [rad]
  template <class V>
  void visit(V&& v) {
    v("azimuth_min", azimuth_min, {"", "rad", -kPi, kPi});
    v("azimuth_max", azimuth_max, {"", "rad", -kPi, kPi});
    v("zenith_min", zenith_min, {"", "rad", 0.0, kPi});
    v("zenith_max", zenith_max, {"", "rad", 0.0, kPi});
  }
  bool contains(const Vec2& polar) const;
};

/// Node selection: min <= dot(axis, q) <= max, q = normalized hull coordinates of the node.
struct NodeRange {
  Vec3 axis{0.0, 1.0, 0.0};
  double min = -1e3, max = 1e3;
  template <class V>
  void visit(V&& v) {
    v("axis", axis, {"axis in normalized hull coordinates", "", -1e3, 1e3});
    v("min", min, {"lower bound of dot(axis, q)", "", -1e3, 1e3});
    v("max", max, {"upper bound of dot(axis, q)", "", -1e3, 1e3});
  }
  bool contains(const Vec3& q) const {
    const double s = axis.dot(q);
    return s >= min && s <= max;
  }
};

/// Combing force field (Fig. 5b), an acceleration [m/s²] added to gravity on the selected
/// segments of the selected strands. kind: "uniform" (vector), "attract" (strength towards
/// `point`, normalized hull coordinates), "radial" (strength away from the hull centre).
struct ForceField {
  std::string kind = "uniform";
  Vec3 vector = Vec3::Zero();  // [m/s²] uniform field (the hull's axes: x left, y up, z face)
  Vec3 point = Vec3::Zero();   // attract: target in normalized hull coordinates
  double strength = 0.0;       // [m/s²] attract / radial
  PolarRange pores;
  NodeRange nodes;
  template <class V>
  void visit(V&& v) {
    v("kind", kind, {"uniform | attract | radial"});
    v("vector", vector, {"uniform field (head axes: x left, y up, z face)", "m/s^2", -1e4, 1e4});
    v("point", point, {"attract target (normalized hull coordinates)", "", -10.0, 10.0});
    v("strength", strength, {"attract/radial strength", "m/s^2", -1e4, 1e4});
    v("pores", pores);
    v("nodes", nodes);
  }
  void validate() const;
  Vec3 accel(const sim::Ellipsoid& hull, const Vec3& p) const;
};

/// Cutting (§2.2): "threshold": segments of the selected strands are removed below
/// dot(axis, q) = threshold (the strand ends exactly at the crossing); "height_length": the kept
/// length depends on the pore height q_y (Fig. 6d): linear from length_low at height_low to
/// length_high at height_high, clamped.
struct CutRule {
  std::string kind = "threshold";
  PolarRange pores;
  Vec3 axis{0.0, 1.0, 0.0};
  double threshold = -10.0;
  double height_low = -1.0, height_high = 1.0;  // pore q_y
  double length_low = 0.03, length_high = 0.1;  // [m]
  template <class V>
  void visit(V&& v) {
    v("kind", kind, {"threshold | height_length"});
    v("pores", pores);
    v("axis", axis, {"cut axis (normalized hull coordinates)", "", -1e3, 1e3});
    v("threshold", threshold, {"nodes below are removed", "", -1e3, 1e3});
    v("height_low", height_low, {"pore height q_y of length_low", "", -10.0, 10.0});
    v("height_high", height_high, {"pore height q_y of length_high", "", -10.0, 10.0});
    v("length_low", length_low, {"kept length at height_low", "m", 0.0, 5.0});
    v("length_high", length_high, {"kept length at height_high", "m", 0.0, 5.0});
  }
  void validate() const;
};

/// A tied bunch (ponytail, Fig. 6c): strands are combed along the hull to `point` and continue
/// from there as a separately designed tail hanging from the tie under gravity.
struct TieParams {
  bool enabled = false;
  Vec3 point{0.0, 0.35, -1.0};          // tie position (normalized hull coordinates)
  double radius = 0.012;                // [m] radius of the tail at the tie
  Vec3 tail_direction{0.0, 0.2, -1.0};  // initial tail direction (the hull's axes)
  double surface_offset = 0.004;        // [m] combed hair lies this far outside the hull
  template <class V>
  void visit(V&& v) {
    v("enabled", enabled, {"tie this part into a tail"});
    v("point", point, {"tie point (normalized hull coordinates)", "", -10.0, 10.0});
    v("radius", radius, {"tail radius at the tie", "m", 0.0, 0.2});
    v("tail_direction", tail_direction, {"initial tail direction (head axes)", "", -1.0, 1.0});
    v("surface_offset", surface_offset, {"combed hair height above the hull", "m", 0.0, 0.05});
  }
};

struct HairPart {
  std::string name = "main";
  std::vector<PoreRegion> pores;
  CantileverParams beam;
  std::vector<ForceField> fields;
  std::vector<CutRule> cuts;
  TieParams tie;
  template <class V>
  void visit(V&& v) {
    v("name", name, {"part name"});
    v("pores", pores);
    v("beam", beam);
    v("fields", fields);
    v("cuts", cuts);
    v("tie", tie);
  }
  void validate() const;
};

struct HairStyle {
  std::string name = "custom";
  std::vector<HairPart> parts;
  template <class V>
  void visit(V&& v) {
    v("name", name, {"style name"});
    v("parts", parts);
  }
  void validate() const;
};

/// Named presets: "bob" (Fig. 3), "swept_back" (Fig. 6b), "ponytail" (Fig. 6c), "short_cut"
/// (Fig. 6d). `density_scale` multiplies every pore density (previews, benchmarks).
HairStyle style_preset(std::string_view name, double density_scale = 1.0);
std::vector<std::string> style_preset_names();

/// Styled hair: strands (cut) plus, per strand, its root record and part index.
struct StyledHair {
  geom::StrandSet strands;  // root first; point count varies after cutting
  HairRoots roots;          // one per strand
  std::vector<uint32_t> part;
};

/// Runs pore sampling, bending with combing fields and cutting for every part; parallel over
/// strands and bit-identical for any thread count. `scalp` places roots on the real head (and
/// feeds CantileverParams::avoid_mesh).
StyledHair build_style(const Context& ctx, const sim::Ellipsoid& hull, const HairStyle& style,
                       uint64_t seed, const ClosestPointFn& scalp = {});

/// Bends given roots with one part's beam and fields, then cuts (no pore sampling): the core of
/// build_style, exposed for tests and benchmarks. nodes: roots.size() x (k+1), strand-major.
void style_roots(const Context& ctx, const sim::Ellipsoid& hull, const HairPart& part,
                 const HairRoots& roots, uint64_t seed, geom::StrandSet& out,
                 const ClosestPointFn& scalp = {});

}  // namespace follicle::hair
