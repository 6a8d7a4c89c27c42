// follicle compare A B [-o err.png] [--units U] [--width W --height H] [--samples N]: distances
// between two meshes (geom::mesh_distance: area-uniform samples of each projected onto the other,
// vertices included in the maxima) printed one-sided and two-sided as mean, RMS, p95 and max in
// --units, and optionally a render of A coloured by the distance of each vertex to B (blue 0 ..
// red at the largest vertex distance) with a colour bar along the right edge.
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>

#include "commands.hpp"
#include "follicle/core/atomic_file.hpp"
#include "follicle/core/error.hpp"
#include "follicle/core/units.hpp"
#include "follicle/geom/mesh_distance.hpp"
#include "follicle/geom/mesh_io.hpp"
#include "follicle/image/image_io.hpp"
#include "follicle/render/framing.hpp"
#include "follicle/render/renderer.hpp"

namespace follicle::cli {

namespace {

// Blue -> cyan -> green -> yellow -> red for t in [0, 1] (linear RGB).
Vec3f error_ramp(double t) {
  t = std::clamp(t, 0.0, 1.0);
  static const Vec3f stops[5] = {Vec3f(0.05f, 0.1f, 0.9f), Vec3f(0.0f, 0.75f, 0.85f),
                                 Vec3f(0.1f, 0.8f, 0.1f), Vec3f(0.95f, 0.85f, 0.05f),
                                 Vec3f(0.9f, 0.05f, 0.03f)};
  const double x = t * 4.0;
  const int i = std::min(3, int(x));
  const float f = float(x - i);
  return stops[i] * (1.0f - f) + stops[i + 1] * f;
}

std::uint8_t to_srgb8(float linear) {
  const float c = std::clamp(linear, 0.0f, 1.0f);
  const float s = c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
  return std::uint8_t(std::lround(s * 255.0f));
}

// A vertical colour bar (0 at the bottom, max at the top) with a white frame at the right edge.
void draw_color_bar(image::ImageRGBA8& img) {
  const int w = std::max(6, img.width() / 40), h = img.height() * 3 / 5;
  const int x0 = img.width() - 2 * w, y0 = (img.height() - h) / 2;
  for (int y = y0 - 1; y <= y0 + h; ++y)
    for (int x = x0 - 1; x <= x0 + w; ++x) {
      if (x < 0 || y < 0 || x >= img.width() || y >= img.height()) continue;
      const bool frame = y == y0 - 1 || y == y0 + h || x == x0 - 1 || x == x0 + w;
      const Vec3f c = frame ? Vec3f(1, 1, 1) : error_ramp(1.0 - double(y - y0) / double(h - 1));
      for (int k = 0; k < 3; ++k) img.at(x, y, k) = to_srgb8(c[k]);
      img.at(x, y, 3) = 255;
    }
}

void print_row(const char* label, const geom::DistanceStats& s, double scale) {
  fmt::print("{:<10} {:>12.4f} {:>12.4f} {:>12.4f} {:>12.4f}\n", label, s.mean * scale,
             s.rms * scale, s.p95 * scale, s.max * scale);
}

}  // namespace

int run_compare(const GlobalOptions& g, const CompareArgs& a) {
  if (!a.output.empty()) {
    auto ext = std::filesystem::path(a.output).extension().string();
    for (auto& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (ext != ".png") throw UsageError(fmt::format("-o must end in .png, got '{}'", a.output));
  }
  const LengthUnit unit = parse_length_unit(a.units);
  auto ctx = make_context(g);
  const auto ma = geom::load_mesh(a.a, unit);  // metres inside; errors name the file
  const auto mb = geom::load_mesh(a.b, unit);
  if (ma.faces.empty()) fail_at(a.a, "the mesh has no triangles to compare");
  if (mb.faces.empty()) fail_at(a.b, "the mesh has no triangles to compare");
  geom::MeshDistanceParams params;
  params.samples = a.samples;
  params.seed = g.seed;
  const auto rep = geom::mesh_distance(*ctx, ma, mb, params);
  const double scale = 1.0 / unit_to_metres(unit);

  // Everything that can fail happens before the PNG is written (atomically).
  if (!a.output.empty()) check_output_writable(a.output);
  std::optional<image::ImageRGBA8> img;
  double vmax = 0;
  if (!a.output.empty()) {
    const auto d = geom::vertex_distances(*ctx, ma, mb);
    for (double x : d) vmax = std::max(vmax, x);
    render::RenderScene rs;
    render::MeshItem item;
    item.mesh = std::make_shared<const geom::TriMesh>(ma);
    item.material.shading = render::MeshShading::BlinnPhong;
    item.material.specular = 0.05;
    item.material.ambient = 0.45;
    item.vertex_colors.reserve(d.size());
    for (double x : d) item.vertex_colors.push_back(error_ramp(vmax > 0 ? x / vmax : 0.0));
    Eigen::AlignedBox3d box;
    for (const auto& p : ma.positions) box.extend(p);
    // Three-quarter view from +z (the shipped head faces +z), slightly from above.
    rs.camera = render::frame_box(box, Vec3(0.35, 0.15, 1.0).normalized(), 0.5, 0.95);
    rs.lights.push_back({Vec3(-0.3, -0.4, -1.0), Vec3(1, 1, 1), 0.75, false});
    rs.background = Vec3(0.06, 0.065, 0.075);
    rs.meshes.push_back(std::move(item));
    render::RenderSettings settings;
    settings.width = a.width;
    settings.height = a.height;
    settings.validate();
    auto renderer = render::Renderer::create_headless(*ctx);
    img = renderer->render(rs, settings);
    draw_color_bar(*img);
  }

  const std::string u = to_string(unit);
  if (!g.quiet) {
    fmt::print("A: {} ({} vertices, {} faces)\nB: {} ({} vertices, {} faces)\n", a.a,
               ma.num_vertices(), ma.num_faces(), a.b, mb.num_vertices(), mb.num_faces());
  }
  fmt::print("{:<10} {:>12} {:>12} {:>12} {:>12}\n", fmt::format("[{}]", u), "mean", "rms", "p95",
             "max");
  print_row("A->B", rep.a_to_b, scale);
  print_row("B->A", rep.b_to_a, scale);
  print_row("two-sided", rep.two_sided, scale);
  if (img) {
    image::write_png(a.output, *img);  // atomic
    if (!g.quiet)
      fmt::print("wrote {} ({}x{}): A coloured by distance to B, blue 0 .. red {:.4f} {}\n",
                 a.output, img->width(), img->height(), vmax * scale, u);
  }
  return 0;
}

}  // namespace follicle::cli
