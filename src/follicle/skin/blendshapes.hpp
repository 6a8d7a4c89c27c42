#pragma once
// Blendshape targets of a face rig: same-topology copies of the neutral mesh (e.g. the ICT
// FaceKit expressions), applied as p = p_neutral + sum_i w_i (p_i - p_neutral) before the
// subcutaneous tissue and the large-scale wrinkles. The wrinkles then follow the shrinkage of
// that deformation (Bando 2002 (2.3)) exactly as they follow the muscles', so a face animated by
// sculpted targets wrinkles too. Not in the paper (its faces are muscle-driven); the blend is the
// standard delta blendshape model.
// Offsets are stored sparse (only the vertices a target moves), structure of arrays.
#include <string>
#include <vector>

#include "follicle/core/context.hpp"
#include "follicle/core/types.hpp"
#include "follicle/geom/trimesh.hpp"

namespace follicle::skin {

struct RefinedMesh;

class Blendshapes {
 public:
  Blendshapes() = default;
  /// Offsets of `targets` from `neutral` (metres, the neutral's frame). Every target must have
  /// the neutral's vertex count and faces; `names` are unique and non-empty. Errors name the
  /// target and `where`, with what differs (vertex count, the first differing face).
  static Blendshapes from_meshes(const geom::TriMesh& neutral, std::vector<std::string> names,
                                 const std::vector<geom::TriMesh>& targets,
                                 const std::string& where);

  std::size_t size() const { return m_names.size(); }
  bool empty() const { return m_names.empty(); }
  const std::vector<std::string>& names() const { return m_names; }
  /// Index of a target by name; -1 when there is none.
  int index(const std::string& name) const;
  /// Vertices the neutral has (the size `accumulate` expects).
  std::size_t num_vertices() const { return m_num_vertices; }
  /// Vertices target i moves (by more than 1e-9 m).
  std::size_t moved(std::size_t i) const { return m_index[i].size(); }
  /// Largest offset of target i [m].
  double max_offset(std::size_t i) const;

  /// positions += sum_i weights[i] * offset_i. `weights` has size() entries or none (no-op);
  /// targets are added in order, so the result is the same for any thread count.
  void accumulate(const Context& ctx, const std::vector<double>& weights,
                  std::vector<Vec3>& positions) const;

  /// The same targets on a refined mesh: offsets of inserted vertices are their parents' mean
  /// (the refinement's midpoint rule, RefinedMesh::propagate).
  Blendshapes refined(const RefinedMesh& refined) const;

 private:
  std::vector<std::string> m_names;
  std::size_t m_num_vertices = 0;
  std::vector<std::vector<std::uint32_t>> m_index;  // per target: moved vertices, ascending
  std::vector<std::vector<Vec3>> m_offset;          // per target: their offsets
};

}  // namespace follicle::skin
