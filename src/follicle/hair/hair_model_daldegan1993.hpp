#pragma once
// Daldegan, Magnenat Thalmann, Kurihara, Thalmann 1993 §3 as a HairSimulation (ADR 0010): the
// animation production process of §3.4 on any groom —
//   1. the groom's strands are translated into polar angles (the initial angles of (3)); the
//      number of strands is reduced: `guides` typical strands, resampled to `guide_segments`
//      segments (the paper: 40), are simulated;
//   2. cylindrical radius tables of the body are made from the head mesh (§3.2);
//   3. the hinge dynamics (1)-(3) with the reaction constraint (4)-(6) advance the typical strands;
//   4. the full hair is generated from them by the wisp model (§3.3).
#include <memory>

#include "follicle/core/params.hpp"
#include "follicle/hair/hair_model.hpp"
#include "follicle/hair/hinge_daldegan1993.hpp"
#include "follicle/hair/wisp_daldegan1993.hpp"
#include "follicle/sim/cylinder_table_daldegan1993.hpp"

namespace follicle::hair {

struct DaldeganParams {
  HingeParams hinge;
  sim::CylinderBodyParams body;
  WispParams wisps;
  int guides = 1000;        // typical strands simulated; 0 = every strand (no wisps)
  int guide_segments = 40;  // segments per typical strand (§3.4)
  bool collision = true;    // cylindrical body tables from the head mesh (§3.2)
  // Ours: before t = 0 the typical strands fall from the styled shape under gravity alone (no
  // head motion, no wind) for settle_time, so a style drapes over the head; the settled pose is
  // the rest pose of every frame (and of a still scene). The springs keep their styled angles.
  double settle_time = 0.0;              // [s]
  Vec3 settle_gravity{0.0, -9.81, 0.0};  // [m/s²] head frame

  template <class V>
  void visit(V&& v) {
    v("hinge", hinge, ParamInfo{"hinge dynamics of the typical strands (§3.1, eqs. 1-3)"});
    v("body", body, ParamInfo{"cylindrical radius tables of the body (§3.2)"});
    v("wisps", wisps, ParamInfo{"how the full hair follows the typical strands (§3.3)"});
    v("guides", guides,
      ParamInfo{"typical strands simulated (§3.3); 0 = simulate every strand", "", 0, 10000000});
    v("guide_segments", guide_segments,
      ParamInfo{"segments of every typical strand (§3.4: 40)", "", 1, 1000});
    v("collision", collision, ParamInfo{"collide with the body's cylinder tables (§3.2)"});
    v("settle_time", settle_time,
      ParamInfo{"let the styled hair fall under gravity for this long before frame 0 (0: start "
                "from the styled shape)",
                "s", 0.0, 60.0});
    v("settle_gravity", settle_gravity,
      ParamInfo{"gravity while settling, head frame (y up)", "m/s^2", -100.0, 100.0});
  }
  void validate() const;
};

/// Indices of `count` typical strands among `n` (spread evenly through the groom's order, which
/// is spatial for generated grooms); every strand when count is 0 or >= n.
std::vector<uint32_t> select_guides(std::size_t n, std::size_t count);

std::unique_ptr<HairSimulation> make_daldegan1993(const Context& ctx, const DaldeganParams& params,
                                                  const HairModelSetup& setup);

}  // namespace follicle::hair
