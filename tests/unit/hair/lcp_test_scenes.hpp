#pragma once
// Small procedural scenes for the LCP tests: a sphere "head" with a scalp cap.
#include <cmath>

#include "follicle/core/context.hpp"
#include "follicle/geom/trimesh.hpp"
#include "follicle/hair/lcp_bando2003.hpp"
#include "follicle/hair/scalp_bando2003.hpp"

namespace follicle::test {

inline geom::TriMesh lcp_sphere(double radius, int nlat = 24, int nlon = 48) {
  geom::TriMesh m;
  m.positions.push_back({0, radius, 0});
  for (int i = 1; i < nlat; ++i) {
    const double th = kPi * i / nlat;
    for (int j = 0; j < nlon; ++j) {
      const double ph = 2 * kPi * j / nlon;
      m.positions.push_back(
          radius * Vec3(std::sin(th) * std::cos(ph), std::cos(th), -std::sin(th) * std::sin(ph)));
    }
  }
  m.positions.push_back({0, -radius, 0});
  const int south = int(m.positions.size()) - 1;
  auto id = [&](int i, int j) { return 1 + (i - 1) * nlon + (j % nlon); };
  for (int j = 0; j < nlon; ++j) m.faces.push_back({0, id(1, j), id(1, j + 1)});
  for (int i = 1; i < nlat - 1; ++i)
    for (int j = 0; j < nlon; ++j) {
      m.faces.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      m.faces.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  for (int j = 0; j < nlon; ++j) m.faces.push_back({id(nlat - 1, j), south, id(nlat - 1, j + 1)});
  m.compute_normals();
  return m;
}

/// Four curves along the latitude `polar` [rad from +y], corners at azimuths 45 + 90k degrees.
inline hair::ScalpCurves lcp_cap_curves(double radius, double polar, double az0 = kPi / 4) {
  hair::ScalpCurves c;
  for (int k = 0; k < 4; ++k)
    for (int i = 0; i <= 4; ++i) {
      const double ph = az0 + kPi / 2 * (k + i / 4.0);
      c[k].push_back(radius * Vec3(std::sin(polar) * std::cos(ph), std::cos(polar),
                                   -std::sin(polar) * std::sin(ph)));
    }
  return c;
}

struct LcpScene {
  geom::TriMesh head;
  hair::Scalp scalp;
  sim::VoxelPlanes body;
  hair::LcpInit init;
};

inline LcpScene lcp_small_scene(const Context& ctx, double spacing = 0.012, double length = 0.12) {
  LcpScene s;
  s.head = lcp_sphere(0.1);
  hair::ScalpParams sp;
  sp.max_length = length;
  sp.root_depth = 0.012;
  s.scalp = hair::Scalp::trim(s.head, lcp_cap_curves(0.1, 1.1), sp);
  sim::VoxelPlanesParams vp;
  vp.voxel_size = 0.01;
  s.body = sim::VoxelPlanes::build({&s.head}, vp, 7);
  hair::LcpInitParams ip;
  ip.spacing = spacing;
  ip.whirl_point = Vec3(0, 0.1, 0.02);
  s.init = hair::initialize_lcp(ctx, s.scalp, ip, &s.body);
  return s;
}

}  // namespace follicle::test
