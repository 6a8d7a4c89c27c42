#pragma once
// The wisp model, Daldegan, Magnenat Thalmann, Kurihara, Thalmann 1993 §3.3: only the typical
// strands (guides) are simulated; every strand of the full hair follows the guide whose root is
// nearest to its own.
//   mode "paper": "we simulate the movement of typical strands and generate other strands by
//     adding random numbers to the origin of the typical strands": a follower is its guide's
//     current shape moved by the follower's own root offset from the guide's root plus a random
//     jitter (both turned with the head), sampled at the follower's arc-length fractions, so it
//     takes the guide's length and shape.
//   mode "offset" (ours, default): every follower point keeps its rest offset from the guide
//     point at the same arc-length fraction, turned by the head rotation:
//       x_j(t) = g(u_j, t) + R (x_j(rest) - g(u_j, rest)),
//     so followers keep their own styled lengths and shapes and reproduce the rest hair exactly
//     when the guides are at rest.
// Guide points are interpolated linearly in the guide's REST arc-length fraction (a material
// parameter; the hinge dynamics keeps segment lengths, so it is also the current fraction).
// Followers may have any number of points.
#include <cstdint>
#include <string>
#include <vector>

#include "follicle/core/context.hpp"
#include "follicle/core/params.hpp"
#include "follicle/core/types.hpp"
#include "follicle/geom/strands.hpp"
#include "follicle/hair/projective_anjyo1992.hpp"  // HeadMotion

namespace follicle::hair {

struct WispParams {
  std::string mode = "offset";  // "offset" | "paper"
  double jitter = 0.002;        // [m] paper mode: radius of the random offset of a follower
  uint64_t seed = 1;            // paper mode: jitter stream (follower s draws from stream s)

  template <class V>
  void visit(V&& v) {
    v("mode", mode,
      {"offset (followers keep their rest offsets from the guide) | paper (followers copy the "
       "guide's shape at their own root plus a random jitter)"});
    v("jitter", jitter, {"paper mode: radius of the random offset of a follower", "m", 0.0, 0.1});
    v("seed", seed, {"paper mode: random seed of the jitter"});
  }
  void validate() const;
};

/// What apply_wisps needs, precomputed from the rest strands.
struct WispBinding {
  bool paper = false;
  std::vector<uint32_t> guide;             // [followers] index of the guide
  std::vector<uint32_t> offsets{0};        // followers' layout (copy of the full hair's offsets)
  std::vector<Vec3f> rest;                 // [follower points] rest positions ("offset" mode)
  std::vector<float> u;                    // [follower points] rest arc-length fraction
  std::vector<Vec3f> shift;                // [followers] root offset + jitter ("paper" mode)
  std::vector<uint32_t> guide_offsets{0};  // guides' layout (checked in apply_wisps)
  std::vector<float> guide_u;              // [guide points] rest arc-length fraction

  std::size_t num_followers() const { return guide.size(); }
  std::size_t num_guides() const { return guide_offsets.size() - 1; }
};

/// Binds every strand of `full_rest` to the guide with the nearest root (ties: lowest index) by
/// a uniform grid over the guide roots searched in growing rings. Both sets in the same frame.
/// Throws follicle::Error for bad parameters, no guides, empty strands.
WispBinding bind_wisps(const geom::StrandSet& guides_rest, const geom::StrandSet& full_rest,
                       const WispParams& params);
/// Same, the follower loop parallel (identical result).
WispBinding bind_wisps(const Context& ctx, const geom::StrandSet& guides_rest,
                       const geom::StrandSet& full_rest, const WispParams& params);

/// The full hair following the guides. `guides_rest`: the guides bound (same frame as the full
/// rest hair); `guides_now`: their current positions (any frame, e.g. world); `head_rotation`:
/// the rotation from the rest frame to the frame of guides_now. Writes full_out's offsets and
/// points (radius / colour kept when their sizes match, else cleared). Throws follicle::Error
/// when the guide layouts do not match the binding.
void apply_wisps(const WispBinding& binding, const geom::StrandSet& guides_rest,
                 const geom::StrandSet& guides_now, const Quat& head_rotation,
                 geom::StrandSet& full_out);
/// Same with the rotation of a HeadMotion.
void apply_wisps(const WispBinding& binding, const geom::StrandSet& guides_rest,
                 const geom::StrandSet& guides_now, const HeadMotion& head,
                 geom::StrandSet& full_out);
/// Parallel over followers (identical result).
void apply_wisps(const Context& ctx, const WispBinding& binding, const geom::StrandSet& guides_rest,
                 const geom::StrandSet& guides_now, const Quat& head_rotation,
                 geom::StrandSet& full_out);

}  // namespace follicle::hair
