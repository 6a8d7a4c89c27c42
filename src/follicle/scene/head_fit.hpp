#pragma once
// `follicle fit` (issue 21 item 2): the bundled template head's face setup carried to another
// head. The template (data/meshes/lee_perry_smith, its setup data/muscles/lee_perry_smith.json)
// is registered onto the new head: a similarity found from 24 principal-axis starts (so any
// rigid orientation, mirrored or not, in any unit), the nose tip found on the new head as its
// most frontal point near where the registration puts it, then a smooth non-rigid deformation
// (geom/registration_icp). Muscles, wrinkle curves (as surface wrinkles), the jaw and the head's
// up and front go through that map (skin/setup_transfer). The hair hull and scalp follow from the
// found up and front (the scene's assets.meshes[].up/front); the template has no tissue map, so
// the new head's tissue is the rig's uniform default.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "follicle/core/context.hpp"
#include "follicle/core/units.hpp"
#include "follicle/geom/registration_icp.hpp"
#include "follicle/geom/trimesh.hpp"
#include "follicle/scene/json_params.hpp"
#include "follicle/skin/skin_json.hpp"

namespace follicle::scene {

struct HeadTemplate {
  geom::TriMesh mesh;  // metres, y up, face towards +z, with the UVs its setup's wrinkles use
  skin::FaceSetup setup;
  geom::TriMesh region;            // the registered part: the head above the neck (no shoulders)
  std::vector<int> region_vertex;  // region vertex -> mesh vertex
  struct Mark {
    std::string name;
    int vertex = -1;  // region vertex
  };
  std::vector<Mark> landmarks;  // nose_tip, chin, mouth, eye_L, eye_R
};

/// Loads the template mesh (in `units`) and its setup, crops the registration region and finds
/// the template's landmarks (nose tip: most frontal vertex between mouth and eyes; chin: most
/// frontal vertex on the midline 1.5-7 cm below the mouth; mouth and eyes: the skin under the
/// orbicularis oris and oculi centres).
HeadTemplate load_head_template(const std::filesystem::path& mesh, LengthUnit units,
                                const std::filesystem::path& setup);

struct HeadFitParams {
  geom::RigidRegistrationParams rigid;
  geom::NonrigidRegistrationParams nonrigid;
};

struct HeadFit {
  skin::FaceSetup setup;      // on the new head, metres in its frame; with up and front
  geom::Similarity rigid;     // template -> new head
  double rigid_residual = 0;  // [m]
  double overlap_template = 0, overlap_head = 0;
  bool orientation_given = false;
  double residual_rms = 0, residual_p95 = 0;  // [m] deformed template to the new head
  double matched_fraction = 0;
  struct Landmark {
    std::string name;
    Vec3 position = Vec3::Zero();  // on the new head [m]
    bool detected = false;         // found on the mesh (true) or carried by the registration
  };
  std::vector<Landmark> landmarks;
  std::vector<std::string> dropped_wrinkles;  // template wrinkles mostly off the new head
  std::vector<Vec3> deformed_region;          // the template region on the new head

  /// A whole head (scalp and all) rather than a face mask: the new head covers at least 45 % of
  /// the template's head and neck (measured: whole heads 67-100 %, masks 16-25 %).
  bool whole_head() const { return overlap_template >= 0.45; }
};

/// Fits the template to `head` (metres). `up`/`front` (the head's, in its frame) replace the
/// orientation search when given. Throws follicle::Error when the registration fails.
HeadFit fit_head(const Context& ctx, const HeadTemplate& tpl, const geom::TriMesh& head,
                 const std::optional<Vec3>& up, const std::optional<Vec3>& front,
                 const HeadFitParams& params = {});

/// The scene `follicle fit` writes next to setup.json: the head (`head_path` as written in the
/// scene, relative to its folder, in `units`, with the found up/front), the template's
/// close-up camera and lights carried by the fit, a skin rig with `expression` and its wrinkles
/// and a bob (none on a face mask, which has no scalp). `mapping` is the rig's texture space
/// (fit_mapping).
Json fitted_scene_json(const HeadFit& fit, const std::string& head_path, LengthUnit units,
                       const std::string& mapping, const std::string& expression = "troubled");

/// The rig's texture space for the fitted wrinkles: "uv" when the head's own UVs hold every
/// furrow on one island, "cylindrical" (about the found axes) when its islands cut one, "auto"
/// (the rig's own layout) for a head without UVs.
std::string fit_mapping(const HeadFit& fit, const geom::TriMesh& head);

/// What `follicle fit` writes into `dir` (created when missing): setup.json, scene.json (head
/// path relative to `dir`) and fit.png, a render of the neutral head with the landmarks (green:
/// found on the mesh, yellow: carried), linear muscles (red, origin to insertion), sphincters
/// (orange) and wrinkle furrows (blue). Every file is written atomically. Returns the paths.
struct FitOutputs {
  std::filesystem::path setup, scene, image;
};
FitOutputs write_head_fit(const Context& ctx, const HeadFit& fit,
                          const std::filesystem::path& head_file, LengthUnit units,
                          const std::string& mapping, const std::filesystem::path& dir,
                          int image_size = 800);

}  // namespace follicle::scene
