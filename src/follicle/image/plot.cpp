// Text from stb_easy_font (a header of static functions that emit one axis-aligned quad per
// stroke; drawn here as filled rectangles), lines through raster.hpp's anti-aliased polylines.
#include "follicle/image/plot.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "follicle/core/error.hpp"
#include "follicle/image/raster.hpp"

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#include <stb_easy_font.h>
#pragma GCC diagnostic pop

namespace follicle::image {

namespace {

constexpr int kLineHeight = 12;  // stb_easy_font's line advance at scale 1

// Printable ASCII only (stb_easy_font indexes a table by c - 32).
std::string printable(const std::string& text) {
  std::string s = text;
  for (auto& c : s)
    if (c != '\n' && (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) > 126))
      c = '?';
  return s;
}

void check_scale(int scale) {
  if (scale < 1) fail("text scale {} must be >= 1", scale);
}

void blend_pixel(ImageRGB8& img, int x, int y, Rgb8 c, float a) {
  if (x < 0 || y < 0 || x >= img.width() || y >= img.height() || !(a > 0.0f)) return;
  a = std::min(a, 1.0f);
  uint8_t* p = img.pixel(x, y);
  const uint8_t v[3] = {c.r, c.g, c.b};
  for (int k = 0; k < 3; ++k)
    p[k] = uint8_t(std::lround(float(p[k]) + a * (float(v[k]) - float(p[k]))));
}

// Tick positions at 1-2-5 steps covering [lo, hi].
struct Ticks {
  double lo = 0, hi = 1, step = 1;
  std::vector<double> values;
  int decimals = 0;
  std::string label(double v) const {
    if (std::abs(v) < step * 1e-6) v = 0.0;  // no "-0.00"
    const double m = std::max(std::abs(lo), std::abs(hi));
    if (decimals > 5 || m >= 1e6) return fmt::format("{:.2g}", v);
    return fmt::format("{:.{}f}", v, decimals);
  }
};

Ticks nice_ticks(double lo, double hi, int target) {
  if (!(hi > lo)) {  // constant data: a range around it
    const double d = lo == 0.0 ? 1.0 : 0.1 * std::abs(lo);
    if (lo == 0.0) {
      hi = 1.0;
    } else {
      lo -= d;
      hi += d;
    }
  }
  target = std::max(target, 2);
  const double raw = (hi - lo) / target;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  const double r = raw / mag;
  Ticks t;
  t.step = (r <= 1.0 ? 1.0 : r <= 2.0 ? 2.0 : r <= 5.0 ? 5.0 : 10.0) * mag;
  const double k0 = std::floor(lo / t.step + 1e-9), k1 = std::ceil(hi / t.step - 1e-9);
  t.lo = k0 * t.step;
  t.hi = k1 * t.step;
  if (!(t.hi > t.lo)) t.hi = t.lo + t.step;
  for (double k = k0; k <= k1 + 0.5; k += 1.0) t.values.push_back(k * t.step);
  t.decimals = std::max(0, int(-std::floor(std::log10(t.step) + 1e-9)));
  return t;
}

void check_series(const std::vector<PlotSeries>& series, const std::string& title) {
  const std::string name = title.empty() ? "plot" : "plot \"" + title + "\"";
  for (const auto& s : series) {
    if (s.x.size() != s.y.size())
      fail("{}: series \"{}\" has {} x values but {} y values", name, s.label, s.x.size(),
           s.y.size());
    for (std::size_t i = 0; i < s.x.size(); ++i)
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i]))
        fail("{}: series \"{}\" has a non-finite value at index {} (x = {}, y = {})", name, s.label,
             i, s.x[i], s.y[i]);
  }
}

}  // namespace

Rgb8 palette_color(std::size_t i) {
  // Okabe & Ito's colour-blind safe palette (without yellow and black, poor on white).
  static constexpr Rgb8 kColors[] = {{0, 114, 178},   {213, 94, 0},   {0, 158, 115},
                                     {204, 121, 167}, {86, 180, 233}, {230, 159, 0}};
  return kColors[i % std::size(kColors)];
}

TextSize text_size(const std::string& text, int scale) {
  check_scale(scale);
  if (text.empty()) return {};
  std::string s = printable(text);
  return {stb_easy_font_width(s.data()) * scale, stb_easy_font_height(s.data()) * scale};
}

void draw_text(ImageRGB8& img, int x, int y, const std::string& text, Rgb8 color, int scale) {
  check_scale(scale);
  if (text.empty()) return;
  std::string s = printable(text);
  // ~270 bytes per character on average (stb_easy_font.h); room for the worst glyphs.
  std::vector<char> buf(s.size() * 1024 + 1024);
  const int quads = stb_easy_font_print(0.0f, 0.0f, s.data(), nullptr, buf.data(), int(buf.size()));
  for (int q = 0; q < quads; ++q) {
    float v0[2], v2[2];  // corners 0 and 2 of the quad: (x0, y0) and (x1, y1)
    std::copy_n(reinterpret_cast<const char*>(buf.data() + q * 64), sizeof v0,
                reinterpret_cast<char*>(v0));
    std::copy_n(reinterpret_cast<const char*>(buf.data() + q * 64 + 32), sizeof v2,
                reinterpret_cast<char*>(v2));
    const int x0 = int(std::lround(v0[0])), y0 = int(std::lround(v0[1]));
    const int x1 = int(std::lround(v2[0])), y1 = int(std::lround(v2[1]));
    fill_rect(img, x + x0 * scale, y + y0 * scale, (x1 - x0) * scale, (y1 - y0) * scale, color);
  }
}

void fill_rect(ImageRGB8& img, int x, int y, int w, int h, Rgb8 color) {
  const int x0 = std::max(x, 0), y0 = std::max(y, 0);
  const int x1 = std::min(x + w, img.width()), y1 = std::min(y + h, img.height());
  for (int j = y0; j < y1; ++j)
    for (int i = x0; i < x1; ++i) {
      uint8_t* p = img.pixel(i, j);
      p[0] = color.r;
      p[1] = color.g;
      p[2] = color.b;
    }
}

void blit(ImageRGB8& dst, const ImageRGB8& src, int x, int y) {
  const int i0 = std::max(0, -x), j0 = std::max(0, -y);
  const int i1 = std::min(src.width(), dst.width() - x),
            j1 = std::min(src.height(), dst.height() - y);
  for (int j = j0; j < j1; ++j)
    for (int i = i0; i < i1; ++i) std::copy_n(src.pixel(i, j), 3, dst.pixel(x + i, y + j));
}

ImageRGB8 flatten(const ImageRGBA8& src, Rgb8 background) {
  ImageRGB8 out(src.width(), src.height());
  const int bg[3] = {background.r, background.g, background.b};
  for (int j = 0; j < src.height(); ++j)
    for (int i = 0; i < src.width(); ++i) {
      const uint8_t* s = src.pixel(i, j);
      uint8_t* d = out.pixel(i, j);
      for (int k = 0; k < 3; ++k)
        d[k] = uint8_t((int(s[k]) * int(s[3]) + bg[k] * (255 - int(s[3])) + 127) / 255);
    }
  return out;
}

Vec2 PlotFrame::to_pixel(double x, double y) const {
  return {double(left) + (x - x_min) / (x_max - x_min) * double(right - left),
          double(bottom) - (y - y_min) / (y_max - y_min) * double(bottom - top)};
}

Plot line_plot(const std::vector<PlotSeries>& series, const PlotOptions& o) {
  check_series(series, o.title);
  check_scale(o.text_scale);
  if (!(o.line_width > 0.0)) fail("plot \"{}\": line width {} must be > 0", o.title, o.line_width);
  const int s = o.text_scale;
  const int line = kLineHeight * s;
  const int pad = 4 * s;

  // Data range.
  double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
  for (const auto& ser : series)
    for (std::size_t i = 0; i < ser.x.size(); ++i) {
      x0 = std::min(x0, ser.x[i]);
      x1 = std::max(x1, ser.x[i]);
      y0 = std::min(y0, ser.y[i]);
      y1 = std::max(y1, ser.y[i]);
    }
  if (!(x0 <= x1)) x0 = x1 = 0.0;  // no data
  if (!(y0 <= y1)) y0 = y1 = 0.0;

  // Legend entries (swatch + label), wrapped into rows above the plot area.
  const int swatch = 10 * s;
  struct Entry {
    std::size_t series;
    int x, row;
  };
  std::vector<Entry> legend;
  int rows = 0, cx = pad;
  for (std::size_t i = 0; i < series.size(); ++i) {
    if (series[i].label.empty()) continue;
    const int w = swatch + 2 * s + text_size(series[i].label, s).width + 6 * s;
    if (rows == 0) rows = 1;
    if (cx > pad && cx + w > o.width - pad) {
      ++rows;
      cx = pad;
    }
    legend.push_back({i, cx, rows - 1});
    cx += w;
  }

  // Vertical layout: title, legend rows, y label, plot area, x tick labels, x label.
  int y = pad;
  const int title_y = y;
  if (!o.title.empty()) y += line + pad;
  const int legend_y = y;
  y += rows * line + (rows ? pad : 0);
  const int ylabel_y = y;
  if (!o.y_label.empty()) y += line;
  const int top = y + line / 2;
  const int bottom = o.height - pad - (o.x_label.empty() ? 0 : line) - line - 2 * s;
  if (bottom - top < 2 * line)
    fail("plot \"{}\": {}x{} px is too small for its text at scale {}", o.title, o.width, o.height,
         s);
  const Ticks yt = nice_ticks(y0, y1, std::max(2, (bottom - top) / (28 * s)));
  int label_w = 0;
  for (double v : yt.values) label_w = std::max(label_w, text_size(yt.label(v), s).width);
  const int left = pad + label_w + 4 * s;
  const int right = o.width - pad - 3 * line / 2;
  if (right - left < 4 * line)
    fail("plot \"{}\": {}x{} px is too small for its text at scale {}", o.title, o.width, o.height,
         s);
  const Ticks xt = nice_ticks(x0, x1, std::max(2, (right - left) / (50 * s)));

  Plot p;
  p.frame = PlotFrame{left, top, right, bottom, xt.lo, xt.hi, yt.lo, yt.hi};
  p.image = ImageRGB8(o.width, o.height);
  ImageRGB8& img = p.image;
  fill_rect(img, 0, 0, o.width, o.height, o.background);

  // Grid and ticks.
  for (double v : xt.values) {
    const int px = int(std::floor(p.frame.to_pixel(v, yt.lo).x()));
    fill_rect(img, std::min(px, right - 1), top, 1, bottom - top, o.grid);
    fill_rect(img, std::min(px, right - 1), bottom, 1, 2 * s, o.foreground);
    const std::string t = xt.label(v);
    const TextSize ts = text_size(t, s);
    draw_text(img, px - ts.width / 2, bottom + 3 * s, t, o.foreground, s);
  }
  for (double v : yt.values) {
    const int py = int(std::floor(p.frame.to_pixel(xt.lo, v).y()));
    fill_rect(img, left, std::min(py, bottom - 1), right - left, 1, o.grid);
    fill_rect(img, left - 2 * s, std::min(py, bottom - 1), 2 * s, 1, o.foreground);
    const std::string t = yt.label(v);
    const TextSize ts = text_size(t, s);
    draw_text(img, left - 3 * s - ts.width, py - 7 * s / 2, t, o.foreground, s);
  }

  // The series, anti-aliased, clipped to the plot area.
  const int aw = right - left, ah = bottom - top;
  for (const auto& ser : series) {
    if (ser.x.empty()) continue;
    ImageF cov(aw, ah, 0.0f);
    std::vector<Vec2> pts;
    pts.reserve(ser.x.size());
    for (std::size_t i = 0; i < ser.x.size(); ++i)
      pts.push_back(p.frame.to_pixel(ser.x[i], ser.y[i]) - Vec2(double(left), double(top)));
    if (pts.size() == 1)
      draw_disc(cov, pts[0], o.line_width, 1.0f);
    else
      draw_polyline(cov, pts, o.line_width, 1.0f);
    for (int j = 0; j < ah; ++j)
      for (int i = 0; i < aw; ++i) blend_pixel(img, left + i, top + j, ser.color, cov.at(i, j));
  }

  // Axes box, labels, title, legend.
  fill_rect(img, left, top, aw, 1, o.foreground);
  fill_rect(img, left, bottom, aw + 1, 1, o.foreground);
  fill_rect(img, left, top, 1, ah, o.foreground);
  fill_rect(img, right, top, 1, ah, o.foreground);
  if (!o.title.empty()) {
    const TextSize ts = text_size(o.title, s);
    draw_text(img, std::max(pad, (o.width - ts.width) / 2), title_y, o.title, o.foreground, s);
  }
  for (const auto& e : legend) {
    const int ly = legend_y + e.row * line;
    fill_rect(img, e.x, ly + 3 * s, swatch, 2 * s, series[e.series].color);
    draw_text(img, e.x + swatch + 2 * s, ly, series[e.series].label, o.foreground, s);
  }
  if (!o.y_label.empty()) draw_text(img, pad, ylabel_y, o.y_label, o.foreground, s);
  if (!o.x_label.empty()) {
    const TextSize ts = text_size(o.x_label, s);
    draw_text(img, left + (aw - ts.width) / 2, o.height - pad - line + s, o.x_label, o.foreground,
              s);
  }
  return p;
}

ImageRGB8 image_grid(const std::vector<LabelledImage>& cells, const GridOptions& o) {
  if (o.columns < 1) fail("image grid: {} columns, expected at least 1", o.columns);
  check_scale(o.text_scale);
  int cw = 0, ih = 0, th = 0;
  for (const auto& c : cells) {
    const TextSize ts = text_size(c.label, o.text_scale);
    cw = std::max({cw, c.image.width(), ts.width});
    ih = std::max(ih, c.image.height());
    th = std::max(th, ts.height);
  }
  const int ch = ih + (th ? th + o.gap / 2 : 0);
  const int n = int(cells.size());
  const int cols = std::min(o.columns, std::max(n, 1));
  const int rows = (n + cols - 1) / cols;
  ImageRGB8 out(o.gap + cols * (cw + o.gap), o.gap + rows * (ch + o.gap));
  fill_rect(out, 0, 0, out.width(), out.height(), o.background);
  for (int k = 0; k < n; ++k) {
    const int x = o.gap + (k % cols) * (cw + o.gap), y = o.gap + (k / cols) * (ch + o.gap);
    const auto& c = cells[std::size_t(k)];
    blit(out, c.image, x + (cw - c.image.width()) / 2, y);
    const TextSize ts = text_size(c.label, o.text_scale);
    draw_text(out, x + (cw - ts.width) / 2, y + ih + o.gap / 2, c.label, o.foreground,
              o.text_scale);
  }
  return out;
}

ImageRGB8 stack(const std::vector<ImageRGB8>& images, bool vertical, int gap, Rgb8 background) {
  int w = 0, h = 0;
  for (std::size_t i = 0; i < images.size(); ++i) {
    const int g = i ? gap : 0;
    if (vertical) {
      w = std::max(w, images[i].width());
      h += g + images[i].height();
    } else {
      w += g + images[i].width();
      h = std::max(h, images[i].height());
    }
  }
  ImageRGB8 out(w, h);
  fill_rect(out, 0, 0, w, h, background);
  int pos = 0;
  for (const auto& im : images) {
    if (vertical) {
      blit(out, im, 0, pos);
      pos += im.height() + gap;
    } else {
      blit(out, im, pos, 0);
      pos += im.width() + gap;
    }
  }
  return out;
}

}  // namespace follicle::image
