#include "follicle/skin/setup_fit.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "follicle/core/error.hpp"
#include "follicle/geom/curves.hpp"
#include "follicle/geom/spatial_embree.hpp"
#include "follicle/geom/uv_locator.hpp"

namespace follicle::skin {

std::vector<SetupFitReport::Muscle> SetupFitReport::off_surface(double tolerance) const {
  std::vector<Muscle> out;
  for (const auto& m : muscles)
    if (!(m.distance <= tolerance)) out.push_back(m);
  return out;
}

std::vector<SetupFitReport::Wrinkle> SetupFitReport::outside_uvs(double fraction) const {
  std::vector<Wrinkle> out;
  for (const auto& w : wrinkles)
    if (w.outside > fraction) out.push_back(w);
  return out;
}

SetupFitReport measure_setup_fit(const geom::TriMesh& mesh, const MuscleSet& muscles,
                                 const std::vector<LargeWrinkle>& wrinkles) {
  SetupFitReport r;
  const auto box = mesh.bounds();
  r.head_size = (box.max() - box.min()).norm();
  const geom::MeshQuery query(mesh);
  for (const auto& m : muscles.linear)
    r.muscles.push_back({m.name, query.closest_point(m.insertion).distance});
  for (const auto& m : muscles.sphincter)
    r.muscles.push_back({m.name, query.closest_point(m.center).distance});
  std::unique_ptr<geom::UvLocator> locator;
  if (mesh.has_uvs()) locator = std::make_unique<geom::UvLocator>(mesh);
  constexpr int kSamples = 33;
  for (const auto& w : wrinkles) {
    geom::Bezier2 curve;
    for (int k = 0; k < 4; ++k) curve.p[std::size_t(k)] = w.control[std::size_t(k)];
    int outside = 0;
    for (const Vec2& q : curve.sample(kSamples))
      outside += !(locator && locator->locate(q, 1e-9).face >= 0);
    r.wrinkles.push_back({w.name, double(outside) / kSamples});
  }
  return r;
}

std::vector<std::string> judge_setup_fit(const SetupFitReport& report, const std::string& where) {
  std::vector<std::string> warnings;
  const auto off = report.off_surface(kMuscleTolerance);
  auto list = [](const auto& items, auto&& describe) {
    std::string s;
    const std::size_t shown = std::min<std::size_t>(items.size(), 4);
    for (std::size_t i = 0; i < shown; ++i) s += (i ? ", " : "") + describe(items[i]);
    if (items.size() > shown) s += fmt::format(", and {} more", items.size() - shown);
    return s;
  };
  const auto muscle_text = [](const SetupFitReport::Muscle& m) {
    return fmt::format("{} {:.1f} cm", m.name, 100 * m.distance);
  };
  const std::string fix = fmt::format(
      "muscle positions are metres in the mesh's frame (this mesh is {:.2f} m across): check the "
      "mesh's units and that the setup was made for this head, in this position and orientation",
      report.head_size);
  if (!report.muscles.empty() && 2 * off.size() > report.muscles.size())
    fail(
        "{}: the face setup does not fit this mesh: {} of {} muscles lie more than {:.0f} cm "
        "from its surface ({}); {}",
        where, off.size(), report.muscles.size(), 100 * kMuscleTolerance, list(off, muscle_text),
        fix);
  if (!off.empty())
    warnings.push_back(fmt::format(
        "{} of {} muscles lie more than {:.0f} cm from the surface ({}); "
        "they move no skin where they should",
        off.size(), report.muscles.size(), 100 * kMuscleTolerance, list(off, muscle_text)));
  const auto wholly = report.outside_uvs(0.999);
  const auto partly = report.outside_uvs(0.25);
  const auto wrinkle_text = [](const SetupFitReport::Wrinkle& w) {
    return fmt::format("{} {:.0f}%", w.name.empty() ? std::string("(unnamed)") : w.name,
                       100 * w.outside);
  };
  if (!report.wrinkles.empty() && wholly.size() == report.wrinkles.size())
    fail(
        "{}: none of the face setup's {} wrinkle curves lies on this mesh's texture layout "
        "(wrinkle curves are in the mesh's own UV space; the setup was made for another UV "
        "layout)",
        where, report.wrinkles.size());
  if (!partly.empty())
    warnings.push_back(fmt::format(
        "{} of {} wrinkle curves lie partly outside the mesh's texture layout, where they cannot "
        "show (share of each curve outside: {})",
        partly.size(), report.wrinkles.size(), list(partly, wrinkle_text)));
  return warnings;
}

}  // namespace follicle::skin
