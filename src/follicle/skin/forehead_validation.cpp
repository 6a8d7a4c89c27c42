#include "follicle/skin/forehead_validation.hpp"

#include <cmath>

#include "follicle/skin/face_rig.hpp"

namespace follicle::skin {

geom::TriMesh make_cylinder_patch(double width, double height, double radius, double spacing) {
  geom::TriMesh m;
  const int nx = std::max(1, int(std::lround(width / spacing)));
  const int ny = std::max(1, int(std::lround(height / spacing)));
  const double size = std::max(width, height);
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) {
      const double s = -0.5 * width + width * i / nx, y = -0.5 * height + height * j / ny;
      if (radius > 0) {
        const double th = s / radius;
        m.positions.emplace_back(radius * std::sin(th), y, radius * std::cos(th));
      } else {
        m.positions.emplace_back(s, y, 0.0);  // flat patch
      }
      m.uvs.emplace_back((s + 0.5 * width) / size, (y + 0.5 * height) / size);
    }
  auto id = [&](int i, int j) { return j * (nx + 1) + i; };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      // Counter-clockwise seen from +z (outside).
      m.faces.emplace_back(id(i, j), id(i + 1, j), id(i + 1, j + 1));
      m.faces.emplace_back(id(i, j), id(i + 1, j + 1), id(i, j + 1));
    }
  m.uv_faces = m.faces;
  m.name = "forehead-patch";
  return m;
}

ForeheadCase make_forehead_case(const Context& ctx, const ForeheadCaseParams& p) {
  p.validate();
  ForeheadCase c;
  c.rest = make_cylinder_patch(p.width, p.height, p.radius, p.grid);
  const double size = std::max(p.width, p.height);
  std::vector<double> ys;
  for (int k = 0; k < p.furrows; ++k) {
    const double y = (k - 0.5 * (p.furrows - 1)) * p.spacing;
    ys.push_back(y);
    LargeWrinkle w;
    w.name = fmt::format("furrow{}", k);
    const double v = (y + 0.5 * p.height) / size;
    const double u0 = -0.2, u1 = p.width / size + 0.2;  // beyond the patch: no end taper inside
    w.control = {Vec2(u0, v), Vec2(u0 + (u1 - u0) / 3, v), Vec2(u0 + 2 * (u1 - u0) / 3, v),
                 Vec2(u1, v)};
    w.depth = p.depth;
    w.width = p.wrinkle_width;
    w.r = p.r;
    w.end_taper = 0.0;
    c.wrinkles.push_back(w);
  }
  const RefinedMesh ref = refine_around_wrinkles(c.rest, c.wrinkles, p.refine);
  const WrinkleLayer layer(ref.mesh, c.wrinkles);
  // Shrink vertically by s0 (a known deformation of the rest surface).
  std::vector<Vec3> def = ref.mesh.positions;
  for (auto& q : def) q.y() *= (1.0 - p.shrink);
  std::vector<double> s;
  double sum = 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < layer.num_wrinkles(); ++i) {
    layer.shrinkage(ctx, i, def, s);
    for (double x : s) {
      sum += x;
      ++n;
      c.max_shrinkage_error = std::max(c.max_shrinkage_error, std::abs(x - p.shrink));
    }
  }
  c.mean_shrinkage = n ? sum / double(n) : 0.0;
  std::vector<double> h;
  layer.heights(ctx, def, h);
  const TextureSpaceMesh& tex = layer.texture_mesh();
  std::vector<Vec3> fn, nrm;
  std::vector<double> fa;
  compute_vertex_normals(ctx, ref.mesh, tex, def, fn, fa, nrm);
  c.generated = ref.mesh;
  for (std::size_t i = 0; i < def.size(); ++i) c.generated.positions[i] = def[i] + h[i] * nrm[i];
  c.generated.normals.clear();
  // Analytic reference.
  geom::TriMesh R = make_cylinder_patch(p.width, p.height, p.radius, p.reference_grid);
  const double M = amplitude_modulation(p.shrink, p.r);
  for (auto& q : R.positions) {
    const double y = q.y();
    double H = 0;
    for (double yk : ys)
      H += M * wrinkle_shape(std::abs(y - yk), p.depth, p.wrinkle_width);  // (2.1)(2.4)
    const Vec3 radial = Vec3(q.x(), 0, q.z()).normalized();
    q = (p.radius + H) * radial + Vec3(0, (1.0 - p.shrink) * y, 0);
  }
  c.reference = std::move(R);
  return c;
}

}  // namespace follicle::skin
