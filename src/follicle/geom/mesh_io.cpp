// Mesh readers/writers.
//  - OBJ: parsed by tinyobjloader (double build). tinyobjloader silently turns unparsable numbers
//    into 0 and reports no line numbers, so a light validation pass runs first and rejects NaN/Inf,
//    short vertex lines and out-of-range indices with file:line. OBJ writing is hand-written
//    because tinyobjloader has no writer (the format is a few printf lines).
//  - PLY: hand-written reader/writer (ASCII, binary little and big endian). Debian has no
//    maintained C++ PLY library (happly/tinyply are not packaged), and the subset we need
//    (vertex x/y/z, normals, per-vertex UVs, face index lists) is small.
//  - glTF 2.0 (.gltf/.glb): tinygltf. Accessors are bounds-checked here before reading.
#include "follicle/geom/mesh_io.hpp"

#include <tiny_gltf.h>
#include <tiny_obj_loader.h>

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <functional>
#include <map>
#include <set>
#include <sstream>
#include <type_traits>

#include "follicle/core/atomic_file.hpp"
#include "follicle/core/error.hpp"

namespace follicle::geom {

namespace {

namespace fs = std::filesystem;

std::string lower_ext(const fs::path& p) {
  std::string e = p.extension().string();
  std::transform(e.begin(), e.end(), e.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  return e;
}

std::string at_line(const fs::path& p, std::size_t line) {
  return fmt::format("{}:{}", p.string(), line);
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

void check_text(const fs::path& path, const std::string& text) {
  if (text.empty()) fail_at(path.string(), "file is empty");
  if (text.find('\0') != std::string::npos)
    fail_at(path.string(), "file contains NUL bytes: not a text file");
}

// ------------------------------------------------------------------------------------- OBJ

// Validation pass: finite coordinates, enough components, indices in range; with line numbers.
// Returns the largest number of vertices of a face.
std::size_t validate_obj(const fs::path& path, const std::string& text) {
  check_text(path, text);
  struct Deferred {
    std::size_t line;
    long long v, vt, vn;
  };
  std::vector<Deferred> deferred;  // positive indices may (rarely) refer forward
  long long nv = 0, nvt = 0, nvn = 0, nf = 0;
  std::size_t max_arity = 0;
  std::vector<std::string_view> toks;
  std::size_t line_no = 0, pos = 0;
  const std::string_view all(text);
  while (pos < all.size()) {
    std::size_t eol = all.find('\n', pos);
    if (eol == std::string_view::npos) eol = all.size();
    std::string_view line = all.substr(pos, eol - pos);
    pos = eol + 1;
    ++line_no;
    if (auto hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
    split_ws(line, toks);
    if (toks.empty()) continue;
    const std::string_view kw = toks[0];
    auto numbers = [&](std::size_t min_count, const char* what) {
      if (toks.size() < 1 + min_count)
        fail_at(at_line(path, line_no), "{} needs {} numbers, found {} (truncated line?)", what,
                min_count, toks.size() - 1);
      for (std::size_t k = 1; k < toks.size(); ++k) {
        double d;
        if (!parse_double(toks[k], d))
          fail_at(at_line(path, line_no), "{}: '{}' is not a number", what, toks[k]);
        if (!std::isfinite(d))
          fail_at(at_line(path, line_no), "{}: coordinate '{}' is not finite", what, toks[k]);
      }
    };
    if (kw == "v") {
      numbers(3, "vertex 'v'");
      ++nv;
    } else if (kw == "vt") {
      numbers(1, "texture coordinate 'vt'");
      ++nvt;
    } else if (kw == "vn") {
      numbers(3, "normal 'vn'");
      ++nvn;
    } else if (kw == "f") {
      if (toks.size() < 4)
        fail_at(at_line(path, line_no), "face needs at least 3 vertices, found {}",
                toks.size() - 1);
      max_arity = std::max(max_arity, toks.size() - 1);
      Deferred d{line_no, 0, 0, 0};
      for (std::size_t k = 1; k < toks.size(); ++k) {
        std::string_view t = toks[k];
        long long idx[3] = {0, 0, 0};
        long long counts[3] = {nv, nvt, nvn};
        const char* names[3] = {"vertex", "texture coordinate", "normal"};
        for (int c = 0; c < 3 && !t.empty(); ++c) {
          std::size_t slash = t.find('/');
          std::string_view part = t.substr(0, slash);
          if (!part.empty()) {
            if (!parse_int(part, idx[c]) || idx[c] == 0)
              fail_at(at_line(path, line_no), "face {} index '{}' is not a valid OBJ index",
                      names[c], part);
            if (idx[c] < 0 && -idx[c] > counts[c])
              fail_at(at_line(path, line_no),
                      "face {} index {} is out of range: only {} defined so far", names[c], idx[c],
                      counts[c]);
          }
          if (slash == std::string_view::npos) break;
          t = t.substr(slash + 1);
        }
        if (idx[0] == 0)
          fail_at(at_line(path, line_no), "face corner '{}' has no vertex index", toks[k]);
        d.v = std::max(d.v, idx[0]);
        d.vt = std::max(d.vt, idx[1]);
        d.vn = std::max(d.vn, idx[2]);
      }
      deferred.push_back(d);
      ++nf;
    }
  }
  for (const Deferred& d : deferred) {
    if (d.v > nv)
      fail_at(at_line(path, d.line), "face vertex index {} is out of range: the file has {}", d.v,
              nv);
    if (d.vt > nvt)
      fail_at(at_line(path, d.line),
              "face texture coordinate index {} is out of range: the file has {}", d.vt, nvt);
    if (d.vn > nvn)
      fail_at(at_line(path, d.line), "face normal index {} is out of range: the file has {}", d.vn,
              nvn);
  }
  if (nf == 0) fail_at(path.string(), "no faces found ({} vertices): not a triangle mesh OBJ", nv);
  return max_arity;
}

// tinyobjloader's ear clipping (right for concave quads and n-gons) takes time growing faster than
// the square of a face's size (one face of 100k vertices: 8.7 s), and it cannot hold a face of
// more than 255 vertices untriangulated. Faces above kMaxEarClippedFace vertices (scanner caps,
// hole fills) are rewritten as triangle fans before it sees them, in linear time; relative
// (negative) indices keep their meaning because no vertex line moves.
constexpr std::size_t kMaxEarClippedFace = 64;

std::string fan_large_faces(const std::string& text) {
  std::string out;
  out.reserve(text.size() + text.size() / 2);
  std::vector<std::string_view> toks;
  std::size_t pos = 0;
  const std::string_view all(text);
  while (pos < all.size()) {
    std::size_t eol = all.find('\n', pos);
    if (eol == std::string_view::npos) eol = all.size();
    const std::string_view raw = all.substr(pos, eol - pos);
    pos = eol + 1;
    std::string_view line = raw;
    if (auto hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
    split_ws(line, toks);
    if (toks.size() > kMaxEarClippedFace + 1 && toks[0] == "f") {
      for (std::size_t k = 2; k + 1 < toks.size(); ++k) {
        out += "f ";
        out += toks[1];
        out += ' ';
        out += toks[k];
        out += ' ';
        out += toks[k + 1];
        out += '\n';
      }
    } else {
      out += raw;
      out += '\n';
    }
  }
  return out;
}

TriMesh load_obj(const fs::path& path) {
  std::string text = read_file(path);
  const std::size_t max_arity = validate_obj(path, text);
  tinyobj::ObjReaderConfig cfg;
  cfg.triangulate = true;
  cfg.vertex_color = false;
  if (max_arity > kMaxEarClippedFace) text = fan_large_faces(text);
  tinyobj::ObjReader reader;
  if (!reader.ParseFromString(text, std::string(), cfg))
    fail_at(path.string(), "tinyobjloader failed: {}", reader.Error());
  const auto& attrib = reader.GetAttrib();
  TriMesh m;
  m.name = path.stem().string();
  m.positions.resize(attrib.vertices.size() / 3);
  for (std::size_t i = 0; i < m.positions.size(); ++i)
    m.positions[i] =
        Vec3(attrib.vertices[3 * i], attrib.vertices[3 * i + 1], attrib.vertices[3 * i + 2]);
  m.uvs.resize(attrib.texcoords.size() / 2);
  for (std::size_t i = 0; i < m.uvs.size(); ++i)
    m.uvs[i] = Vec2(attrib.texcoords[2 * i], attrib.texcoords[2 * i + 1]);
  bool any_missing_uv = false;
  // `vn` normals are per corner; TriMesh keeps one per position vertex: the normalised sum of
  // the normals its corners use (the file's normal where a vertex has one, a smooth blend across
  // a hard edge). Kept only when every corner names a normal.
  const std::size_t nn = attrib.normals.size() / 3;
  std::vector<Vec3> normal_sum(nn > 0 ? m.positions.size() : 0, Vec3::Zero());
  bool all_normals = nn > 0;
  for (const auto& shape : reader.GetShapes()) {
    const auto& mesh = shape.mesh;
    std::size_t base = 0;
    for (std::size_t f = 0; f < mesh.num_face_vertices.size(); ++f) {
      const std::size_t n = mesh.num_face_vertices[f];
      for (std::size_t k = 1; k + 1 < n; ++k) {  // fan (tinyobj already triangulated: n == 3)
        const tinyobj::index_t c[3] = {mesh.indices[base], mesh.indices[base + k],
                                       mesh.indices[base + k + 1]};
        m.faces.emplace_back(c[0].vertex_index, c[1].vertex_index, c[2].vertex_index);
        m.uv_faces.emplace_back(c[0].texcoord_index, c[1].texcoord_index, c[2].texcoord_index);
        for (const auto& ci : c) any_missing_uv |= ci.texcoord_index < 0;
        for (const auto& ci : c) {
          if (!all_normals) break;
          if (ci.normal_index < 0 || std::size_t(ci.normal_index) >= nn || ci.vertex_index < 0 ||
              std::size_t(ci.vertex_index) >= normal_sum.size()) {
            all_normals = false;
            break;
          }
          const auto* q = &attrib.normals[3 * std::size_t(ci.normal_index)];
          normal_sum[std::size_t(ci.vertex_index)] += Vec3(q[0], q[1], q[2]);
        }
      }
      base += n;
    }
  }
  if (m.uvs.empty()) {
    m.uv_faces.clear();
  } else if (any_missing_uv) {  // faces without 'vt' get a shared (0,0) UV
    const int dummy = int(m.uvs.size());
    m.uvs.emplace_back(0, 0);
    for (Vec3i& f : m.uv_faces)
      for (int k = 0; k < 3; ++k)
        if (f[k] < 0) f[k] = dummy;
  }
  if (m.faces.empty()) fail_at(path.string(), "no faces after triangulation");
  if (all_normals) {
    m.normals.resize(m.positions.size(), Vec3::Zero());
    for (std::size_t i = 0; i < m.positions.size(); ++i) {
      const double len = normal_sum[i].norm();
      if (len > 0 && std::isfinite(len)) {
        m.normals[i] = normal_sum[i] / len;
      } else if (len == 0 && normal_sum[i].allFinite()) {
        continue;  // unused vertex or opposite normals: filled in below
      } else {
        all_normals = false;
        break;
      }
    }
    if (!all_normals) {
      m.normals.clear();
    } else {  // vertices without a usable file normal get the computed one
      const std::vector<Vec3> file = m.normals;
      m.compute_normals();
      for (std::size_t i = 0; i < file.size(); ++i)
        if (file[i] != Vec3::Zero()) m.normals[i] = file[i];
    }
  }
  m.check(path.string());
  return m;
}

void save_obj(const TriMesh& m, const fs::path& path) {
  std::string out;
  out.reserve(m.positions.size() * 40 + m.faces.size() * 30 + 128);
  out += "# written by Follicle\n";
  for (const Vec3& p : m.positions) out += fmt::format("v {} {} {}\n", p.x(), p.y(), p.z());
  for (const Vec2& t : m.uvs) out += fmt::format("vt {} {}\n", t.x(), t.y());
  const bool normals = m.has_normals();
  if (normals)
    for (const Vec3& n : m.normals) out += fmt::format("vn {} {} {}\n", n.x(), n.y(), n.z());
  if (!m.name.empty()) out += fmt::format("o {}\n", m.name);
  for (std::size_t f = 0; f < m.faces.size(); ++f) {
    out += 'f';
    for (int k = 0; k < 3; ++k) {
      const int v = m.faces[f][k] + 1;
      if (m.has_uvs() && normals)
        out += fmt::format(" {}/{}/{}", v, m.uv_faces[f][k] + 1, v);
      else if (m.has_uvs())
        out += fmt::format(" {}/{}", v, m.uv_faces[f][k] + 1);
      else if (normals)
        out += fmt::format(" {}//{}", v, v);
      else
        out += fmt::format(" {}", v);
    }
    out += '\n';
  }
  write_file_atomically(path, out);
}

// ------------------------------------------------------------------------------------- PLY

enum class PlyType { i8, u8, i16, u16, i32, u32, f32, f64 };

bool ply_type(std::string_view s, PlyType& t) {
  static constexpr std::pair<std::string_view, PlyType> table[] = {
      {"char", PlyType::i8},    {"int8", PlyType::i8},     {"uchar", PlyType::u8},
      {"uint8", PlyType::u8},   {"short", PlyType::i16},   {"int16", PlyType::i16},
      {"ushort", PlyType::u16}, {"uint16", PlyType::u16},  {"int", PlyType::i32},
      {"int32", PlyType::i32},  {"uint", PlyType::u32},    {"uint32", PlyType::u32},
      {"float", PlyType::f32},  {"float32", PlyType::f32}, {"double", PlyType::f64},
      {"float64", PlyType::f64}};
  for (const auto& [n, v] : table)
    if (n == s) {
      t = v;
      return true;
    }
  return false;
}

std::size_t ply_size(PlyType t) {
  switch (t) {
    case PlyType::i8:
    case PlyType::u8: return 1;
    case PlyType::i16:
    case PlyType::u16: return 2;
    case PlyType::i32:
    case PlyType::u32:
    case PlyType::f32: return 4;
    case PlyType::f64: return 8;
  }
  return 1;
}

struct PlyProperty {
  std::string name;
  bool is_list = false;
  PlyType count_type = PlyType::u8;
  PlyType type = PlyType::f32;
};

struct PlyElement {
  std::string name;
  std::size_t count = 0;
  std::vector<PlyProperty> props;
};

enum class PlyFormat { ascii, binary_le, binary_be };

// Reads values either from ASCII tokens (with line tracking) or from binary bytes.
class PlyReader {
 public:
  PlyReader(const fs::path& path, const std::string& data, std::size_t pos, std::size_t line,
            PlyFormat fmt)
      : m_path(path), m_data(data), m_pos(pos), m_line(line), m_fmt(fmt) {}

  // `what` names the value in an error message: a string, or a callable returning one, called
  // only when the read fails (formatting a description for every value read took most of the
  // time of loading a large binary PLY).
  template <class What>
  double read(PlyType t, const What& what) {
    if (m_fmt == PlyFormat::ascii) return read_ascii(t, what);
    return read_binary(t, what);
  }
  std::string where() const {
    return m_fmt == PlyFormat::ascii ? at_line(m_path, m_line)
                                     : fmt::format("{} (byte {})", m_path.string(), m_pos);
  }
  std::size_t remaining() const { return m_data.size() - m_pos; }
  PlyFormat format() const { return m_fmt; }

 private:
  template <class What>
  static std::string describe(const What& what) {
    if constexpr (std::is_invocable_v<const What&>)
      return std::string(what());
    else
      return std::string(what);
  }

  template <class What>
  double read_ascii(PlyType t, const What& what) {
    // skip whitespace, counting lines
    while (m_pos < m_data.size()) {
      const char c = m_data[m_pos];
      if (c == '\n') {
        ++m_line;
        ++m_pos;
      } else if (c == ' ' || c == '\t' || c == '\r') {
        ++m_pos;
      } else {
        break;
      }
    }
    if (m_pos >= m_data.size())
      fail_at(at_line(m_path, m_line), "unexpected end of file while reading {} (truncated?)",
              describe(what));
    std::size_t e = m_pos;
    while (e < m_data.size() && !std::isspace(static_cast<unsigned char>(m_data[e]))) ++e;
    std::string_view tok(m_data.data() + m_pos, e - m_pos);
    m_pos = e;
    double d;
    if (t == PlyType::f32 || t == PlyType::f64) {
      if (!parse_double(tok, d))
        fail_at(at_line(m_path, m_line), "{}: '{}' is not a number", describe(what), tok);
    } else {
      long long i;
      if (!parse_int(tok, i))
        fail_at(at_line(m_path, m_line), "{}: '{}' is not an integer", describe(what), tok);
      d = double(i);
    }
    return d;
  }

  template <class What>
  double read_binary(PlyType t, const What& what) {
    const std::size_t n = ply_size(t);
    if (m_pos + n > m_data.size())
      fail_at(fmt::format("{} (byte {})", m_path.string(), m_pos),
              "unexpected end of file while reading {} (truncated?)", describe(what));
    unsigned char b[8];
    std::memcpy(b, m_data.data() + m_pos, n);
    m_pos += n;
    const bool swap =
        (m_fmt == PlyFormat::binary_be) == (std::endian::native == std::endian::little);
    if (swap) std::reverse(b, b + n);
    switch (t) {
      case PlyType::i8: return double(int8_t(b[0]));
      case PlyType::u8: return double(b[0]);
      case PlyType::i16: {
        int16_t v;
        std::memcpy(&v, b, 2);
        return v;
      }
      case PlyType::u16: {
        uint16_t v;
        std::memcpy(&v, b, 2);
        return v;
      }
      case PlyType::i32: {
        int32_t v;
        std::memcpy(&v, b, 4);
        return v;
      }
      case PlyType::u32: {
        uint32_t v;
        std::memcpy(&v, b, 4);
        return v;
      }
      case PlyType::f32: {
        float v;
        std::memcpy(&v, b, 4);
        return v;
      }
      case PlyType::f64: {
        double v;
        std::memcpy(&v, b, 8);
        return v;
      }
    }
    return 0;
  }

  const fs::path& m_path;
  const std::string& m_data;
  std::size_t m_pos;
  std::size_t m_line;
  PlyFormat m_fmt;
};

// Appends the triangles of the strip poly[start..]: triangle k is (v[k], v[k+1], v[k+2]), every
// odd one reversed to keep the strip's winding; triangles with a repeated vertex are dropped
// (strips are stitched with them).
void add_strip(const std::vector<int>& poly, std::size_t start, std::vector<Vec3i>& faces) {
  for (std::size_t k = start; k + 2 < poly.size(); ++k) {
    const int a = poly[k], b = poly[k + 1], c = poly[k + 2];
    if (a == b || b == c || a == c) continue;
    if ((k - start) % 2 == 0)
      faces.emplace_back(a, b, c);
    else
      faces.emplace_back(b, a, c);
  }
}

// Cuts one planar-ish polygon into triangles with its winding. Triangles pass through; a quad is
// split along the diagonal that keeps both halves facing the quad's (Newell) normal, which is
// right for convex and concave quads; an n-gon of up to 64 vertices is ear-clipped in the plane
// of its Newell normal (O(n^2), as tinyobjloader does for OBJ; written here because no Debian
// package offers polygon triangulation for C++ and tinyobjloader's is internal); larger polygons
// (scanner hole fills) and those with no ear left (self-intersecting) fall back to a fan.
void triangulate_polygon(const std::vector<Vec3>& pos, const std::vector<int>& poly,
                         std::vector<Vec3i>& faces) {
  const std::size_t n = poly.size();
  if (n == 3) {
    faces.emplace_back(poly[0], poly[1], poly[2]);
    return;
  }
  auto fan = [&](const std::vector<int>& ring) {
    for (std::size_t j = 1; j + 1 < ring.size(); ++j)
      faces.emplace_back(ring[0], ring[j], ring[j + 1]);
  };
  Vec3 normal = Vec3::Zero();  // Newell's method
  for (std::size_t j = 0; j < n; ++j) {
    const Vec3& a = pos[std::size_t(poly[j])];
    const Vec3& b = pos[std::size_t(poly[(j + 1) % n])];
    normal += Vec3((a.y() - b.y()) * (a.z() + b.z()), (a.z() - b.z()) * (a.x() + b.x()),
                   (a.x() - b.x()) * (a.y() + b.y()));
  }
  if (!(normal.squaredNorm() > 0) || n > 64) return fan(poly);
  auto facing = [&](int a, int b, int c) {
    const Vec3& pa = pos[std::size_t(a)];
    return (pos[std::size_t(b)] - pa).cross(pos[std::size_t(c)] - pa).dot(normal);
  };
  if (n == 4) {
    const int a = poly[0], b = poly[1], c = poly[2], d = poly[3];
    if (facing(a, b, c) > 0 && facing(a, c, d) > 0) {
      faces.emplace_back(a, b, c);
      faces.emplace_back(a, c, d);
    } else {
      faces.emplace_back(b, c, d);
      faces.emplace_back(b, d, a);
    }
    return;
  }
  // Project onto the plane: drop the normal's largest axis; keep counter-clockwise orientation.
  int drop = 0;
  normal.cwiseAbs().maxCoeff(&drop);
  const int ax = (drop + 1) % 3, ay = (drop + 2) % 3;
  const double flip = normal[drop] < 0 ? -1.0 : 1.0;
  auto p2 = [&](int v) {
    const Vec3& p = pos[std::size_t(v)];
    return Vec2(p[ax], flip * p[ay]);
  };
  auto cross2 = [](const Vec2& o, const Vec2& a, const Vec2& b) {
    return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
  };
  std::vector<int> ring = poly;
  while (ring.size() > 3) {
    bool cut = false;
    for (std::size_t j = 0; j < ring.size() && !cut; ++j) {
      const std::size_t jp = (j + ring.size() - 1) % ring.size(), jn = (j + 1) % ring.size();
      const Vec2 a = p2(ring[jp]), b = p2(ring[j]), c = p2(ring[jn]);
      if (cross2(a, b, c) <= 0) continue;  // reflex or flat corner
      bool empty = true;
      for (std::size_t q = 0; q < ring.size() && empty; ++q) {
        if (q == jp || q == j || q == jn) continue;
        const Vec2 p = p2(ring[q]);
        empty = !(cross2(a, b, p) >= 0 && cross2(b, c, p) >= 0 && cross2(c, a, p) >= 0);
      }
      if (!empty) continue;
      faces.emplace_back(ring[jp], ring[j], ring[jn]);
      ring.erase(ring.begin() + std::ptrdiff_t(j));
      cut = true;
    }
    if (!cut) return fan(ring);
  }
  faces.emplace_back(ring[0], ring[1], ring[2]);
}

TriMesh load_ply(const fs::path& path) {
  const std::string data = read_file(path);
  const std::string file = path.string();
  if (data.empty()) fail_at(file, "file is empty");
  // Header: lines up to "end_header".
  std::size_t pos = 0, line = 0;
  auto next_line = [&](std::string_view& out) {
    if (pos >= data.size()) return false;
    std::size_t eol = data.find('\n', pos);
    if (eol == std::string::npos) eol = data.size();
    out = std::string_view(data).substr(pos, eol - pos);
    if (!out.empty() && out.back() == '\r') out.remove_suffix(1);
    pos = std::min(data.size(), eol + 1);
    ++line;
    return true;
  };
  std::string_view l;
  if (!next_line(l) || l != "ply")
    fail_at(at_line(path, 1), "not a PLY file: expected the magic line 'ply'");
  PlyFormat format = PlyFormat::ascii;
  bool have_format = false, have_end = false;
  std::vector<PlyElement> elements;
  std::vector<std::string_view> toks;
  while (next_line(l)) {
    split_ws(l, toks);
    if (toks.empty()) continue;
    if (toks[0] == "comment" || toks[0] == "obj_info") continue;
    if (toks[0] == "end_header") {
      have_end = true;
      break;
    }
    if (toks[0] == "format") {
      if (toks.size() != 3 || toks[2] != "1.0")
        fail_at(at_line(path, line), "bad format line, expected 'format <kind> 1.0'");
      if (toks[1] == "ascii")
        format = PlyFormat::ascii;
      else if (toks[1] == "binary_little_endian")
        format = PlyFormat::binary_le;
      else if (toks[1] == "binary_big_endian")
        format = PlyFormat::binary_be;
      else
        fail_at(at_line(path, line),
                "unknown PLY format '{}', expected ascii, binary_little_endian or "
                "binary_big_endian",
                toks[1]);
      have_format = true;
    } else if (toks[0] == "element") {
      long long count;
      if (toks.size() != 3 || !parse_int(toks[2], count) || count < 0)
        fail_at(at_line(path, line), "bad element line, expected 'element <name> <count>'");
      elements.push_back({std::string(toks[1]), std::size_t(count), {}});
    } else if (toks[0] == "property") {
      if (elements.empty()) fail_at(at_line(path, line), "property before any element");
      PlyProperty p;
      if (toks.size() == 5 && toks[1] == "list") {
        p.is_list = true;
        if (!ply_type(toks[2], p.count_type) || !ply_type(toks[3], p.type))
          fail_at(at_line(path, line), "unknown PLY type in list property");
        if (p.count_type == PlyType::f32 || p.count_type == PlyType::f64)
          fail_at(at_line(path, line), "list count type must be an integer type");
        p.name = std::string(toks[4]);
      } else if (toks.size() == 3) {
        if (!ply_type(toks[1], p.type))
          fail_at(at_line(path, line), "unknown PLY type '{}'", toks[1]);
        p.name = std::string(toks[2]);
      } else {
        fail_at(at_line(path, line),
                "bad property line, expected 'property <type> <name>' or 'property list "
                "<count type> <type> <name>'");
      }
      elements.back().props.push_back(p);
    } else {
      fail_at(at_line(path, line), "unknown header keyword '{}'", toks[0]);
    }
  }
  if (!have_end) fail_at(file, "no 'end_header' line: truncated or not a PLY file");
  if (!have_format) fail_at(file, "no 'format' line in the header");

  PlyReader rd(path, data, pos, line + 1, format);
  TriMesh m;
  m.name = path.stem().string();
  bool have_vertex = false;
  std::size_t nv = 0;
  for (const PlyElement& el : elements) {
    // Guard against absurd counts before allocating: each item needs at least one byte/token.
    std::size_t min_item = 0;
    for (const auto& p : el.props)
      min_item += p.is_list ? ply_size(p.count_type) : ply_size(p.type);
    if (format != PlyFormat::ascii && min_item > 0 && el.count > rd.remaining() / min_item)
      fail_at(file, "element '{}' declares {} items but the file holds at most {} (truncated?)",
              el.name, el.count, rd.remaining() / min_item);
    if (format == PlyFormat::ascii && el.props.size() > 0 && el.count > rd.remaining())
      fail_at(file, "element '{}' declares {} items but the file is too short (truncated?)",
              el.name, el.count);
    if (el.name == "vertex") {
      have_vertex = true;
      nv = el.count;
      int ix = -1, iy = -1, iz = -1, inx = -1, iny = -1, inz = -1, iu = -1, iv = -1;
      for (std::size_t k = 0; k < el.props.size(); ++k) {
        const std::string& n = el.props[k].name;
        const int ki = int(k);
        if (el.props[k].is_list) continue;
        if (n == "x")
          ix = ki;
        else if (n == "y")
          iy = ki;
        else if (n == "z")
          iz = ki;
        else if (n == "nx")
          inx = ki;
        else if (n == "ny")
          iny = ki;
        else if (n == "nz")
          inz = ki;
        else if (n == "u" || n == "s" || n == "texture_u" || n == "texture_s")
          iu = ki;
        else if (n == "v" || n == "t" || n == "texture_v" || n == "texture_t")
          iv = ki;
      }
      if (ix < 0 || iy < 0 || iz < 0) fail_at(file, "vertex element lacks x, y and z properties");
      const bool normals = inx >= 0 && iny >= 0 && inz >= 0;
      const bool uvs = iu >= 0 && iv >= 0;
      m.positions.resize(el.count);
      if (normals) m.normals.resize(el.count);
      if (uvs) m.uvs.resize(el.count);
      std::vector<double> vals(el.props.size(), 0.0);
      for (std::size_t i = 0; i < el.count; ++i) {
        for (std::size_t k = 0; k < el.props.size(); ++k) {
          const PlyProperty& p = el.props[k];
          if (p.is_list) {
            const double c = rd.read(p.count_type, "vertex list count");
            if (c < 0) fail_at(rd.where(), "negative list count {}", c);
            for (long long j = 0; j < (long long)c; ++j) rd.read(p.type, "vertex list item");
          } else {
            vals[k] =
                rd.read(p.type, [&] { return fmt::format("vertex {} property '{}'", i, p.name); });
            if (!std::isfinite(vals[k]))
              fail_at(rd.where(), "vertex {} property '{}' is not finite ({})", i, p.name, vals[k]);
          }
        }
        m.positions[i] = Vec3(vals[std::size_t(ix)], vals[std::size_t(iy)], vals[std::size_t(iz)]);
        if (normals)
          m.normals[i] =
              Vec3(vals[std::size_t(inx)], vals[std::size_t(iny)], vals[std::size_t(inz)]);
        if (uvs) m.uvs[i] = Vec2(vals[std::size_t(iu)], vals[std::size_t(iv)]);
      }
    } else if (el.name == "face" || el.name == "tristrips") {
      // `face`: one polygon per item (triangles, quads and n-gons, cut by triangulate_polygon).
      // `tristrips` (Stanford's strip element, e.g. the scanned models of the Stanford
      // repository): each list is one or more triangle strips separated by -1; triangle k of a
      // strip is (v[k], v[k+1], v[k+2]) with every second one reversed so that all keep the
      // strip's winding; triangles with a repeated vertex (the usual strip stitches) are dropped.
      const bool strips = el.name == "tristrips";
      if (!have_vertex) fail_at(file, "{} element before the vertex element", el.name);
      int ilist = -1;
      for (std::size_t k = 0; k < el.props.size(); ++k)
        if (el.props[k].is_list &&
            (el.props[k].name == "vertex_indices" || el.props[k].name == "vertex_index"))
          ilist = int(k);
      if (ilist < 0) fail_at(file, "{} element lacks a 'vertex_indices' list property", el.name);
      std::vector<int> poly;
      for (std::size_t i = 0; i < el.count; ++i) {
        for (std::size_t k = 0; k < el.props.size(); ++k) {
          const PlyProperty& p = el.props[k];
          if (!p.is_list) {
            rd.read(p.type, "face property");
            continue;
          }
          const double c = rd.read(p.count_type, [&] {
            return fmt::format("{} {} index count", strips ? "strip list" : "face", i);
          });
          if (c < 0) fail_at(rd.where(), "{} {} has negative index count {}", el.name, i, c);
          if (int(k) != ilist) {
            for (long long j = 0; j < (long long)c; ++j) rd.read(p.type, "list item");
            continue;
          }
          poly.clear();
          std::size_t strip_start = 0;
          for (long long j = 0; j < (long long)c; ++j) {
            const double idx = rd.read(p.type, [&] {
              return fmt::format("{} {} index", strips ? "strip list" : "face", i);
            });
            if (strips && idx == -1) {
              add_strip(poly, strip_start, m.faces);
              strip_start = poly.size();
              continue;
            }
            if (!(idx >= 0 && idx < double(nv)))
              fail_at(rd.where(), "{} {} references vertex {}, expected an index in [0, {}){}",
                      strips ? "strip list" : "face", i, idx, nv,
                      strips ? " or -1 between strips" : "");
            poly.push_back(int(idx));
          }
          if (strips) {
            add_strip(poly, strip_start, m.faces);
          } else {
            if (poly.size() < 3)
              fail_at(rd.where(), "face {} has {} vertices, expected at least 3", i, poly.size());
            triangulate_polygon(m.positions, poly, m.faces);
          }
        }
      }
    } else {
      for (std::size_t i = 0; i < el.count; ++i)
        for (const PlyProperty& p : el.props) {
          if (p.is_list) {
            const double c =
                rd.read(p.count_type, [&] { return fmt::format("'{}' list count", el.name); });
            if (c < 0) fail_at(rd.where(), "negative list count {}", c);
            for (long long j = 0; j < (long long)c; ++j)
              rd.read(p.type, [&] { return fmt::format("'{}' list item", el.name); });
          } else {
            rd.read(p.type, [&] { return fmt::format("'{}' property", el.name); });
          }
        }
    }
  }
  if (!have_vertex) fail_at(file, "no vertex element");
  if (m.faces.empty()) fail_at(file, "no faces: not a triangle mesh PLY");
  if (!m.uvs.empty()) m.uv_faces = m.faces;
  m.check(file);
  return m;
}

template <class T>
void put_le(std::string& out, T v) {
  unsigned char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) std::reverse(b, b + sizeof(T));
  out.append(reinterpret_cast<const char*>(b), sizeof(T));
}

void save_ply(const TriMesh& in, const fs::path& path, bool ascii) {
  const TriMesh m = split_uv_seams(in);
  const bool normals = m.has_normals(), uvs = m.has_uvs();
  std::string out;
  out += "ply\n";
  out += ascii ? "format ascii 1.0\n" : "format binary_little_endian 1.0\n";
  out += "comment written by Follicle\n";
  out += fmt::format("element vertex {}\n", m.positions.size());
  out += "property double x\nproperty double y\nproperty double z\n";
  if (normals) out += "property float nx\nproperty float ny\nproperty float nz\n";
  if (uvs) out += "property float s\nproperty float t\n";
  out += fmt::format("element face {}\n", m.faces.size());
  out += "property list uchar int vertex_indices\nend_header\n";
  for (std::size_t i = 0; i < m.positions.size(); ++i) {
    const Vec3& p = m.positions[i];
    if (ascii) {
      out += fmt::format("{} {} {}", p.x(), p.y(), p.z());
      if (normals)
        out += fmt::format(" {} {} {}", float(m.normals[i].x()), float(m.normals[i].y()),
                           float(m.normals[i].z()));
      if (uvs) out += fmt::format(" {} {}", float(m.uvs[i].x()), float(m.uvs[i].y()));
      out += '\n';
    } else {
      for (int k = 0; k < 3; ++k) put_le<double>(out, p[k]);
      if (normals)
        for (int k = 0; k < 3; ++k) put_le<float>(out, float(m.normals[i][k]));
      if (uvs)
        for (int k = 0; k < 2; ++k) put_le<float>(out, float(m.uvs[i][k]));
    }
  }
  for (const Vec3i& f : m.faces) {
    if (ascii) {
      out += fmt::format("3 {} {} {}\n", f[0], f[1], f[2]);
    } else {
      put_le<uint8_t>(out, 3);
      for (int k = 0; k < 3; ++k) put_le<int32_t>(out, f[k]);
    }
  }
  write_file_atomically(path, out);
}

// ------------------------------------------------------------------------------------ glTF

bool no_image_loader(tinygltf::Image*, const int, std::string*, std::string*, int, int,
                     const unsigned char*, int, void*) {
  return true;  // geometry only: images are not decoded
}

// Reads `count` elements of `ncomp` components as doubles, with bounds checks.
std::vector<double> read_accessor(const fs::path& path, const tinygltf::Model& model, int index,
                                  int want_type, const char* what, bool allow_int) {
  const std::string file = path.string();
  if (index < 0 || std::size_t(index) >= model.accessors.size())
    fail_at(file, "{} accessor {} does not exist", what, index);
  const tinygltf::Accessor& acc = model.accessors[std::size_t(index)];
  if (acc.sparse.isSparse) fail_at(file, "{} accessor {} is sparse: not supported", what, index);
  if (acc.type != want_type)
    fail_at(file, "{} accessor {} has type {}, expected {}", what, index, acc.type, want_type);
  if (acc.bufferView < 0 || std::size_t(acc.bufferView) >= model.bufferViews.size())
    fail_at(file, "{} accessor {} has no valid bufferView", what, index);
  const tinygltf::BufferView& bv = model.bufferViews[std::size_t(acc.bufferView)];
  if (bv.buffer < 0 || std::size_t(bv.buffer) >= model.buffers.size())
    fail_at(file, "{} bufferView {} has no valid buffer", what, acc.bufferView);
  const auto& buf = model.buffers[std::size_t(bv.buffer)].data;
  const int csize = tinygltf::GetComponentSizeInBytes(uint32_t(acc.componentType));
  const int ncomp = tinygltf::GetNumComponentsInType(uint32_t(acc.type));
  if (csize <= 0 || ncomp <= 0)
    fail_at(file, "{} accessor {} has a bad component type", what, index);
  const bool is_float = acc.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT;
  if (!is_float && !allow_int && !acc.normalized)
    fail_at(file, "{} accessor {} must be float or normalized integers", what, index);
  const std::size_t elem = std::size_t(csize) * std::size_t(ncomp);
  const std::size_t stride = bv.byteStride ? bv.byteStride : elem;
  if (stride < elem) fail_at(file, "{} bufferView stride {} < element size {}", what, stride, elem);
  if (bv.byteOffset > buf.size() || bv.byteLength > buf.size() - bv.byteOffset)
    fail_at(file, "{} bufferView {} exceeds its buffer ({} bytes)", what, acc.bufferView,
            buf.size());
  if (acc.count > 0 && (acc.byteOffset > bv.byteLength ||
                        (acc.count - 1) > (bv.byteLength - acc.byteOffset) / stride ||
                        acc.byteOffset + (acc.count - 1) * stride + elem > bv.byteLength))
    fail_at(file, "{} accessor {} ({} elements) exceeds its bufferView ({} bytes): truncated?",
            what, index, acc.count, bv.byteLength);
  std::vector<double> out(acc.count * std::size_t(ncomp));
  const unsigned char* base = buf.data() + bv.byteOffset + acc.byteOffset;
  for (std::size_t i = 0; i < acc.count; ++i)
    for (int c = 0; c < ncomp; ++c) {
      const unsigned char* p = base + i * stride + std::size_t(c * csize);
      double v = 0;
      switch (acc.componentType) {
        case TINYGLTF_COMPONENT_TYPE_FLOAT: {
          float f;
          std::memcpy(&f, p, 4);
          v = f;
          break;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
          v = *p;
          if (acc.normalized) v /= 255.0;
          break;
        case TINYGLTF_COMPONENT_TYPE_BYTE:
          v = int8_t(*p);
          if (acc.normalized) v = std::max(v / 127.0, -1.0);
          break;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
          uint16_t s;
          std::memcpy(&s, p, 2);
          v = s;
          if (acc.normalized) v /= 65535.0;
          break;
        }
        case TINYGLTF_COMPONENT_TYPE_SHORT: {
          int16_t s;
          std::memcpy(&s, p, 2);
          v = s;
          if (acc.normalized) v = std::max(v / 32767.0, -1.0);
          break;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
          uint32_t s;
          std::memcpy(&s, p, 4);
          v = s;
          break;
        }
        default: fail_at(file, "{} accessor {} has an unsupported component type", what, index);
      }
      if (!std::isfinite(v)) fail_at(file, "{} element {} is not finite", what, i);
      out[i * std::size_t(ncomp) + std::size_t(c)] = v;
    }
  return out;
}

Affine3 node_matrix(const tinygltf::Node& n) {
  Affine3 xf = Affine3::Identity();
  if (n.matrix.size() == 16) {
    Mat4 m;
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) m(r, c) = n.matrix[std::size_t(c * 4 + r)];  // column-major
    xf.matrix() = m;
    return xf;
  }
  if (n.translation.size() == 3)
    xf.translate(Vec3(n.translation[0], n.translation[1], n.translation[2]));
  if (n.rotation.size() == 4)
    xf.rotate(Quat(n.rotation[3], n.rotation[0], n.rotation[1], n.rotation[2]).normalized());
  if (n.scale.size() == 3) xf.scale(Vec3(n.scale[0], n.scale[1], n.scale[2]));
  return xf;
}

void append_gltf_mesh(const fs::path& path, const tinygltf::Model& model, int mesh_index,
                      const Affine3& xf, TriMesh& out, bool& all_normals, bool& all_uvs) {
  const std::string file = path.string();
  if (mesh_index < 0 || std::size_t(mesh_index) >= model.meshes.size())
    fail_at(file, "node references mesh {} which does not exist", mesh_index);
  for (const tinygltf::Primitive& prim : model.meshes[std::size_t(mesh_index)].primitives) {
    if (prim.mode != TINYGLTF_MODE_TRIANGLES && prim.mode != -1) continue;  // points/lines: skip
    auto it = prim.attributes.find("POSITION");
    if (it == prim.attributes.end()) fail_at(file, "primitive without POSITION attribute");
    const auto pos = read_accessor(path, model, it->second, TINYGLTF_TYPE_VEC3, "POSITION", false);
    const std::size_t nv = pos.size() / 3;
    const int base = int(out.positions.size());
    for (std::size_t i = 0; i < nv; ++i)
      out.positions.push_back(xf * Vec3(pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]));
    auto nit = prim.attributes.find("NORMAL");
    if (nit != prim.attributes.end() && all_normals) {
      const auto nrm = read_accessor(path, model, nit->second, TINYGLTF_TYPE_VEC3, "NORMAL", false);
      if (nrm.size() != pos.size()) fail_at(file, "NORMAL count differs from POSITION count");
      const Mat3 nm = xf.linear().inverse().transpose();
      for (std::size_t i = 0; i < nv; ++i)
        out.normals.push_back((nm * Vec3(nrm[3 * i], nrm[3 * i + 1], nrm[3 * i + 2])).normalized());
    } else {
      all_normals = false;
    }
    auto tit = prim.attributes.find("TEXCOORD_0");
    if (tit != prim.attributes.end() && all_uvs) {
      const auto uv =
          read_accessor(path, model, tit->second, TINYGLTF_TYPE_VEC2, "TEXCOORD_0", false);
      if (uv.size() / 2 != nv) fail_at(file, "TEXCOORD_0 count differs from POSITION count");
      for (std::size_t i = 0; i < nv; ++i)
        out.uvs.emplace_back(uv[2 * i], 1.0 - uv[2 * i + 1]);  // glTF origin is top-left
    } else {
      all_uvs = false;
    }
    std::vector<double> idx;
    if (prim.indices >= 0) {
      idx = read_accessor(path, model, prim.indices, TINYGLTF_TYPE_SCALAR, "indices", true);
    } else {
      idx.resize(nv);
      for (std::size_t i = 0; i < nv; ++i) idx[i] = double(i);
    }
    if (idx.size() % 3 != 0)
      fail_at(file, "triangle primitive has {} indices, not a multiple of 3", idx.size());
    for (std::size_t t = 0; t < idx.size(); t += 3) {
      Vec3i f;
      for (int k = 0; k < 3; ++k) {
        const double v = idx[t + std::size_t(k)];
        if (!(v >= 0 && v < double(nv)))
          fail_at(file, "triangle {} references vertex {}, expected an index in [0, {})", t / 3, v,
                  nv);
        f[k] = base + int(v);
      }
      out.faces.push_back(f);
    }
  }
}

TriMesh load_gltf(const fs::path& path, bool binary) {
  const std::string file = path.string();
  if (!fs::exists(path)) fail_at(file, "cannot open: no such file");
  if (fs::file_size(path) == 0) fail_at(file, "file is empty");
  tinygltf::Model model;
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(no_image_loader, nullptr);
  std::string err, warn;
  bool ok = false;
  try {
    ok = binary ? loader.LoadBinaryFromFile(&model, &err, &warn, file)
                : loader.LoadASCIIFromFile(&model, &err, &warn, file);
  } catch (const std::exception& e) {
    fail_at(file, "glTF parse error: {}", e.what());
  }
  if (!ok) fail_at(file, "glTF parse error: {}", err.empty() ? std::string("unknown") : err);
  TriMesh m;
  m.name = path.stem().string();
  bool all_normals = true, all_uvs = true;
  // Walk the default scene's node tree with world transforms (guarding against cycles).
  std::set<int> visiting;
  std::function<void(int, const Affine3&, int)> walk = [&](int ni, const Affine3& parent,
                                                           int depth) {
    if (ni < 0 || std::size_t(ni) >= model.nodes.size())
      fail_at(file, "node {} does not exist", ni);
    if (depth > 256 || !visiting.insert(ni).second)
      fail_at(file, "node hierarchy has a cycle at node {}", ni);
    const tinygltf::Node& n = model.nodes[std::size_t(ni)];
    const Affine3 xf = parent * node_matrix(n);
    if (n.mesh >= 0) append_gltf_mesh(path, model, n.mesh, xf, m, all_normals, all_uvs);
    for (int c : n.children) walk(c, xf, depth + 1);
    visiting.erase(ni);
  };
  if (!model.scenes.empty()) {
    const int si = model.defaultScene >= 0 ? model.defaultScene : 0;
    if (std::size_t(si) >= model.scenes.size())
      fail_at(file, "default scene {} does not exist", si);
    for (int ni : model.scenes[std::size_t(si)].nodes) walk(ni, Affine3::Identity(), 0);
  } else {
    for (std::size_t mi = 0; mi < model.meshes.size(); ++mi)
      append_gltf_mesh(path, model, int(mi), Affine3::Identity(), m, all_normals, all_uvs);
  }
  if (m.faces.empty()) fail_at(file, "no triangles found in the glTF scene");
  if (!all_normals) m.normals.clear();
  if (!all_uvs) m.uvs.clear();
  if (!m.uvs.empty()) m.uv_faces = m.faces;
  m.check(file);
  return m;
}

template <class T>
int add_buffer_view(tinygltf::Model& model, const std::vector<T>& data, int target) {
  auto& buf = model.buffers[0].data;
  while (buf.size() % 4) buf.push_back(0);
  tinygltf::BufferView bv;
  bv.buffer = 0;
  bv.byteOffset = buf.size();
  bv.byteLength = data.size() * sizeof(T);
  bv.target = target;
  const auto* p = reinterpret_cast<const unsigned char*>(data.data());
  buf.insert(buf.end(), p, p + bv.byteLength);
  model.bufferViews.push_back(bv);
  return int(model.bufferViews.size() - 1);
}

int add_accessor(tinygltf::Model& model, int view, int ctype, int type, std::size_t count) {
  tinygltf::Accessor a;
  a.bufferView = view;
  a.byteOffset = 0;
  a.componentType = ctype;
  a.type = type;
  a.count = count;
  model.accessors.push_back(a);
  return int(model.accessors.size() - 1);
}

void save_gltf(const TriMesh& in, const fs::path& path, bool binary) {
  const TriMesh m = split_uv_seams(in);
  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "Follicle";
  model.buffers.resize(1);
  tinygltf::Primitive prim;
  prim.mode = TINYGLTF_MODE_TRIANGLES;
  std::vector<float> pos(m.positions.size() * 3);
  std::vector<double> mn(3, 0.0), mx(3, 0.0);
  for (std::size_t i = 0; i < m.positions.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      pos[3 * i + std::size_t(k)] = float(m.positions[i][k]);
      const double v = double(pos[3 * i + std::size_t(k)]);
      mn[std::size_t(k)] = i == 0 ? v : std::min(mn[std::size_t(k)], v);
      mx[std::size_t(k)] = i == 0 ? v : std::max(mx[std::size_t(k)], v);
    }
  const int ipos =
      add_accessor(model, add_buffer_view(model, pos, TINYGLTF_TARGET_ARRAY_BUFFER),
                   TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, m.positions.size());
  model.accessors[std::size_t(ipos)].minValues = mn;
  model.accessors[std::size_t(ipos)].maxValues = mx;
  prim.attributes["POSITION"] = ipos;
  if (m.has_normals()) {
    std::vector<float> nrm(m.normals.size() * 3);
    for (std::size_t i = 0; i < m.normals.size(); ++i)
      for (int k = 0; k < 3; ++k) nrm[3 * i + std::size_t(k)] = float(m.normals[i][k]);
    prim.attributes["NORMAL"] =
        add_accessor(model, add_buffer_view(model, nrm, TINYGLTF_TARGET_ARRAY_BUFFER),
                     TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, m.normals.size());
  }
  if (m.has_uvs()) {
    std::vector<float> uv(m.uvs.size() * 2);
    for (std::size_t i = 0; i < m.uvs.size(); ++i) {
      uv[2 * i] = float(m.uvs[i].x());
      uv[2 * i + 1] = float(1.0 - m.uvs[i].y());  // glTF origin is top-left
    }
    prim.attributes["TEXCOORD_0"] =
        add_accessor(model, add_buffer_view(model, uv, TINYGLTF_TARGET_ARRAY_BUFFER),
                     TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC2, m.uvs.size());
  }
  std::vector<uint32_t> idx(m.faces.size() * 3);
  for (std::size_t f = 0; f < m.faces.size(); ++f)
    for (int k = 0; k < 3; ++k) idx[3 * f + std::size_t(k)] = uint32_t(m.faces[f][k]);
  prim.indices =
      add_accessor(model, add_buffer_view(model, idx, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER),
                   TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR, idx.size());
  tinygltf::Mesh mesh;
  mesh.name = m.name;
  mesh.primitives.push_back(prim);
  model.meshes.push_back(mesh);
  tinygltf::Node node;
  node.mesh = 0;
  model.nodes.push_back(node);
  tinygltf::Scene scene;
  scene.nodes.push_back(0);
  model.scenes.push_back(scene);
  model.defaultScene = 0;
  std::ostringstream os;
  tinygltf::TinyGLTF writer;
  if (!writer.WriteGltfSceneToStream(&model, os, !binary, binary))
    fail_at(path.string(), "tinygltf failed to serialise the mesh");
  write_file_atomically(path, os.str());
}

}  // namespace

TriMesh split_uv_seams(const TriMesh& mesh) {
  if (!mesh.has_uvs()) return mesh;
  if (mesh.uv_faces == mesh.faces && mesh.uvs.size() == mesh.positions.size()) return mesh;
  TriMesh out;
  out.name = mesh.name;
  std::map<std::pair<int, int>, int> ids;
  out.faces.resize(mesh.faces.size());
  const bool normals = mesh.has_normals();
  for (std::size_t f = 0; f < mesh.faces.size(); ++f)
    for (int k = 0; k < 3; ++k) {
      const auto key = std::make_pair(mesh.faces[f][k], mesh.uv_faces[f][k]);
      auto [it, inserted] = ids.emplace(key, int(out.positions.size()));
      if (inserted) {
        out.positions.push_back(mesh.positions[std::size_t(key.first)]);
        out.uvs.push_back(mesh.uvs[std::size_t(key.second)]);
        if (normals) out.normals.push_back(mesh.normals[std::size_t(key.first)]);
      }
      out.faces[f][k] = it->second;
    }
  out.uv_faces = out.faces;
  return out;
}

TriMesh load_mesh(const std::filesystem::path& path, LengthUnit unit) {
  const std::string ext = lower_ext(path);
  TriMesh m;
  if (ext == ".obj")
    m = load_obj(path);
  else if (ext == ".ply")
    m = load_ply(path);
  else if (ext == ".gltf")
    m = load_gltf(path, false);
  else if (ext == ".glb")
    m = load_gltf(path, true);
  else
    fail_at(path.string(), "unknown mesh extension '{}': expected .obj, .ply, .gltf or .glb", ext);
  const double s = unit_to_metres(unit);
  if (s != 1.0) {
    m.scale(s);
    m.check(path.string());  // the size limits hold in metres too
  }
  return m;
}

void save_mesh(const TriMesh& mesh, const std::filesystem::path& path, LengthUnit unit,
               bool ascii) {
  const std::string ext = lower_ext(path);
  if (ext != ".obj" && ext != ".ply" && ext != ".gltf" && ext != ".glb")
    fail_at(path.string(), "unknown mesh extension '{}': expected .obj, .ply, .gltf or .glb", ext);
  // glTF 2.0 fixes the unit: "the units for all linear distances are meters". A file in mm would
  // be read by every other tool as 1000 times too large (a 400 m head in Blender).
  if ((ext == ".gltf" || ext == ".glb") && unit != LengthUnit::m)
    fail_at(path.string(), "glTF stores metres by specification; write it with units m, not {}",
            to_string(unit));
  mesh.check(path.string());
  TriMesh m = mesh;
  const double s = unit_to_metres(unit);
  if (s != 1.0) m.scale(1.0 / s);
  if (ext == ".obj")
    save_obj(m, path);
  else if (ext == ".ply")
    save_ply(m, path, ascii);
  else
    save_gltf(m, path, ext == ".glb");
}

}  // namespace follicle::geom
