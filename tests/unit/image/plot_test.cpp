// Text, line plots and image grids (image/plot.hpp): text lands inside the box text_size
// reports, a plotted y = x line passes through the pixels PlotFrame maps the data to, bad data
// fails with a message naming the series.
#include "follicle/image/plot.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "follicle/core/error.hpp"

using namespace follicle;
using namespace follicle::image;
using ::testing::HasSubstr;

namespace {

constexpr Rgb8 kWhite{255, 255, 255};
constexpr Rgb8 kInk{10, 20, 30};

Rgb8 at(const ImageRGB8& img, int x, int y) {
  const uint8_t* p = img.pixel(x, y);
  return {p[0], p[1], p[2]};
}

ImageRGB8 blank(int w, int h) {
  ImageRGB8 img(w, h);
  fill_rect(img, 0, 0, w, h, kWhite);
  return img;
}

// Pixels of colour c inside and outside [x0, x1) x [y0, y1).
std::pair<int, int> count(const ImageRGB8& img, Rgb8 c, int x0, int y0, int x1, int y1) {
  int in = 0, out = 0;
  for (int y = 0; y < img.height(); ++y)
    for (int x = 0; x < img.width(); ++x)
      if (at(img, x, y) == c) ((x >= x0 && x < x1 && y >= y0 && y < y1) ? in : out)++;
  return {in, out};
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(PlotText, DrawsInsideTheBoxTextSizeReports) {
  for (int scale : {1, 2, 3}) {
    ImageRGB8 img = blank(200, 80);
    const std::string text = "Frame 12 [mm]";
    const TextSize ts = text_size(text, scale);
    EXPECT_EQ(ts.width, scale * text_size(text, 1).width);
    EXPECT_EQ(ts.height, 12 * scale);
    draw_text(img, 7, 9, text, kInk, scale);
    const auto [in, out] = count(img, kInk, 7, 9, 7 + ts.width, 9 + ts.height);
    EXPECT_GT(in, 20 * scale * scale) << scale;  // every glyph has strokes
    EXPECT_EQ(out, 0) << scale;
    // Strokes reach both ends of the box (first and last glyph drawn).
    bool left = false, right = false;
    for (int y = 9; y < 9 + ts.height; ++y) {
      for (int x = 7; x < 7 + 3 * scale; ++x) left |= at(img, x, y) == kInk;
      for (int x = 7 + ts.width - 8 * scale; x < 7 + ts.width; ++x) right |= at(img, x, y) == kInk;
    }
    EXPECT_TRUE(left && right) << scale;
  }
}

TEST(PlotText, ClipsAtTheImageEdgeAndMapsNonAsciiToQuestionMarks) {
  ImageRGB8 img = blank(30, 10);
  draw_text(img, 20, 5, "clipped text", kInk, 2);  // mostly outside: must not write out of bounds
  EXPECT_GT(count(img, kInk, 0, 0, 30, 10).first, 0);

  ImageRGB8 a = blank(40, 20), b = blank(40, 20);
  draw_text(a, 2, 2, "a\xc3\xa9", kInk, 1);  // 'a' + UTF-8 e-acute (two non-ASCII bytes)
  draw_text(b, 2, 2, "a??", kInk, 1);
  EXPECT_TRUE(a == b);
  EXPECT_THROW(text_size("x", 0), Error);
}

TEST(LinePlot, AYEqualsXLinePassesThroughTheMappedPixels) {
  PlotSeries s{"y = x", {}, {}, Rgb8{200, 30, 40}};
  for (int i = 0; i <= 20; ++i) {
    s.x.push_back(0.5 * i);
    s.y.push_back(0.5 * i);
  }
  PlotOptions o;
  o.title = "identity";
  o.x_label = "x [m]";
  o.y_label = "y [m]";
  o.line_width = 3.0;  // the centre pixel of a 3-px line is fully covered
  const Plot p = line_plot({s}, o);
  ASSERT_EQ(p.image.width(), o.width);
  ASSERT_EQ(p.image.height(), o.height);
  // 1-2-5 ticks: the data range 0..10 is already whole ticks.
  EXPECT_DOUBLE_EQ(p.frame.x_min, 0.0);
  EXPECT_DOUBLE_EQ(p.frame.x_max, 10.0);
  EXPECT_DOUBLE_EQ(p.frame.y_min, 0.0);
  EXPECT_DOUBLE_EQ(p.frame.y_max, 10.0);
  EXPECT_LT(p.frame.left, p.frame.right);
  EXPECT_LT(p.frame.top, p.frame.bottom);
  for (double t = 0.7; t < 9.5; t += 0.83) {
    const Vec2 q = p.frame.to_pixel(t, t);
    EXPECT_EQ(at(p.image, int(q.x()), int(q.y())), s.color) << t;
    // Well off the line (a quarter of the range above it): not the line's colour.
    const Vec2 off = p.frame.to_pixel(t, t + 2.5);
    if (off.y() > p.frame.top + 2) {
      const Rgb8 c = at(p.image, int(off.x()), int(off.y()));
      EXPECT_FALSE(c == s.color) << t;
    }
  }
  // The data corners map to the plot area's corners.
  EXPECT_NEAR(p.frame.to_pixel(0, 0).x(), p.frame.left, 1e-9);
  EXPECT_NEAR(p.frame.to_pixel(0, 0).y(), p.frame.bottom, 1e-9);
  EXPECT_NEAR(p.frame.to_pixel(10, 10).x(), p.frame.right, 1e-9);
  EXPECT_NEAR(p.frame.to_pixel(10, 10).y(), p.frame.top, 1e-9);
  // The legend swatch shows the series colour above the plot area.
  EXPECT_GT(count(p.image, s.color, 0, 0, o.width, p.frame.top).first, 10);
}

TEST(LinePlot, RangesCoverEverySeriesAndConstantDataGetsARange) {
  PlotSeries a{"a", {0.0, 1.0, 2.0}, {-3.0, 0.2, 7.4}, palette_color(0)};
  PlotSeries b{"b", {0.5, 3.3}, {1.0, 1.0}, palette_color(1)};
  const Plot p = line_plot({a, b}, PlotOptions{});
  EXPECT_LE(p.frame.x_min, 0.0);
  EXPECT_GE(p.frame.x_max, 3.3);
  EXPECT_LE(p.frame.y_min, -3.0);
  EXPECT_GE(p.frame.y_max, 7.4);
  EXPECT_FALSE(palette_color(0) == palette_color(1));

  PlotSeries zero{"zero", {0.0, 1.0}, {0.0, 0.0}, palette_color(2)};
  const Plot z = line_plot({zero}, PlotOptions{});
  EXPECT_LT(z.frame.y_min, z.frame.y_max);
  PlotSeries tiny{"tiny", {0.0, 1.0}, {2e-9, 2e-9}, palette_color(2)};
  const Plot t = line_plot({tiny}, PlotOptions{});
  EXPECT_LT(t.frame.y_min, 2e-9);
  EXPECT_GT(t.frame.y_max, 2e-9);
}

TEST(LinePlot, BadDataIsAClearError) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  PlotSeries s{"kinetic", {0.0, 1.0, 2.0}, {0.0, nan, 1.0}, palette_color(0)};
  PlotOptions o;
  o.title = "energy";
  const std::string e = error_of([&] { line_plot({s}, o); });
  EXPECT_THAT(e, HasSubstr("\"energy\""));
  EXPECT_THAT(e, HasSubstr("\"kinetic\""));
  EXPECT_THAT(e, HasSubstr("non-finite value at index 1"));

  s.y = {0.0, 1.0};
  EXPECT_THAT(error_of([&] { line_plot({s}, o); }), HasSubstr("3 x values but 2 y values"));
  s.y = {0.0, 1.0, 2.0};
  o.width = 40;
  o.height = 40;
  EXPECT_THAT(error_of([&] { line_plot({s}, o); }), HasSubstr("too small"));
}

TEST(ImageGrid, PlacesImagesInCellsWithCaptionsBelow) {
  const Rgb8 red{255, 0, 0}, blue{0, 0, 255};
  ImageRGB8 r(20, 10), b(30, 16);
  fill_rect(r, 0, 0, 20, 10, red);
  fill_rect(b, 0, 0, 30, 16, blue);
  GridOptions o;
  o.columns = 2;
  o.gap = 4;
  o.text_scale = 1;
  o.foreground = kInk;
  const ImageRGB8 g = image_grid({{r, "A"}, {b, "B"}, {r, "C"}}, o);
  const int cw = 30, ch = 16 + 12 + 2;  // largest image; caption line + gap/2
  EXPECT_EQ(g.width(), 4 + 2 * (cw + 4));
  EXPECT_EQ(g.height(), 4 + 2 * (ch + 4));
  // Cell (0, 0): the red image centred horizontally; cell (1, 0): blue at its origin.
  EXPECT_EQ(at(g, 4 + 5, 4), red);
  EXPECT_EQ(at(g, 4 + 5 + 19, 4 + 9), red);
  EXPECT_EQ(at(g, 4 + 4, 4), kWhite);
  EXPECT_EQ(at(g, 4 + cw + 4, 4), blue);
  EXPECT_EQ(at(g, 4 + 5, 4 + ch + 4), red);  // third cell on the second row
  // Captions are drawn under the images, inside each cell.
  EXPECT_GT(count(g, kInk, 4, 4 + 16, 4 + cw, 4 + ch).first, 5);
  EXPECT_GT(count(g, kInk, 4 + cw + 4, 4 + 16, 4 + 2 * cw + 4, 4 + ch).first, 5);
  o.columns = 0;
  EXPECT_THROW(image_grid({{r, "A"}}, o), Error);
}

TEST(ImageCompose, StackAndFlatten) {
  ImageRGB8 a(10, 5), b(4, 8);
  fill_rect(a, 0, 0, 10, 5, Rgb8{1, 2, 3});
  fill_rect(b, 0, 0, 4, 8, Rgb8{4, 5, 6});
  const ImageRGB8 v = stack({a, b}, true, 2, kWhite);
  EXPECT_EQ(v.width(), 10);
  EXPECT_EQ(v.height(), 15);
  EXPECT_EQ(at(v, 0, 7), (Rgb8{4, 5, 6}));
  EXPECT_EQ(at(v, 5, 7), kWhite);
  const ImageRGB8 h = stack({a, b}, false, 3, kWhite);
  EXPECT_EQ(h.width(), 17);
  EXPECT_EQ(h.height(), 8);
  EXPECT_EQ(at(h, 13, 7), (Rgb8{4, 5, 6}));

  ImageRGBA8 rgba(2, 1);
  const uint8_t px[8] = {200, 100, 50, 255, 200, 100, 50, 0};
  std::copy_n(px, 8, rgba.data());
  const ImageRGB8 f = flatten(rgba, Rgb8{0, 10, 20});
  EXPECT_EQ(at(f, 0, 0), (Rgb8{200, 100, 50}));
  EXPECT_EQ(at(f, 1, 0), (Rgb8{0, 10, 20}));
}
