#include "follicle/hair/groom.hpp"

#include <algorithm>
#include <cmath>

#include "follicle/core/error.hpp"
#include "follicle/core/parallel.hpp"

namespace follicle::hair {

void Groom::check(const std::string& where) const {
  strands.check(where);
  const std::size_t n = strands.num_strands();
  if (!roots.empty() && roots.size() != n)
    fail_at(where, "{} root bindings for {} strands, expected none or one per strand", roots.size(),
            n);
  if (!material.empty() && material.size() != n)
    fail_at(where, "{} material indices for {} strands, expected none or one per strand",
            material.size(), n);
  for (std::size_t s = 0; s < n; ++s) {
    if (strands.strand_size(s) < 2)
      fail_at(where, "strand {} has {} point(s), expected at least 2", s, strands.strand_size(s));
    if (!(strand_length(strands, s) > 0.0)) fail_at(where, "strand {} has zero length", s);
  }
  for (std::size_t s = 0; s < roots.size(); ++s)
    if (!roots[s].bary.allFinite()) fail_at(where, "strand {} has a non-finite root binding", s);
}

double bind_roots(const Context& ctx, const geom::MeshQuery& query, Groom& groom) {
  const std::size_t n = groom.num_strands();
  std::vector<Vec3> roots(n);
  for (std::size_t s = 0; s < n; ++s)
    roots[s] = groom.strands.points[groom.strands.strand_begin(s)].cast<double>();
  const auto hits = query.closest_points(ctx, roots);
  groom.roots.assign(n, RootBinding{});
  double worst = 0.0;
  for (std::size_t s = 0; s < n; ++s) {
    if (hits[s].face < 0) fail("groom: strand {} found no closest point on the mesh", s);
    groom.roots[s].face = hits[s].face;
    groom.roots[s].bary = hits[s].bary.cast<float>();
    worst = std::max(worst, hits[s].distance);
  }
  return worst;
}

namespace {

void check_binding(const Groom& groom, const geom::TriMesh& mesh) {
  if (!groom.bound()) fail("groom: the roots are not bound to a mesh");
  for (std::size_t s = 0; s < groom.roots.size(); ++s) {
    const int32_t f = groom.roots[s].face;
    if (f < 0 || std::size_t(f) >= mesh.faces.size())
      fail("groom: strand {} is bound to face {} but the mesh has {} faces", s, f,
           mesh.faces.size());
  }
}

}  // namespace

std::vector<Vec3> bound_root_positions(const Groom& groom, const geom::TriMesh& mesh) {
  check_binding(groom, mesh);
  std::vector<Vec3> out(groom.roots.size());
  for (std::size_t s = 0; s < out.size(); ++s) {
    const auto& r = groom.roots[s];
    const Vec3i& f = mesh.faces[std::size_t(r.face)];
    out[s] = double(r.bary[0]) * mesh.positions[std::size_t(f[0])] +
             double(r.bary[1]) * mesh.positions[std::size_t(f[1])] +
             double(r.bary[2]) * mesh.positions[std::size_t(f[2])];
  }
  return out;
}

std::vector<Vec3> bound_root_normals(const Groom& groom, const geom::TriMesh& mesh) {
  check_binding(groom, mesh);
  const bool smooth = mesh.normals.size() == mesh.positions.size();
  std::vector<Vec3> out(groom.roots.size());
  for (std::size_t s = 0; s < out.size(); ++s) {
    const auto& r = groom.roots[s];
    const std::size_t fi = std::size_t(r.face);
    Vec3 nrm = mesh.face_normal(fi);
    if (smooth) {
      const Vec3i& f = mesh.faces[fi];
      const Vec3 ns = double(r.bary[0]) * mesh.normals[std::size_t(f[0])] +
                      double(r.bary[1]) * mesh.normals[std::size_t(f[1])] +
                      double(r.bary[2]) * mesh.normals[std::size_t(f[2])];
      if (ns.norm() > 1e-12) nrm = ns;
    }
    const double len = nrm.norm();
    out[s] = len > 0 ? Vec3(nrm / len) : Vec3(0.0, 1.0, 0.0);
  }
  return out;
}

double strand_length(const geom::StrandSet& strands, std::size_t s) {
  double len = 0.0;
  const uint32_t b = strands.strand_begin(s), e = strands.offsets[s + 1];
  for (uint32_t i = b + 1; i < e; ++i)
    len += (strands.points[i] - strands.points[i - 1]).cast<double>().norm();
  return len;
}

namespace {

// Resamples strand s of `in` to n points by arc length (first and last point kept exactly),
// interpolating radius and colour, appending to `out`.
void resample_strand(const geom::StrandSet& in, std::size_t s, std::size_t n,
                     geom::StrandSet& out) {
  const uint32_t b = in.strand_begin(s);
  const std::size_t count = in.strand_size(s);
  std::vector<double> acc(count, 0.0);
  for (std::size_t i = 1; i < count; ++i)
    acc[i] = acc[i - 1] + (in.points[b + i] - in.points[b + i - 1]).cast<double>().norm();
  const double L = acc.back();
  std::size_t j = 1;
  for (std::size_t k = 0; k < n; ++k) {
    const double t = L * double(k) / double(n - 1);
    while (j < count - 1 && acc[j] < t) ++j;
    const double seg = acc[j] - acc[j - 1];
    const double u = seg > 0 ? std::clamp((t - acc[j - 1]) / seg, 0.0, 1.0) : 0.0;
    const uint32_t a = b + uint32_t(j - 1), c = b + uint32_t(j);
    Vec3f p = (in.points[a].cast<double>() + u * (in.points[c] - in.points[a]).cast<double>())
                  .cast<float>();
    if (k == 0) p = in.points[b];
    if (k == n - 1) p = in.points[b + count - 1];
    out.points.push_back(p);
    if (!in.radius.empty())
      out.radius.push_back(float((1.0 - u) * in.radius[a] + u * in.radius[c]));
    if (!in.color.empty())
      out.color.push_back(((1.0f - float(u)) * in.color[a] + float(u) * in.color[c]));
  }
  out.offsets.push_back(uint32_t(out.points.size()));
}

template <class Count>
Groom resample_with(const Groom& g, Count&& count) {
  Groom out;
  out.roots = g.roots;
  out.material = g.material;
  const auto& in = g.strands;
  for (std::size_t s = 0; s < in.num_strands(); ++s) {
    if (in.strand_size(s) < 2) fail("groom: strand {} has fewer than 2 points", s);
    resample_strand(in, s, count(s), out.strands);
  }
  return out;
}

}  // namespace

Groom resample_groom(const Groom& groom, double segment_length, std::size_t min_points,
                     std::size_t max_points) {
  if (!(segment_length > 0.0) || !std::isfinite(segment_length))
    fail("groom: resampling needs a segment length > 0, got {}", segment_length);
  min_points = std::max<std::size_t>(min_points, 2);
  max_points = std::max(max_points, min_points);
  return resample_with(groom, [&](std::size_t s) {
    // Segments of at most segment_length (a length within a relative 1e-6 of a whole number of
    // segments, e.g. after a float coordinate's round-off, counts as that number).
    const double n =
        std::ceil(strand_length(groom.strands, s) / segment_length * (1.0 - 1e-6)) + 1.0;
    return std::clamp(std::size_t(std::min(n, 1e9)), min_points, max_points);
  });
}

Groom resample_groom_fixed(const Groom& groom, std::size_t points_per_strand) {
  if (points_per_strand < 2)
    fail("groom: resampling needs at least 2 points per strand, got {}", points_per_strand);
  return resample_with(groom, [&](std::size_t) { return points_per_strand; });
}

}  // namespace follicle::hair
