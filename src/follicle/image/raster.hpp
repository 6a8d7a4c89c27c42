#pragma once
// Anti-aliased 2-D rasterization of discs, thick line segments and polylines into float images
// (height maps, masks, density maps). Coordinates are in pixels: pixel (x, y) covers
// [x, x+1) x [y, y+1), so its centre is (x+0.5, y+0.5); row 0 is the top row.
// Coverage is the analytic 1-pixel-wide ramp clamp(0.5 + r - d, 0, 1) of the distance d from the
// pixel centre to the shape's centre line/point, which is exact for straight edges of
// axis-aligned shapes and within a few percent elsewhere.
#include <functional>
#include <vector>

#include "follicle/core/types.hpp"
#include "follicle/image/image.hpp"

namespace follicle::image {

enum class Blend {
  Over,  // v = cov * value + (1 - cov) * old
  Max,   // v = max(old, cov * value)
  Min,   // v = old + cov * (min(old, value) - old)
  Add,   // v = old + cov * value
};

/// Filled disc of `radius` pixels.
void draw_disc(ImageF& img, const Vec2& centre, double radius, float value,
               Blend blend = Blend::Over);
/// Segment a-b with round caps, total width `width` pixels (a capsule of radius width/2).
void draw_line(ImageF& img, const Vec2& a, const Vec2& b, double width, float value,
               Blend blend = Blend::Over);
/// Joined segments with round joins; each pixel is written once (the nearest segment wins), so
/// overlapping joins do not double up with Blend::Add.
void draw_polyline(ImageF& img, const std::vector<Vec2>& pts, double width, float value,
                   Blend blend = Blend::Over);
/// General profile along a segment: for every pixel whose centre lies within `radius` of the
/// segment a-b, value = profile(d, t), where d is the distance [px] from the pixel centre to the
/// segment and t in [0,1] the parameter of the closest point. No coverage ramp is applied: the
/// profile itself should fall off smoothly (e.g. a wrinkle furrow shape).
void draw_line_profile(ImageF& img, const Vec2& a, const Vec2& b, double radius,
                       const std::function<float(double d, double t)>& profile,
                       Blend blend = Blend::Add);

}  // namespace follicle::image
