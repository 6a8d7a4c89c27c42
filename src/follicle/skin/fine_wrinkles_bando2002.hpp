#pragma once
// Fine-scale wrinkles of Bando et al. 2002 (thesis §2.6; paper §5, §7): direction fields over the
// texture-space mesh, furrow carving into a height image with an occupancy image, wrinkle
// characteristics from the direction magnitude (2.5), body-part seams and per-frame amplitude
// modulation by the shrinkage perpendicular to each field (2.3, 2.4).
//
// Texture-space conventions: a body part is a geom::TriMesh with UVs in [0,1]^2 (mesh.uvs,
// mesh.uv_faces). Images are `resolution` texels square, row 0 on top: texel (x, y) covers
// u in [x/N, (x+1)/N], v in [1-(y+1)/N, 1-y/N] (the usual OBJ/OpenGL texture orientation). A
// texture-space direction (du, dv) is (du, -dv) in texel coordinates. Direction fields live on
// the uv vertices (mesh.uvs), so UV seams split them like the texture does.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "follicle/core/context.hpp"
#include "follicle/core/params.hpp"
#include "follicle/core/types.hpp"
#include "follicle/geom/trimesh.hpp"
#include "follicle/image/image.hpp"

namespace follicle::skin {

struct FineWrinkleParams {
  int resolution = 1024;     // height/occupancy image size [texels], 64..4096
  double unit_texels = 1.0;  // texels per length unit of (2.5) (the paper: one pixel)
  double unit_mm = 0.0;      // > 0: one (2.5) unit is this long on the skin [mm] (overrides
                             // unit_texels through the mesh's mean texel size)
  int max_failures = 200;    // consecutive random starts on occupied texels -> fill pass
  bool fill_pass = true;     // then start furrows from every remaining free texel
  double depth_m = 60e-6;    // skin depth of a furrow of intensity I = 0 [m] (maps only)
  double r = 0.5;            // (2.4) modulation parameter for fine wrinkles (paper: 0.5)

  template <class V>
  void visit(V&& v) {
    v("resolution", resolution, ParamInfo{"height image size", "texels", 64, 4096});
    v("unit_texels", unit_texels, ParamInfo{"texels per Eq. 2.5 unit", "texels", 0.05, 64});
    v("unit_mm", unit_mm, ParamInfo{"Eq. 2.5 unit on the skin (0 = use unit_texels)", "mm", 0, 10});
    v("max_failures", max_failures, ParamInfo{"failed random starts before fill", "", 1, 1e7});
    v("fill_pass", fill_pass, ParamInfo{"fill remaining free texels", ""});
    v("depth_m", depth_m, ParamInfo{"furrow depth at I = 0", "m", 0, 0.01});
    v("r", r, ParamInfo{"amplitude modulation r (2.4)", "", 0, 1});
  }
  void validate() const { validate_params(*this, "fine_wrinkles"); }
};

/// A user-given direction at one uv vertex (index into mesh.uvs); |direction| in [0, 1].
struct DirectionKey {
  int vertex = 0;
  Vec2 direction = Vec2::Zero();  // texture space (u, v)
};

/// §2.6.1: direction vectors at every uv vertex, minimizing the mapping's spring energy (Eck
/// harmonic weights over the 3D mesh, geom::harmonic_interpolate) with the keys fixed.
/// Magnitudes are clamped to [0, 1]. Throws follicle::Error (naming `where`) on bad keys.
std::vector<Vec2> interpolate_direction_field(const geom::TriMesh& mesh,
                                              const std::vector<DirectionKey>& keys,
                                              const std::string& where = "directions");

/// (2.5) wrinkle characteristics from the direction magnitude m in [0,1] and a random number
/// r_rand in (-1, 1). Lengths D, W_h, W_o in (2.5) units; I is the gray level of the furrow
/// (1 = white = no furrow), so the carved depth is 1 - I = m^2.
struct FurrowParameters {
  int N = 0;
  double theta = 0, D = 0, I = 0, Wh = 0, Wo = 0;
};
FurrowParameters furrow_parameters(double m, double r_rand);

/// The texture-space mesh rasterized at one resolution (SoA): per texel the uv face whose
/// triangle contains the texel centre (-1: not mapped) and its barycentric coordinates.
struct TexelMap {
  int size = 0;
  std::vector<int32_t> tri;
  std::vector<float> b1, b2;      // corner 0 weight = 1 - b1 - b2
  std::vector<uint32_t> covered;  // indices of mapped texels, ascending
  double metres_per_texel = 0;    // sqrt(3D area / texel area) over the whole mesh
  bool inside(int x, int y) const { return x >= 0 && y >= 0 && x < size && y < size; }
};
TexelMap rasterize_texture_space(const Context& ctx, const geom::TriMesh& mesh, int resolution);

/// Polylines in texel coordinates (furrow centre lines), SoA.
struct Polylines {
  std::vector<Vec2f> points;
  std::vector<uint32_t> offsets{0};  // polyline k = points[offsets[k] .. offsets[k+1])
  std::size_t size() const { return offsets.size() - 1; }
};

/// State copied from a neighbouring body part over the shared strip (§2.6.4).
struct SeamInit {
  std::vector<DirectionKey> directions;  // extra fixed keys on the strip's uv vertices
  image::ImageF height;                  // the neighbour's heights where `locked`
  std::vector<uint8_t> locked;           // per texel: 1 inside the shared strip
  Polylines furrows;                     // the neighbour's furrow segments mapped here
};

struct HeightField {
  std::vector<Vec2> directions;  // per uv vertex (§2.6.1)
  image::ImageF height;          // 1 = untouched skin, furrows carved down to I (§2.6.2)
  image::ImageF occupancy;       // binary 0/1
  Polylines furrows;             // each furrow: backward half reversed + forward half
  int random_furrows = 0, fill_furrows = 0, failed_starts = 0, segments = 0;
};

/// §2.6.2: carves one field's furrows (the walk is sequential, deterministic for a seed; the
/// height strokes of step 5 are then drawn in parallel over row bands, in walk order, so the
/// images do not depend on the thread count). `directions` are per uv vertex (already
/// interpolated). `unit_texels` is the resolved (2.5) unit.
HeightField carve_furrows(const Context& ctx, const geom::TriMesh& mesh, const TexelMap& texels,
                          std::vector<Vec2> directions, double unit_texels,
                          const FineWrinkleParams& p, uint64_t seed,
                          const SeamInit* init = nullptr);

/// Both fields of a body part.
struct FineWrinkles {
  TexelMap texels;
  std::array<HeightField, 2> fields;
  double unit_texels = 1.0;  // resolved (2.5) unit
  double depth_m = 0.0;
  double r = 0.5;
};

/// Resolves the (2.5) unit in texels for a mesh's texel size.
double resolve_unit_texels(const FineWrinkleParams& p, const TexelMap& texels);

/// Interpolates both direction fields and carves both height fields (the two fields run in
/// parallel; each is sequential, so results are identical for any thread count). The seed
/// comes from ctx.seed(). `seams[k]` (optional) initializes field k from a neighbouring part.
FineWrinkles generate_fine_wrinkles(const Context& ctx, const geom::TriMesh& mesh,
                                    const std::array<std::vector<DirectionKey>, 2>& keys,
                                    const FineWrinkleParams& p,
                                    const std::array<const SeamInit*, 2>& seams = {nullptr,
                                                                                   nullptr});

/// Corresponding faces of two body parts over their shared boundary strip; corner c of
/// faces_a[i] is the same surface point as corner c of faces_b[i].
struct SharedStrip {
  std::vector<int> faces_a, faces_b;
};

/// §2.6.4: after part A is generated, copies field `field` of A (directions at the strip's uv
/// vertices, mapped through each triangle's uv affine map; heights; furrow segments) into the
/// texture space of part B, to be passed to generate_fine_wrinkles for B.
SeamInit make_seam_init(const geom::TriMesh& mesh_a, const FineWrinkles& a, int field,
                        const geom::TriMesh& mesh_b, const TexelMap& texels_b,
                        const SharedStrip& strip);

/// §2.6.4 animated fine wrinkles: per frame, shrinkage (2.3) perpendicular to each field's
/// direction at every uv vertex, and the two height fields modulated by M(s) (2.4) and
/// superimposed. Precomputes everything that does not depend on the deformed positions.
class FineWrinkleAnimator {
 public:
  FineWrinkleAnimator(const geom::TriMesh& rest, const FineWrinkles& w);

  /// s[k][uv vertex] for field k; the deformed mesh has rest's topology (positions only).
  void shrinkage(const Context& ctx, const std::vector<Vec3>& deformed,
                 std::array<std::vector<float>, 2>& s) const;
  /// Shrinkage texture of one field (per-texel interpolation of the vertex values; 0 unmapped).
  void shrinkage_texture(const Context& ctx, const std::vector<float>& s, image::ImageF& out) const;
  /// Relief = -sum_k M(s_k) (1 - h_k) in units of the full furrow depth (0 = skin surface,
  /// negative in furrows); displacement [m] = relief * depth_m. Parallel over rows.
  void modulate(const Context& ctx, const std::array<std::vector<float>, 2>& s,
                image::ImageF& relief) const;
  /// Relief of the rest state (s = 0 everywhere, M = r).
  void rest_relief(const Context& ctx, image::ImageF& relief) const;

  int size() const { return m_size; }
  double metres_per_texel() const { return m_mpt; }
  double depth_m() const { return m_depth; }
  std::size_t num_uv_vertices() const { return m_pos_of_uv.size(); }

 private:
  struct Side {            // one of the (up to) two triangles around a uv vertex along +-d_p
    int v2 = -1, v3 = -1;  // position indices
    float a = 0, b = 0;    // d_p = a e2 + b e3
    float l2 = 0, l3 = 0;  // rest 3D edge lengths |x2 - x1|, |x3 - x1|
  };
  int m_size = 0;
  double m_mpt = 0, m_depth = 0, m_r = 0.5;
  std::vector<int> m_pos_of_uv;
  std::vector<Vec3i> m_uv_faces;
  std::array<std::vector<std::array<Side, 2>>, 2> m_sides;  // [field][uv vertex][+/-]
  TexelMap m_texels;
  std::array<std::vector<float>, 2> m_depth_img;  // 1 - h_k per texel
  std::vector<float> m_lut;                       // M(s) on [kLutLo, 1]
  // modulate(): the relief of texels without any furrow depth is -0 (0 where unmapped) for every
  // s, so it is copied from m_blank; only the texels with depth in some field ("active", in
  // raster order, rows m_act_row[y] .. m_act_row[y+1]) are computed.
  std::vector<float> m_blank;
  std::vector<uint32_t> m_act_row, m_act_idx;
  std::vector<int32_t> m_act_face;
  std::vector<float> m_act_b1, m_act_b2, m_act_d0, m_act_d1;
};

}  // namespace follicle::skin
