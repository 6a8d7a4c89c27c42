#pragma once
// Camera matrices (OpenGL conventions: right-handed view space looking down -z, clip z in
// [-w, w]) and projection of world points to output pixels.
#include <optional>

#include "follicle/core/types.hpp"
#include "follicle/render/render_scene.hpp"

namespace follicle::render {

Mat4 look_at(const Vec3& eye, const Vec3& target, const Vec3& up);
Mat4 view_matrix(const Camera& cam);
Mat4 perspective(double fov_y, double aspect, double z_near, double z_far);
Mat4 projection_matrix(const Camera& cam, double aspect);
Mat4 orthographic(double left, double right, double bottom, double top, double z_near,
                  double z_far);

/// Pixel coordinates (x right, y down; pixel (i, j) covers [i, i+1) x [j, j+1)) of world point p
/// in a width x height image; nullopt when p is behind the camera.
std::optional<Vec2> project_to_pixel(const Camera& cam, int width, int height, const Vec3& p);

/// Whether any of the world box can be in the view: false when all eight corners lie beyond one
/// plane of the view frustum (near and far included). Conservative: a box across a frustum edge
/// counts as seen.
bool box_in_view(const Camera& cam, double aspect, const Eigen::AlignedBox3d& box);

}  // namespace follicle::render
