#pragma once
// Hair strand files: Cem Yuksel .hair (read/write, bit-exact round trip), TressFX .tfx
// (read/write; resampled to a fixed power-of-two vertex count on write), USD ASCII BasisCurves
// (.usda, write) and OBJ polylines (write). Facts: ../shared/docs/hair-formats.md. A file's
// coordinates are in its own unit; readers convert to metres, writers back.
// Binary formats are hand-written (no Debian package; cyHairFile.h is the reference layout).
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
/// Resamples each strand by arc length to `verts_per_strand` (power of two, 4..64); the root
/// vertex gets w = 0 (pinned), the others w = 1.
TfxFile strands_to_tfx(const StrandSet& s, LengthUnit unit, uint32_t verts_per_strand = 32);

/// Files. The format is chosen by extension: .hair, .tfx, .usda, .obj (write only for the last
/// two). Malformed files throw follicle::Error naming the file and what was expected.
StrandSet load_strands(const std::filesystem::path& path, LengthUnit unit);
void save_strands(const StrandSet& s, const std::filesystem::path& path, LengthUnit unit,
                  uint32_t tfx_verts_per_strand = 32);
/// USD ASCII BasisCurves (linear, nonperiodic), metersPerUnit from `unit`, widths per vertex
/// from radius (or a constant 80 µm), displayColor per vertex when colours are present.
std::string strands_to_usda(const StrandSet& s, LengthUnit unit);
/// OBJ: `v x y z` per point and one `l` polyline per strand.
std::string strands_to_obj(const StrandSet& s, LengthUnit unit);
/// Resamples one polyline by arc length to n points (n >= 2).
std::vector<Vec3f> resample_polyline(const Vec3f* pts, std::size_t count, std::size_t n);

}  // namespace follicle::geom
