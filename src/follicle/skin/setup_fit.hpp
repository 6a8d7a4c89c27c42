#pragma once
// Does a face setup fit a mesh? A setup's muscle positions are metres in the mesh's frame and its
// wrinkle curves lie in the mesh's texture space; a setup made for another head, or a head loaded
// in the wrong unit, moved or rotated, deforms nothing where it should and shows no wrinkles,
// silently (issue 21, item 6). This measures how far the muscles lie from the surface and how much
// of each wrinkle curve lies on the mesh's UV layout, so the scene can warn or refuse with
// numbers instead of rendering a face without wrinkles.
#include <string>
#include <vector>

#include "follicle/geom/trimesh.hpp"
#include "follicle/skin/large_wrinkles_bando2002.hpp"
#include "follicle/skin/muscles_waters1987.hpp"

namespace follicle::skin {

struct SetupFitReport {
  struct Muscle {
    std::string name;
    double distance = 0;  // [m] from its skin point (linear: insertion; sphincter: centre)
  };
  struct Wrinkle {
    std::string name;
    double outside = 0;  // fraction of the curve's samples on no UV triangle, in [0, 1]
  };
  std::vector<Muscle> muscles;    // every muscle, MuscleSet order (linear, then sphincter)
  std::vector<Wrinkle> wrinkles;  // every wrinkle
  double head_size = 0;           // [m] the mesh's bounding-box diagonal

  /// Muscles whose skin point is farther than `tolerance` from the surface.
  std::vector<Muscle> off_surface(double tolerance) const;
  /// Wrinkles with more than `fraction` of their curve outside the UV layout.
  std::vector<Wrinkle> outside_uvs(double fraction) const;
};

/// Distances by closest-point query on the mesh (Embree), UV coverage by testing 33 points per
/// curve against the mesh's UV triangles. A mesh without UVs reports every wrinkle as outside.
SetupFitReport measure_setup_fit(const geom::TriMesh& mesh, const MuscleSet& muscles,
                                 const std::vector<LargeWrinkle>& wrinkles);

/// The verdict the scene applies: a muscle's skin point more than kMuscleTolerance (2 cm) off
/// the surface is named in a warning, and when most muscles are off, or every wrinkle lies
/// wholly outside the UV layout, the setup is refused (it was made for another head or unit).
/// Returns the warnings; throws follicle::Error naming `where` and the numbers when refused.
constexpr double kMuscleTolerance = 0.02;  // [m]
std::vector<std::string> judge_setup_fit(const SetupFitReport& report, const std::string& where);

}  // namespace follicle::skin
