#pragma once
// Loader for Keith Waters' own face (Parke & Waters 1996 Appendix 1 "geoface"/SimpleFace data in
// ../shared/data/waters-geoface): the left half face is mirrored (x -> -x) and welded on x = 0,
// duplicate triangles dropped, triangles turned counter-clockwise seen from the front; the 18
// linear muscles and (SimpleFace) the six expression macros become a MuscleSet.
#include <filesystem>

#include "follicle/geom/trimesh.hpp"
#include "follicle/skin/muscles_waters1987.hpp"

namespace follicle::skin {

struct WatersFace {
  geom::TriMesh mesh;  // full face, metres, y up, looking +z
  MuscleSet muscles;   // 18 linear muscles (+ expressions when expression-macros.dat exists)
};

/// `dir` holds faceline.dat, index.dat, muscle.dat and optionally expression-macros.dat.
/// Model units are converted with `metres_per_unit` (the data are plausibly centimetres).
/// Throws follicle::Error naming the file and line on malformed data.
WatersFace load_waters_geoface(const std::filesystem::path& dir, double metres_per_unit = 0.01);

}  // namespace follicle::skin
