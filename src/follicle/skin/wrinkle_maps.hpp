#pragma once
// Texture maps from fine-wrinkle relief (§2.6: the superimposed height fields are bump-mapped):
// tangent-space normal maps and height/normal/displacement export as float EXR and 8-bit PNG
// for Blender or a game engine. Texture orientation as in fine_wrinkles_bando2002.hpp (row 0 =
// v = 1); tangent-space normals use +x = +u, +y = +v (OpenGL convention), z out of the skin.
#include <filesystem>
#include <string>

#include "follicle/core/context.hpp"
#include "follicle/image/image.hpp"

namespace follicle::skin {

/// Tangent-space unit normals of the surface z = relief * depth_m * strength over texels of
/// metres_per_texel (central differences, clamped at the border).
image::ImageRGBF normal_map_from_relief(const Context& ctx, const image::ImageF& relief,
                                        double depth_m, double metres_per_texel,
                                        double strength = 1.0);

struct MapExportInfo {
  double depth_m = 60e-6;       // relief unit -> metres
  double metres_per_texel = 0;  // texel size on the skin
  double strength = 1.0;        // bump strength for the normal map
};

/// Writes DIR/STEM_height.{exr,png} (relief + 1 in [0,1]: 1 = skin surface; PNG scaled by 1/2
/// so two superimposed full-depth fields fit), DIR/STEM_displacement.{exr,png} (metres; PNG maps
/// [-2 depth_m, 0] to [0, 255]) and DIR/STEM_normal.{exr,png} (RGB = n * 0.5 + 0.5).
void export_wrinkle_maps(const Context& ctx, const std::filesystem::path& dir,
                         const std::string& stem, const image::ImageF& relief,
                         const MapExportInfo& info);

}  // namespace follicle::skin
