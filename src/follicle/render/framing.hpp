#pragma once
// Helpers that build cameras and ready-made scenes: framing a bounding box, and the textured
// default head (data/meshes/lee_perry_smith) used by the render-head benchmark and tests.
#include <filesystem>

#include "follicle/render/render_scene.hpp"

namespace follicle::render {

/// A camera looking at the centre of `box` from direction `from_dir` (pointing from the target
/// towards the eye), far enough that the bounding sphere fills `fill` (0..1] of the vertical
/// field of view. Near/far planes enclose the box.
Camera frame_box(const Eigen::AlignedBox3d& box, const Vec3& from_dir, double fov_y = 0.5,
                 double fill = 0.9, const Vec3& up = Vec3(0, 1, 0));

/// The Lee Perry-Smith head (head.obj in millimetres, albedo.jpg, normal_tangent.jpg) in
/// `head_dir`, three-quarter view, key light with shadow + fill light, Blinn-Phong (or the
/// Lafortune skin BRDF when `lafortune` is set). Throws follicle::Error when files are missing.
RenderScene make_head_scene(const std::filesystem::path& head_dir, bool lafortune = false);

}  // namespace follicle::render
