#include "follicle/skin/tissue_bando2002.hpp"

#include <algorithm>
#include <cmath>

#include "follicle/core/error.hpp"
#include "follicle/core/parallel.hpp"

namespace follicle::skin {

double sample_texture(const image::ImageF& img, const Vec2& uv) {
  if (img.empty()) return 0.0;
  const int W = img.width(), H = img.height();
  double u = uv.x() - std::floor(uv.x());
  const double v = std::clamp(uv.y(), 0.0, 1.0);
  const double x = u * W - 0.5, y = (1.0 - v) * H - 0.5;
  const int x0 = int(std::floor(x)), y0 = int(std::floor(y));
  const double fx = x - x0, fy = y - y0;
  auto at = [&](int xi, int yi) {
    xi = ((xi % W) + W) % W;
    yi = std::clamp(yi, 0, H - 1);
    return double(img.at(xi, yi));
  };
  return (1 - fy) * ((1 - fx) * at(x0, y0) + fx * at(x0 + 1, y0)) +
         fy * ((1 - fx) * at(x0, y0 + 1) + fx * at(x0 + 1, y0 + 1));
}

std::vector<double> initial_thickness(const TextureSpaceMesh& tex, const image::ImageF* map,
                                      const TissueParams& params) {
  params.validate();
  std::vector<double> h(tex.vertex_uv.size(), params.default_thickness);
  if (map && !map->empty())
    for (std::size_t i = 0; i < h.size(); ++i)
      h[i] = std::clamp(sample_texture(*map, tex.vertex_uv[i]), 0.0, 1.0) * params.max_thickness;
  return h;
}

SubcutaneousTissue::SubcutaneousTissue(const geom::TriMesh& rest, const TextureSpaceMesh& tex,
                                       std::vector<double> h0)
    : m_tex(&tex), m_h0(std::move(h0)) {
  if (m_h0.size() != rest.positions.size())
    fail("tissue: {} thickness values for {} vertices", m_h0.size(), rest.positions.size());
  m_rest_area.resize(rest.faces.size());
  for (std::size_t f = 0; f < rest.faces.size(); ++f) m_rest_area[f] = rest.face_area(f);
}

void SubcutaneousTissue::expansion(const Context& ctx, const std::vector<double>& area,
                                   std::vector<double>& e) const {
  e.resize(m_h0.size());
  parallel_for(
      ctx, 0, m_h0.size(),
      [&](std::size_t i) {
        double s = 0;
        int n = 0;
        for (std::size_t k = m_tex->vf_offsets[i]; k < m_tex->vf_offsets[i + 1]; ++k) {
          const auto f = std::size_t(m_tex->vf_faces[k]);
          if (m_rest_area[f] > 0) {
            s += area[f] / m_rest_area[f];
            ++n;
          }
        }
        e[i] = n > 0 ? s / n : 1.0;  // e_i: mean area ratio of the incident triangles
      },
      1024);
}

void SubcutaneousTissue::offsets(const Context& ctx, const std::vector<double>& area,
                                 std::vector<double>& off) const {
  expansion(ctx, area, off);
  for (std::size_t i = 0; i < off.size(); ++i) {
    const double e = std::max(off[i], 1e-3);  // guard collapsed triangles
    off[i] = m_h0[i] / e - m_h0[i];           // h_i = h0_i / e_i (volume preservation)
  }
}

}  // namespace follicle::skin
