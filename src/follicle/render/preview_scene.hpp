#pragma once
// The reduced scene an interactive view draws while its camera moves (issue 25): a smaller image
// (upscaled on screen), an even spread of at most `max_strands` strands and `max_particles` hair
// particles (drawn wider, so the hair keeps its coverage), a smaller shadow map and no
// supersampling. The full scene is drawn again as soon as the camera stops. Used by
// follicle-viewer and the `viewer-frame` benchmark workload.
#include <cstddef>
#include <memory>
#include <utility>
#include <vector>

#include "follicle/core/params.hpp"
#include "follicle/render/render_scene.hpp"

namespace follicle::render {

struct PreviewParams {
  double scale = 0.5;          // image size while moving / the view's size
  int max_strands = 12000;     // strands drawn while moving (over all strand items)
  int max_points = 60000;      // strand points drawn while moving (every m-th along a strand)
  int max_particles = 20000;   // hair particles drawn while moving (over all particle items)
  int max_triangles = 20000;   // triangles of a mesh drawn while moving (simplified above)
  int shadow_map_size = 1024;  // [texels] at most, while moving
  template <class V>
  void visit(V&& v) {
    v("scale", scale, ParamInfo{"image size while moving / view size", "", 0.1, 1.0});
    v("max_strands", max_strands, ParamInfo{"strands drawn while moving", "", 1, 1e8});
    v("max_points", max_points, ParamInfo{"strand points drawn while moving", "", 2, 1e9});
    v("max_particles", max_particles, ParamInfo{"hair particles drawn while moving", "", 1, 1e8});
    v("max_triangles", max_triangles, ParamInfo{"mesh triangles drawn while moving", "", 4, 1e9});
    v("shadow_map_size", shadow_map_size, ParamInfo{"shadow map while moving", "", 64, 16384});
  }
  void validate() const { validate_params(*this, "preview"); }
};

/// Reduces scenes for the moving view; keeps the reduced strand and particle sets of the last
/// call, so a camera move over an unchanged scene copies nothing (the sets are shared_ptrs that
/// the scene's session keeps while they do not change).
class PreviewReducer {
 public:
  /// Replaces the strand and particle sets of `rs` by reduced ones and lowers `s` (size by
  /// p.scale, supersample 1, the shadow map to p.shadow_map_size).
  void reduce(RenderScene& rs, RenderSettings& s, const PreviewParams& p);

 private:
  template <class T>
  struct Entry {
    std::weak_ptr<const T> source;
    std::pair<std::size_t, std::size_t> key;  // (every k-th item, every m-th point)
    std::shared_ptr<const T> reduced;
  };
  std::vector<Entry<geom::StrandSet>> m_strands;
  std::vector<Entry<geom::ParticleSet>> m_particles;
  std::vector<Entry<geom::TriMesh>> m_meshes;
  // The simplified faces of the last topologies seen: an animated mesh (a new object every
  // frame, same faces) is simplified once, its new positions and normals taken as they come.
  struct Topology {
    std::size_t vertices = 0, hash = 0, max_triangles = 0;
    std::vector<Vec3i> faces, uv_faces;
  };
  std::vector<Topology> m_topologies;
};

/// A copy of m drawn with at most about max_faces triangles: meshoptimizer's edge-collapse
/// simplification of its faces, with UV seams and open borders kept in place (no cracks, no
/// texture smear), stopping at 1 % of the mesh's size in error. The faces index m's own
/// positions, normals and UVs, which are kept as they are (the normals computed when m has
/// none). m itself when it has no more than max_faces faces.
geom::TriMesh simplified_mesh(const geom::TriMesh& m, std::size_t max_faces);

/// Every k-th strand of s (k >= 1), and of each strand every m-th point from the root and the
/// tip (m >= 1); radii and colours kept.
geom::StrandSet every_kth_strand(const geom::StrandSet& s, std::size_t k, std::size_t m = 1);
/// Every k-th particle of s (k >= 1), radii scaled by sqrt(k).
geom::ParticleSet every_kth_particle(const geom::ParticleSet& s, std::size_t k);

}  // namespace follicle::render
