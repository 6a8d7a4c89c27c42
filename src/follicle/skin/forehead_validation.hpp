#pragma once
// Analytic validation of large-scale wrinkles (Bando 2002 §2.7, after the digitized-forehead
// comparison): a forehead-like cylindrical patch (radius R about the vertical axis) carries
// horizontal furrows; the skin is shrunk vertically by a known fraction s0. The computed
// shrinkage must equal s0 and the wrinkled surface must match the analytic surface
//   p(theta, y) = (R + M(s0) sum_k S(|y - y_k|)) (sin theta, 0, cos theta) + (1 - s0) y e_y.
#include <vector>

#include "follicle/core/context.hpp"
#include "follicle/core/params.hpp"
#include "follicle/geom/trimesh.hpp"
#include "follicle/skin/adaptive_refine_volino1999.hpp"
#include "follicle/skin/large_wrinkles_bando2002.hpp"

namespace follicle::skin {

struct ForeheadCaseParams {
  double width = 0.10;           // arc length [m]
  double height = 0.06;          // [m]
  double radius = 0.08;          // forehead curvature radius [m]
  double grid = 0.003;           // coarse mesh spacing [m]
  double shrink = 0.5;           // s0, vertical shrinkage
  double depth = 0.010;          // d [m]: furrow depth M(s0) d = 5 mm for s0 = 0.5, r = 0
  double wrinkle_width = 0.004;  // w [m]
  double r = 0.0;
  int furrows = 3;
  double spacing = 0.014;          // between furrows [m]
  double reference_grid = 0.0005;  // analytic reference mesh spacing [m]
  RefineParams refine{4, 0.25, 6.0};
  template <class V>
  void visit(V&& v) {
    v("width", width, ParamInfo{"patch arc length", "m", 1e-3, 1.0});
    v("height", height, ParamInfo{"patch height", "m", 1e-3, 1.0});
    v("radius", radius, ParamInfo{"curvature radius", "m", 1e-2, 100.0});
    v("grid", grid, ParamInfo{"coarse spacing", "m", 1e-4, 0.1});
    v("shrink", shrink, ParamInfo{"vertical shrinkage s0", "", 0.0, 0.9});
    v("depth", depth, ParamInfo{"furrow depth d", "m", 0.0, 0.1});
    v("wrinkle_width", wrinkle_width, ParamInfo{"furrow width w", "m", 1e-4, 0.1});
    v("r", r, ParamInfo{"rest amplitude ratio", "", 0.0, 1.0});
    v("furrows", furrows, ParamInfo{"number of furrows", "", 1, 20});
    v("spacing", spacing, ParamInfo{"furrow spacing", "m", 1e-3, 1.0});
    v("reference_grid", reference_grid, ParamInfo{"reference spacing", "m", 1e-5, 0.1});
    v("refine", refine, ParamInfo{"adaptive refinement", ""});
  }
  void validate() const { validate_params(*this, "forehead_case"); }
};

struct ForeheadCase {
  geom::TriMesh rest;  // coarse patch with UVs
  std::vector<LargeWrinkle> wrinkles;
  geom::TriMesh generated;         // refined, shrunk, wrinkled by the method
  geom::TriMesh reference;         // analytic surface (fine grid)
  double mean_shrinkage = 0;       // mean computed s over all wrinkle entries
  double max_shrinkage_error = 0;  // max |s - s0|
};

/// A cylindrical patch grid with isometric UVs (u = arc/size, v = y/size, size = max(w, h));
/// radius <= 0 gives a flat patch in the z = 0 plane.
geom::TriMesh make_cylinder_patch(double width, double height, double radius, double spacing);

ForeheadCase make_forehead_case(const Context& ctx, const ForeheadCaseParams& p);

}  // namespace follicle::skin
