#include "follicle/skin/wrinkle_transfer.hpp"

#include <fmt/format.h>

#include "follicle/core/error.hpp"
#include "follicle/geom/curves.hpp"
#include "follicle/geom/spatial_embree.hpp"
#include "follicle/geom/uv_locator.hpp"

namespace follicle::skin {

void SurfaceWrinkle::validate() const {
  validate_params(*this, "surface wrinkle '" + name + "'");
  if (points.size() < 2)
    fail("surface wrinkle '{}': {} point(s), need at least 2 along the furrow", name,
         points.size());
  for (const auto& p : points)
    if (!p.allFinite()) fail("surface wrinkle '{}': a point is not finite", name);
}

std::vector<LargeWrinkle> place_surface_wrinkles(const geom::TriMesh& mesh,
                                                 const std::vector<SurfaceWrinkle>& wrinkles,
                                                 const std::string& where, double max_distance) {
  std::vector<LargeWrinkle> out;
  if (wrinkles.empty()) return out;
  if (!mesh.has_uvs())
    fail("{}: the mesh has no texture coordinates to place the surface wrinkles on", where);
  const geom::MeshQuery query(mesh);
  const std::vector<int> island = geom::uv_islands(mesh);
  for (const auto& w : wrinkles) {
    w.validate();
    std::vector<Vec2> uv;
    int first_island = -1;
    for (std::size_t i = 0; i < w.points.size(); ++i) {
      const auto cp = query.closest_point(w.points[i]);
      if (cp.face < 0 || !(cp.distance <= max_distance))
        fail(
            "{}: surface wrinkle '{}': point {} lies {:.1f} mm from the skin (at most {:.0f} mm): "
            "the points are metres in the mesh's frame; check the units and that they were made "
            "for this head",
            where, w.name, i, 1e3 * cp.distance, 1e3 * max_distance);
      const auto f = std::size_t(cp.face);
      if (first_island < 0) first_island = island[f];
      if (island[f] != first_island)
        fail(
            "{}: surface wrinkle '{}' crosses a seam of the texture layout (point {} lies on "
            "another UV island than point 0); split it into two wrinkles or change the mapping",
            where, w.name, i);
      const Vec3i& t = mesh.uv_faces[f];
      uv.push_back(cp.bary[0] * mesh.uvs[std::size_t(t[0])] +
                   cp.bary[1] * mesh.uvs[std::size_t(t[1])] +
                   cp.bary[2] * mesh.uvs[std::size_t(t[2])]);
    }
    const geom::Bezier2 c = geom::fit_cubic_bezier<2>(uv);
    LargeWrinkle lw;
    lw.name = w.name;
    for (int k = 0; k < 4; ++k) lw.control[std::size_t(k)] = c.p[std::size_t(k)];
    lw.depth = w.depth;
    lw.width = w.width;
    lw.r = w.r;
    lw.end_taper = w.end_taper;
    out.push_back(lw);
  }
  return out;
}

std::vector<SurfaceWrinkle> lift_wrinkles_to_surface(const geom::TriMesh& mesh,
                                                     const std::vector<LargeWrinkle>& wrinkles,
                                                     const std::string& where, int samples) {
  std::vector<SurfaceWrinkle> out;
  if (wrinkles.empty()) return out;
  if (samples < 2) fail("{}: lifting wrinkles needs at least 2 samples, got {}", where, samples);
  if (!mesh.has_uvs())
    fail("{}: the mesh has no texture coordinates: its wrinkle curves cannot be found on it",
         where);
  const geom::UvLocator locator(mesh);
  for (const auto& w : wrinkles) {
    geom::Bezier2 c;
    for (int k = 0; k < 4; ++k) c.p[std::size_t(k)] = w.control[std::size_t(k)];
    SurfaceWrinkle s;
    s.name = w.name;
    s.depth = w.depth;
    s.width = w.width;
    s.r = w.r;
    s.end_taper = w.end_taper;
    for (const Vec2& q : c.sample_by_length(std::size_t(samples))) {
      const auto hit = locator.locate(q, 1e-6);
      if (hit.face < 0) continue;
      const Vec3i& f = mesh.faces[std::size_t(hit.face)];
      s.points.push_back(hit.bary[0] * mesh.positions[std::size_t(f[0])] +
                         hit.bary[1] * mesh.positions[std::size_t(f[1])] +
                         hit.bary[2] * mesh.positions[std::size_t(f[2])]);
    }
    if (s.points.size() < 2)
      fail("{}: wrinkle '{}' lies outside the mesh's texture layout ({} of {} samples on it)",
           where, w.name, s.points.size(), samples);
    out.push_back(std::move(s));
  }
  return out;
}

std::vector<LargeWrinkle> carry_wrinkles(const geom::TriMesh& from, const geom::TriMesh& to,
                                         const std::vector<LargeWrinkle>& wrinkles,
                                         const std::string& where) {
  if (from.positions.size() != to.positions.size() || from.faces.size() != to.faces.size())
    fail("{}: carrying wrinkles needs the same surface ({} / {} vertices, {} / {} faces)", where,
         from.positions.size(), to.positions.size(), from.faces.size(), to.faces.size());
  // The same surface: each lifted point lies on it, so max_distance only absorbs rounding.
  return place_surface_wrinkles(to, lift_wrinkles_to_surface(from, wrinkles, where, 33), where,
                                1e-6 * (1.0 + (from.bounds().max() - from.bounds().min()).norm()));
}

}  // namespace follicle::skin
