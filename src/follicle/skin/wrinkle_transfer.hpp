#pragma once
// Large wrinkles given on the surface instead of in texture space. A face-setup file's wrinkle
// curves are cubic Béziers in the texture space of the head it was made for (Bando 2002 §2.5);
// a head without UVs, or one mapped anew (skin[].mapping, §2.4), has another texture space. A
// wrinkle given as points on the surface (metres, the mesh's frame) is placed on any layout:
// each point goes to its closest surface point, that face's UV triangle gives the texture
// position with the same barycentric weights, and a cubic Bézier is fitted through the positions.
// Lifting is the inverse: samples of a texture-space curve located on the mesh's UV layout and
// mapped to the surface. Together they carry a wrinkle from one UV layout of a mesh to another.
#include <string>
#include <vector>

#include "follicle/core/params.hpp"
#include "follicle/core/types.hpp"
#include "follicle/geom/trimesh.hpp"
#include "follicle/skin/large_wrinkles_bando2002.hpp"

namespace follicle::skin {

struct SurfaceWrinkle {
  std::string name;
  std::vector<Vec3> points;  // >= 2, along the furrow, metres in the mesh's frame
  double depth = 0.003;      // d [m]
  double width = 0.003;      // w [m]
  double r = 0.0;            // (2.4) rest amplitude ratio
  double end_taper = 0.15;
  template <class V>
  void visit(V&& v) {
    v("name", name, ParamInfo{"wrinkle name", ""});
    v("points", points,
      ParamInfo{"points along the furrow on the skin (at least 2; metres, the mesh's frame)", "m",
                -100.0, 100.0});
    v("depth", depth, ParamInfo{"furrow depth d", "m", 0.0, 0.1});
    v("width", width, ParamInfo{"furrow width w", "m", 1e-6, 0.1});
    v("r", r, ParamInfo{"rest amplitude ratio r", "", 0.0, 1.0});
    v("end_taper", end_taper, ParamInfo{"end taper fraction", "", 0.0, 0.5});
  }
  /// Ranges, at least 2 finite points. Throws follicle::Error naming the wrinkle.
  void validate() const;
  static constexpr const char* kRequired[] = {"points"};
};

/// Samples taken along a texture-space curve when it is lifted to the surface.
constexpr int kLiftSamples = 9;

/// Texture-space wrinkles of `mesh` (which needs a UV layout) from surface wrinkles. Throws
/// follicle::Error naming `where` and the wrinkle when a point lies farther than `max_distance`
/// from the surface, or its points fall on different UV islands (it crosses a seam of the
/// layout).
std::vector<LargeWrinkle> place_surface_wrinkles(const geom::TriMesh& mesh,
                                                 const std::vector<SurfaceWrinkle>& wrinkles,
                                                 const std::string& where,
                                                 double max_distance = 0.02);

/// Surface wrinkles from texture-space ones: `samples` points at uniform arc length along each
/// curve, located on the mesh's UV layout and mapped to the surface; samples on no UV triangle
/// are dropped. Throws follicle::Error naming `where` and the wrinkle when fewer than 2 remain.
std::vector<SurfaceWrinkle> lift_wrinkles_to_surface(const geom::TriMesh& mesh,
                                                     const std::vector<LargeWrinkle>& wrinkles,
                                                     const std::string& where,
                                                     int samples = kLiftSamples);

/// The wrinkles of `from`'s UV layout on `to`'s: the same surface (positions and faces) with
/// another UV layout. Lift (33 samples), then place. One cubic in the new layout follows the old
/// curve's image within about 1 mm on the skin for the shipped 7 cm folds (measured 1.04 mm).
std::vector<LargeWrinkle> carry_wrinkles(const geom::TriMesh& from, const geom::TriMesh& to,
                                         const std::vector<LargeWrinkle>& wrinkles,
                                         const std::string& where);

}  // namespace follicle::skin
