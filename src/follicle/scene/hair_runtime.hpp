#pragma once
// Internal to the scene module: the hair state a Session keeps (styled strands, solver state,
// strand cache, head-motion track). Included by session.cpp and session_hair.cpp only.
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "follicle/anim/rigid_motion.hpp"
#include "follicle/geom/strands.hpp"
#include "follicle/hair/groom.hpp"
#include "follicle/hair/hair_model.hpp"
#include "follicle/hair/hairstyler_daldegan1993.hpp"
#include "follicle/scene/session.hpp"
#include "follicle/sim/ellipsoid.hpp"

namespace follicle::scene {

class HairRuntime {
 public:
  struct Group {
    bool built = false;
    sim::Ellipsoid hull;                            // scene coordinates, at rest
    std::shared_ptr<const hair::Groom> groom;       // scene coordinates, at rest, roots bound
    std::shared_ptr<const geom::StrandSet> styled;  // groom->strands
    std::vector<hair::HairMaterial> materials;      // of a HairStyler groom (else empty)
    // Roots riding a skin rig's deforming surface (the hair's mesh has a skin[] rig): the roots
    // bound to the rig's refined rest mesh, and the groom's roots at rest (scene coordinates).
    std::optional<std::size_t> skin_rig;
    hair::Groom skin_binding;
    std::vector<Vec3> skin_rest_roots;
    std::unique_ptr<hair::HairSimulation> sim;
    int state_frame = -1;  // frame the simulation state belongs to (-1: none yet)
    int last_frame = -1;   // frame of `last`
    std::shared_ptr<const geom::StrandSet> last;
  };
  std::vector<Group> groups;
  HairStats stats;
  std::map<std::string, std::shared_ptr<const geom::StrandSet>> groom_files;  // by file|units
  std::filesystem::path cache_dir;
  bool cache_ready = false;
  bool track_built = false;
  std::optional<anim::RigidMotionTrack> track;
};

}  // namespace follicle::scene
