// Strand files. Binary formats (.hair, .tfx) check every count against the byte size before
// allocating. Text formats (.usda, .obj) are parsed by hand with file:line errors: OpenUSD (the
// only full USD implementation) is not packaged in Debian, and tinyobjloader drops `l` elements'
// line numbers and silently accepts unparsable numbers, so both readers are written here.
#include "follicle/geom/strand_io.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <string_view>

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
  // Throws unless n elements of `elem` bytes exist at pos. n may be a lying count: the test
  // divides instead of multiplying (no overflow) and runs before anything is allocated.
  void need(uint64_t n, const char* what, std::size_t elem = 1) const {
    if (pos > b.size() || n > uint64_t(b.size() - pos) / elem)
      fail_at(where,
              "file is truncated or a count is wrong: expected {} bytes of {} at offset {}, the "
              "file has {} bytes",
              n * elem, what, pos, b.size());
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
  void get_array(std::vector<T>& out, uint64_t n, const char* what) {
    need(n, what, sizeof(T));
    out.resize(std::size_t(n));
    if (n) std::memcpy(out.data(), b.data() + pos, std::size_t(n) * sizeof(T));
    pos += std::size_t(n) * sizeof(T);
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

std::string lower_ext(const std::filesystem::path& p) {
  std::string e = p.extension().string();
  std::transform(e.begin(), e.end(), e.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  return e;
}

std::string at_line(const std::string& where, std::size_t line) {
  return fmt::format("{}:{}", where, line);
}

bool parse_double(std::string_view tok, double& out) {
  if (!tok.empty() && tok.front() == '+') tok.remove_prefix(1);
  const char* b = tok.data();
  const char* e = b + tok.size();
  auto r = std::from_chars(b, e, out);
  return r.ec == std::errc() && r.ptr == e;
}

bool parse_int(std::string_view tok, long long& out) {
  if (!tok.empty() && tok.front() == '+') tok.remove_prefix(1);
  const char* b = tok.data();
  const char* e = b + tok.size();
  auto r = std::from_chars(b, e, out);
  return r.ec == std::errc() && r.ptr == e;
}

// Text writers print "{:.9g}" of the double value in the file unit. Float -> text -> float is
// then exact (9 = max_digits10 of float): the printed decimal is within 5e-9 (relative) of the
// value, far inside half a float ulp (>= 3e-8), and the reader rounds to float only once.

}  // namespace

// ------------------------------------------------------------------------------------ .hair

CyHairFile parse_cyhair(const std::string& bytes, const std::string& where) {
  Reader r{bytes, where};
  if (bytes.size() >= 4 && bytes.compare(0, 4, "HAIR") != 0)
    fail_at(where, "not a .hair file: expected the signature \"HAIR\"");
  r.need(128, "header");
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
  r.get_array(f.points, 3 * total, "points");
  if (f.arrays & CyHairFile::kThickness) r.get_array(f.thickness, total, "thickness");
  if (f.arrays & CyHairFile::kTransparency) r.get_array(f.transparency, total, "transparency");
  if (f.arrays & CyHairFile::kColors) r.get_array(f.colors, 3 * total, "colours");
  if (r.pos != bytes.size())
    fail_at(where, "{} unexpected trailing bytes after the arrays (the header counts {} points)",
            bytes.size() - r.pos, total);
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
  check_finite(f.thickness, where, "thickness");
  check_finite(f.colors, where, "colour");
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

// ------------------------------------------------------------------------------------- .tfx

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
    fail_at(where, "vertices per strand {} is not a power of two in [2, 64]", v);
  if (f.num_strands == 0) fail_at(where, "file has no strands");
  if (f.offset_positions < 160)
    fail_at(where, "position offset {} lies inside the 160-byte header", f.offset_positions);
  const uint64_t nv = uint64_t(f.num_strands) * v;
  auto section = [&](uint32_t off, std::vector<float>& out, uint64_t n, const char* what) {
    if (off == 0) return;
    if (off < 160) fail_at(where, "{} offset {} lies inside the 160-byte header", what, off);
    Reader s{bytes, where, off};
    s.get_array(out, n, what);
  };
  section(f.offset_positions, f.positions, 4 * nv, "positions");
  section(f.offset_strand_uv, f.strand_uv, 2 * uint64_t(f.num_strands), "strand UVs");
  section(f.offset_vertex_uv, f.vertex_uv, 2 * nv, "vertex UVs");
  section(f.offset_strand_thickness, f.strand_thickness, f.num_strands, "strand thickness");
  section(f.offset_vertex_color, f.vertex_color, 4 * nv, "vertex colours");
  check_finite(f.positions, where, "position");
  check_finite(f.strand_thickness, where, "strand thickness");
  check_finite(f.vertex_color, where, "vertex colour");
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

// Unit changes are done in double and rounded to float once (exact when the unit is metres).
StrandSet cyhair_to_strands(const CyHairFile& f, LengthUnit unit) {
  const double s = unit_to_metres(unit);
  StrandSet out;
  out.offsets.reserve(std::size_t(f.hair_count) + 1);
  uint32_t pos = 0;
  for (uint32_t h = 0; h < f.hair_count; ++h) {
    const uint32_t nseg = (f.arrays & CyHairFile::kSegments) ? f.segments[h] : f.default_segments;
    pos += nseg + 1;
    out.offsets.push_back(pos);
  }
  out.points.resize(f.point_count);
  for (uint32_t i = 0; i < f.point_count; ++i)
    out.points[i] =
        (Vec3(f.points[3 * i], f.points[3 * i + 1], f.points[3 * i + 2]) * s).cast<float>();
  if (f.arrays & CyHairFile::kThickness) {
    out.radius.resize(f.point_count);
    for (uint32_t i = 0; i < f.point_count; ++i) out.radius[i] = float(0.5 * f.thickness[i] * s);
  }
  if (f.arrays & CyHairFile::kColors) {
    out.color.resize(f.point_count);
    for (uint32_t i = 0; i < f.point_count; ++i)
      out.color[i] = Vec3f(f.colors[3 * i], f.colors[3 * i + 1], f.colors[3 * i + 2]);
  }
  return out;
}

CyHairFile strands_to_cyhair(const StrandSet& s, LengthUnit unit) {
  const double k = 1.0 / unit_to_metres(unit);
  CyHairFile f;
  if (s.num_strands() > std::numeric_limits<uint32_t>::max() ||
      s.num_points() > std::numeric_limits<uint32_t>::max())
    fail("{} strands / {} points do not fit a .hair file (32-bit counts)", s.num_strands(),
         s.num_points());
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
    for (int c = 0; c < 3; ++c) f.points[3 * i + c] = float(s.points[i][c] * k);
  if (s.radius.size() == s.num_points() && !s.radius.empty()) {
    f.arrays |= CyHairFile::kThickness;
    f.thickness.resize(s.num_points());
    for (std::size_t i = 0; i < s.num_points(); ++i) f.thickness[i] = float(2.0 * s.radius[i] * k);
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
  const double s = unit_to_metres(unit);
  StrandSet out;
  const uint32_t v = f.verts_per_strand;
  const std::size_t n = std::size_t(f.num_strands) * v;
  if (f.positions.size() != 4 * n)
    fail("TressFX data holds {} position floats, expected 4 x {} strands x {} vertices",
         f.positions.size(), f.num_strands, v);
  out.points.resize(n);
  for (uint32_t h = 0; h < f.num_strands; ++h) out.offsets.push_back((h + 1) * v);
  for (std::size_t i = 0; i < n; ++i)
    out.points[i] = (Vec3(f.positions[4 * i], f.positions[4 * i + 1], f.positions[4 * i + 2]) * s)
                        .cast<float>();
  if (f.vertex_color.size() == 4 * n && n) {
    out.color.resize(n);
    for (std::size_t i = 0; i < n; ++i)
      out.color[i] =
          Vec3f(f.vertex_color[4 * i], f.vertex_color[4 * i + 1], f.vertex_color[4 * i + 2]);
  }
  if (f.strand_thickness.size() == f.num_strands && n) {
    out.radius.resize(n);
    for (std::size_t i = 0; i < n; ++i) out.radius[i] = float(0.5 * f.strand_thickness[i / v] * s);
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
  if (s.num_strands() > std::numeric_limits<uint32_t>::max() / 64)
    fail("{} strands do not fit a .tfx file", s.num_strands());
  const double k = 1.0 / unit_to_metres(unit);
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
      for (int c = 0; c < 3; ++c) f.positions.push_back(float(r[i][c] * k));
      f.positions.push_back(i == 0 ? 0.0f : 1.0f);
    }
  }
  return f;
}

// ------------------------------------------------------------------------------------- OBJ

namespace {

// Logical OBJ lines: comments stripped, backslash continuations joined; `line` is where the
// logical line starts.
template <class F>
void for_each_obj_line(const std::string& text, F&& f) {
  std::string logical;
  std::size_t start_line = 0, line_no = 0, pos = 0;
  bool continuing = false;
  while (pos < text.size()) {
    std::size_t eol = text.find('\n', pos);
    if (eol == std::string::npos) eol = text.size();
    std::string_view line(text.data() + pos, eol - pos);
    pos = eol + 1;
    ++line_no;
    if (auto hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ' || line.back() == '\t'))
      line.remove_suffix(1);
    if (!continuing) {
      logical.clear();
      start_line = line_no;
    }
    continuing = !line.empty() && line.back() == '\\';
    if (continuing) line.remove_suffix(1);
    logical.append(line);
    logical.push_back(' ');
    if (!continuing) f(std::string_view(logical), start_line);
  }
  if (continuing) f(std::string_view(logical), start_line);
}

void split_ws(std::string_view line, std::vector<std::string_view>& toks) {
  toks.clear();
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    std::size_t j = i;
    while (j < line.size() && line[j] != ' ' && line[j] != '\t' && line[j] != '\r') ++j;
    if (j > i) toks.push_back(line.substr(i, j - i));
    i = j;
  }
}

}  // namespace

StrandSet obj_to_strands(const std::string& text, const std::string& where, LengthUnit unit) {
  if (text.empty()) fail_at(where, "file is empty");
  if (text.find('\0') != std::string::npos)
    fail_at(where, "file contains NUL bytes: not a text OBJ file");
  const double mpu = unit_to_metres(unit);
  std::vector<double> xyz, rgb;
  bool all_rgb = true;
  struct Poly {
    std::size_t line, begin, end;  // [begin, end) into `idx`
  };
  std::vector<Poly> polys;
  std::vector<long long> idx;  // 0-based vertex indices (positive ones checked at the end)
  std::size_t faces = 0;
  std::vector<std::string_view> toks;
  for_each_obj_line(text, [&](std::string_view line, std::size_t ln) {
    split_ws(line, toks);
    if (toks.empty()) return;
    if (toks[0] == "v") {
      if (toks.size() < 4)
        fail_at(at_line(where, ln), "vertex 'v' needs 3 coordinates, found {} (truncated line?)",
                toks.size() - 1);
      double d[6] = {0, 0, 0, 0, 0, 0};
      for (std::size_t k = 1; k < toks.size(); ++k) {
        double x;
        if (!parse_double(toks[k], x))
          fail_at(at_line(where, ln), "vertex 'v': '{}' is not a number", toks[k]);
        if (!std::isfinite(x))
          fail_at(at_line(where, ln), "vertex 'v': coordinate '{}' is not finite", toks[k]);
        if (k <= 6) d[k - 1] = x;
      }
      xyz.insert(xyz.end(), d, d + 3);
      if (toks.size() == 7)
        rgb.insert(rgb.end(), d + 3, d + 6);
      else
        all_rgb = false;
    } else if (toks[0] == "l") {
      if (toks.size() < 2)  // one index is a one-point strand (the writer keeps those)
        fail_at(at_line(where, ln), "polyline 'l' has no vertex indices");
      const long long nv = (long long)(xyz.size() / 3);
      Poly p{ln, idx.size(), 0};
      for (std::size_t k = 1; k < toks.size(); ++k) {
        const std::string_view part = toks[k].substr(0, toks[k].find('/'));
        long long i;
        if (!parse_int(part, i) || i == 0)
          fail_at(at_line(where, ln),
                  "polyline 'l' index '{}' is not a valid OBJ index (1-based, or negative for "
                  "relative)",
                  toks[k]);
        if (i < 0 && -i > nv)
          fail_at(at_line(where, ln),
                  "polyline 'l' index {} is out of range: only {} vertices are defined so far", i,
                  nv);
        idx.push_back(i < 0 ? nv + i : i - 1);
      }
      p.end = idx.size();
      polys.push_back(p);
    } else if (toks[0] == "f") {
      ++faces;
    }
  });
  const long long nv = (long long)(xyz.size() / 3);
  if (polys.empty())
    fail_at(where, "no polylines ('l' elements) found ({} vertices, {} faces): not a strand OBJ",
            nv, faces);
  for (const Poly& p : polys)
    for (std::size_t k = p.begin; k < p.end; ++k)
      if (idx[k] >= nv)
        fail_at(at_line(where, p.line),
                "polyline 'l' index {} is out of range: the file has {} vertices", idx[k] + 1, nv);
  if (idx.size() > std::numeric_limits<uint32_t>::max())
    fail_at(where, "{} polyline points do not fit a strand set", idx.size());
  StrandSet s;
  s.points.reserve(idx.size());
  for (const Poly& p : polys) {
    for (std::size_t k = p.begin; k < p.end; ++k) {
      const double* q = xyz.data() + 3 * idx[k];
      s.points.push_back(Vec3(q[0] * mpu, q[1] * mpu, q[2] * mpu).cast<float>());
      if (all_rgb) {
        const double* c = rgb.data() + 3 * idx[k];
        s.color.push_back(Vec3(c[0], c[1], c[2]).cast<float>());
      }
    }
    s.offsets.push_back(uint32_t(s.points.size()));
  }
  return s;
}

// ------------------------------------------------------------------------------------- USD
//
// A tolerant reader of the USD ASCII layer syntax (usda 1.0), hand-written because OpenUSD is
// not packaged in Debian. It tokenizes the whole grammar (comments #, //, /* */; strings '..',
// "..", triple-quoted; asset paths @..@ / @@@..@@@; prim paths <..>; nested dictionaries and
// metadata in parentheses, list ops) and keeps only what strands need: layer metersPerUnit and
// upAxis, the prim tree with specifier, type and `active`, BasisCurves geometry attributes and
// every prim's xformOps. Everything else is skipped by balanced brackets. No composition.

namespace {
namespace usd {

enum class Tk : uint8_t { End, Ident, Number, String, Punct, Path, Asset };

struct Tok {
  Tk kind = Tk::End;
  std::string_view text;  // source text (String: the raw body)
  std::string str;        // String: decoded
  std::size_t line = 0;
  bool is(char c) const { return kind == Tk::Punct && text.size() == 1 && text[0] == c; }
  bool ident(std::string_view s) const { return kind == Tk::Ident && text == s; }
};

std::string describe(const Tok& t) {
  switch (t.kind) {
    case Tk::End: return "the end of the file";
    case Tk::String: return fmt::format("the string \"{}\"", t.str.substr(0, 40));
    default: return fmt::format("'{}'", t.text.substr(0, 40));
  }
}

class Lexer {
 public:
  Lexer(std::string_view s, const std::string& where) : m_s(s), m_where(where) {}
  const Tok& peek() {
    if (!m_has) {
      m_tok = lex();
      m_has = true;
    }
    return m_tok;
  }
  Tok next() {
    peek();
    m_has = false;
    return std::move(m_tok);
  }
  template <class... A>
  [[noreturn]] void error(std::size_t line, fmt::format_string<A...> f, A&&... a) const {
    fail_at(at_line(m_where, line), f, std::forward<A>(a)...);
  }
  void expect(char c, const char* context) {
    const Tok t = next();
    if (!t.is(c)) error(t.line, "expected '{}' {}, found {}", c, context, describe(t));
  }

 private:
  Tok lex();
  std::string_view m_s;
  const std::string& m_where;
  std::size_t m_pos = 0, m_line = 1;
  Tok m_tok;
  bool m_has = false;
};

bool is_id0(char c) {
  return std::isalpha(static_cast<unsigned char>(c)) || c == '_';
}
bool is_id(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == ':' || c == '.';
}
bool is_digit(char c) {
  return c >= '0' && c <= '9';
}

Tok Lexer::lex() {
  const std::size_t n = m_s.size();
  for (;;) {  // whitespace and comments
    if (m_pos >= n) return Tok{Tk::End, {}, {}, m_line};
    const char c = m_s[m_pos];
    const char d = m_pos + 1 < n ? m_s[m_pos + 1] : '\0';
    if (c == '\n') {
      ++m_line;
      ++m_pos;
    } else if (c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v') {
      ++m_pos;
    } else if (c == '#' || (c == '/' && d == '/')) {
      while (m_pos < n && m_s[m_pos] != '\n') ++m_pos;
    } else if (c == '/' && d == '*') {
      const std::size_t e = m_s.find("*/", m_pos + 2);
      if (e == std::string_view::npos) error(m_line, "unterminated /* comment");
      m_line += std::size_t(std::count(m_s.begin() + m_pos, m_s.begin() + e, '\n'));
      m_pos = e + 2;
    } else {
      break;
    }
  }
  Tok t;
  t.line = m_line;
  const std::size_t b = m_pos;
  const char c = m_s[b];
  const char d = b + 1 < n ? m_s[b + 1] : '\0';
  if (c == '"' || c == '\'') {
    const bool triple = b + 2 < n && d == c && m_s[b + 2] == c;
    std::size_t p = b + (triple ? 3 : 1);
    for (;;) {
      if (p >= n) error(t.line, "unterminated string");
      const char ch = m_s[p];
      if (ch == '\\') {
        if (p + 1 >= n) error(t.line, "unterminated string");
        const char e = m_s[p + 1];
        t.str.push_back(e == 'n' ? '\n' : e == 't' ? '\t' : e == 'r' ? '\r' : e);
        if (e == '\n') ++m_line;
        p += 2;
        continue;
      }
      if (ch == c && (!triple || (p + 2 < n && m_s[p + 1] == c && m_s[p + 2] == c))) {
        p += triple ? 3 : 1;
        break;
      }
      if (ch == '\n') {
        if (!triple) error(t.line, "unterminated string (a line ends inside the quotes)");
        ++m_line;
      }
      t.str.push_back(ch);
      ++p;
    }
    t.kind = Tk::String;
    t.text = m_s.substr(b, p - b);
    m_pos = p;
    return t;
  }
  if (c == '@' || c == '<') {
    const bool triple = c == '@' && m_s.compare(b, 3, "@@@") == 0;
    const std::string_view close = triple ? "@@@" : (c == '@' ? "@" : ">");
    const std::size_t e = m_s.find(close, b + (triple ? 3 : 1));
    const std::size_t nl = m_s.find('\n', b);
    if (e == std::string_view::npos || (!triple && nl < e))
      error(t.line, "unterminated {} (expected a closing '{}')",
            c == '@' ? "asset path" : "prim path", close);
    t.kind = c == '@' ? Tk::Asset : Tk::Path;
    t.text = m_s.substr(b, e + close.size() - b);
    m_line += std::size_t(std::count(m_s.begin() + b, m_s.begin() + e, '\n'));
    m_pos = e + close.size();
    return t;
  }
  const bool sign = c == '-' || c == '+';
  if (is_digit(c) || ((sign || c == '.') && (is_digit(d) || d == '.')) ||
      (sign && (m_s.compare(b + 1, 3, "inf") == 0 || m_s.compare(b + 1, 3, "nan") == 0))) {
    std::size_t p = b + (sign ? 1 : 0);
    while (p < n) {
      const char ch = m_s[p];
      const bool exp_sign = (ch == '+' || ch == '-') && (m_s[p - 1] == 'e' || m_s[p - 1] == 'E');
      if (!(std::isalnum(static_cast<unsigned char>(ch)) || ch == '.' || exp_sign)) break;
      ++p;
    }
    t.kind = Tk::Number;
    t.text = m_s.substr(b, p - b);
    m_pos = p;
    return t;
  }
  if (is_id0(c)) {
    std::size_t p = b + 1;
    while (p < n && is_id(m_s[p])) ++p;
    t.kind = Tk::Ident;
    t.text = m_s.substr(b, p - b);
    m_pos = p;
    return t;
  }
  if (std::strchr("()[]{}=,;:&", c) && c != '\0') {
    t.kind = Tk::Punct;
    t.text = m_s.substr(b, 1);
    m_pos = b + 1;
    return t;
  }
  error(t.line, "unexpected character '{}' (byte 0x{:02x})", c,
        unsigned(static_cast<unsigned char>(c)));
}

// A value we keep: numbers (flattened tuples, `arity` numbers per element) or strings.
struct Value {
  std::vector<double> nums;
  std::size_t arity = 0;
  std::vector<std::string> strs;
  bool is_list = false, blocked = false;
  std::size_t count() const { return arity ? nums.size() / arity : strs.size(); }
};

struct Attr {
  std::string type;
  std::size_t line = 0;
  bool has_value = false, sampled = false;
  double sample_time = 0;
  Value val;
  std::string interpolation;
  double element_size = 1;
};

struct Prim {
  char spec = 'd';  // def, over, class
  std::string type, path;
  std::size_t line = 0;
  bool active = true;
  std::map<std::string, Attr, std::less<>> attrs;
  std::vector<Prim> children;
};

struct Layer {
  bool has_mpu = false;
  double mpu = 1.0;
  std::string up_axis;
  std::vector<Prim> roots;
};

class Notes {
 public:
  void add(std::string s) {
    if (std::find(m_v.begin(), m_v.end(), s) == m_v.end()) m_v.push_back(std::move(s));
  }
  std::vector<std::string> take() { return std::move(m_v); }

 private:
  std::vector<std::string> m_v;
};

bool is_curve_attr(std::string_view n) {
  return n == "points" || n == "curveVertexCounts" || n == "widths" || n == "type" ||
         n == "basis" || n == "wrap" || n.starts_with("primvars:widths") ||
         n.starts_with("primvars:displayColor");
}

class Parser {
 public:
  Parser(std::string_view text, const std::string& where, Notes& notes)
      : m_lex(text, where), m_notes(notes) {}

  Layer parse() {
    Layer layer;
    if (m_lex.peek().is('('))
      metadata([&](const Tok& key) {
        if (key.text == "metersPerUnit") {
          const double d = number();
          if (!(d > 0)) m_lex.error(key.line, "metersPerUnit must be > 0, got {}", d);
          layer.mpu = d;
          layer.has_mpu = true;
        } else if (key.text == "upAxis") {
          const Tok v = m_lex.next();
          layer.up_axis = v.kind == Tk::String ? v.str : std::string(v.text);
        } else {
          if (key.text == "subLayers") m_notes.add("subLayers are not read (no composition)");
          skip_value();
        }
      });
    for (;;) {
      const Tok& t = m_lex.peek();
      if (t.kind == Tk::End) break;
      if (t.ident("def") || t.ident("over") || t.ident("class")) {
        prim(layer.roots, "", 0);
      } else if (t.ident("reorder")) {
        reorder();
      } else {
        m_lex.error(t.line, "expected a prim ('def', 'over' or 'class'), found {}", describe(t));
      }
    }
    return layer;
  }

 private:
  static constexpr int kMaxDepth = 200;  // nesting of prims and tuples (no stack overflow)

  template <class F>
  void metadata(F&& on_key) {
    m_lex.expect('(', "to open metadata");
    for (;;) {
      const Tok& t = m_lex.peek();
      if (t.is(')')) {
        m_lex.next();
        return;
      }
      if (t.is(';') || t.is(',') || t.kind == Tk::String) {  // separators, doc strings
        m_lex.next();
        continue;
      }
      if (t.kind != Tk::Ident)
        m_lex.error(t.line, "expected a metadata name or ')', found {}", describe(t));
      Tok key = m_lex.next();
      if (is_list_op(key.text) && m_lex.peek().kind == Tk::Ident) key = m_lex.next();
      if (!m_lex.peek().is('=')) continue;
      m_lex.next();
      on_key(key);
    }
  }

  static bool is_list_op(std::string_view s) {
    return s == "prepend" || s == "append" || s == "delete" || s == "add" || s == "reorder";
  }

  void reorder() {
    m_lex.next();
    m_lex.next();  // nameChildren / properties / rootPrims
    m_lex.expect('=', "after 'reorder ...'");
    skip_value();
  }

  void skip_group(const Tok& open) {
    std::vector<char> closers{open.is('(') ? ')' : open.is('[') ? ']' : '}'};
    while (!closers.empty()) {
      const Tok t = m_lex.next();
      if (t.kind == Tk::End)
        m_lex.error(open.line, "'{}' is never closed (expected '{}' before the end of the file)",
                    open.text, closers.back());
      if (t.kind != Tk::Punct) continue;
      const char c = t.text[0];
      if (c == '(' || c == '[' || c == '{') {
        closers.push_back(c == '(' ? ')' : c == '[' ? ']' : '}');
      } else if (c == ')' || c == ']' || c == '}') {
        if (c != closers.back())
          m_lex.error(t.line, "mismatched '{}' (expected '{}')", c, closers.back());
        closers.pop_back();
      }
    }
  }

  void skip_value() {
    const Tok t = m_lex.next();
    if (t.is('(') || t.is('[') || t.is('{')) {
      skip_group(t);
      return;
    }
    if (t.kind == Tk::End || t.kind == Tk::Punct)
      m_lex.error(t.line, "expected a value, found {}", describe(t));
    if (t.kind == Tk::Asset) {  // reference: @layer@</prim> (layer offset)
      if (m_lex.peek().kind == Tk::Path) m_lex.next();
      if (m_lex.peek().is('(')) skip_group(m_lex.next());
    }
  }

  double number() {
    const Tok t = m_lex.next();
    if (t.ident("true") || t.ident("false")) return t.text == "true" ? 1.0 : 0.0;
    double d = 0;
    if ((t.kind != Tk::Number && t.kind != Tk::Ident) || !parse_double(t.text, d))
      m_lex.error(t.line, "expected a number, found {}", describe(t));
    if (!std::isfinite(d)) m_lex.error(t.line, "number '{}' is not finite (NaN/Inf)", t.text);
    return d;
  }

  void tuple(std::vector<double>& out, int depth) {
    const Tok open = m_lex.next();  // '('
    if (depth > 8) m_lex.error(open.line, "tuples nested deeper than 8 levels");
    for (;;) {
      const Tok& t = m_lex.peek();
      if (t.is(')')) {
        m_lex.next();
        return;
      }
      if (t.is('('))
        tuple(out, depth + 1);
      else
        out.push_back(number());
      const Tok& sep = m_lex.peek();
      if (sep.is(','))
        m_lex.next();
      else if (!sep.is(')'))
        m_lex.error(sep.line, "expected ',' or ')' in a tuple, found {}", describe(sep));
    }
  }

  void element(Value& v, std::size_t i) {
    const Tok& t = m_lex.peek();
    const std::size_t line = t.line;
    if (t.kind == Tk::String) {
      if (!v.nums.empty()) m_lex.error(line, "a list mixes numbers and strings");
      v.strs.push_back(m_lex.next().str);
      return;
    }
    const std::size_t before = v.nums.size();
    if (t.is('('))
      tuple(v.nums, 0);
    else
      v.nums.push_back(number());
    if (!v.strs.empty()) m_lex.error(line, "a list mixes numbers and strings");
    const std::size_t k = v.nums.size() - before;
    if (v.arity == 0) v.arity = k;
    if (k == 0 || k != v.arity)
      m_lex.error(line, "element {} has {} components, expected {} like the first", i, k, v.arity);
  }

  Value value() {
    Value v;
    if (m_lex.peek().ident("None")) {
      m_lex.next();
      v.blocked = true;
      return v;
    }
    if (!m_lex.peek().is('[')) {
      element(v, 0);
      return v;
    }
    m_lex.next();
    v.is_list = true;
    for (std::size_t i = 0;; ++i) {
      if (m_lex.peek().is(']')) break;
      element(v, i);
      const Tok& sep = m_lex.peek();
      if (sep.is(','))
        m_lex.next();
      else if (!sep.is(']'))
        m_lex.error(sep.line, "expected ',' or ']' in a list, found {}", describe(sep));
    }
    m_lex.next();
    return v;
  }

  void time_samples(Attr* a) {
    m_lex.expect('{', "to open timeSamples");
    for (;;) {
      const Tok& t = m_lex.peek();
      if (t.is('}')) {
        m_lex.next();
        return;
      }
      if (t.is(',')) {
        m_lex.next();
        continue;
      }
      const double time = number();
      m_lex.expect(':', "after the time of a time sample");
      if (a && (!a->has_value || (a->sampled && time < a->sample_time))) {
        a->val = value();  // the earliest sample, unless there is a default value
        a->has_value = a->sampled = true;
        a->sample_time = time;
      } else {
        skip_value();
      }
    }
  }

  void property(Prim& p) {
    Tok t = m_lex.next();
    while (t.ident("custom") || t.ident("uniform") || t.ident("varying") || t.ident("config") ||
           (t.kind == Tk::Ident && is_list_op(t.text)))
      t = m_lex.next();
    if (t.kind != Tk::Ident)
      m_lex.error(t.line, "expected a property, a prim or '}}', found {}", describe(t));
    if (t.text == "rel") {
      const Tok name = m_lex.next();
      if (name.kind != Tk::Ident)
        m_lex.error(name.line, "expected a relationship name, found {}", describe(name));
      if (m_lex.peek().is('=')) {
        m_lex.next();
        skip_value();
      }
      if (m_lex.peek().is('(')) skip_group(m_lex.next());
      return;
    }
    const Tok type = t;
    if (m_lex.peek().is('[')) {
      m_lex.next();
      m_lex.expect(']', "after '[' in an array type");
    }
    const Tok name = m_lex.next();
    if (name.kind != Tk::Ident)
      m_lex.error(name.line, "expected an attribute name after the type '{}', found {}", type.text,
                  describe(name));
    std::string_view base = name.text, suffix;
    if (const auto dot = base.rfind('.'); dot != std::string_view::npos) {
      suffix = base.substr(dot + 1);
      base = base.substr(0, dot);
    }
    const bool keep =
        base.starts_with("xformOp") || (p.type == "BasisCurves" && is_curve_attr(base));
    Attr* a = keep ? &p.attrs[std::string(base)] : nullptr;
    if (a) {
      a->type = std::string(type.text);
      if (!a->line) a->line = name.line;
    }
    if (m_lex.peek().is('=')) {
      m_lex.next();
      if (suffix == "timeSamples") {
        time_samples(a);
      } else if (a && suffix.empty()) {
        a->val = value();
        a->has_value = true;
        a->sampled = false;
        a->line = name.line;
      } else {
        skip_value();
      }
    }
    if (m_lex.peek().is('('))
      metadata([&](const Tok& key) {
        if (a && key.text == "interpolation") {
          const Tok v = m_lex.next();
          if (v.kind != Tk::String)
            m_lex.error(v.line, "interpolation must be a quoted token, found {}", describe(v));
          a->interpolation = v.str;
        } else if (a && key.text == "elementSize") {
          a->element_size = number();
        } else {
          skip_value();
        }
      });
  }

  void prim(std::vector<Prim>& out, const std::string& parent, int depth) {
    const Tok spec = m_lex.next();
    if (depth > kMaxDepth) m_lex.error(spec.line, "prims nested deeper than {} levels", kMaxDepth);
    Prim p;
    p.spec = spec.text[0];
    p.line = spec.line;
    if (m_lex.peek().kind == Tk::Ident) p.type = std::string(m_lex.next().text);
    const Tok name = m_lex.next();
    if (name.kind != Tk::String)
      m_lex.error(name.line, "expected the prim's name in quotes after '{}', found {}", spec.text,
                  describe(name));
    p.path = parent + "/" + name.str;
    if (m_lex.peek().is('('))
      metadata([&](const Tok& key) {
        if (key.text == "active") {
          p.active = number() != 0.0;
        } else {
          if (key.text == "references" || key.text == "payload" || key.text == "inherits" ||
              key.text == "specializes")
            m_notes.add(
                fmt::format("{} of <{}> are not followed (no composition)", key.text, p.path));
          skip_value();
        }
      });
    m_lex.expect('{', fmt::format("to open the body of <{}>", p.path).c_str());
    for (;;) {
      const Tok& t = m_lex.peek();
      if (t.is('}')) {
        m_lex.next();
        break;
      }
      if (t.kind == Tk::End)
        m_lex.error(p.line, "prim <{}> is never closed (expected '}}' before the end of the file)",
                    p.path);
      if (t.is(';')) {
        m_lex.next();
      } else if (t.ident("def") || t.ident("over") || t.ident("class")) {
        prim(p.children, p.path, depth + 1);
      } else if (t.ident("variantSet")) {
        m_lex.next();
        m_lex.next();  // its name
        m_lex.expect('=', "after 'variantSet \"name\"'");
        skip_value();
        m_notes.add(fmt::format("variant sets of <{}> are not read", p.path));
      } else if (t.ident("reorder")) {
        reorder();
      } else {
        property(p);
      }
    }
    out.push_back(std::move(p));
  }

  Lexer m_lex;
  Notes& m_notes;
};

// --- evaluation ------------------------------------------------------------------------

const Attr* get(const Prim& p, std::string_view name) {
  const auto it = p.attrs.find(name);
  if (it == p.attrs.end() || !it->second.has_value || it->second.val.blocked) return nullptr;
  return &it->second;
}

struct Xform {
  Mat4 m = Mat4::Identity();  // column-vector convention: p' = m * p
  bool identity = true, reset = false;
};

Mat4 rotation(int axis, double deg) {
  Mat4 m = Mat4::Identity();
  m.topLeftCorner<3, 3>() = Eigen::AngleAxisd(deg * kPi / 180.0, Vec3::Unit(axis)).matrix();
  return m;
}

// One xformOp. USD stores row-vector matrices (p' = p M, translation in the last row) and
// applies the ops of xformOpOrder so that the first one is outermost.
Mat4 op_matrix(const Attr& a, std::string_view type, std::string_view op, const Prim& p,
               const std::string& where) {
  const std::vector<double>& v = a.val.nums;
  auto need = [&](std::size_t n) {
    if (v.size() != n || !a.val.strs.empty())
      fail_at(at_line(where, a.line), "{} of <{}> needs {} numbers, found {}", op, p.path, n,
              v.size());
  };
  Mat4 m = Mat4::Identity();
  if (type == "translate") {
    need(3);
    m.block<3, 1>(0, 3) = Vec3(v[0], v[1], v[2]);
  } else if (type == "scale") {
    need(3);
    m.diagonal().head<3>() = Vec3(v[0], v[1], v[2]);
  } else if (type == "transform") {
    need(16);
    if (v[3] != 0 || v[7] != 0 || v[11] != 0 || v[15] != 1)
      fail_at(at_line(where, a.line),
              "{} of <{}> is projective (last column ({}, {}, {}, {}), expected (0, 0, 0, 1))", op,
              p.path, v[3], v[7], v[11], v[15]);
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) m(c, r) = v[std::size_t(4 * r + c)];  // transpose
  } else if (type == "rotateX" || type == "rotateY" || type == "rotateZ") {
    need(1);
    m = rotation(type[6] - 'X', v[0]);
  } else if (type.size() == 9 && type.starts_with("rotate") &&
             std::is_permutation(type.begin() + 6, type.end(), std::string_view("XYZ").begin())) {
    need(3);  // angles about X, Y, Z; the name gives the order, the first letter applied first
    for (int k = 6; k < 9; ++k) m = rotation(type[k] - 'X', v[std::size_t(type[k] - 'X')]) * m;
  } else if (type == "orient") {
    need(4);  // quaternion (real, i, j, k)
    const Eigen::Quaterniond q(v[0], v[1], v[2], v[3]);
    if (q.norm() == 0)
      fail_at(at_line(where, a.line), "{} of <{}> is a zero quaternion", op, p.path);
    m.topLeftCorner<3, 3>() = q.normalized().toRotationMatrix();
  } else {
    fail_at(at_line(where, a.line),
            "{} of <{}>: unsupported xformOp type '{}' (supported: translate, scale, rotateX/Y/Z, "
            "rotateXYZ and its permutations, orient, transform)",
            op, p.path, type);
  }
  return m;
}

Xform local_xform(const Prim& p, const std::string& where, Notes& notes) {
  Xform x;
  const Attr* order = get(p, "xformOpOrder");
  if (!order) {
    for (const auto& [name, a] : p.attrs)
      if (name.starts_with("xformOp:") && a.has_value)
        notes.add(fmt::format("xformOps of <{}> are ignored: it has no xformOpOrder", p.path));
    return x;
  }
  if (!order->val.nums.empty())
    fail_at(at_line(where, order->line), "xformOpOrder of <{}> must be a list of op names", p.path);
  for (std::size_t i = 0; i < order->val.strs.size(); ++i) {
    std::string_view op = order->val.strs[i];
    if (op == "!resetXformStack!") {
      if (i != 0)
        fail_at(at_line(where, order->line),
                "xformOpOrder of <{}>: !resetXformStack! must come first", p.path);
      x.reset = true;
      continue;
    }
    const bool invert = op.starts_with("!invert!");
    if (invert) op.remove_prefix(8);
    const Attr* a = get(p, op);
    if (!op.starts_with("xformOp:") || !a)
      fail_at(at_line(where, order->line),
              "xformOpOrder of <{}> names '{}' but the prim has no value for it", p.path, op);
    const std::string_view rest = op.substr(8);
    Mat4 m = op_matrix(*a, rest.substr(0, rest.find(':')), op, p, where);
    if (invert) {
      if (std::abs(m.determinant()) < 1e-300)
        fail_at(at_line(where, a->line), "!invert!{} of <{}> is singular", op, p.path);
      m = m.inverse().eval();
    }
    x.m = x.m * m;
    x.identity = false;
  }
  return x;
}

// Cubic basis weights (USD BasisCurves matrices): bezier (vstep 3), uniform B-spline and
// Catmull-Rom (vstep 1).
enum class Basis { linear, bezier, bspline, catmull_rom };

std::array<double, 4> weights(Basis b, double u) {
  const double u2 = u * u, u3 = u2 * u, w = 1 - u;
  switch (b) {
    case Basis::bezier: return {w * w * w, 3 * u * w * w, 3 * u2 * w, u3};
    case Basis::bspline:
      return {w * w * w / 6, (3 * u3 - 6 * u2 + 4) / 6, (-3 * u3 + 3 * u2 + 3 * u + 1) / 6, u3 / 6};
    case Basis::catmull_rom:
      return {(-u3 + 2 * u2 - u) / 2, (3 * u3 - 5 * u2 + 2) / 2, (-3 * u3 + 4 * u2 + u) / 2,
              (u3 - u2) / 2};
    case Basis::linear: break;
  }
  return {w, u, 0, 0};
}

enum class Interp { none, constant, uniform, varying, vertex };

// A primvar resolved to one value (dim numbers) per interpolation element, indices applied.
struct Primvar {
  Interp interp = Interp::none;
  std::size_t dim = 1;
  std::vector<double> v;
  const double* at(std::size_t i) const { return v.data() + dim * i; }
};

struct PrimOut {
  std::vector<Vec3f> points;
  std::vector<uint32_t> sizes;
  std::vector<float> radius;
  std::vector<Vec3f> color;
};

class Emitter {
 public:
  Emitter(const std::string& where, double mpu, uint32_t samples, Notes& notes)
      : m_where(where), m_mpu(mpu), m_samples(samples), m_notes(notes) {}

  void walk(const Prim& p, const Mat4& parent, bool parent_identity) {
    if (p.spec != 'd') {
      m_notes.add(fmt::format("'{}' prim <{}> is skipped with its children (not defined here)",
                              p.spec == 'o' ? "over" : "class", p.path));
      return;
    }
    if (!p.active) {
      m_notes.add(fmt::format("inactive prim <{}> is skipped with its children", p.path));
      return;
    }
    const Xform x = local_xform(p, m_where, m_notes);
    Mat4 world = parent;
    bool identity = parent_identity;
    if (x.reset) {
      world = x.m;
      identity = x.identity;
    } else if (!x.identity) {
      world = parent * x.m;
      identity = false;
    }
    if (p.type == "BasisCurves")
      curves(p, world, identity);
    else if (p.type == "NurbsCurves" || p.type == "HermiteCurves")
      m_notes.add(fmt::format("{} prim <{}> is not read (only BasisCurves)", p.type, p.path));
    for (const Prim& c : p.children) walk(c, world, identity);
  }

  std::vector<PrimOut>& outputs() { return m_out; }

 private:
  [[noreturn]] void fail_line(std::size_t line, const std::string& msg) const {
    fail_at(at_line(m_where, line), "{}", msg);
  }

  std::string token(const Prim& p, const char* name, const char* fallback) const {
    const Attr* a = get(p, name);
    if (!a) return fallback;
    if (a->val.strs.size() != 1 || a->val.is_list)
      fail_line(a->line, fmt::format("'{}' of <{}> must be one token", name, p.path));
    return a->val.strs[0];
  }

  // counts: constant 1, uniform = curves, varying, vertex = authored points.
  Primvar primvar(const Prim& p, const std::string& name, std::size_t dim, std::size_t curves,
                  std::size_t varying, std::size_t vertex) const {
    Primvar pv;
    pv.dim = dim;
    const Attr* a = get(p, name);
    if (!a) return pv;
    const Value& val = a->val;
    const std::size_t n = val.count();
    if (!val.strs.empty() || (n > 0 && val.arity != dim))
      fail_line(a->line,
                fmt::format("'{}' of <{}> must hold {}-component numbers", name, p.path, dim));
    if (a->element_size != 1)
      fail_line(a->line, fmt::format("'{}' of <{}>: elementSize {} is not supported (expected 1)",
                                     name, p.path, a->element_size));
    std::vector<std::size_t> index;
    std::size_t count = n;
    if (const Attr* ai = get(p, name + ":indices")) {
      const Value& iv = ai->val;
      if (!iv.strs.empty() || (iv.count() > 0 && iv.arity != 1))
        fail_line(ai->line, fmt::format("'{}:indices' of <{}> must be integers", name, p.path));
      for (std::size_t i = 0; i < iv.nums.size(); ++i) {
        const double k = iv.nums[i];
        if (k != std::floor(k) || k < 0 || k >= double(n))
          fail_line(ai->line, fmt::format("'{}:indices'[{}] = {} of <{}> is not an index into "
                                          "its {} values",
                                          name, i, k, p.path, n));
        index.push_back(std::size_t(k));
      }
      count = index.size();
    }
    const std::string& s = a->interpolation;
    if (s.empty()) {  // infer from the count (widths default to vertex, others to constant)
      pv.interp = count == vertex    ? Interp::vertex
                  : count == 1       ? Interp::constant
                  : count == curves  ? Interp::uniform
                  : count == varying ? Interp::varying
                                     : Interp::none;
      if (pv.interp == Interp::none)
        fail_line(a->line, fmt::format("'{}' of <{}> has {} values: expected 1 (constant), {} "
                                       "(uniform), {} (varying) or {} (vertex)",
                                       name, p.path, count, curves, varying, vertex));
    } else {
      std::size_t expect = 0;
      if (s == "constant") {
        pv.interp = Interp::constant;
        expect = 1;
      } else if (s == "uniform") {
        pv.interp = Interp::uniform;
        expect = curves;
      } else if (s == "varying" || s == "faceVarying") {
        pv.interp = Interp::varying;
        expect = varying;
      } else if (s == "vertex") {
        pv.interp = Interp::vertex;
        expect = vertex;
      } else {
        fail_line(a->line,
                  fmt::format("'{}' of <{}>: unknown interpolation \"{}\"", name, p.path, s));
      }
      if (count != expect)
        fail_line(a->line, fmt::format("'{}' of <{}> has {} values but interpolation \"{}\" needs "
                                       "{}",
                                       name, p.path, count, s, expect));
    }
    if (index.empty()) {
      pv.v = val.nums;
    } else {
      pv.v.reserve(index.size() * dim);
      for (std::size_t i : index)
        pv.v.insert(pv.v.end(), val.nums.begin() + std::ptrdiff_t(i * dim),
                    val.nums.begin() + std::ptrdiff_t((i + 1) * dim));
    }
    return pv;
  }

  void curves(const Prim& p, const Mat4& world, bool identity) {
    const Attr* pa = get(p, "points");
    if (!pa) fail_line(p.line, fmt::format("BasisCurves <{}> has no 'points'", p.path));
    const Attr* ca = get(p, "curveVertexCounts");
    if (!ca) fail_line(p.line, fmt::format("BasisCurves <{}> has no 'curveVertexCounts'", p.path));
    if (!pa->val.strs.empty() || (pa->val.count() > 0 && pa->val.arity != 3))
      fail_line(pa->line, fmt::format("'points' of <{}> must be 3-component points", p.path));
    if (!ca->val.strs.empty() || (ca->val.count() > 0 && ca->val.arity != 1))
      fail_line(ca->line, fmt::format("'curveVertexCounts' of <{}> must be integers", p.path));
    const std::vector<double>& P = pa->val.nums;
    const std::size_t npts = P.size() / 3;
    const std::vector<double>& C = ca->val.nums;
    uint64_t sum = 0;
    for (std::size_t c = 0; c < C.size(); ++c) {
      if (C[c] != std::floor(C[c]) || C[c] < 1 || C[c] > 4294967295.0)
        fail_line(ca->line, fmt::format("curveVertexCounts[{}] = {} of <{}> is not a positive "
                                        "integer",
                                        c, C[c], p.path));
      sum += uint64_t(C[c]);
    }
    if (sum != npts)
      fail_line(ca->line, fmt::format("curveVertexCounts of <{}> sum to {} but 'points' (line {}) "
                                      "holds {} points",
                                      p.path, sum, pa->line, npts));
    // Topology.
    const std::string type = token(p, "type", "cubic"), wrap = token(p, "wrap", "nonperiodic");
    const std::string bname = token(p, "basis", "bezier");
    const std::size_t tline = get(p, "type") ? get(p, "type")->line : p.line;
    Basis basis = Basis::linear;
    if (type == "cubic") {
      if (bname == "bezier")
        basis = Basis::bezier;
      else if (bname == "bspline")
        basis = Basis::bspline;
      else if (bname == "catmullRom")
        basis = Basis::catmull_rom;
      else
        fail_line(get(p, "basis") ? get(p, "basis")->line : tline,
                  fmt::format("basis \"{}\" of <{}> is not supported (expected bezier, bspline or "
                              "catmullRom)",
                              bname, p.path));
    } else if (type != "linear") {
      fail_line(tline,
                fmt::format("type \"{}\" of <{}>: expected \"linear\" or \"cubic\"", type, p.path));
    }
    const std::size_t wline = get(p, "wrap") ? get(p, "wrap")->line : p.line;
    if (wrap == "periodic")
      fail_line(wline, fmt::format("wrap \"periodic\" (closed curves) of <{}> is not supported: "
                                   "hair strands are open; use nonperiodic or pinned",
                                   p.path));
    if (wrap != "nonperiodic" && wrap != "pinned")
      fail_line(wline,
                fmt::format("wrap \"{}\" of <{}>: expected nonperiodic or pinned", wrap, p.path));
    const bool pinned = wrap == "pinned";
    // Pinned curves get phantom end points, as Hydra expands them (HdsiPinnedCurveExpanding-
    // SceneIndex): a B-spline repeats each end point twice, a Catmull-Rom once, a Bezier never.
    const uint32_t rep = pinned ? (basis == Basis::bspline       ? 2u
                                   : basis == Basis::catmull_rom ? 1u
                                                                 : 0u)
                                : 0u;
    const uint32_t vstep = basis == Basis::bezier ? 3 : 1;
    const uint32_t N = m_samples;
    struct Topo {
      uint32_t n, spans, varying;
    };
    std::vector<Topo> topo(C.size());
    uint64_t total_out = 0, total_varying = 0;
    for (std::size_t c = 0; c < C.size(); ++c) {
      const uint32_t n = uint32_t(C[c]);
      Topo& t = topo[c];
      t.n = n;
      if (basis == Basis::linear) {
        t.spans = n - 1;
        t.varying = n;
        total_out += n;
      } else {
        const uint64_t m = uint64_t(n) + 2 * rep;
        const uint32_t min_n = rep > 0 ? 2 : 4;
        if (n < min_n || (basis == Basis::bezier && (m - 4) % 3 != 0))
          fail_line(ca->line,
                    fmt::format("curve {} of <{}> has {} vertices; a {} cubic {} curve needs {}", c,
                                p.path, n, wrap, bname,
                                basis == Basis::bezier ? "4, 7, 10, ... (3 per span + 1)"
                                                       : fmt::format("at least {}", min_n)));
        t.spans = uint32_t((m - 4) / vstep + 1);
        // Authored varying values: spans + 1 of the curve without phantom points (2 at least).
        t.varying = rep > 0 ? (n >= 4 ? (n - 4) / vstep + 2 : 2) : t.spans + 1;
        total_out += uint64_t(t.spans) * N + 1;
      }
      total_varying += t.varying;
    }
    if (total_out > std::numeric_limits<uint32_t>::max())
      fail_line(ca->line, fmt::format("<{}> evaluates to {} points, more than a strand set holds",
                                      p.path, total_out));
    const std::string wname = get(p, "primvars:widths") ? "primvars:widths" : "widths";
    const Primvar W = primvar(p, wname, 1, C.size(), total_varying, npts);
    const Primvar K = primvar(p, "primvars:displayColor", 3, C.size(), total_varying, npts);
    const double rscale =
        identity ? 1.0 : std::cbrt(std::abs(world.topLeftCorner<3, 3>().determinant()));

    PrimOut out;
    out.points.reserve(std::size_t(total_out));
    out.sizes.reserve(C.size());
    std::size_t o = 0, vo = 0;  // authored vertex and varying offsets of the curve
    std::array<double, 4> w{};
    auto emit = [&](std::size_t c, const Topo& t, auto&& ctrl, std::size_t span, double u) {
      Vec3 q = Vec3::Zero();
      double r = 0;
      Vec3 col = Vec3::Zero();
      const std::size_t base = span * vstep;
      if (basis == Basis::linear) {  // exact: no arithmetic on the coordinates
        const std::size_t i = ctrl(base);
        q = Vec3(P[3 * i], P[3 * i + 1], P[3 * i + 2]);
        if (W.interp == Interp::vertex) r = *W.at(i);
        if (K.interp == Interp::vertex) col = Eigen::Map<const Vec3>(K.at(i));
      } else {
        for (std::size_t j = 0; j < 4; ++j) {
          if (w[j] == 0) continue;
          const std::size_t i = ctrl(base + j);
          q += w[j] * Vec3(P[3 * i], P[3 * i + 1], P[3 * i + 2]);
          if (W.interp == Interp::vertex) r += w[j] * *W.at(i);
          if (K.interp == Interp::vertex) col += w[j] * Eigen::Map<const Vec3>(K.at(i));
        }
      }
      // Varying: linear between span ends (phantom ends repeat the first / last value).
      const std::size_t pad = t.spans + 1 - t.varying, front = (pad + 1) / 2;
      auto vary = [&](std::size_t s) {
        return vo + std::min<std::size_t>(s >= front ? s - front : 0, t.varying - 1);
      };
      const std::size_t va = vary(span), vb = vary(std::min<std::size_t>(span + 1, t.spans));
      auto pick = [&](const Primvar& pv, std::size_t d, auto set) {
        switch (pv.interp) {
          case Interp::constant: set(pv.at(0)); break;
          case Interp::uniform: set(pv.at(c)); break;
          case Interp::varying: {
            std::array<double, 3> m{};
            for (std::size_t e = 0; e < d; ++e) m[e] = (1 - u) * pv.at(va)[e] + u * pv.at(vb)[e];
            set(m.data());
            break;
          }
          default: break;
        }
      };
      pick(W, 1, [&](const double* x) { r = x[0]; });
      pick(K, 3, [&](const double* x) { col = Vec3(x[0], x[1], x[2]); });
      if (!identity) q = (world * q.homogeneous()).head<3>();
      out.points.push_back((q * m_mpu).cast<float>());
      if (W.interp != Interp::none)
        out.radius.push_back(float(std::max(0.0, 0.5 * r * rscale * m_mpu)));
      if (K.interp != Interp::none) out.color.push_back(col.cast<float>());
    };
    for (std::size_t c = 0; c < C.size(); ++c) {
      const Topo& t = topo[c];
      if (basis == Basis::linear) {
        auto ctrl = [&](std::size_t j) { return o + j; };
        for (std::size_t i = 0; i < t.n; ++i)
          emit(c, t, ctrl, std::min<std::size_t>(i, t.spans), 0);
        out.sizes.push_back(t.n);
      } else {
        auto ctrl = [&](std::size_t j) {
          return o + std::min<std::size_t>(j > rep ? j - rep : 0, t.n - 1);
        };
        for (std::size_t s = 0; s < t.spans; ++s)
          for (uint32_t k = 0; k < N; ++k) {
            const double u = double(k) / double(N);
            w = weights(basis, u);
            emit(c, t, ctrl, s, u);
          }
        w = weights(basis, 1.0);
        emit(c, t, ctrl, t.spans - 1, 1.0);
        out.sizes.push_back(t.spans * N + 1);
      }
      o += t.n;
      vo += t.varying;
    }
    if (basis != Basis::linear)
      m_notes.add(
          fmt::format("{} cubic {} curves ({}) of <{}> evaluated as polylines, {} points "
                      "per span",
                      C.size(), bname, wrap, p.path, N));
    if (!identity)
      m_notes.add(
          fmt::format("the transform of <{}> (its xformOps and its ancestors') was "
                      "applied",
                      p.path));
    m_out.push_back(std::move(out));
  }

  const std::string& m_where;
  double m_mpu;
  uint32_t m_samples;
  Notes& m_notes;
  std::vector<PrimOut> m_out;
};

}  // namespace usd
}  // namespace

StrandSet usda_to_strands(const std::string& text, const std::string& where, LengthUnit unit,
                          StrandFileInfo* info, const UsdReadOptions& opt) {
  if (opt.cubic_samples_per_span < 1 || opt.cubic_samples_per_span > 1024)
    fail("cubic samples per span must be in [1, 1024], got {}", opt.cubic_samples_per_span);
  if (text.rfind("PXR-USDC", 0) == 0)
    fail_at(where,
            "binary USD (usdc) is not supported (OpenUSD is not available): save the layer as "
            "ASCII .usda");
  if (text.rfind("#usda", 0) != 0)
    fail_at(where, "not a USD ASCII layer: expected '#usda 1.0' on the first line");
  if (text.find('\0') != std::string::npos) fail_at(where, "file contains NUL bytes");
  usd::Notes notes;
  usd::Parser parser(text, where, notes);
  const usd::Layer layer = parser.parse();
  const double mpu = layer.has_mpu ? layer.mpu : unit_to_metres(unit);
  if (!layer.up_axis.empty() && layer.up_axis != "Y")
    notes.add(fmt::format("upAxis is {}: coordinates are kept as written (no axis change)",
                          layer.up_axis));
  usd::Emitter emitter(where, mpu, opt.cubic_samples_per_span, notes);
  for (const usd::Prim& p : layer.roots) emitter.walk(p, Mat4::Identity(), true);
  std::vector<usd::PrimOut>& outs = emitter.outputs();
  if (outs.empty())
    fail_at(where,
            "no BasisCurves prim found (expected 'def BasisCurves \"Name\" {{ int[] "
            "curveVertexCounts = [...] point3f[] points = [...] }}')");
  // Radius / colour only when every prim has them (a strand set keeps all or none).
  bool all_r = true, all_c = true, any_r = false, any_c = false;
  uint64_t total = 0;
  for (const auto& o : outs) {
    all_r &= !o.radius.empty() || o.points.empty();
    all_c &= !o.color.empty() || o.points.empty();
    any_r |= !o.radius.empty();
    any_c |= !o.color.empty();
    total += o.points.size();
  }
  if (total > std::numeric_limits<uint32_t>::max())
    fail_at(where, "{} points in total do not fit a strand set", total);
  if (any_r && !all_r) notes.add("widths are dropped: not every BasisCurves prim has them");
  if (any_c && !all_c) notes.add("displayColor is dropped: not every BasisCurves prim has it");
  StrandSet s;
  s.points.reserve(std::size_t(total));
  for (auto& o : outs) {
    for (uint32_t n : o.sizes) s.offsets.push_back(s.offsets.back() + n);
    s.points.insert(s.points.end(), o.points.begin(), o.points.end());
    if (all_r && any_r) s.radius.insert(s.radius.end(), o.radius.begin(), o.radius.end());
    if (all_c && any_c) s.color.insert(s.color.end(), o.color.begin(), o.color.end());
    o = {};
  }
  if (info) {
    info->format = "usda";
    info->metres_per_unit = mpu;
    info->unit_from_file = layer.has_mpu;
    info->notes = notes.take();
  }
  return s;
}

// ----------------------------------------------------------------------------- files, writers

StrandSet load_strands(const std::filesystem::path& path, LengthUnit unit, StrandFileInfo* info) {
  const std::string ext = lower_ext(path);
  const std::string where = path.string();
  StrandFileInfo fi;
  fi.metres_per_unit = unit_to_metres(unit);
  StrandSet s;
  if (ext == ".hair") {
    fi.format = "hair";
    s = cyhair_to_strands(parse_cyhair(read_file(path), where), unit);
  } else if (ext == ".tfx") {
    fi.format = "tfx";
    s = tfx_to_strands(parse_tfx(read_file(path), where), unit);
  } else if (ext == ".usda" || ext == ".usd") {
    s = usda_to_strands(read_file(path), where, unit, &fi);
  } else if (ext == ".obj") {
    fi.format = "obj";
    s = obj_to_strands(read_file(path), where, unit);
  } else {
    fail_at(where, "unknown hair file extension \"{}\" (readable: .hair, .tfx, .usda, .usd, .obj)",
            ext);
  }
  if (s.num_strands() == 0) fail_at(where, "the file holds no strands (expected at least one)");
  s.check(where);
  if (info) *info = std::move(fi);
  return s;
}

void save_strands(const StrandSet& s, const std::filesystem::path& path, LengthUnit unit,
                  uint32_t tfx_verts) {
  const std::string ext = lower_ext(path);
  const std::string where = path.string();
  if (ext != ".hair" && ext != ".tfx" && ext != ".usda" && ext != ".obj")
    fail_at(where, "unknown hair file extension \"{}\" (writable: .hair, .tfx, .usda, .obj)", ext);
  if (s.num_strands() == 0) fail_at(where, "nothing to write: the strand set is empty");
  s.check(where);
  std::string bytes;
  if (ext == ".hair")
    bytes = serialize_cyhair(strands_to_cyhair(s, unit));
  else if (ext == ".tfx")
    bytes = serialize_tfx(strands_to_tfx(s, unit, tfx_verts));
  else if (ext == ".usda")
    bytes = strands_to_usda(s, unit);
  else
    bytes = strands_to_obj(s, unit);
  write_file_atomically(path, bytes);
}

bool is_strand_extension(const std::filesystem::path& path) {
  const std::string e = lower_ext(path);
  return e == ".hair" || e == ".tfx" || e == ".usda" || e == ".obj";
}

bool is_strand_file(const std::filesystem::path& path) {
  const std::string e = lower_ext(path);
  if (e == ".hair" || e == ".tfx" || e == ".usda" || e == ".usd") return true;
  if (e != ".obj") return false;
  // Only the first word of each logical line matters, and a mesh is known at its first `f`: a
  // scan that stops there (assembling and splitting every line of the file took a fifth of
  // loading a 1M-triangle mesh). Words are split as split_ws does.
  const std::string text = read_file(path);
  bool any_l = false, continuing = false;
  std::size_t pos = 0;
  while (pos < text.size()) {
    std::size_t eol = text.find('\n', pos);
    if (eol == std::string::npos) eol = text.size();
    std::string_view line(text.data() + pos, eol - pos);
    pos = eol + 1;
    if (auto hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ' || line.back() == '\t'))
      line.remove_suffix(1);
    const bool starts_logical = !continuing;
    continuing = !line.empty() && line.back() == '\\';
    if (!starts_logical) continue;
    const std::size_t b = line.find_first_not_of(" \t\r");
    if (b == std::string_view::npos) continue;
    const std::size_t e1 = line.find_first_of(" \t\r\\", b);
    const std::string_view word = line.substr(b, e1 == std::string_view::npos ? e1 : e1 - b);
    if (word == "f") return false;
    any_l |= word == "l";
  }
  return any_l;
}

std::string strands_to_usda(const StrandSet& s, LengthUnit unit) {
  const double k = 1.0 / unit_to_metres(unit);
  std::string o;
  auto out = std::back_inserter(o);
  fmt::format_to(out,
                 "#usda 1.0\n(\n    defaultPrim = \"Hair\"\n    metersPerUnit = {}\n    upAxis = "
                 "\"Y\"\n)\n\n",
                 unit_to_metres(unit));
  o += "def BasisCurves \"Hair\"\n{\n    uniform token type = \"linear\"\n    uniform token wrap = "
       "\"nonperiodic\"\n";
  o += "    int[] curveVertexCounts = [";
  for (std::size_t h = 0; h < s.num_strands(); ++h)
    fmt::format_to(out, "{}{}", h ? ", " : "", s.strand_size(h));
  o += "]\n    point3f[] points = [";
  for (std::size_t i = 0; i < s.num_points(); ++i)
    fmt::format_to(out, "{}({:.9g}, {:.9g}, {:.9g})", i ? ", " : "", s.points[i].x() * k,
                   s.points[i].y() * k, s.points[i].z() * k);
  o += "]\n    float[] widths = [";
  const bool has_r = s.radius.size() == s.num_points() && !s.radius.empty();
  if (has_r) {
    for (std::size_t i = 0; i < s.num_points(); ++i)
      fmt::format_to(out, "{}{:.9g}", i ? ", " : "", 2 * double(s.radius[i]) * k);
    o += "] (\n        interpolation = \"vertex\"\n    )\n";
  } else {
    fmt::format_to(out, "{:.9g}] (\n        interpolation = \"constant\"\n    )\n", 80e-6 * k);
  }
  if (s.color.size() == s.num_points() && !s.color.empty()) {
    o += "    color3f[] primvars:displayColor = [";
    for (std::size_t i = 0; i < s.num_points(); ++i)
      fmt::format_to(out, "{}({:.9g}, {:.9g}, {:.9g})", i ? ", " : "", s.color[i].x(),
                     s.color[i].y(), s.color[i].z());
    o += "] (\n        interpolation = \"vertex\"\n    )\n";
  }
  o += "}\n";
  return o;
}

std::string strands_to_obj(const StrandSet& s, LengthUnit unit) {
  const double k = 1.0 / unit_to_metres(unit);
  const bool rgb = s.color.size() == s.num_points() && !s.color.empty();
  std::string o;
  auto out = std::back_inserter(o);
  fmt::format_to(out, "# Follicle hair strands: {} polylines, {} points, units {}{}\n",
                 s.num_strands(), s.num_points(), to_string(unit),
                 rgb ? ", vertex colours as v x y z r g b" : "");
  for (std::size_t i = 0; i < s.num_points(); ++i) {
    const Vec3f& p = s.points[i];
    fmt::format_to(out, "v {:.9g} {:.9g} {:.9g}", p.x() * k, p.y() * k, p.z() * k);
    if (rgb)
      fmt::format_to(out, " {:.9g} {:.9g} {:.9g}", s.color[i].x(), s.color[i].y(), s.color[i].z());
    o += '\n';
  }
  for (std::size_t h = 0; h < s.num_strands(); ++h) {
    o += 'l';
    for (uint32_t i = s.offsets[h]; i < s.offsets[h + 1]; ++i) fmt::format_to(out, " {}", i + 1);
    o += '\n';
  }
  return o;
}

}  // namespace follicle::geom
