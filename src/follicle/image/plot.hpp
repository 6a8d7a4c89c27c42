#pragma once
// Pictures for people to compare results: bitmap text (stb_easy_font, ASCII), filled rectangles,
// blits, line plots with axes, ticks, axis labels and a legend, and grids of labelled images,
// all into 8-bit RGB images. Pixel (x, y) covers [x, x+1) x [y, y+1); row 0 is the top row.
#include <cstdint>
#include <string>
#include <vector>

#include "follicle/core/types.hpp"
#include "follicle/image/image.hpp"

namespace follicle::image {

struct Rgb8 {
  uint8_t r = 0, g = 0, b = 0;
  bool operator==(const Rgb8&) const = default;
};

/// Distinct line colours for series i = 0, 1, ... (a colour-blind safe palette, then repeats).
Rgb8 palette_color(std::size_t i);

/// Size [px] of `text` drawn at integer `scale` (lines split at '\n'; 12 px per line at scale 1).
struct TextSize {
  int width = 0, height = 0;
};
TextSize text_size(const std::string& text, int scale = 1);
/// Draws `text` with its top-left corner at (x, y), clipped to the image. Characters outside
/// printable ASCII are drawn as '?'. Throws when scale < 1.
void draw_text(ImageRGB8& img, int x, int y, const std::string& text, Rgb8 color, int scale = 1);

/// Fills [x, x+w) x [y, y+h), clipped to the image.
void fill_rect(ImageRGB8& img, int x, int y, int w, int h, Rgb8 color);
/// Copies `src` with its top-left corner at (x, y) of `dst`, clipped.
void blit(ImageRGB8& dst, const ImageRGB8& src, int x, int y);
/// `src` composited over an opaque `background` (straight alpha; 8-bit sRGB values as they are).
ImageRGB8 flatten(const ImageRGBA8& src, Rgb8 background);

/// One line of a plot: y(x), drawn in the order given. NaN or infinite values are errors.
struct PlotSeries {
  std::string label;  // legend entry ("" = not in the legend)
  std::vector<double> x, y;
  Rgb8 color;
};

struct PlotOptions {
  std::string title;
  std::string x_label;      // with its unit, e.g. "time [s]"
  std::string y_label;      // with its unit, e.g. "stretch [%]"
  int width = 560;          // [px] whole image
  int height = 360;         // [px] whole image
  int text_scale = 2;       // title, labels, ticks and legend
  double line_width = 2.0;  // [px]
  Rgb8 background{255, 255, 255};
  Rgb8 foreground{20, 20, 20};
  Rgb8 grid{225, 225, 225};
};

/// Where the data went: the plot area [left, right) x [top, bottom) in image pixels and the data
/// range it spans (x_min at `left`, y_min at `bottom`).
struct PlotFrame {
  int left = 0, top = 0, right = 0, bottom = 0;
  double x_min = 0, x_max = 1, y_min = 0, y_max = 1;
  /// Continuous image coordinates of the data point (x, y).
  Vec2 to_pixel(double x, double y) const;
};

struct Plot {
  ImageRGB8 image;
  PlotFrame frame;
};

/// A line plot of `series` with axes, ticks at 1-2-5 steps, grid lines, the axis labels, the
/// title and a legend (above the plot area). Axis ranges cover every series, rounded out to whole
/// ticks. Throws follicle::Error naming the plot and series for x/y of different sizes,
/// non-finite values, or an image too small for the text.
Plot line_plot(const std::vector<PlotSeries>& series, const PlotOptions& options);

/// An image with a caption drawn under it.
struct LabelledImage {
  ImageRGB8 image;
  std::string label;
};

struct GridOptions {
  int columns = 1;
  int gap = 8;  // [px] between cells and around the grid
  int text_scale = 2;
  Rgb8 background{255, 255, 255};
  Rgb8 foreground{20, 20, 20};
};

/// Cells laid out row by row in `columns` columns; every cell is as large as the largest image
/// plus its caption line(s); images are centred in their cell. Throws when columns < 1.
ImageRGB8 image_grid(const std::vector<LabelledImage>& cells, const GridOptions& options);

/// Images one below the other (vertical) or side by side, `gap` px apart, left/top aligned.
ImageRGB8 stack(const std::vector<ImageRGB8>& images, bool vertical, int gap, Rgb8 background);

}  // namespace follicle::image
