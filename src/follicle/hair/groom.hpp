#pragma once
// Groom: the one hair description every hair model starts from (docs/adr/0010-one-hair-system.md).
// A groom is the rest shape of a set of strands in scene coordinates plus, per strand, where its
// root sits on the growth mesh (triangle + barycentric weights) and which material it uses. It
// comes from a file (assets.grooms[]: .hair, .tfx, .usda, OBJ polylines) or from a generator
// (Anjyo 1992 cantilever styling, Daldegan 1993 HairStyler); every model (hair_model.hpp) is
// built from one. Binding the roots to a mesh lets them ride that mesh when it deforms.
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "follicle/core/context.hpp"
#include "follicle/core/types.hpp"
#include "follicle/geom/spatial_embree.hpp"
#include "follicle/geom/strands.hpp"
#include "follicle/geom/trimesh.hpp"

namespace follicle::hair {

/// Where a strand's root sits on a triangle mesh: point = Σ bary[k] * positions[face[k]].
struct RootBinding {
  int32_t face = -1;  // -1: not bound
  Vec3f bary{1.0f, 0.0f, 0.0f};
};

struct Groom {
  geom::StrandSet strands;         // rest shape [m], scene coordinates, point 0 of a strand = root
  std::vector<RootBinding> roots;  // empty, or one per strand
  std::vector<uint16_t> material;  // empty, or one per strand (index into the model's materials)

  std::size_t num_strands() const { return strands.num_strands(); }
  bool bound() const { return !roots.empty(); }
  /// Throws follicle::Error naming `where` on inconsistent arrays, non-finite points, strands
  /// with fewer than 2 points or zero length.
  void check(const std::string& where) const;
};

/// Binds every strand's root to the nearest point of the mesh behind `query` (scene coordinates,
/// the same as the groom's). Returns the largest root-to-surface distance [m] (how far the file's
/// roots were from the mesh); parallel, deterministic.
double bind_roots(const Context& ctx, const geom::MeshQuery& query, Groom& groom);

/// The points the roots are bound to on `mesh` (which must have the binding mesh's topology; its
/// positions may be deformed). Throws when the groom is unbound or a face index is out of range.
std::vector<Vec3> bound_root_positions(const Groom& groom, const geom::TriMesh& mesh);
/// Unit normals of `mesh` at the bound points (the face normal, or the interpolated vertex normal
/// when the mesh has vertex normals).
std::vector<Vec3> bound_root_normals(const Groom& groom, const geom::TriMesh& mesh);

/// Arc length of strand s.
double strand_length(const geom::StrandSet& strands, std::size_t s);

/// Resamples every strand by arc length to points spaced `segment_length` apart (at least
/// `min_points`, at most `max_points` points; the last point is the original tip, so the length
/// is kept up to the chord error of the original polyline). Radius and colour are interpolated.
/// Roots and materials are kept.
Groom resample_groom(const Groom& groom, double segment_length, std::size_t min_points = 2,
                     std::size_t max_points = 1024);
/// Resamples every strand to exactly `points_per_strand` points (>= 2), same rules.
Groom resample_groom_fixed(const Groom& groom, std::size_t points_per_strand);

}  // namespace follicle::hair
