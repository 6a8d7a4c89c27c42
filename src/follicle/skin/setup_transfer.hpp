#pragma once
// Carrying a face setup from the head it was made for (the template) to another head (issue 21
// item 2, `follicle fit`). The template's vertices have been registered onto the new head
// (geom/registration_icp: a similarity, then a smooth deformation); that registration is a map
// from the template's space to the new head's, and everything in the setup goes through it:
// - points on the skin (linear insertions, sphincter centres, wrinkle points): the closest point
//   on the template (face, barycentric weights) goes to the same weights on the deformed
//   template, then to the closest point of the new head; the point's height over the template's
//   skin is kept along the new head's normal, scaled;
// - points inside (linear origins, the jaw pivot): the similarity plus the displacement of the
//   nearby template vertices (Gaussian weights), so a bony origin keeps its depth under the skin;
// - directions (sphincter semi-axes, the jaw's axis and plane normal) turn with the similarity's
//   rotation and lengths scale by its factor; angles, fractions and expressions are kept.
// Wrinkles drawn in the template's texture space are lifted to its surface
// (skin/wrinkle_transfer) and carried as points, so they become `surface_wrinkles` that any
// texture layout of the new head places (its own UVs or the rig's mapping).
#include <memory>
#include <string>
#include <vector>

#include "follicle/core/context.hpp"
#include "follicle/geom/registration_icp.hpp"
#include "follicle/geom/trimesh.hpp"
#include "follicle/skin/skin_json.hpp"

namespace follicle::skin {

/// Template space -> new head space. `region` is the part of the template that was registered
/// (metres, template frame); `deformed` its vertices on the new head.
class HeadMap {
 public:
  HeadMap(const geom::TriMesh& region, std::vector<Vec3> deformed, const geom::Similarity& rigid,
          const geom::TriMesh& target);
  ~HeadMap();
  HeadMap(HeadMap&&) noexcept;
  HeadMap& operator=(HeadMap&&) = delete;
  HeadMap(const HeadMap&) = delete;
  HeadMap& operator=(const HeadMap&) = delete;

  /// A point on or near the template's skin, to the new head's skin (keeping its height over it).
  /// `gap` (when given) receives how far the deformed template lies from the new head there [m]:
  /// large where the template runs past the new head's edge (a forehead beyond a mask's rim).
  Vec3 skin_point(const Vec3& p, double* gap = nullptr) const;
  /// A point inside the template (or anywhere): similarity plus the nearby displacement.
  Vec3 inner_point(const Vec3& p) const;
  Vec3 direction(const Vec3& v) const { return m_rigid.R * v; }
  double length(double l) const { return m_rigid.s * l; }
  const geom::Similarity& rigid() const { return m_rigid; }

 private:
  struct Impl;
  const geom::TriMesh& m_region;
  std::vector<Vec3> m_deformed;
  geom::Similarity m_rigid;
  const geom::TriMesh& m_target;
  std::unique_ptr<Impl> m_impl;
};

/// The template's setup on the new head. `template_mesh` is the mesh the setup was made for
/// (its UVs lift the texture-space wrinkles). Expressions and names are kept; the result's
/// `up` and `front` are the template's turned by the map. A wrinkle point whose deformed
/// template lies more than `edge_gap` from the new head is off its surface: a wrinkle keeps its
/// longest run of points on it when that run holds at least half of them, and is dropped
/// otherwise (named in `dropped`). Throws follicle::Error naming `where` when a wrinkle cannot
/// be lifted.
FaceSetup transfer_face_setup(const FaceSetup& setup, const geom::TriMesh& template_mesh,
                              const HeadMap& map, const std::string& where, double edge_gap,
                              std::vector<std::string>* dropped = nullptr);

}  // namespace follicle::skin
