#pragma once
// CPU evaluation of the Lafortune generalized-cosine BRDF (docs/skin-constants.md §4.1), the
// reference for the GLSL version in the mesh shader and for tests.
#include "follicle/core/types.hpp"
#include "follicle/render/render_scene.hpp"

namespace follicle::render {

/// The skin fit of pbrt-v1 materials/skin.cpp (Marschner-measured skin): rho_d and three lobes.
LafortuneBrdf lafortune_skin_marschner();

/// f_r(wo, wi) [1/sr] per RGB channel, both unit directions in the local frame (z = normal):
/// rho_d/pi + sum_k max(0, Cxy (wo.x wi.x + wo.y wi.y) + Cz wo.z wi.z)^n.
/// Zero when either direction is below the surface.
Vec3 eval_lafortune(const LafortuneBrdf& brdf, const Vec3& wo, const Vec3& wi);

/// Directional albedo rho(theta_i) = integral of f cos(theta_o) d(omega_o) over the hemisphere,
/// by the midpoint rule on an n_theta x n_phi grid in (theta_o, phi_o).
Vec3 lafortune_directional_albedo(const LafortuneBrdf& brdf, double theta_i, int n_theta = 200,
                                  int n_phi = 400);

}  // namespace follicle::render
