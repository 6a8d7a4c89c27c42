#pragma once
// Session: a loaded, validated scene plus everything derived from it (loaded meshes and
// textures, later simulation state). It turns the scene into a render::RenderScene per frame; the
// renderer never sees the scene file or a solver.
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "follicle/core/context.hpp"
#include "follicle/geom/strands.hpp"
#include "follicle/geom/trimesh.hpp"
#include "follicle/image/image.hpp"
#include "follicle/render/render_scene.hpp"
#include "follicle/scene/scene.hpp"
#include "follicle/skin/face_rig.hpp"
#include "follicle/skin/hand_rig.hpp"

namespace follicle::scene {

class HairRuntime;  // session_hair.cpp
class HandRuntime;  // session_hand.cpp
class LcpRuntime;   // session_lcp.cpp
class SkinRuntime;  // session_skin.cpp

/// Counters of the hair pipeline (tests check that cached frames are not re-simulated).
struct HairStats {
  std::size_t builds = 0;       // hair groups styled
  std::size_t steps = 0;        // dynamics steps taken
  std::size_t cache_reads = 0;  // frames read from the strand cache
  std::size_t cache_writes = 0;
};

class Session {
 public:
  /// Parses and validates `scene_file` (strict: unknown keys, wrong types, out-of-range values
  /// and missing asset files are errors naming the file and JSON path). Meshes load lazily.
  /// `ctx` must outlive the Session.
  static Session load(const std::filesystem::path& scene_file, const Context& ctx);
  /// From parsed JSON; relative asset paths resolve against `base_dir`.
  static Session from_json(const Json& j, const std::filesystem::path& base_dir,
                           const std::string& name_for_errors, const Context& ctx);
  /// From an already built Scene (validated here).
  Session(Scene scene, std::filesystem::path base_dir, std::string source_name, const Context& ctx);
  ~Session();
  Session(Session&&) noexcept;
  Session& operator=(Session&&) noexcept;

  const Scene& scene() const { return m_scene; }
  /// For command-line overrides (e.g. --width); call validate() after editing.
  Scene& scene() { return m_scene; }
  void validate() const;
  const std::filesystem::path& base_dir() const { return m_base_dir; }
  /// The file the scene came from (for messages).
  const std::string& source_name() const { return m_source; }
  const Context& context() const { return *m_ctx; }

  /// A path from the scene file resolved against the scene's folder.
  std::filesystem::path resolve(const std::string& relative) const;

  /// The mesh of assets.meshes[index] in metres (file units converted; the asset transform is
  /// NOT applied, it goes into MeshItem::transform), with vertex normals. Cached.
  std::shared_ptr<const geom::TriMesh> mesh(std::size_t index);
  /// Index of the mesh asset called `name`; throws when there is none.
  std::size_t mesh_index(const std::string& name) const;
  /// A texture (PNG/JPEG) by scene-relative path. Cached.
  std::shared_ptr<const image::ImageRGBA8> texture(const std::string& relative);
  /// Loads every asset now (for `follicle validate`): malformed files fail here.
  void load_all_assets();

  /// What to draw at `frame` (frame >= 0; static scenes look the same at every frame).
  render::RenderScene render_scene(int frame = 0);
  render::RenderSettings render_settings() const;

  /// Number of frames of the scene's animation (1 for a still scene) and the time of a frame.
  int frame_count() const;
  double frame_time(int frame) const;
  /// Per-frame strand cache folder ("" = none): frames found there are read instead of simulated,
  /// simulated frames are written there. A cache made for different hair/animation settings is
  /// discarded (its key file differs).
  void set_strand_cache(const std::filesystem::path& dir);
  /// World-space strands of hair group `group` at `frame` (uncoloured): the styled hair for a
  /// still scene, else the dynamics stepped deterministically from frame 0 (consecutive frames
  /// continue from the kept state). Throws when the dynamics blow up.
  std::shared_ptr<const geom::StrandSet> hair_strands(std::size_t group, int frame);
  /// Every hair group at `frame`, concatenated (for export).
  geom::StrandSet all_hair(int frame);
  const HairStats& hair_stats() const;
  /// The rigid head-motion transform at `frame` (rest -> current), none for a still head.
  std::optional<Affine3> head_motion_transform(int frame);

  /// The hand ("hand" section) at `frame`: skinned mesh with joint wrinkles and the modulated
  /// fine relief [m] (no relief when hand.wrinkles is false). Throws when there is no hand.
  skin::HandFrame hand_frame(int frame);
  /// Finger flexion in [0, 1] of the hand at `frame`.
  double hand_flexion(int frame) const;
  /// Writes the fine-wrinkle relief of every fine-wrinkle source as height, normal and
  /// displacement maps (float EXR + 8-bit PNG, skin::export_wrinkle_maps) into `dir`: the hand
  /// (stem "hand_...") and each skin rig with "fine" (stem "skinR_..." for skin[R]); the rest
  /// state when frame < 0 ("..._rest"), else the modulated relief at that frame
  /// ("..._frame_NNNN"). Returns the stems written. Throws when the scene has no fine-wrinkle
  /// source (see has_wrinkle_maps).
  std::vector<std::string> export_wrinkle_maps(const std::filesystem::path& dir, int frame);
  /// True when the scene has a fine-wrinkle source for export_wrinkle_maps.
  bool has_wrinkle_maps() const;
  /// LCP hair particles ("lcp" section) in the world frame with directions t_i at `frame`,
  /// simulated deterministically from frame 0 (consecutive frames continue from the kept state).
  /// Throws when there is no lcp section or the simulation blows up.
  std::shared_ptr<const geom::ParticleSet> lcp_particles(int frame);
  /// Simulation steps taken by the LCP hair so far (tests check consecutive frames continue).
  std::size_t lcp_steps() const;

  /// Face rigs ("skin" section, session_skin.cpp). The rig of skin[rig] (built on first use).
  const skin::FaceRig& face_rig(std::size_t rig);
  /// The muscle pose of skin[rig] at `frame`: its expression, or its contraction track sampled.
  skin::MusclePose skin_pose(std::size_t rig, int frame);
  /// The deformed, wrinkled mesh of skin[rig] at `frame` (mesh-file coordinates in metres, the
  /// asset transform NOT applied; normals of the deformed surface). Cached per frame.
  std::shared_ptr<const geom::TriMesh> skin_mesh(std::size_t rig, int frame);
  /// The fine-wrinkle relief of skin[rig] at `frame` over the mesh UVs [m] (the bump map of its
  /// material; Bando 2002 §2.6), or null without "fine". Fields built on first use; cached.
  std::shared_ptr<const image::ImageF> skin_fine_relief(std::size_t rig, int frame);
  /// Index into scene().skin of the rig on mesh asset `asset`, if any.
  std::optional<std::size_t> skin_rig_of_mesh(std::size_t asset) const;
  /// Loads every face-setup file and checks the skin section against it (for validate).
  void load_skin_setups();

  /// A few lines describing the scene (for `follicle info`).
  std::string summary() const;

 private:
  Scene m_scene;
  std::filesystem::path m_base_dir;
  std::string m_source;
  const Context* m_ctx;
  std::map<std::string, std::shared_ptr<const geom::TriMesh>> m_meshes;
  std::map<std::string, std::shared_ptr<const image::ImageRGBA8>> m_textures;
  std::unique_ptr<HairRuntime> m_hair;
  HairRuntime& hair_runtime();
  std::shared_ptr<HandRuntime> m_hand;  // shared_ptr: incomplete type here
  std::shared_ptr<LcpRuntime> m_lcp;
  void add_hand_items(render::RenderScene& rs, int frame);
  void add_lcp_items(render::RenderScene& rs, int frame);
  std::shared_ptr<SkinRuntime> m_skin;  // session_skin.cpp
  SkinRuntime& skin_runtime();
  void resolve_skin(std::size_t rig);
  void validate_skin_files() const;
  void apply_skin(std::size_t asset, render::MeshItem& item, int frame);
};

}  // namespace follicle::scene
