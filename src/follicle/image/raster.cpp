// Hand-written because no library in the stack rasterizes into float images with analytic
// coverage (stb has no rasterizer for this; Cairo/Skia are not dependencies).
#include "follicle/image/raster.hpp"

#include <algorithm>
#include <cmath>

namespace follicle::image {
namespace {

inline void blend_px(float& dst, float value, double cov, Blend blend) {
  const float c = float(cov);
  switch (blend) {
    case Blend::Over: dst = c * value + (1.f - c) * dst; break;
    case Blend::Max: dst = std::max(dst, c * value); break;
    case Blend::Min: dst = dst + c * (std::min(dst, value) - dst); break;
    case Blend::Add: dst = dst + c * value; break;
  }
}

struct SegDist {
  double d, t;
};
inline SegDist seg_dist(const Vec2& p, const Vec2& a, const Vec2& b) {
  const Vec2 ab = b - a;
  const double l2 = ab.squaredNorm();
  double t = l2 > 0 ? (p - a).dot(ab) / l2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  return {(p - (a + t * ab)).norm(), t};
}

struct PixBox {
  int x0, y0, x1, y1;  // inclusive
  bool empty() const { return x0 > x1 || y0 > y1; }
};
PixBox box_of(const ImageF& img, double minx, double miny, double maxx, double maxy) {
  PixBox b;
  b.x0 = std::max(0, int(std::floor(minx)));
  b.y0 = std::max(0, int(std::floor(miny)));
  b.x1 = std::min(img.width() - 1, int(std::ceil(maxx)));
  b.y1 = std::min(img.height() - 1, int(std::ceil(maxy)));
  return b;
}

void check_finite(const Vec2& p, double r, const char* what) {
  if (!p.allFinite() || !std::isfinite(r) || r < 0) {
    fail("{}: non-finite coordinate or negative size ({}, {}, {})", what, p.x(), p.y(), r);
  }
}

}  // namespace

void draw_disc(ImageF& img, const Vec2& c, double radius, float value, Blend blend) {
  check_finite(c, radius, "draw_disc");
  const double ext = radius + 1.0;
  const PixBox bx = box_of(img, c.x() - ext, c.y() - ext, c.x() + ext, c.y() + ext);
  for (int y = bx.y0; y <= bx.y1; ++y) {
    for (int x = bx.x0; x <= bx.x1; ++x) {
      const double d = (Vec2(x + 0.5, y + 0.5) - c).norm();
      const double cov = std::clamp(0.5 + radius - d, 0.0, 1.0);
      if (cov > 0) blend_px(img.at(x, y), value, cov, blend);
    }
  }
}

void draw_line(ImageF& img, const Vec2& a, const Vec2& b, double width, float value, Blend blend) {
  draw_polyline(img, {a, b}, width, value, blend);
}

void draw_polyline(ImageF& img, const std::vector<Vec2>& pts, double width, float value,
                   Blend blend) {
  if (pts.empty()) return;
  const double r = 0.5 * width;
  double minx = 1e300, miny = 1e300, maxx = -1e300, maxy = -1e300;
  for (const Vec2& p : pts) {
    check_finite(p, r, "draw_polyline");
    minx = std::min(minx, p.x());
    miny = std::min(miny, p.y());
    maxx = std::max(maxx, p.x());
    maxy = std::max(maxy, p.y());
  }
  if (pts.size() == 1) return draw_disc(img, pts[0], r, value, blend);
  const PixBox bx = box_of(img, minx - r - 1, miny - r - 1, maxx + r + 1, maxy + r + 1);
  if (bx.empty()) return;
  for (int y = bx.y0; y <= bx.y1; ++y) {
    for (int x = bx.x0; x <= bx.x1; ++x) {
      const Vec2 p(x + 0.5, y + 0.5);
      double d = 1e300;
      for (std::size_t i = 0; i + 1 < pts.size(); ++i)
        d = std::min(d, seg_dist(p, pts[i], pts[i + 1]).d);
      const double cov = std::clamp(0.5 + r - d, 0.0, 1.0);
      if (cov > 0) blend_px(img.at(x, y), value, cov, blend);
    }
  }
}

void draw_line_profile(ImageF& img, const Vec2& a, const Vec2& b, double radius,
                       const std::function<float(double d, double t)>& profile, Blend blend) {
  check_finite(a, radius, "draw_line_profile");
  check_finite(b, radius, "draw_line_profile");
  const PixBox bx =
      box_of(img, std::min(a.x(), b.x()) - radius - 1, std::min(a.y(), b.y()) - radius - 1,
             std::max(a.x(), b.x()) + radius + 1, std::max(a.y(), b.y()) + radius + 1);
  for (int y = bx.y0; y <= bx.y1; ++y) {
    for (int x = bx.x0; x <= bx.x1; ++x) {
      const SegDist sd = seg_dist(Vec2(x + 0.5, y + 0.5), a, b);
      if (sd.d <= radius) blend_px(img.at(x, y), profile(sd.d, sd.t), 1.0, blend);
    }
  }
}

}  // namespace follicle::image
