#include "follicle/scene/hand_section.hpp"

#include <fmt/format.h>

#include <cmath>

#include "follicle/core/error.hpp"

namespace follicle::scene {

double LcpPartSpec::at(double t) const {
  if (!(t > t0 && t < t1)) return 0.0;
  const double s = std::sin(kPi * (t - t0) / (t1 - t0));
  return accel * s * s;
}

void LcpSpec::validate() const {
  scenario.validate();
  dynamics.validate();
  render.splat.validate();
  if (part) {
    if (!(part->t1 > part->t0))
      fail("part.t1 ({}) must be greater than part.t0 ({})", part->t1, part->t0);
    if (scenario.shake || scenario.wind)
      fail(
          "part: the parting force is for the back hair under gravity only; turn off "
          "scenario.shake and scenario.wind");
  }
}

}  // namespace follicle::scene
