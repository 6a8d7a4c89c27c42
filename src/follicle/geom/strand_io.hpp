#pragma once
// Hair strand files, read and written: Cem Yuksel .hair (bit-exact round trip), TressFX .tfx
// (resampled to a fixed power-of-two vertex count on write), USD ASCII BasisCurves (.usda; .usd
// when it is ASCII) and OBJ polylines (`v` + `l`). Facts: ../shared/docs/hair-formats.md.
//
// Units: a file's coordinates are in its own unit; readers convert to metres, writers back. The
// `unit` argument gives that unit, except for USD: a layer that declares `metersPerUnit` is read
// in that unit and the argument is ignored (the file knows best; a USD layer without it is read
// in `unit`). Writers put `unit` into the USD `metersPerUnit`.
//
// Exactness: .usda and .obj print coordinates with max_digits10 (9) significant digits of the
// double-precision value in the file unit; readers parse doubles, scale once in double and round
// once to float, so float positions survive write -> read exactly in any unit.
//
// Binary formats are hand-written (no Debian package; cyHairFile.h is the reference layout). USD
// is parsed by a hand-written, tolerant USDA reader because OpenUSD is not packaged in Debian;
// binary USD (usdc, "PXR-USDC") is refused with a clear error.
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "follicle/core/units.hpp"
#include "follicle/geom/strands.hpp"

namespace follicle::geom {

/// Raw .hair contents (little-endian, 128-byte header), kept exactly for bit-exact round trips.
struct CyHairFile {
  static constexpr uint32_t kSegments = 1, kPoints = 2, kThickness = 4, kTransparency = 8,
                            kColors = 16;
  uint32_t hair_count = 0, point_count = 0, arrays = 0;
  uint32_t default_segments = 0;
  float default_thickness = 1.0f, default_transparency = 0.0f;
  std::array<float, 3> default_color{0.5f, 0.5f, 0.5f};
  std::array<char, 88> info{};
  std::vector<uint16_t> segments;   // hair_count when kSegments
  std::vector<float> points;        // 3 * point_count
  std::vector<float> thickness;     // point_count when kThickness
  std::vector<float> transparency;  // point_count when kTransparency
  std::vector<float> colors;        // 3 * point_count when kColors
};
/// Every count is checked against the byte size before anything is allocated.
CyHairFile parse_cyhair(const std::string& bytes, const std::string& where);
std::string serialize_cyhair(const CyHairFile& f);

/// Raw .tfx contents (TressFX 4.0, 160-byte header), kept exactly.
struct TfxFile {
  float version = 4.0f;
  uint32_t num_strands = 0, verts_per_strand = 0;
  uint32_t offset_positions = 160, offset_strand_uv = 0, offset_vertex_uv = 0,
           offset_strand_thickness = 0, offset_vertex_color = 0;
  std::array<uint32_t, 32> reserved{};
  std::vector<float> positions;         // 4 * strands * verts (x, y, z, w = inverse mass)
  std::vector<float> strand_uv;         // 2 * strands, optional
  std::vector<float> vertex_uv;         // 2 * strands * verts, optional
  std::vector<float> strand_thickness;  // strands, optional
  std::vector<float> vertex_color;      // 4 * strands * verts, optional
};
TfxFile parse_tfx(const std::string& bytes, const std::string& where);
std::string serialize_tfx(const TfxFile& f);

/// StrandSet <-> raw files. `unit`: the file's length unit (points are stored in it).
StrandSet cyhair_to_strands(const CyHairFile& f, LengthUnit unit);
CyHairFile strands_to_cyhair(const StrandSet& s, LengthUnit unit);
StrandSet tfx_to_strands(const TfxFile& f, LengthUnit unit);
/// Resamples each strand by arc length to `verts_per_strand` (power of two, 4..64) unless every
/// strand already has that many points; the root vertex gets w = 0 (pinned), the others w = 1.
TfxFile strands_to_tfx(const StrandSet& s, LengthUnit unit, uint32_t verts_per_strand = 32);

/// What a reader found besides the strands.
struct StrandFileInfo {
  std::string format;              // "hair", "tfx", "usda", "obj"
  double metres_per_unit = 1.0;    // the unit the coordinates were read in
  bool unit_from_file = false;     // USD metersPerUnit (overrides the unit argument)
  std::vector<std::string> notes;  // what was converted or ignored (cubic curves, up axis...)
};

/// USD reading options.
struct UsdReadOptions {
  /// Cubic BasisCurves (bezier, bspline, catmullRom) become polylines with this many points per
  /// span (u = 0, 1/n, ..., (n-1)/n of each span, plus the curve's end point). Linear curves are
  /// kept exactly.
  uint32_t cubic_samples_per_span = 8;
};

/// USD ASCII (usda 1.0) BasisCurves. Reads every defined, active BasisCurves prim of the layer
/// (several prims are concatenated in file order): points, curveVertexCounts, widths or
/// primvars:widths (constant / uniform / varying / vertex; radius = width / 2), primvars:
/// displayColor (same interpolations, optional :indices), type linear or cubic with basis
/// bezier / bspline / catmullRom, wrap nonperiodic or pinned (periodic is refused: strands are
/// open), and the xformOp stack (translate, scale, rotateX/Y/Z, rotateXYZ.., orient, transform,
/// !invert!, !resetXformStack!) of the prim and its ancestors, which is applied (widths scale by
/// the cube root of the determinant). Attributes without a default value use their earliest time
/// sample. `over`/`class` prims, variant sets, references, payloads and sublayers are not
/// composed (listed in info->notes when present). Errors name the file and line.
StrandSet usda_to_strands(const std::string& text, const std::string& where, LengthUnit unit,
                          StrandFileInfo* info = nullptr, const UsdReadOptions& opt = {});
/// OBJ polylines: `v x y z [w]` (or `v x y z r g b`: colours are kept when every vertex has
/// them), one strand per `l` element (indices may be negative or `v/vt`; lines may continue with
/// a trailing backslash). Faces and everything else are ignored. Errors name the file and line.
StrandSet obj_to_strands(const std::string& text, const std::string& where, LengthUnit unit);

/// Files. The format is chosen by extension: .hair, .tfx, .usda/.usd (ASCII), .obj (read and
/// write; .usd is read only). Malformed, truncated or lying files and files without strands throw
/// follicle::Error naming the file (and line for text formats) and what was expected.
StrandSet load_strands(const std::filesystem::path& path, LengthUnit unit,
                       StrandFileInfo* info = nullptr);
/// Writes atomically (temp file + rename). Throws for an empty or inconsistent set.
void save_strands(const StrandSet& s, const std::filesystem::path& path, LengthUnit unit,
                  uint32_t tfx_verts_per_strand = 32);
/// True for .hair, .tfx, .usda, .usd, and for an .obj that has `l` polylines and no faces (an
/// .obj with faces is a mesh). Reads the file only for .obj (throws when it cannot).
bool is_strand_file(const std::filesystem::path& path);
/// True when save_strands can write this extension (.hair, .tfx, .usda, .obj).
bool is_strand_extension(const std::filesystem::path& path);

/// USD ASCII BasisCurves (linear, nonperiodic), metersPerUnit from `unit`, widths per vertex
/// from radius (or a constant 80 µm, which reads back as a per-point radius of 40 µm),
/// displayColor per vertex when colours are present. 9 significant digits.
std::string strands_to_usda(const StrandSet& s, LengthUnit unit);
/// OBJ: `v x y z` per point (`v x y z r g b` when colours are present) and one `l` polyline per
/// strand. Radii are not stored (OBJ has no convention for them). 9 significant digits.
std::string strands_to_obj(const StrandSet& s, LengthUnit unit);
/// Resamples one polyline by arc length to n points (n >= 2).
std::vector<Vec3f> resample_polyline(const Vec3f* pts, std::size_t count, std::size_t n);

}  // namespace follicle::geom
