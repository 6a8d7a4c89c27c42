#pragma once
// The hair-model harness (issue 20): every hair model on the same groom under the same motion,
// measured the same way from the strands they output (no model hooks; docs/adr/0010):
//
//  - stretch [%]: max over segments of |l / l_rest - 1| * 100, l_rest from the groom's rest
//    strands when the model outputs the groom's points, else from the model's own frame 0; a
//    length change within the float32 rounding of the segment's end points (4 eps_float times
//    the sum of their largest coordinates, ~0.1 um for a head at the origin) counts as none, or
//    the cut tips' micrometre segments would show ~0.02 % of pure rounding;
//  - penetration [mm]: the deepest strand point inside the growth mesh; points are carried back
//    into the mesh's rest pose with the inverse head motion and tested against its signed
//    distance (closed meshes: inside by ray-crossing parity);
//  - root drift [mm]: the largest distance from a strand's point 0 to the point its root is bound
//    to on the moved mesh (the roots ride the head rigidly, so this should be ~0);
//  - energy [J]: point masses m_i = lambda * (half the rest lengths of the segments next to i),
//    lambda = rho pi r^2 the linear density of one hair; kinetic sum(m |v|^2 / 2) with v from
//    finite differences of consecutive frames (central inside the range, one-sided at its ends),
//    potential -sum(m g . x) with the scene's gravity, both in the world frame;
//  - ms per simulated second: wall-clock time of the frame steps (steady clock; the groom build,
//    the model's set-up, the first frame, the metrics and the pictures are not timed).
//
// Each model runs in its own Session on a copy of the scene where only hair[group] is kept (its
// `model` switched; the groom depends on `groom`/`style` only, so it is the same for all models)
// and the `lcp` and `hand` sections are dropped. The head-motion pivot stays the original one.
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "follicle/core/context.hpp"
#include "follicle/core/params.hpp"
#include "follicle/core/progress.hpp"
#include "follicle/image/image.hpp"
#include "follicle/scene/json_params.hpp"
#include "follicle/scene/scene.hpp"

namespace follicle::render {
class Renderer;
}

namespace follicle::scene {

/// Names of every hair model, in the order of follicle_enum_names(HairModel).
std::vector<std::string> hair_model_names();

struct HarnessOptions {
  int first_frame = 0;
  int last_frame = -1;              // -1: the scene's last frame
  std::vector<std::string> models;  // empty: every model
  std::size_t group = 0;            // hair group whose groom the models run
  std::vector<int> sheet_frames;    // frames pictured; empty: first, middle and last
  int thumb_size = 320;             // [px] width of each picture (0: no pictures)
  double hair_density = 1300.0;     // [kg/m^3] of keratin
  double hair_radius = 40e-6;       // [m] of one hair

  template <class V>
  void visit(V&& v) {
    v("first_frame", first_frame, ParamInfo{"first frame measured", "", 0, 1e9});
    v("last_frame", last_frame,
      ParamInfo{"last frame measured (-1: the scene's last)", "", -1, 1e9});
    v("models", models, ParamInfo{"hair models to run (empty: all)"});
    v("group", group, ParamInfo{"hair group (index into hair[])", "", 0, 1e6});
    v("sheet_frames", sheet_frames, ParamInfo{"frames pictured on the sheet"});
    v("thumb_size", thumb_size, ParamInfo{"width of each picture (0: none)", "px", 0, 4096});
    v("hair_density", hair_density, ParamInfo{"mass density of hair", "kg/m^3", 1.0, 1e5});
    v("hair_radius", hair_radius, ParamInfo{"radius of one hair", "m", 1e-7, 1e-2});
  }
  void validate() const { validate_params(*this, "harness"); }
};

/// What one model did. Arrays have one entry per frame measured (`frames` of them).
struct HarnessModelResult {
  std::string model;
  std::string error;  // "" when every frame ran; else why the model stopped (arrays are partial)
  std::size_t strands = 0, points = 0;  // of the model's output
  int frames = 0;                       // frames measured
  bool rest_from_groom = true;          // stretch rest lengths: groom (true) or model frame 0
  double max_stretch_percent = 0.0;
  double max_penetration_mm = 0.0;
  double root_drift_mm = 0.0;
  double ms_per_simulated_second = 0.0;
  double wall_seconds = 0.0;  // timed part
  std::vector<double> time_s, kinetic_j, potential_j, total_j, stretch_percent, penetration_mm,
      drift_mm;
  std::vector<image::ImageRGB8> pictures;  // one per sheet frame reached (empty without)
};

struct HarnessReport {
  std::string scene;  // source name
  std::size_t group = 0;
  std::string group_name;
  int first_frame = 0, last_frame = 0;
  double fps = 24.0;
  Vec3 gravity = Vec3::Zero();
  double hair_density = 0.0, hair_radius = 0.0, linear_density = 0.0;  // [kg/m^3], [m], [kg/m]
  std::size_t groom_strands = 0, groom_points = 0;
  std::vector<int> sheet_frames;
  std::vector<HarnessModelResult> models;
};

/// Runs the models of `options` on hair[group] of `scene` (relative paths against `base_dir`,
/// `source` in messages) over frames [first_frame, last_frame]. `progress` (may be null) gets
/// one tick per model per frame. Pictures (thumb_size > 0) are rendered with `renderer`, or a
/// headless one made here when it is null. Throws follicle::Error for a still scene (no
/// "animation"), a group or frame range out of range, fewer than two frames, an unknown model
/// name (listing the known ones), or a sheet frame outside the range. A model whose dynamics
/// fail is reported in its result (`error`), not thrown.
HarnessReport run_harness(const Scene& scene, const std::filesystem::path& base_dir,
                          const std::string& source, const Context& ctx,
                          const HarnessOptions& options, Progress* progress = nullptr,
                          render::Renderer* renderer = nullptr);

/// The report as JSON: the run's settings and a "models" list with every field of
/// HarnessModelResult except the pictures (non-finite numbers become null).
Json harness_json(const HarnessReport& report);

/// The comparison sheet: the models side by side at the sheet frames (one labelled picture per
/// model and frame; rows = models), plots of stretch, kinetic energy and total-energy change over
/// time (one line per model) and one line of numbers per model.
image::ImageRGB8 harness_sheet(const HarnessReport& report);

}  // namespace follicle::scene
