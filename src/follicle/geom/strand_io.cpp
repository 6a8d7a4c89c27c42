#include "follicle/geom/strand_io.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "follicle/core/atomic_file.hpp"
#include "follicle/core/error.hpp"

namespace follicle::geom {

namespace {

// Little-endian readers (x86-64 and ARM are little-endian; std::memcpy keeps it well-defined).
static_assert(sizeof(float) == 4);

struct Reader {
  const std::string& b;
  const std::string& where;
  std::size_t pos = 0;
  void need(std::size_t n, const char* what) const {
    if (pos + n > b.size() || pos + n < pos)
      fail_at(where, "file is truncated: expected {} bytes of {} at offset {}, file has {}", n,
              what, pos, b.size());
  }
  template <class T>
  T get(const char* what) {
    need(sizeof(T), what);
    T v;
    std::memcpy(&v, b.data() + pos, sizeof(T));
    pos += sizeof(T);
    return v;
  }
  template <class T>
  void get_array(std::vector<T>& out, std::size_t n, const char* what) {
    if (n > (b.size() / sizeof(T)) + 1) need(n * sizeof(T), what);
    need(n * sizeof(T), what);
    out.resize(n);
    if (n) std::memcpy(out.data(), b.data() + pos, n * sizeof(T));
    pos += n * sizeof(T);
  }
};

template <class T>
void put(std::string& out, const T& v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof(T));
}
template <class T>
void put_array(std::string& out, const std::vector<T>& v) {
  if (!v.empty()) out.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
}

void check_finite(const std::vector<float>& v, const std::string& where, const char* what) {
  for (std::size_t i = 0; i < v.size(); ++i)
    if (!std::isfinite(v[i])) fail_at(where, "{} value {} is not finite (NaN/Inf)", what, i);
}

}  // namespace

CyHairFile parse_cyhair(const std::string& bytes, const std::string& where) {
  Reader r{bytes, where};
  r.need(128, "header");
  if (bytes.compare(0, 4, "HAIR") != 0)
    fail_at(where, "not a .hair file: expected signature \"HAIR\"");
  r.pos = 4;
  CyHairFile f;
  f.hair_count = r.get<uint32_t>("hair count");
  f.point_count = r.get<uint32_t>("point count");
  f.arrays = r.get<uint32_t>("array flags");
  f.default_segments = r.get<uint32_t>("default segments");
  f.default_thickness = r.get<float>("default thickness");
  f.default_transparency = r.get<float>("default transparency");
  for (auto& c : f.default_color) c = r.get<float>("default colour");
  std::memcpy(f.info.data(), bytes.data() + r.pos, 88);
  r.pos += 88;
  if (f.arrays & ~31u) fail_at(where, "unknown array flags 0x{:x} (expected bits 0..4)", f.arrays);
  if (!(f.arrays & CyHairFile::kPoints)) fail_at(where, "file has no points array");
  const uint64_t total = uint64_t(f.point_count);
  if (f.arrays & CyHairFile::kSegments) r.get_array(f.segments, f.hair_count, "segments");
  r.get_array(f.points, std::size_t(3 * total), "points");
  if (f.arrays & CyHairFile::kThickness) r.get_array(f.thickness, std::size_t(total), "thickness");
  if (f.arrays & CyHairFile::kTransparency)
    r.get_array(f.transparency, std::size_t(total), "transparency");
  if (f.arrays & CyHairFile::kColors) r.get_array(f.colors, std::size_t(3 * total), "colours");
  if (r.pos != bytes.size())
    fail_at(where, "{} unexpected trailing bytes after the arrays", bytes.size() - r.pos);
  // Consistency: sum of (segments + 1) must equal the point count.
  uint64_t expect = 0;
  if (f.arrays & CyHairFile::kSegments) {
    for (auto s : f.segments) expect += uint64_t(s) + 1;
  } else {
    expect = uint64_t(f.hair_count) * (uint64_t(f.default_segments) + 1);
  }
  if (expect != total)
    fail_at(where, "segment counts describe {} points but the header says {}", expect, total);
  check_finite(f.points, where, "point coordinate");
  return f;
}

std::string serialize_cyhair(const CyHairFile& f) {
  std::string out;
  out.reserve(128 + f.points.size() * 4);
  out.append("HAIR", 4);
  put(out, f.hair_count);
  put(out, f.point_count);
  put(out, f.arrays);
  put(out, f.default_segments);
  put(out, f.default_thickness);
  put(out, f.default_transparency);
  for (float c : f.default_color) put(out, c);
  out.append(f.info.data(), 88);
  if (f.arrays & CyHairFile::kSegments) put_array(out, f.segments);
  put_array(out, f.points);
  if (f.arrays & CyHairFile::kThickness) put_array(out, f.thickness);
  if (f.arrays & CyHairFile::kTransparency) put_array(out, f.transparency);
  if (f.arrays & CyHairFile::kColors) put_array(out, f.colors);
  return out;
}

TfxFile parse_tfx(const std::string& bytes, const std::string& where) {
  Reader r{bytes, where};
  r.need(160, "header");
  TfxFile f;
  f.version = r.get<float>("version");
  f.num_strands = r.get<uint32_t>("strand count");
  f.verts_per_strand = r.get<uint32_t>("vertices per strand");
  f.offset_positions = r.get<uint32_t>("position offset");
  f.offset_strand_uv = r.get<uint32_t>("strand UV offset");
  f.offset_vertex_uv = r.get<uint32_t>("vertex UV offset");
  f.offset_strand_thickness = r.get<uint32_t>("thickness offset");
  f.offset_vertex_color = r.get<uint32_t>("colour offset");
  for (auto& v : f.reserved) v = r.get<uint32_t>("reserved");
  if (!std::isfinite(f.version) || f.version < 1.0f || f.version > 100.0f)
    fail_at(where, "not a TressFX file: version {} (expected 4.0)", f.version);
  const uint32_t v = f.verts_per_strand;
  if (v < 2 || v > 64 || (v & (v - 1)) != 0)
    fail_at(where, "vertices per strand {} is not a power of two in [4, 64]", v);
  if (f.num_strands == 0) fail_at(where, "file has no strands");
  if (f.offset_positions < 160)
    fail_at(where, "position offset {} lies inside the header", f.offset_positions);
  const std::size_t nv = std::size_t(f.num_strands) * v;
  auto section = [&](uint32_t off, std::vector<float>& out, std::size_t n, const char* what) {
    if (off == 0) return;
    if (off < 160) fail_at(where, "{} offset {} lies inside the header", what, off);
    Reader s{bytes, where, off};
    s.get_array(out, n, what);
  };
  section(f.offset_positions, f.positions, 4 * nv, "positions");
  section(f.offset_strand_uv, f.strand_uv, 2 * std::size_t(f.num_strands), "strand UVs");
  section(f.offset_vertex_uv, f.vertex_uv, 2 * nv, "vertex UVs");
  section(f.offset_strand_thickness, f.strand_thickness, f.num_strands, "strand thickness");
  section(f.offset_vertex_color, f.vertex_color, 4 * nv, "vertex colours");
  check_finite(f.positions, where, "position");
  return f;
}

std::string serialize_tfx(const TfxFile& f) {
  std::string out;
  put(out, f.version);
  put(out, f.num_strands);
  put(out, f.verts_per_strand);
  put(out, f.offset_positions);
  put(out, f.offset_strand_uv);
  put(out, f.offset_vertex_uv);
  put(out, f.offset_strand_thickness);
  put(out, f.offset_vertex_color);
  for (auto v : f.reserved) put(out, v);
  auto place = [&](uint32_t off, const std::vector<float>& v) {
    if (off == 0 || v.empty()) return;
    const std::size_t end = std::size_t(off) + v.size() * 4;
    if (out.size() < end) out.resize(end, '\0');
    std::memcpy(out.data() + off, v.data(), v.size() * 4);
  };
  place(f.offset_positions, f.positions);
  place(f.offset_strand_uv, f.strand_uv);
  place(f.offset_vertex_uv, f.vertex_uv);
  place(f.offset_strand_thickness, f.strand_thickness);
  place(f.offset_vertex_color, f.vertex_color);
  return out;
}

StrandSet cyhair_to_strands(const CyHairFile& f, LengthUnit unit) {
  const float s = float(unit_to_metres(unit));
  StrandSet out;
  out.offsets.reserve(f.hair_count + 1);
  uint32_t pos = 0;
  for (uint32_t h = 0; h < f.hair_count; ++h) {
    const uint32_t nseg = (f.arrays & CyHairFile::kSegments) ? f.segments[h] : f.default_segments;
    pos += nseg + 1;
    out.offsets.push_back(pos);
  }
  out.points.resize(f.point_count);
  for (uint32_t i = 0; i < f.point_count; ++i)
    out.points[i] = Vec3f(f.points[3 * i], f.points[3 * i + 1], f.points[3 * i + 2]) * s;
  if (f.arrays & CyHairFile::kThickness) {
    out.radius.resize(f.point_count);
    for (uint32_t i = 0; i < f.point_count; ++i) out.radius[i] = 0.5f * f.thickness[i] * s;
  }
  if (f.arrays & CyHairFile::kColors) {
    out.color.resize(f.point_count);
    for (uint32_t i = 0; i < f.point_count; ++i)
      out.color[i] = Vec3f(f.colors[3 * i], f.colors[3 * i + 1], f.colors[3 * i + 2]);
  }
  return out;
}

CyHairFile strands_to_cyhair(const StrandSet& s, LengthUnit unit) {
  const float k = float(1.0 / unit_to_metres(unit));
  CyHairFile f;
  f.hair_count = uint32_t(s.num_strands());
  f.point_count = uint32_t(s.num_points());
  f.arrays = CyHairFile::kSegments | CyHairFile::kPoints;
  for (std::size_t i = 0; i < s.num_strands(); ++i) {
    if (s.strand_size(i) < 1 || s.strand_size(i) > 65536)
      fail("strand {} has {} points; .hair stores 1..65536", i, s.strand_size(i));
    f.segments.push_back(uint16_t(s.strand_size(i) - 1));
  }
  f.points.resize(3 * s.num_points());
  for (std::size_t i = 0; i < s.num_points(); ++i)
    for (int c = 0; c < 3; ++c) f.points[3 * i + c] = s.points[i][c] * k;
  if (s.radius.size() == s.num_points() && !s.radius.empty()) {
    f.arrays |= CyHairFile::kThickness;
    f.thickness.resize(s.num_points());
    for (std::size_t i = 0; i < s.num_points(); ++i) f.thickness[i] = 2.0f * s.radius[i] * k;
  }
  if (s.color.size() == s.num_points() && !s.color.empty()) {
    f.arrays |= CyHairFile::kColors;
    f.colors.resize(3 * s.num_points());
    for (std::size_t i = 0; i < s.num_points(); ++i)
      for (int c = 0; c < 3; ++c) f.colors[3 * i + c] = s.color[i][c];
  }
  const char* info = "Follicle";
  std::memcpy(f.info.data(), info, std::strlen(info));
  return f;
}

StrandSet tfx_to_strands(const TfxFile& f, LengthUnit unit) {
  const float s = float(unit_to_metres(unit));
  StrandSet out;
  const uint32_t v = f.verts_per_strand;
  out.points.resize(std::size_t(f.num_strands) * v);
  for (uint32_t h = 0; h < f.num_strands; ++h) out.offsets.push_back((h + 1) * v);
  for (std::size_t i = 0; i < out.points.size(); ++i)
    out.points[i] = Vec3f(f.positions[4 * i], f.positions[4 * i + 1], f.positions[4 * i + 2]) * s;
  if (!f.vertex_color.empty()) {
    out.color.resize(out.points.size());
    for (std::size_t i = 0; i < out.points.size(); ++i)
      out.color[i] =
          Vec3f(f.vertex_color[4 * i], f.vertex_color[4 * i + 1], f.vertex_color[4 * i + 2]);
  }
  if (!f.strand_thickness.empty()) {
    out.radius.resize(out.points.size());
    for (std::size_t i = 0; i < out.points.size(); ++i)
      out.radius[i] = 0.5f * f.strand_thickness[i / v] * s;
  }
  return out;
}

std::vector<Vec3f> resample_polyline(const Vec3f* pts, std::size_t count, std::size_t n) {
  std::vector<Vec3f> out(n, count ? pts[0] : Vec3f::Zero());
  if (count < 2 || n < 2) return out;
  std::vector<double> acc(count, 0.0);
  for (std::size_t i = 1; i < count; ++i)
    acc[i] = acc[i - 1] + (pts[i] - pts[i - 1]).cast<double>().norm();
  const double L = acc.back();
  std::size_t j = 1;
  for (std::size_t k = 0; k < n; ++k) {
    const double t = L * double(k) / double(n - 1);
    while (j < count - 1 && acc[j] < t) ++j;
    const double seg = acc[j] - acc[j - 1];
    const double u = seg > 0 ? std::clamp((t - acc[j - 1]) / seg, 0.0, 1.0) : 0.0;
    out[k] = (pts[j - 1].cast<double>() + u * (pts[j] - pts[j - 1]).cast<double>()).cast<float>();
  }
  out.front() = pts[0];
  out.back() = pts[count - 1];
  return out;
}

TfxFile strands_to_tfx(const StrandSet& s, LengthUnit unit, uint32_t verts) {
  if (verts < 4 || verts > 64 || (verts & (verts - 1)) != 0)
    fail("TressFX vertices per strand must be a power of two in [4, 64], got {}", verts);
  const float k = float(1.0 / unit_to_metres(unit));
  TfxFile f;
  f.num_strands = uint32_t(s.num_strands());
  f.verts_per_strand = verts;
  f.positions.reserve(4 * std::size_t(f.num_strands) * verts);
  bool resample = false;
  for (std::size_t h = 0; h < s.num_strands(); ++h) resample |= s.strand_size(h) != verts;
  for (std::size_t h = 0; h < s.num_strands(); ++h) {
    const Vec3f* p = s.points.data() + s.strand_begin(h);
    std::vector<Vec3f> r =
        resample ? resample_polyline(p, s.strand_size(h), verts) : std::vector<Vec3f>(p, p + verts);
    for (uint32_t i = 0; i < verts; ++i) {
      for (int c = 0; c < 3; ++c) f.positions.push_back(r[i][c] * k);
      f.positions.push_back(i == 0 ? 0.0f : 1.0f);
    }
  }
  return f;
}

static std::string lower_ext(const std::filesystem::path& p) {
  std::string e = p.extension().string();
  std::transform(e.begin(), e.end(), e.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  return e;
}

StrandSet load_strands(const std::filesystem::path& path, LengthUnit unit) {
  const std::string ext = lower_ext(path);
  const std::string where = path.string();
  if (ext == ".hair") return cyhair_to_strands(parse_cyhair(read_file(path), where), unit);
  if (ext == ".tfx") return tfx_to_strands(parse_tfx(read_file(path), where), unit);
  fail_at(where, "unknown hair file extension \"{}\" (readable: .hair, .tfx)", ext);
}

void save_strands(const StrandSet& s, const std::filesystem::path& path, LengthUnit unit,
                  uint32_t tfx_verts) {
  const std::string ext = lower_ext(path);
  std::string bytes;
  if (ext == ".hair")
    bytes = serialize_cyhair(strands_to_cyhair(s, unit));
  else if (ext == ".tfx")
    bytes = serialize_tfx(strands_to_tfx(s, unit, tfx_verts));
  else if (ext == ".usda")
    bytes = strands_to_usda(s, unit);
  else if (ext == ".obj")
    bytes = strands_to_obj(s, unit);
  else
    fail_at(path.string(),
            "unknown hair file extension \"{}\" (writable: .hair, .tfx, .usda, .obj)", ext);
  write_file_atomically(path, bytes);
}

std::string strands_to_usda(const StrandSet& s, LengthUnit unit) {
  const double k = 1.0 / unit_to_metres(unit);
  std::string o;
  o += fmt::format(
      "#usda 1.0\n(\n    defaultPrim = \"Hair\"\n    metersPerUnit = {}\n    upAxis = \"Y\"\n)\n\n",
      unit_to_metres(unit));
  o += "def BasisCurves \"Hair\"\n{\n    uniform token type = \"linear\"\n    uniform token wrap = "
       "\"nonperiodic\"\n";
  o += "    int[] curveVertexCounts = [";
  for (std::size_t h = 0; h < s.num_strands(); ++h)
    o += fmt::format("{}{}", h ? ", " : "", s.strand_size(h));
  o += "]\n    point3f[] points = [";
  for (std::size_t i = 0; i < s.num_points(); ++i)
    o += fmt::format("{}({:.9g}, {:.9g}, {:.9g})", i ? ", " : "", s.points[i].x() * k,
                     s.points[i].y() * k, s.points[i].z() * k);
  o += "]\n    float[] widths = [";
  const bool has_r = s.radius.size() == s.num_points() && !s.radius.empty();
  if (has_r) {
    for (std::size_t i = 0; i < s.num_points(); ++i)
      o += fmt::format("{}{:.9g}", i ? ", " : "", 2 * s.radius[i] * k);
    o += "] (\n        interpolation = \"vertex\"\n    )\n";
  } else {
    o += fmt::format("{:.9g}] (\n        interpolation = \"constant\"\n    )\n", 80e-6 * k);
  }
  if (s.color.size() == s.num_points() && !s.color.empty()) {
    o += "    color3f[] primvars:displayColor = [";
    for (std::size_t i = 0; i < s.num_points(); ++i)
      o += fmt::format("{}({:.6g}, {:.6g}, {:.6g})", i ? ", " : "", s.color[i].x(), s.color[i].y(),
                       s.color[i].z());
    o += "] (\n        interpolation = \"vertex\"\n    )\n";
  }
  o += "}\n";
  return o;
}

std::string strands_to_obj(const StrandSet& s, LengthUnit unit) {
  const double k = 1.0 / unit_to_metres(unit);
  std::string o = fmt::format("# Follicle hair strands: {} polylines, units {}\n", s.num_strands(),
                              to_string(unit));
  for (const auto& p : s.points)
    o += fmt::format("v {:.9g} {:.9g} {:.9g}\n", p.x() * k, p.y() * k, p.z() * k);
  for (std::size_t h = 0; h < s.num_strands(); ++h) {
    o += "l";
    for (uint32_t i = s.offsets[h]; i < s.offsets[h + 1]; ++i) o += fmt::format(" {}", i + 1);
    o += "\n";
  }
  return o;
}

}  // namespace follicle::geom
