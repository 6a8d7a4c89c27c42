#pragma once
// Internal to the scene module: the hand rig and LCP hair state a Session keeps. Included by
// session_hand.cpp and session_lcp.cpp only.
#include <memory>
#include <optional>
#include <vector>

#include "follicle/geom/strands.hpp"
#include "follicle/hair/lcp_scenario_bando2003.hpp"
#include "follicle/scene/session.hpp"
#include "follicle/sim/voxel_planes.hpp"
#include "follicle/skin/hand_rig.hpp"

namespace follicle::scene {

class HandRuntime {
 public:
  std::unique_ptr<skin::HandRig> rig;
  int last_frame = -1;  // frame of `last`
  std::optional<skin::HandFrame> last;
};

class LcpRuntime {
 public:
  std::unique_ptr<Context> ctx;  // the session's threads and log, the section's seed
  std::unique_ptr<hair::LcpScenario> sim;
  std::shared_ptr<const geom::TriMesh> head;  // head frame
  int state_frame = -1;                       // frame the scenario state belongs to
  int last_frame = -1;
  std::shared_ptr<const geom::ParticleSet> last;
  Affine3 last_head = Affine3::Identity();  // head pose at last_frame
  std::shared_ptr<const geom::ParticleSet> last_air;
  std::size_t steps = 0;
  std::vector<Vec3> force;  // with lcp.part: the parting force of the step [N, world]
};

}  // namespace follicle::scene
