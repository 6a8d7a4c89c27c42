#include "follicle/hair/hairdressing_anjyo1992.hpp"

#include <algorithm>
#include <cmath>

#include "follicle/core/error.hpp"
#include "follicle/core/parallel.hpp"
#include "follicle/core/params.hpp"
#include "follicle/core/rng.hpp"

namespace follicle::hair {

bool PolarRange::contains(const Vec2& polar) const {
  const double az = polar.x(), ze = polar.y();
  if (ze < zenith_min || ze > zenith_max) return false;
  if (azimuth_min <= azimuth_max) return az >= azimuth_min && az <= azimuth_max;
  return az >= azimuth_min || az <= azimuth_max;
}

void ForceField::validate() const {
  validate_params(*this, "field");
  if (kind != "uniform" && kind != "attract" && kind != "radial")
    fail_at("field.kind", "unknown field kind \"{}\"; expected uniform, attract or radial", kind);
}

Vec3 ForceField::accel(const sim::Ellipsoid& hull, const Vec3& p) const {
  if (kind == "uniform") return hull.rotation * vector;  // given in the head's axes
  if (kind == "attract") {
    const Vec3 t = hull.from_normalized(point) - p;
    const double n = t.norm();
    return n > 1e-12 ? Vec3(strength * t / n) : Vec3::Zero();
  }
  const Vec3 t = p - hull.centre;  // radial
  const double n = t.norm();
  return n > 1e-12 ? Vec3(strength * t / n) : Vec3::Zero();
}

void CutRule::validate() const {
  validate_params(*this, "cut");
  if (kind != "threshold" && kind != "height_length")
    fail_at("cut.kind", "unknown cut kind \"{}\"; expected threshold or height_length", kind);
  if (kind == "height_length" && !(height_high > height_low))
    fail_at("cut.height_high", "height_high {} must exceed height_low {}", height_high, height_low);
}

void HairPart::validate() const {
  validate_params(*this, "part");
  for (const auto& p : pores) p.validate();
  for (const auto& f : fields) f.validate();
  for (const auto& c : cuts) c.validate();
  if (tie.enabled && tie.tail_direction.norm() < 1e-9)
    fail_at("part.tie.tail_direction", "tail direction must not be zero");
}

void HairStyle::validate() const {
  for (std::size_t i = 0; i < parts.size(); ++i) {
    try {
      parts[i].validate();
    } catch (const Error& e) {
      fail_at(fmt::format("style.parts[{}]", i), "{}", e.what());
    }
  }
}

namespace {

// Great-circle path on the hull (grown by `offset`) from direction qa to qb (unit vectors in
// normalized coordinates), as a dense world polyline.
std::vector<Vec3> hull_path(const sim::Ellipsoid& hull, double offset, const Vec3& qa,
                            const Vec3& qb, int samples) {
  std::vector<Vec3> out;
  const double ang = std::acos(std::clamp(qa.dot(qb), -1.0, 1.0));
  const sim::Ellipsoid g = hull.grown(offset);
  for (int s = 0; s <= samples; ++s) {
    const double t = double(s) / samples;
    Vec3 q;
    if (ang < 1e-9) {
      q = qa;
    } else {
      q = (std::sin((1 - t) * ang) * qa + std::sin(t * ang) * qb) / std::sin(ang);
    }
    out.push_back(g.from_normalized(q.normalized()));
  }
  return out;
}

// Resamples polyline `path` (starting at nodes[0]) with step d into nodes[1..]; returns the number
// of segments produced (<= max_seg).
int walk_path(const std::vector<Vec3>& path, double d, int max_seg, Vec3* nodes) {
  int n = 0;
  Vec3 cur = nodes[0];
  std::size_t j = 1;
  while (n < max_seg && j < path.size()) {
    // Find the first path point at distance >= d from cur, intersect the segment with the sphere.
    while (j < path.size() && (path[j] - cur).norm() < d) ++j;
    if (j >= path.size()) break;
    const Vec3 a = path[j - 1], b = path[j];
    // Solve |a + s (b - a) - cur| = d for s in [0, 1].
    const Vec3 ab = b - a, ac = a - cur;
    const double A = ab.squaredNorm(), B = 2 * ab.dot(ac), C = ac.squaredNorm() - d * d;
    const double disc = std::max(0.0, B * B - 4 * A * C);
    double s = A > 0 ? (-B + std::sqrt(disc)) / (2 * A) : 1.0;
    s = std::clamp(s, 0.0, 1.0);
    cur = a + s * ab;
    nodes[++n] = cur;
  }
  return n;
}

}  // namespace

void style_roots(const Context& ctx, const sim::Ellipsoid& hull, const HairPart& part,
                 const HairRoots& roots, uint64_t seed, geom::StrandSet& out,
                 const ClosestPointFn& scalp) {
  part.validate();
  const int k = part.beam.segments;
  const std::size_t n = roots.size();
  std::vector<Vec3> nodes(n * std::size_t(k + 1));
  std::vector<double> cut_t(n, double(k));  // kept length in segments (fractional)
  parallel_for(
      ctx, 0, n,
      [&](std::size_t s) {
        Vec3* P = &nodes[s * std::size_t(k + 1)];
        const Vec2 polar = roots.polar[s];
        const double L = roots.length[s];
        const double d = L / k;
        // Fields acting on this strand (selected by its pore).
        uint32_t active[32];
        int na = 0;
        for (std::size_t f = 0; f < part.fields.size() && na < 32; ++f)
          if (part.fields[f].pores.contains(polar)) active[na++] = uint32_t(f);
        SegmentLoadFn extra;
        if (na > 0) {
          extra = [&, na, active_ptr = &active[0]](int, const Vec3& mid) {
            Vec3 a = Vec3::Zero();
            const Vec3 q = hull.normalized(mid);
            for (int f = 0; f < na; ++f) {
              const ForceField& ff = part.fields[active_ptr[f]];
              if (ff.nodes.contains(q)) a += ff.accel(hull, mid);
            }
            return a;
          };
        }
        if (!part.tie.enabled) {
          bend_strand(part.beam, &hull, roots.position[s], roots.direction[s], L, extra, P, scalp);
        } else {
          // Combed along the hull to the tie, then a separately designed tail (Fig. 6c).
          Rng rng = Rng::stream(seed ^ 0x7A11ull, s);
          const Vec3 tail_dir = (hull.rotation * part.tie.tail_direction).normalized();
          Vec3 e1 = tail_dir.cross(Vec3::UnitX());
          if (e1.norm() < 1e-6) e1 = tail_dir.cross(Vec3::UnitY());
          e1.normalize();
          const Vec3 e2 = tail_dir.cross(e1);
          // Each strand arrives at its own point of the tie disc.
          const double rr = part.tie.radius * std::sqrt(rng.uniform());
          const double ang = 2 * kPi * rng.uniform();
          const Vec3 tie_s =
              hull.from_normalized(part.tie.point) + rr * (std::cos(ang) * e1 + std::sin(ang) * e2);
          P[0] = roots.position[s];
          const Vec3 qa = hull.normalized(roots.position[s]).normalized();
          const Vec3 qb = hull.normalized(tie_s).normalized();
          const auto path = hull_path(hull, part.tie.surface_offset, qa, qb, 96);
          const int used = walk_path(path, d, k - 1, P);
          const int m = k - used;
          // The tail: a cantilever of the remaining m segments hanging from the tie.
          CantileverParams tb = part.beam;
          tb.segments = m;
          Vec3 tail[65];
          const Vec3 dir_s =
              (tail_dir + 0.2 * (rng.uniform(-1, 1) * e1 + rng.uniform(-1, 1) * e2)).normalized();
          bend_strand(tb, &hull, P[used], dir_s, m * d, extra, tail, {});
          for (int i = 1; i <= m; ++i) P[used + i] = tail[i];
        }
        // Cutting.
        double t = double(k);
        for (const CutRule& c : part.cuts) {
          if (!c.pores.contains(polar)) continue;
          if (c.kind == "threshold") {
            for (int i = 0; i <= k; ++i) {
              const double v = c.axis.dot(hull.normalized(P[i])) - c.threshold;
              if (v < 0) {
                if (i == 0) {
                  t = 0;
                } else {
                  const double vp = c.axis.dot(hull.normalized(P[i - 1])) - c.threshold;
                  t = std::min(t, (i - 1) + vp / (vp - v));
                }
                break;
              }
            }
          } else {
            const double h = hull.normalized(roots.position[s]).y();
            const double a =
                std::clamp((h - c.height_low) / (c.height_high - c.height_low), 0.0, 1.0);
            const double keep = c.length_low + a * (c.length_high - c.length_low);
            t = std::min(t, keep / d);
          }
        }
        cut_t[s] = std::max(0.0, t);
      },
      64);
  // Assemble (serial, in strand order).
  for (std::size_t s = 0; s < n; ++s) {
    const Vec3* P = &nodes[s * std::size_t(k + 1)];
    const double t = cut_t[s];
    const int whole = int(std::floor(t + 1e-9));
    const double frac = t - whole;
    const int npts = whole + 1 + (frac > 1e-6 && whole < k ? 1 : 0);
    if (npts < 2) {
      out.offsets.push_back(out.offsets.back());  // keep the index aligned; removed below
      continue;
    }
    for (int i = 0; i <= whole; ++i) out.points.push_back(P[i].cast<float>());
    if (npts > whole + 1)
      out.points.push_back((P[whole] + frac * (P[whole + 1] - P[whole])).cast<float>());
    out.offsets.push_back(uint32_t(out.points.size()));
  }
}

StyledHair build_style(const Context& ctx, const sim::Ellipsoid& hull, const HairStyle& style,
                       uint64_t seed, const ClosestPointFn& scalp) {
  style.validate();
  StyledHair all;
  HairRoots kept;
  for (std::size_t pi = 0; pi < style.parts.size(); ++pi) {
    const HairPart& part = style.parts[pi];
    const uint64_t pseed = seed * 0x9E3779B97F4A7C15ull + pi + 1;
    HairRoots roots = sample_pores(ctx, hull, part.pores, pseed, scalp);
    geom::StrandSet strands;
    style_roots(ctx, hull, part, roots, pseed, strands, scalp);
    // Drop strands cut away completely (empty), keep roots aligned with strands.
    for (std::size_t s = 0; s < strands.num_strands(); ++s) {
      const uint32_t b = strands.offsets[s], e = strands.offsets[s + 1];
      if (e - b < 2) continue;
      for (uint32_t i = b; i < e; ++i) all.strands.points.push_back(strands.points[i]);
      all.strands.offsets.push_back(uint32_t(all.strands.points.size()));
      kept.position.push_back(roots.position[s]);
      kept.direction.push_back(roots.direction[s]);
      kept.polar.push_back(roots.polar[s]);
      kept.length.push_back(roots.length[s]);
      kept.region.push_back(roots.region[s]);
      all.part.push_back(uint32_t(pi));
    }
  }
  all.roots = std::move(kept);
  return all;
}

}  // namespace follicle::hair
