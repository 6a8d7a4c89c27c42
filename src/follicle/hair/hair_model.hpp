#pragma once
// The one simulation-model interface of the hair module (docs/adr/0010-one-hair-system.md).
// Every hair model — Anjyo 1992 projective dynamics, Daldegan 1993 hinge dynamics, Bando 2003
// loosely connected particles — is built from a Groom (groom.hpp) in the head frame and advanced
// by time under the same environment: gravity, a wind field and the rigid head motion. The scene
// layer keeps one hair path for all of them; adding a model means its folder of solver files, a
// factory returning a HairSimulation, and one line in the scene's model table.
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "follicle/core/context.hpp"
#include "follicle/core/types.hpp"
#include "follicle/geom/strands.hpp"
#include "follicle/hair/groom.hpp"
#include "follicle/hair/projective_anjyo1992.hpp"
#include "follicle/sim/ellipsoid.hpp"
#include "follicle/sim/step_report.hpp"

namespace follicle::hair {

/// What acts on the hair at time t, in world coordinates.
struct HairEnvironment {
  Vec3 gravity{0.0, -9.81, 0.0};     // [m/s²]
  Vec3 wind = Vec3::Zero();          // [m/s²] uniform wind: force per unit mass of hair
  Vec3 air_velocity = Vec3::Zero();  // [m/s] uniform air velocity (models with drag)
  HeadMotion head;                   // the head frame (origin, orientation) and its derivatives
};
using EnvironmentFn = std::function<HairEnvironment(double t)>;

/// One model running on one groom. Not thread-safe; steps are parallel inside and deterministic.
class HairSimulation {
 public:
  virtual ~HairSimulation() = default;
  /// The model's name as the scene spells it ("anjyo1992", "daldegan1993", "bando2003").
  virtual const char* model() const = 0;
  /// Back to the rest state at t = 0 (the groom's shape, no motion).
  virtual void reset() = 0;
  /// Advances from time() to t_end with the model's own step (it may stop short of t_end by less
  /// than one step; the next call continues). A failed report leaves the state unusable until
  /// reset().
  virtual sim::StepReport advance(const Context& ctx, double t_end, const EnvironmentFn& env) = 0;
  /// Simulated time [s] and steps taken since reset().
  virtual double time() const = 0;
  virtual uint64_t steps() const = 0;
  /// The strands now in world coordinates, placed by the head pose `head` (the environment's at
  /// time()), one polyline per groom strand with the model's own points.
  virtual void strands(const HeadMotion& head, geom::StrandSet& out) const = 0;
};

/// What every model gets besides its own parameters: the groom in the head frame (origin at the
/// head's centre, y up, z towards the face), the head's hull in that frame, the head surface in
/// that frame (for models that collide with it; may be null) and the seed.
struct HairModelSetup {
  Groom rest;
  sim::Ellipsoid hull;
  std::shared_ptr<const geom::TriMesh> head_mesh;
  uint64_t seed = 1;
};

/// Anjyo, Usami, Kurihara 1992 §3 on any groom (hair_model_anjyo1992.cpp).
std::unique_ptr<HairSimulation> make_anjyo1992(const Context& ctx, const ProjectiveParams& params,
                                               const HairModelSetup& setup);

}  // namespace follicle::hair
