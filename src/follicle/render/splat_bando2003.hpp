#pragma once
// Hair splatting of Bando, Chen & Nishita 2003 (§3.4 of the thesis in
// ../shared/papers/000_c01fb93c031b01a4.txt): particles rendered as textured billboards aligned
// with the hair direction t_i, lit by a Kajiya-Kay phase function with Goldman's directionality
// factor, self-shadowed by a light-view pass over the particles sorted by depth from the light.
//
// The GL implementation lives in splat_gl.cpp (used by the renderer for ParticleItems with
// ParticleShading::HairSplat); this header holds the same formulas on the CPU (for tests, docs
// and CPU users) and the procedural hair texture. Directions: `to_light` and `to_eye` point away
// from the particle (unit); the projection direction d_p points from the eye (or the light)
// towards the particle.
#include <cstdint>

#include "follicle/core/types.hpp"
#include "follicle/image/image.hpp"
#include "follicle/render/render_scene.hpp"

namespace follicle::render {

/// Goldman 1997 directionality: kappa = ((t x l) . (t x e)) / (|t x l| |t x e|) in [-1, 1]
/// (+1: eye and light on the same side of the hair, reflection; -1: transmission), and
/// f_dir = (1 + kappa)/2 * reflect + (1 - kappa)/2 * transmit. kappa = 0 when t is parallel to
/// l or e.
double goldman_kappa(const Vec3& t, const Vec3& to_light, const Vec3& to_eye);
double goldman_directionality(const Vec3& t, const Vec3& to_light, const Vec3& to_eye,
                              double reflect, double transmit);

/// Kajiya-Kay 1989 phase function times Goldman's f_dir, per unit light colour:
/// f_dir * (diffuse * sin(t, l) * colour + specular * max(0, sin(t,l) sin(t,e) - (t.l)(t.e))^p).
Vec3 kajiya_goldman(const Vec3& t, const Vec3& to_light, const Vec3& to_eye, const Vec3& colour,
                    const SplatMaterial& m);

/// The billboard frame of Fig. 3.5(b) (billboard_axes() of kSplatCommon): the billboard lies
/// across the projection direction d_p (unit) with its vertical axis `along` the projection of
/// t; `across` = d_p x along; s = max(sin(theta), min_sin) with cos(theta) = t . d_p. When t is
/// parallel to d_p the axes are an arbitrary frame across d_p and s = min_sin.
void splat_billboard_axes(const Vec3& t, const Vec3& d_p, double min_sin, Vec3& along, Vec3& across,
                          double& s);

/// Effective sin(theta) of a billboard, cos(theta) = t . d_p, clamped below by min_sin
/// (the billboard is drawn `sin_eff` times its length along the projected t).
double splat_sin_theta(const Vec3& t, const Vec3& d_p, double min_sin);
/// Billboard opacity alpha / sin(theta) (Bando 2003 §3.4), with sin(theta) clamped below by
/// min_sin and the result clamped to [0, 1].
double splat_opacity(double alpha, const Vec3& t, const Vec3& d_p, double min_sin);

/// The procedural hair texture of Fig. 3.5(a): `strands` thin vertical streaks (the hair runs
/// along the image's vertical axis) with Gaussian cross-section, per-streak brightness and
/// alpha, fading in and out along their length, over a soft envelope that vanishes at the
/// billboard's border. RGB is a linear grey brightness factor (multiplied by the hair colour),
/// A the coverage. Deterministic for a seed. Throws follicle::Error for sizes < 4 or strands < 1.
image::ImageRGBA8 make_hair_texture(int width = 64, int height = 128, int strands = 9,
                                    uint64_t seed = 2003);

/// Synthetic test scene: a sphere "head" (radius 0.1 m at the origin, skin-coloured
/// Blinn-Phong) with about `particles` hair particles (radius `radius`) along strands that
/// start on the crown and back of the head, follow the sphere down to its equator and hang
/// straight down (a sheet 4-25 mm thick), directions t_i along the strands; one key light with
/// shadows from the upper left-back, a weak fill light and a camera behind the head.
/// particles[0] is the HairSplat item, meshes[0] the head. Deterministic for a seed; throws
/// follicle::Error for particles < 1.
RenderScene make_hair_sheet_scene(int particles = 2000, uint64_t seed = 1, double radius = 0.006);

}  // namespace follicle::render
