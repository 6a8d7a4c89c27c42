#include "follicle/geom/spatial_embree.hpp"

#include <embree3/rtcore.h>

#include <cmath>

#include "follicle/core/error.hpp"
#include "follicle/core/parallel.hpp"

namespace follicle::geom {

Vec3 closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  // Ericson, Real-Time Collision Detection, 5.1.5 (Voronoi regions of the triangle).
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return Vec3(1, 0, 0);
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return Vec3(0, 1, 0);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double v = d1 / (d1 - d3);
    return Vec3(1 - v, v, 0);
  }
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return Vec3(0, 0, 1);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double w = d2 / (d2 - d6);
    return Vec3(1 - w, 0, w);
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return Vec3(0, 1 - w, w);
  }
  const double sum = va + vb + vc;
  if (!(sum > 0)) return Vec3(1, 0, 0);  // degenerate triangle: fall back to a corner
  const double v = vb / sum, w = vc / sum;
  return Vec3(1 - v - w, v, w);
}

struct MeshQuery::Impl {
  std::vector<Vec3> positions;
  std::vector<Vec3i> faces;
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  double start_radius = 0;    // first radius of the growing closest-point search
  double give_up_radius = 0;  // beyond this, search unbounded
  ~Impl() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
};

namespace {

struct PointQueryData {
  const std::vector<Vec3>* positions;
  const std::vector<Vec3i>* faces;
  Vec3 q;
  ClosestPoint best;
};

bool closest_point_callback(RTCPointQueryFunctionArguments* args) {
  auto* d = static_cast<PointQueryData*>(args->userPtr);
  const Vec3i& f = (*d->faces)[args->primID];
  const Vec3& a = (*d->positions)[std::size_t(f[0])];
  const Vec3& b = (*d->positions)[std::size_t(f[1])];
  const Vec3& c = (*d->positions)[std::size_t(f[2])];
  const Vec3 w = closest_point_on_triangle(d->q, a, b, c);
  const Vec3 x = w[0] * a + w[1] * b + w[2] * c;
  const double dist = (x - d->q).norm();
  if (dist < d->best.distance ||
      (dist == d->best.distance && int(args->primID) < d->best.face)) {  // deterministic ties
    d->best = {x, int(args->primID), w, dist};
    // Shrink the search sphere (rounded up so float rounding never prunes an equal candidate).
    args->query->radius = std::nextafter(float(dist), std::numeric_limits<float>::infinity());
    return true;
  }
  return false;
}

}  // namespace

MeshQuery::MeshQuery(const TriMesh& mesh) : m_impl(std::make_unique<Impl>()) {
  if (mesh.faces.empty()) fail("MeshQuery: the mesh has no faces");
  mesh.check("MeshQuery");
  m_impl->positions = mesh.positions;
  m_impl->faces = mesh.faces;
  const Eigen::AlignedBox3d box = mesh.bounds();
  const double diag = box.sizes().norm();
  m_impl->start_radius = diag > 0 ? diag / 128 : 1.0;
  m_impl->give_up_radius = diag > 0 ? 4 * diag : 1.0;
  m_impl->device = rtcNewDevice(nullptr);
  if (!m_impl->device)
    fail("MeshQuery: cannot create an Embree device (error {})", int(rtcGetDeviceError(nullptr)));
  m_impl->scene = rtcNewScene(m_impl->device);
  rtcSetSceneBuildQuality(m_impl->scene, RTC_BUILD_QUALITY_HIGH);
  RTCGeometry geom = rtcNewGeometry(m_impl->device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0,
                                                         RTC_FORMAT_FLOAT3, 3 * sizeof(float),
                                                         mesh.positions.size()));
  auto* ib = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(
      geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), mesh.faces.size()));
  if (!vb || !ib) {
    rtcReleaseGeometry(geom);
    fail("MeshQuery: Embree could not allocate buffers (error {})",
         int(rtcGetDeviceError(m_impl->device)));
  }
  for (std::size_t i = 0; i < mesh.positions.size(); ++i)
    for (int k = 0; k < 3; ++k) vb[3 * i + std::size_t(k)] = float(mesh.positions[i][k]);
  for (std::size_t f = 0; f < mesh.faces.size(); ++f)
    for (int k = 0; k < 3; ++k) ib[3 * f + std::size_t(k)] = uint32_t(mesh.faces[f][k]);
  rtcCommitGeometry(geom);
  rtcAttachGeometry(m_impl->scene, geom);
  rtcReleaseGeometry(geom);
  rtcCommitScene(m_impl->scene);
  if (auto err = rtcGetDeviceError(m_impl->device); err != RTC_ERROR_NONE)
    fail("MeshQuery: Embree BVH build failed (error {})", int(err));
}

MeshQuery::~MeshQuery() = default;
MeshQuery::MeshQuery(MeshQuery&&) noexcept = default;
MeshQuery& MeshQuery::operator=(MeshQuery&&) noexcept = default;

const std::vector<Vec3>& MeshQuery::positions() const {
  return m_impl->positions;
}
const std::vector<Vec3i>& MeshQuery::faces() const {
  return m_impl->faces;
}

namespace {
void fill_ray(RTCRay& r, const Vec3& o, const Vec3& d, double tmin, double tmax) {
  r.org_x = float(o.x());
  r.org_y = float(o.y());
  r.org_z = float(o.z());
  r.dir_x = float(d.x());
  r.dir_y = float(d.y());
  r.dir_z = float(d.z());
  r.tnear = float(tmin);
  r.tfar = std::isfinite(tmax) ? float(tmax) : std::numeric_limits<float>::infinity();
  r.time = 0;
  r.mask = 0xFFFFFFFFu;
  r.id = 0;
  r.flags = 0;
}
}  // namespace

RayHit MeshQuery::intersect(const Vec3& origin, const Vec3& dir, double tmin, double tmax) const {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRayHit rh;
  fill_ray(rh.ray, origin, dir, tmin, tmax);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(m_impl->scene, &ctx, &rh);
  RayHit out;
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return out;
  out.hit = true;
  out.face = int(rh.hit.primID);
  out.bary = Vec3(1.0 - double(rh.hit.u) - double(rh.hit.v), rh.hit.u, rh.hit.v);
  const Vec3i& f = m_impl->faces[std::size_t(out.face)];
  out.point = out.bary[0] * m_impl->positions[std::size_t(f[0])] +
              out.bary[1] * m_impl->positions[std::size_t(f[1])] +
              out.bary[2] * m_impl->positions[std::size_t(f[2])];
  out.distance = rh.ray.tfar;
  return out;
}

bool MeshQuery::occluded(const Vec3& origin, const Vec3& dir, double tmin, double tmax) const {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRay r;
  fill_ray(r, origin, dir, tmin, tmax);
  rtcOccluded1(m_impl->scene, &ctx, &r);
  return r.tfar < 0;  // Embree sets tfar = -inf on a hit
}

ClosestPoint MeshQuery::closest_point(const Vec3& p, double max_distance) const {
  // Embree visits every primitive overlapping the query sphere until the callback shrinks it,
  // so an unbounded query far from the surface starts by visiting much of the BVH. Growing the
  // radius geometrically from a small start (x8 per round) costs a few cheap small queries and
  // is several times faster for points away from the surface; the result is identical.
  double r = std::min(max_distance, m_impl->start_radius);
  for (;;) {
    PointQueryData data{&m_impl->positions, &m_impl->faces, p, ClosestPoint{}};
    data.best.distance = r;
    RTCPointQuery q;
    q.x = float(p.x());
    q.y = float(p.y());
    q.z = float(p.z());
    q.time = 0;
    q.radius = std::isfinite(r) ? std::nextafter(float(r), std::numeric_limits<float>::infinity())
                                : std::numeric_limits<float>::infinity();
    RTCPointQueryContext ctx;
    rtcInitPointQueryContext(&ctx);
    rtcPointQuery(m_impl->scene, &q, &ctx, closest_point_callback, &data);
    if (data.best.face >= 0) return data.best;
    if (r >= max_distance) {
      data.best.distance = std::numeric_limits<double>::infinity();
      return data.best;
    }
    r = r * 8 >= m_impl->give_up_radius ? max_distance : std::min(max_distance, r * 8);
  }
}

std::vector<ClosestPoint> MeshQuery::closest_points(const Context& ctx, std::span<const Vec3> pts,
                                                    double max_distance) const {
  std::vector<ClosestPoint> out(pts.size());
  parallel_for(
      ctx, 0, pts.size(), [&](std::size_t i) { out[i] = closest_point(pts[i], max_distance); },
      512);
  return out;
}

}  // namespace follicle::geom
