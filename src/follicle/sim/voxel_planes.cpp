#include "follicle/sim/voxel_planes.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "follicle/core/error.hpp"
#include "follicle/core/resources.hpp"
#include "follicle/core/rng.hpp"

namespace follicle::sim {

namespace {
// The cell of a key (VoxelPlanes::key inverted).
Eigen::Vector3i unkey(uint64_t k) {
  auto g = [](uint64_t v) { return int(v & 0x1FFFFFu) - (1 << 20); };
  return Eigen::Vector3i(g(k), g(k >> 21), g(k >> 42));
}
constexpr int kFaceNeighbours[6][3] = {{-1, 0, 0}, {1, 0, 0},  {0, -1, 0},
                                       {0, 1, 0},  {0, 0, -1}, {0, 0, 1}};
}  // namespace

uint64_t VoxelPlanes::key(const Eigen::Vector3i& c) {
  // 21 bits per axis, offset so negative cells stay distinct.
  auto f = [](int v) { return uint64_t(uint32_t(v + (1 << 20)) & 0x1FFFFFu); };
  return f(c.x()) | (f(c.y()) << 21) | (f(c.z()) << 42);
}

Eigen::Vector3i VoxelPlanes::cell(const Vec3& x) const {
  return Eigen::Vector3i(int(std::floor(x.x() / m_size)), int(std::floor(x.y() / m_size)),
                         int(std::floor(x.z() / m_size)));
}

VoxelPlanes VoxelPlanes::build(const std::vector<const geom::TriMesh*>& meshes,
                               const VoxelPlanesParams& params, uint64_t seed) {
  params.validate();
  if (meshes.empty()) fail("voxel planes: no body mesh given");
  VoxelPlanes vp;
  vp.m_size = params.voxel_size;
  const double density = params.samples_per_voxel / (params.voxel_size * params.voxel_size);
  struct Acc {
    Vec3 p = Vec3::Zero();
    Vec3 n = Vec3::Zero();
    int count = 0;
  };
  // Resource guard: the sample count is known from the area before any sampling (a sphere head
  // of 10 m radius asked for 178 M samples and ran for minutes with growing memory).
  double total_area = 0;
  for (const geom::TriMesh* m : meshes) {
    if (!m) continue;
    for (const Vec3i& fc : m->faces) {
      bool in_range = true;
      for (int k = 0; k < 3; ++k)
        in_range = in_range && fc[k] >= 0 && std::size_t(fc[k]) < m->positions.size();
      if (!in_range) continue;  // reported below with the face number
      total_area += 0.5 * (m->positions[fc[1]] - m->positions[fc[0]])
                              .cross(m->positions[fc[2]] - m->positions[fc[0]])
                              .norm();
    }
  }
  const double expected = total_area * density;
  if (!(expected <= params.max_samples))
    fail_at("voxel_planes.max_samples",
            "the body's surface of {:.4g} m^2 at voxel_size {} m needs {} samples, more than the "
            "budget of {} (is the body in metres? a larger voxel_size or fewer samples_per_voxel "
            "also help)",
            total_area, params.voxel_size, format_count(expected),
            format_count(params.max_samples));
  std::unordered_map<uint64_t, Acc> acc;
  Rng rng = Rng::stream(seed, 0x564f58ull);
  for (std::size_t mi = 0; mi < meshes.size(); ++mi) {
    const geom::TriMesh* m = meshes[mi];
    if (!m || m->faces.empty()) fail("voxel planes: body mesh {} is empty", mi);
    const auto nv = m->positions.size();
    for (std::size_t f = 0; f < m->faces.size(); ++f) {
      const Vec3i& fc = m->faces[f];
      for (int k = 0; k < 3; ++k)
        if (fc[k] < 0 || std::size_t(fc[k]) >= nv)
          fail("voxel planes: body mesh {} face {} has vertex index {} out of range [0, {})", mi, f,
               fc[k], nv);
      const Vec3 &a = m->positions[fc[0]], &b = m->positions[fc[1]], &c = m->positions[fc[2]];
      if (!a.allFinite() || !b.allFinite() || !c.allFinite())
        fail("voxel planes: body mesh {} face {} has a non-finite vertex", mi, f);
      const Vec3 cr = (b - a).cross(c - a);
      const double area = 0.5 * cr.norm();
      if (area <= 0) continue;
      const Vec3 n = cr.normalized();
      // Number of samples proportional to area; the fractional part is drawn at random.
      const double expect = area * density;
      int count = int(std::floor(expect));
      if (rng.uniform() < expect - count) ++count;
      for (int s = 0; s < count; ++s) {
        double r1 = rng.uniform(), r2 = rng.uniform();
        if (r1 + r2 > 1) {
          r1 = 1 - r1;
          r2 = 1 - r2;
        }
        const Vec3 p = a + r1 * (b - a) + r2 * (c - a);
        Acc& e = acc[key(vp.cell(p))];
        e.p += p;
        e.n += n;
        ++e.count;
        ++vp.m_num_samples;
      }
    }
  }
  for (auto& [k, e] : acc) {
    BodyPlane pl;
    pl.p = e.p / e.count;
    const double nn = e.n.norm();
    if (nn < 1e-9) continue;  // opposite sheets cancel: no usable plane
    pl.n = e.n / nn;
    vp.m_planes.emplace(k, pl);
  }
  // Voxels the surface only clips at a corner or an edge may draw no sample and leave a hole in
  // the shell, through which a particle passes into the empty inside unseen (a strand's tip in a
  // head shake went 8.5 mm into a sphere head through one). An empty voxel that the plane of a
  // sampled face neighbour passes through gets that plane, the nearest to its centre of those
  // (edge and corner neighbours' planes extrapolate too far on a scanned head): the surface crosses
  // it, sampling missed it. Each value depends on the sampled voxels only (the neighbours in a
  // fixed order), not on any iteration order.
  std::vector<uint64_t> empty_near;
  std::vector<std::pair<uint64_t, BodyPlane>> filled;
  for (const auto& [k, e] : acc) {
    const Eigen::Vector3i c = unkey(k);
    for (const auto& o : kFaceNeighbours) {
      const uint64_t nk = key(c + Eigen::Vector3i(o[0], o[1], o[2]));
      if (!acc.count(nk)) empty_near.push_back(nk);
    }
  }
  std::sort(empty_near.begin(), empty_near.end());
  empty_near.erase(std::unique(empty_near.begin(), empty_near.end()), empty_near.end());
  for (const uint64_t k : empty_near) {
    const Eigen::Vector3i c = unkey(k);
    const Vec3 centre = (c.cast<double>() + Vec3::Constant(0.5)) * vp.m_size;
    const BodyPlane* best = nullptr;
    double best_d = 0;
    for (const auto& o : kFaceNeighbours) {
      const auto it = vp.m_planes.find(key(c + Eigen::Vector3i(o[0], o[1], o[2])));
      if (it == vp.m_planes.end()) continue;
      const BodyPlane& pl = it->second;
      const double d = std::abs((centre - pl.p).dot(pl.n));
      const double reach = 0.5 * vp.m_size * pl.n.cwiseAbs().sum();  // the cube's extent along n
      if (d <= reach && (!best || d < best_d)) best = &pl, best_d = d;
    }
    if (best) filled.emplace_back(k, *best);
  }
  for (const auto& [k, pl] : filled) vp.m_planes.emplace(k, pl);
  vp.build_dense_index();
  return vp;
}

void VoxelPlanes::build_dense_index() {
  m_dense.clear();
  m_dense_planes.clear();
  if (m_planes.empty()) return;
  Eigen::Vector3i lo = unkey(m_planes.begin()->first), hi = lo;
  for (const auto& [k, pl] : m_planes) {
    const Eigen::Vector3i c = unkey(k);
    lo = lo.cwiseMin(c);
    hi = hi.cwiseMax(c);
  }
  const Eigen::Vector3i dim = hi - lo + Eigen::Vector3i::Ones();
  const std::size_t cells = std::size_t(dim.x()) * std::size_t(dim.y()) * std::size_t(dim.z());
  if (cells > kMaxDenseCells) return;  // a sparse body over a large box: hash lookups
  m_lo = lo;
  m_dim = dim;
  m_dense.assign(cells, -1);
  m_dense_planes.reserve(m_planes.size());
  for (const auto& [k, pl] : m_planes) {
    const Eigen::Vector3i c = unkey(k) - lo;
    m_dense[(std::size_t(c.z()) * std::size_t(dim.y()) + std::size_t(c.y())) *
                std::size_t(dim.x()) +
            std::size_t(c.x())] = int32_t(m_dense_planes.size());
    m_dense_planes.push_back(pl);
  }
}

const BodyPlane* VoxelPlanes::find(const Vec3& x) const {
  if (m_planes.empty()) return nullptr;
  if (!m_dense.empty()) {
    // The same cell as cell(x) (the same division), range-checked before the conversion so a
    // point outside the box (or NaN) is simply "no plane".
    const double f[3] = {x.x() / m_size, x.y() / m_size, x.z() / m_size};
    int c[3];
    for (int a = 0; a < 3; ++a) {
      const double rel = f[a] - double(m_lo[a]);
      if (!(rel >= 0.0 && rel < double(m_dim[a]))) return nullptr;
      // floor(f) - lo without a libm call: f - lo is in [0, dim) here, so truncation is floor,
      // except where f is an integer and f - lo rounds differently: compare against the
      // integer cell of f itself.
      int i = int(rel);
      const double fl = double(m_lo[a] + i);
      if (fl > f[a])
        --i;
      else if (fl + 1.0 <= f[a])
        ++i;
      if (i < 0 || i >= m_dim[a]) return nullptr;
      c[a] = i;
    }
    const int32_t k = m_dense[(std::size_t(c[2]) * std::size_t(m_dim.y()) + std::size_t(c[1])) *
                                  std::size_t(m_dim.x()) +
                              std::size_t(c[0])];
    return k < 0 ? nullptr : &m_dense_planes[std::size_t(k)];
  }
  auto it = m_planes.find(key(cell(x)));
  return it == m_planes.end() ? nullptr : &it->second;
}

double VoxelPlanes::distance(const Vec3& x) const {
  const BodyPlane* pl = find(x);
  if (!pl) return std::numeric_limits<double>::infinity();
  return (x - pl->p).dot(pl->n);  // (3.19)
}

std::vector<BodyPlane> VoxelPlanes::planes() const {
  std::vector<BodyPlane> out;
  out.reserve(m_planes.size());
  for (const auto& [k, p] : m_planes) out.push_back(p);
  return out;
}

namespace {
// (3.23) Coulomb friction against a normal stopping acceleration of magnitude fcn.
Vec3 coulomb_friction(const Vec3& vt1, double fcn, double dt, double mu) {
  const double vt1n = vt1.norm();
  if (vt1n < mu * fcn * dt) return -vt1 / dt;   // sticking
  if (vt1n > 0) return -mu * fcn * vt1 / vt1n;  // sliding
  return Vec3::Zero();
}
}  // namespace

Vec3 body_contact_accel(const BodyPlane& plane, const Vec3& x, const Vec3& v_rel, const Vec3& a,
                        double dt, const BodyContactParams& params) {
  const Vec3& n = plane.n;
  const double d = (x - plane.p).dot(n);  // (3.19) distance from the body surface
  if (!(d < params.threshold)) return Vec3::Zero();
  Vec3 out = Vec3::Zero();
  const Vec3 vn = v_rel.dot(n) * n, vt = v_rel - vn;
  const Vec3 an = a.dot(n) * n, at = a - an;
  const Vec3 vn1 = vn + an * dt;  // (3.20) normal velocity after the step
  if (vn1.dot(n) <= 0) {
    const Vec3 fc = -an - vn / dt;  // (3.21) stop the particle at the surface (inelastic)
    out += fc;
    const Vec3 vt1 = vt + at * dt;  // (3.22) tangential velocity without friction
    out += coulomb_friction(vt1, fc.norm(), dt, params.mu);
  }
  if (d < 0) out += -params.k_r * d * n;  // (3.24) repulsion (per unit mass)
  return out;
}

Vec3 body_contact_accel_speculative(const BodyPlane& plane, const Vec3& x, const Vec3& v_rel,
                                    const Vec3& a, double dt, const BodyContactParams& params) {
  const Vec3& n = plane.n;
  const double d = (x - plane.p).dot(n);  // (3.19)
  if (!(d >= params.threshold)) return body_contact_accel(plane, x, v_rel, a, dt, params);
  const double vn1 = v_rel.dot(n) + a.dot(n) * dt;   // (3.20) normal velocity after the step
  const double edge = -(d - params.threshold) / dt;  // the normal velocity reaching the edge
  if (!(vn1 < edge)) return Vec3::Zero();
  const double fcn = (edge - vn1) / dt;  // (3.21) on the approach beyond the edge
  const Vec3 vt1 = (v_rel - v_rel.dot(n) * n) + (a - a.dot(n) * n) * dt;  // (3.22)
  return fcn * n + coulomb_friction(vt1, fcn, dt, params.mu);
}

}  // namespace follicle::sim
