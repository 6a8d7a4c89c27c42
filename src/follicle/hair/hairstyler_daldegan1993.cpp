#include "follicle/hair/hairstyler_daldegan1993.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <type_traits>

#include "follicle/core/error.hpp"
#include "follicle/core/parallel.hpp"
#include "follicle/core/rng.hpp"
#include "follicle/geom/curves.hpp"
#include "follicle/image/image_io.hpp"

namespace follicle::hair {

namespace {

std::string join(const std::string& where, const std::string& key) {
  return where.empty() ? key : where + "." + key;
}
std::string indexed(const std::string& where, const std::string& key, std::size_t i) {
  return join(where, key) + "[" + std::to_string(i) + "]";
}

template <class T>
struct is_optional : std::false_type {};
template <class T>
struct is_optional<std::optional<T>> : std::true_type {};

// ParamValidator that also checks the value of a present std::optional field.
struct OptionalRangeCheck {
  std::string where;
  template <class T>
  void operator()(const char* name, T& v, const ParamInfo& info = {}) {
    ParamValidator pv(where);
    if constexpr (is_optional<T>::value) {
      if (v) pv(name, *v, info);
    } else {
      pv(name, v, info);
    }
  }
};

std::string hint_text(const std::string& hint) {
  return hint.empty() ? std::string() : fmt::format(" (did you mean \"{}\"?)", hint);
}

std::string name_list(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += fmt::format("{}\"{}\"", s.empty() ? "" : ", ", n);
  return s;
}

// ---- built-in curves -------------------------------------------------------------------------

// A planar curve (x-y: tangent-normal) of unit length whose direction above the tangent turns
// linearly from a0 to a1 [deg], with an optional binormal wave of `waves` periods.
std::vector<Vec3> turning_curve(double a0_deg, double a1_deg, int n, double wave_amp = 0.0,
                                double waves = 0.0) {
  std::vector<Vec3> pts;
  Vec2 p(0.0, 0.0);
  for (int i = 0; i <= n; ++i) {
    const double s = double(i) / n;
    pts.emplace_back(p.x(), p.y(), wave_amp * std::sin(2.0 * kPi * waves * s));
    const double a = (a0_deg + (a1_deg - a0_deg) * (s + 0.5 / n)) * kPi / 180.0;
    p += Vec2(std::cos(a), std::sin(a)) / n;
  }
  return pts;
}

// Helix about an axis leaving the surface at 50° towards the tangent.
std::vector<Vec3> curl_curve() {
  const double ang = 50.0 * kPi / 180.0, r = 0.045, turns = 3.0, axial = 0.6;
  const Vec3 a(std::cos(ang), std::sin(ang), 0.0), e1(-std::sin(ang), std::cos(ang), 0.0),
      e2(0.0, 0.0, 1.0);
  std::vector<Vec3> pts;
  const int n = 72;
  for (int i = 0; i <= n; ++i) {
    const double s = double(i) / n, th = 2.0 * kPi * turns * s;
    pts.push_back(axial * s * a + r * (1.0 - std::cos(th)) * e1 + r * std::sin(th) * e2);
  }
  return pts;
}

const std::vector<std::string>& builtin_names() {
  static const std::vector<std::string> names{"straight", "swept",   "wavy", "curl",
                                              "fur",      "eyebrow", "beard"};
  return names;
}

// Arc-length resampling of a dense polyline to n points (first and last kept).
void resample_polyline(const std::vector<Vec3>& dense, std::size_t n, std::vector<Vec3>& out) {
  std::vector<double> acc(dense.size(), 0.0);
  for (std::size_t i = 1; i < dense.size(); ++i)
    acc[i] = acc[i - 1] + (dense[i] - dense[i - 1]).norm();
  const double L = acc.back();
  out.resize(n);
  std::size_t j = 1;
  for (std::size_t k = 0; k < n; ++k) {
    const double t = L * double(k) / double(n - 1);
    while (j < dense.size() - 1 && acc[j] < t) ++j;
    const double seg = acc[j] - acc[j - 1];
    const double u = seg > 0 ? std::clamp((t - acc[j - 1]) / seg, 0.0, 1.0) : 0.0;
    out[k] = dense[j - 1] + u * (dense[j] - dense[j - 1]);
  }
  out.front() = dense.front();
  out.back() = dense.back();
}

double polyline_length(const std::vector<Vec3>& p) {
  double L = 0.0;
  for (std::size_t i = 1; i < p.size(); ++i) L += (p[i] - p[i - 1]).norm();
  return L;
}

// Root at the origin, unit polyline length.
void normalize_shape(std::vector<Vec3>& p) {
  const Vec3 o = p.front();
  for (auto& q : p) q -= o;
  const double L = polyline_length(p);
  if (L > 0)
    for (auto& q : p) q /= L;
}

// ---- index files -----------------------------------------------------------------------------

void parse_index_file(const std::filesystem::path& file, const std::string& json_path,
                      const char* what, RegionInput& out) {
  std::ifstream in(file);
  if (!in) fail_at(json_path, "cannot open the {} index file '{}'", what, file.string());
  out.source = file.string();
  std::string line;
  uint32_t lineno = 0;
  while (std::getline(in, line)) {
    ++lineno;
    const auto hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    std::size_t i = 0;
    while (i < line.size()) {
      while (i < line.size() &&
             (std::isspace(static_cast<unsigned char>(line[i])) || line[i] == ','))
        ++i;
      if (i >= line.size()) break;
      std::size_t j = i;
      while (j < line.size() && !std::isspace(static_cast<unsigned char>(line[j])) &&
             line[j] != ',')
        ++j;
      const std::string tok = line.substr(i, j - i);
      int64_t v = -1;
      const auto [ptr, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), v);
      if (ec != std::errc() || ptr != tok.data() + tok.size() || v < 0)
        fail_at(fmt::format("{}:{}", file.string(), lineno),
                "expected a {} index (a non-negative integer), got \"{}\" ({})", what, tok,
                json_path);
      out.indices.push_back(v);
      out.lines.push_back(lineno);
      i = j;
    }
  }
}

// ---- triangle parametrization ----------------------------------------------------------------

// Heitz 2019, "A Low-Distortion Map Between Triangle and Square": unit square -> triangle
// (x, y >= 0, x + y <= 1), area-preserving. Returns barycentric weights (1 - x - y, x, y).
Vec3 square_to_triangle(double u, double v) {
  if (v > u) {
    u *= 0.5;
    v -= u;
  } else {
    v *= 0.5;
    u -= v;
  }
  return Vec3(1.0 - u - v, u, v);
}

double wrap01(double x) {
  const double f = x - std::floor(x);
  return f < 1.0 ? f : 0.0;
}

Vec3 any_perpendicular(const Vec3& n) {
  const Vec3 a = std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  return (a - a.dot(n) * n).normalized();
}

std::vector<Vec3> vertex_normals_of(const geom::TriMesh& m) {
  if (m.has_normals()) {
    std::vector<Vec3> n(m.normals);
    for (auto& v : n) {
      const double l = v.norm();
      v = l > 0 ? Vec3(v / l) : Vec3(0, 0, 1);
    }
    return n;
  }
  geom::TriMesh tmp;
  tmp.positions = m.positions;
  tmp.faces = m.faces;
  tmp.compute_normals();
  return std::move(tmp.normals);
}

// The transform of the tangent plane from a rest triangle to its deformed version: the linear
// map taking the rest edges and unit normal to the deformed ones.
Mat3 triangle_jacobian(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& a2, const Vec3& b2,
                       const Vec3& c2) {
  Mat3 M, M2;
  const Vec3 e1 = b - a, e2 = c - a, f1 = b2 - a2, f2 = c2 - a2;
  const Vec3 n = e1.cross(e2), n2 = f1.cross(f2);
  const double ln = n.norm(), ln2 = n2.norm();
  if (!(ln > 0)) return Mat3::Identity();
  M << e1, e2, n / ln;
  M2 << f1, f2, (ln2 > 0 ? Vec3(n2 / ln2) : Vec3::Zero());
  return M2 * M.inverse();
}

uint64_t mix_seed(uint64_t style_seed, uint64_t tri_seed) {
  return style_seed ^ (tri_seed * 0x9E3779B97F4A7C15ull + 0x632BE59BD9B4E019ull);
}

constexpr double kGolden = 0.61803398874989484820;  // rank-1 lattice generator

}  // namespace

// ---- curves ----------------------------------------------------------------------------------

std::vector<std::string> builtin_curve_names() {
  return builtin_names();
}

HairCurve builtin_curve(std::string_view name) {
  HairCurve c;
  c.name = std::string(name);
  if (name == "straight")
    c.points = {Vec3(0, 0, 0), Vec3(0, 1, 0)};
  else if (name == "swept")
    c.points = turning_curve(45.0, -35.0, 24);
  else if (name == "wavy")
    c.points = turning_curve(40.0, -30.0, 60, 0.05, 2.5);
  else if (name == "curl")
    c.points = curl_curve();
  else if (name == "fur")
    c.points = turning_curve(60.0, 25.0, 12);
  else if (name == "eyebrow")
    c.points = turning_curve(20.0, 3.0, 12);
  else if (name == "beard")
    c.points = turning_curve(75.0, -20.0, 24);
  else
    fail("unknown built-in hair curve \"{}\"; expected one of {}", name,
         name_list(builtin_names()));
  return c;
}

std::vector<Vec3> sample_curve(const HairCurve& curve, std::size_t n, const std::string& where) {
  if (n < 2) fail_at(where, "a hair needs at least 2 points, got {}", n);
  std::vector<Vec3> pts;
  for (std::size_t i = 0; i < curve.points.size(); ++i) {
    const Vec3& p = curve.points[i];
    if (!p.allFinite()) fail_at(indexed(where, "points", i), "point is not finite");
    if (!pts.empty() && (p - pts.back()).norm() <= 1e-12) continue;  // drop repeated points
    pts.push_back(p);
  }
  if (pts.size() < 2)
    fail_at(join(where, "points"), "a curve needs at least 2 distinct points, got {}", pts.size());
  const geom::CatmullRom3 spline(pts, 0.5);
  const std::size_t per = std::max<std::size_t>(16, 1024 / spline.num_segments());
  const std::vector<Vec3> dense = spline.sample(per);
  if (polyline_length(dense) <= 1e-12) fail_at(join(where, "points"), "the curve has zero length");
  std::vector<Vec3> out;
  resample_polyline(dense, n, out);
  normalize_shape(out);
  if (!(out[1].y() > 1e-9))
    fail_at(join(where, "points"),
            "the hair must leave the surface: its first segment has a normal component (y) of {} "
            "<= 0, so it would start inside the mesh",
            out[1].y());
  return out;
}

// ---- regions ---------------------------------------------------------------------------------

const char* to_string(RegionSelect s) {
  for (const auto& [e, n] : follicle_enum_names(RegionSelect{}))
    if (e == s) return n;
  return "?";
}

void HairRegion::validate(const std::string& where) const {
  OptionalRangeCheck check{where};
  const_cast<HairRegion*>(this)->visit(check);
  // Which selector arguments belong to which kind.
  struct Arg {
    const char* name;
    bool given;
    RegionSelect k1, k2;
  };
  using S = RegionSelect;
  const Arg args[] = {
      {"mask", mask.has_value(), S::Mask, S::Mask},
      {"threshold", threshold.has_value(), S::Mask, S::Mask},
      {"mask_scales_density", mask_scales_density.has_value(), S::Mask, S::Mask},
      {"triangles", triangles.has_value(), S::Triangles, S::Triangles},
      {"vertices", vertices.has_value(), S::Vertices, S::Vertices},
      {"indices", indices.has_value(), S::Triangles, S::Vertices},
      {"centre", centre.has_value(), S::Sphere, S::Sphere},
      {"radius", radius.has_value(), S::Sphere, S::Sphere},
      {"min", min.has_value(), S::Box, S::Box},
      {"max", max.has_value(), S::Box, S::Box},
      {"point", point.has_value(), S::HalfSpace, S::HalfSpace},
      {"normal", normal.has_value(), S::HalfSpace, S::HalfSpace},
  };
  for (const Arg& a : args) {
    if (!a.given) continue;
    if (a.k1 == select || a.k2 == select) continue;
    const std::string kinds =
        a.k2 == a.k1 ? fmt::format("\"{}\"", to_string(a.k1))
                     : fmt::format("\"{}\" or \"{}\"", to_string(a.k1), to_string(a.k2));
    fail_at(join(where, a.name), "only used with \"select\": {} (this region selects \"{}\")",
            kinds, to_string(select));
  }
  auto need = [&](bool given, const char* key) {
    if (!given) fail_at(where, "\"select\": \"{}\" needs \"{}\"", to_string(select), key);
  };
  switch (select) {
    case RegionSelect::All: break;
    case RegionSelect::Mask:
      need(mask.has_value(), "mask");
      if (mask->empty()) fail_at(join(where, "mask"), "the mask path is empty");
      break;
    case RegionSelect::Triangles:
    case RegionSelect::Vertices: {
      const bool file =
          select == RegionSelect::Triangles ? triangles.has_value() : vertices.has_value();
      const char* key = select == RegionSelect::Triangles ? "triangles" : "vertices";
      if (file == indices.has_value())
        fail_at(where, "\"select\": \"{}\" needs either \"{}\" (an index file) or \"indices\"",
                to_string(select), key);
      if (file && (select == RegionSelect::Triangles ? *triangles : *vertices).empty())
        fail_at(join(where, key), "the index file path is empty");
      if (indices)
        for (std::size_t i = 0; i < indices->size(); ++i)
          if ((*indices)[i] < 0)
            fail_at(indexed(where, "indices", i), "index {} is negative", (*indices)[i]);
      break;
    }
    case RegionSelect::Sphere:
      need(centre.has_value(), "centre");
      need(radius.has_value(), "radius");
      break;
    case RegionSelect::Box:
      need(min.has_value(), "min");
      need(max.has_value(), "max");
      for (int k = 0; k < 3; ++k)
        if ((*min)[k] > (*max)[k])
          fail_at(join(where, "max"), "max[{}] = {} is below min[{}] = {}", k, (*max)[k], k,
                  (*min)[k]);
      break;
    case RegionSelect::HalfSpace:
      need(point.has_value(), "point");
      need(normal.has_value(), "normal");
      if (!(normal->norm() > 1e-12)) fail_at(join(where, "normal"), "the normal is zero");
      break;
  }
}

void HairRegion::apply(TriangleHairParams& p) const {
  if (curve) p.curve = *curve;
  if (material) p.material = *material;
  if (jitter) p.jitter = *jitter;
  if (tangent) p.tangent = *tangent;
  if (angle_deg) p.angle_deg = *angle_deg;
  if (angle_variation_deg) p.angle_variation_deg = *angle_variation_deg;
  if (scale) p.scale = *scale;
  if (scale_variation) p.scale_variation = *scale_variation;
  if (density) p.density = *density;
  if (seed) p.seed = *seed;
}

void HairStylerParams::validate(const std::string& where) const {
  OptionalRangeCheck check{where};
  const_cast<HairStylerParams*>(this)->visit(check);
  defaults.validate(join(where, "defaults"));
  if (!(comb.norm() > 1e-12)) fail_at(join(where, "comb"), "the comb direction is zero");
  if (!(comb_fallback.norm() > 1e-12))
    fail_at(join(where, "comb_fallback"), "the fallback comb direction is zero");
  if (comb.normalized().cross(comb_fallback.normalized()).norm() < 1e-3)
    fail_at(join(where, "comb_fallback"), "must not be parallel to comb");
  if (materials.empty()) fail_at(join(where, "materials"), "at least one material is needed");
  if (materials.size() > 65535) fail_at(join(where, "materials"), "too many materials");
  std::vector<std::string> mat_names, curve_names = builtin_names();
  for (std::size_t i = 0; i < materials.size(); ++i) {
    const std::string w = indexed(where, "materials", i);
    materials[i].validate(w);
    if (std::find(mat_names.begin(), mat_names.end(), materials[i].name) != mat_names.end())
      fail_at(join(w, "name"), "material name \"{}\" is used twice", materials[i].name);
    mat_names.push_back(materials[i].name);
  }
  std::vector<std::string> user;
  for (std::size_t i = 0; i < curves.size(); ++i) {
    const std::string w = indexed(where, "curves", i);
    if (curves[i].name.empty()) fail_at(join(w, "name"), "a curve needs a name");
    if (std::find(user.begin(), user.end(), curves[i].name) != user.end())
      fail_at(join(w, "name"), "curve name \"{}\" is used twice", curves[i].name);
    user.push_back(curves[i].name);
    if (std::find(curve_names.begin(), curve_names.end(), curves[i].name) == curve_names.end())
      curve_names.push_back(curves[i].name);
    sample_curve(curves[i], std::size_t(std::max(points_per_hair, 2)), w);
  }
  auto check_names = [&](const std::string& w, const std::string* curve,
                         const std::string* material) {
    if (curve && std::find(curve_names.begin(), curve_names.end(), *curve) == curve_names.end()) {
      const std::string hint = did_you_mean(*curve, curve_names);
      fail_at(join(w, "curve"), "unknown curve \"{}\"{}; known curves: {}", *curve, hint_text(hint),
              name_list(curve_names));
    }
    if (material && !material->empty() &&
        std::find(mat_names.begin(), mat_names.end(), *material) == mat_names.end()) {
      const std::string hint = did_you_mean(*material, mat_names);
      fail_at(join(w, "material"), "unknown material \"{}\"{}; known materials: {}", *material,
              hint_text(hint), name_list(mat_names));
    }
  };
  check_names(join(where, "defaults"), &defaults.curve, &defaults.material);
  for (std::size_t i = 0; i < regions.size(); ++i) {
    const std::string w = indexed(where, "regions", i);
    regions[i].validate(w);
    check_names(w, regions[i].curve ? &*regions[i].curve : nullptr,
                regions[i].material ? &*regions[i].material : nullptr);
  }
}

// ---- inputs ----------------------------------------------------------------------------------

StylerInputs load_styler_inputs(
    const HairStylerParams& params,
    const std::function<std::filesystem::path(const std::string&)>& resolve) {
  StylerInputs in;
  in.regions.resize(params.regions.size());
  for (std::size_t i = 0; i < params.regions.size(); ++i) {
    const HairRegion& r = params.regions[i];
    const std::string w = indexed("", "regions", i);
    RegionInput& out = in.regions[i];
    auto path_of = [&](const std::string& p) {
      return resolve ? resolve(p) : std::filesystem::path(p);
    };
    if (r.select == RegionSelect::Mask && r.mask) {
      const auto file = path_of(*r.mask);
      if (!std::filesystem::exists(file))
        fail_at(join(w, "mask"), "mask image '{}' not found", file.string());
      try {
        out.mask = image::read_gray_map(file);
      } catch (const Error& e) {
        fail_at(join(w, "mask"), "cannot read the mask image: {}", e.what());
      }
      if (out.mask.empty()) fail_at(join(w, "mask"), "mask image '{}' is empty", file.string());
      out.source = file.string();
      out.loaded = true;
    } else if (r.select == RegionSelect::Triangles && r.triangles) {
      parse_index_file(path_of(*r.triangles), join(w, "triangles"), "triangle", out);
      out.loaded = true;
    } else if (r.select == RegionSelect::Vertices && r.vertices) {
      parse_index_file(path_of(*r.vertices), join(w, "vertices"), "vertex", out);
      out.loaded = true;
    }
  }
  return in;
}

// ---- tangent correction ----------------------------------------------------------------------

Vec3 correct_tangent(const Vec3& tangent_old, const Vec3& normal_new) {
  const Vec3 b = normal_new.cross(tangent_old);  // §2: binormal = N_new × t_old
  const Vec3 t = b.cross(normal_new);            // §2: t_new from N_new and the binormal
  const double len = t.norm();
  if (len > 1e-12 * std::max(1.0, tangent_old.norm())) return t / len;
  return any_perpendicular(normal_new);
}

// ---- the styler ------------------------------------------------------------------------------

HairStyler::HairStyler(const geom::TriMesh& mesh, const HairStylerParams& params,
                       const StylerInputs& inputs)
    : m_params(params) {
  params.validate();
  mesh.check("hairstyler mesh");
  if (mesh.faces.empty()) fail("hairstyler: the mesh has no triangles");
  if (!inputs.regions.empty() && inputs.regions.size() != params.regions.size())
    fail("hairstyler: {} region inputs for {} regions (use load_styler_inputs)",
         inputs.regions.size(), params.regions.size());
  m_positions = mesh.positions;
  m_faces = mesh.faces;
  m_vertex_normals = vertex_normals_of(mesh);
  const std::size_t nf = m_faces.size(), nv = m_positions.size();
  m_face_normals.resize(nf);
  m_face_area.resize(nf);
  for (std::size_t f = 0; f < nf; ++f) {
    m_face_normals[f] = mesh.face_normal(f);
    m_face_area[f] = mesh.face_area(f);
  }
  const std::size_t P = std::size_t(params.points_per_hair);

  // Curve table: built-ins, then user curves (replacing a built-in of the same name).
  m_curve_names = builtin_names();
  m_shapes.clear();
  for (const auto& n : m_curve_names)
    m_shapes.push_back(sample_curve(builtin_curve(n), P, "curve \"" + n + "\""));
  for (std::size_t i = 0; i < params.curves.size(); ++i) {
    auto shape = sample_curve(params.curves[i], P, indexed("", "curves", i));
    auto it = std::find(m_curve_names.begin(), m_curve_names.end(), params.curves[i].name);
    if (it != m_curve_names.end()) {
      m_shapes[std::size_t(it - m_curve_names.begin())] = std::move(shape);
    } else {
      m_curve_names.push_back(params.curves[i].name);
      m_shapes.push_back(std::move(shape));
    }
  }

  // Per-triangle parameters: defaults, then the regions in order.
  m_tri.assign(nf, params.defaults);
  m_excluded.assign(nf, 0);
  auto centroid = [&](std::size_t f) {
    const Vec3i& t = m_faces[f];
    return Vec3((m_positions[std::size_t(t[0])] + m_positions[std::size_t(t[1])] +
                 m_positions[std::size_t(t[2])]) /
                3.0);
  };
  std::vector<uint8_t> sel(nf);
  std::vector<float> mask_value;
  for (std::size_t ri = 0; ri < params.regions.size(); ++ri) {
    const HairRegion& r = params.regions[ri];
    const std::string w = indexed("", "regions", ri);
    const RegionInput* in = inputs.regions.empty() ? nullptr : &inputs.regions[ri];
    std::fill(sel.begin(), sel.end(), uint8_t(0));
    mask_value.clear();
    // Index list (file or inline) with a message source per entry.
    auto index_list = [&](const char* key, const char* what, const char* whats,
                          std::size_t limit) -> const std::vector<int64_t>& {
      const std::vector<int64_t>* list = nullptr;
      if (r.indices) {
        list = &*r.indices;
        for (std::size_t k = 0; k < list->size(); ++k)
          if (std::size_t((*list)[k]) >= limit)
            fail_at(indexed(w, "indices", k), "{} index {} is out of range: the mesh has {} {}",
                    what, (*list)[k], limit, whats);
      } else {
        if (!in || !in->loaded)
          fail_at(join(w, key), "the index file was not loaded (call load_styler_inputs)");
        list = &in->indices;
        for (std::size_t k = 0; k < list->size(); ++k)
          if (std::size_t((*list)[k]) >= limit)
            fail_at(fmt::format("{}:{}", in->source, in->lines[k]),
                    "{} index {} is out of range: the mesh has {} {} ({})", what, (*list)[k], limit,
                    whats, join(w, key));
      }
      return *list;
    };
    switch (r.select) {
      case RegionSelect::All: std::fill(sel.begin(), sel.end(), uint8_t(1)); break;
      case RegionSelect::Mask: {
        if (!mesh.has_uvs())
          fail_at(join(w, "mask"),
                  "the mesh \"{}\" has no texture coordinates; a \"mask\" region needs UVs (use "
                  "a \"triangles\", \"vertices\" or geometric selector instead)",
                  mesh.name);
        if (!in || !in->loaded || in->mask.empty())
          fail_at(join(w, "mask"), "the mask image was not loaded (call load_styler_inputs)");
        const image::ImageF& img = in->mask;
        const double thr = r.threshold.value_or(0.5);
        mask_value.assign(nf, 0.0f);
        for (std::size_t f = 0; f < nf; ++f) {
          const Vec3i& uf = mesh.uv_faces[f];
          const Vec2 uv = (mesh.uvs[std::size_t(uf[0])] + mesh.uvs[std::size_t(uf[1])] +
                           mesh.uvs[std::size_t(uf[2])]) /
                          3.0;
          // Bilinear, clamped, v up (row 0 of the image is v = 1).
          const double x = std::clamp(uv.x(), 0.0, 1.0) * img.width() - 0.5;
          const double y = (1.0 - std::clamp(uv.y(), 0.0, 1.0)) * img.height() - 0.5;
          const int x0 = int(std::floor(x)), y0 = int(std::floor(y));
          const double fx = x - x0, fy = y - y0;
          auto px = [&](int xi, int yi) {
            return double(
                img.at(std::clamp(xi, 0, img.width() - 1), std::clamp(yi, 0, img.height() - 1)));
          };
          const double val = (1 - fy) * ((1 - fx) * px(x0, y0) + fx * px(x0 + 1, y0)) +
                             fy * ((1 - fx) * px(x0, y0 + 1) + fx * px(x0 + 1, y0 + 1));
          mask_value[f] = float(val);
          sel[f] = val > thr;
        }
        break;
      }
      case RegionSelect::Triangles:
        for (int64_t t : index_list("triangles", "triangle", "triangles", nf))
          sel[std::size_t(t)] = 1;
        break;
      case RegionSelect::Vertices: {
        std::vector<uint8_t> vsel(nv, 0);
        for (int64_t v : index_list("vertices", "vertex", "vertices", nv)) vsel[std::size_t(v)] = 1;
        for (std::size_t f = 0; f < nf; ++f) {
          const Vec3i& t = m_faces[f];
          sel[f] = vsel[std::size_t(t[0])] && vsel[std::size_t(t[1])] && vsel[std::size_t(t[2])];
        }
        break;
      }
      case RegionSelect::Sphere:
        for (std::size_t f = 0; f < nf; ++f) sel[f] = (centroid(f) - *r.centre).norm() <= *r.radius;
        break;
      case RegionSelect::Box:
        for (std::size_t f = 0; f < nf; ++f) {
          const Vec3 c = centroid(f);
          sel[f] = (c.array() >= r.min->array()).all() && (c.array() <= r.max->array()).all();
        }
        break;
      case RegionSelect::HalfSpace:
        for (std::size_t f = 0; f < nf; ++f) sel[f] = (centroid(f) - *r.point).dot(*r.normal) >= 0;
        break;
    }
    const bool scale_by_mask =
        r.select == RegionSelect::Mask && r.mask_scales_density.value_or(false);
    for (std::size_t f = 0; f < nf; ++f) {
      if (bool(sel[f]) == r.invert) continue;
      if (r.exclude) m_excluded[f] = *r.exclude ? 1 : 0;
      r.apply(m_tri[f]);
      if (scale_by_mask) m_tri[f].density *= double(mask_value[f]);
    }
  }

  // Resolve names and tangents per face.
  std::map<std::string, uint16_t> curve_index, material_index;
  for (std::size_t i = 0; i < m_curve_names.size(); ++i)
    curve_index[m_curve_names[i]] = uint16_t(i);
  for (std::size_t i = 0; i < params.materials.size(); ++i)
    material_index[params.materials[i].name] = uint16_t(i);
  m_curve.resize(nf);
  m_material.resize(nf);
  m_face_tangent.resize(nf);
  m_grow.assign(nf, 0);
  for (std::size_t f = 0; f < nf; ++f) {
    const TriangleHairParams& p = m_tri[f];
    m_curve[f] = curve_index.at(p.curve);
    m_material[f] = p.material.empty() ? uint16_t(0) : material_index.at(p.material);
    const Vec3& n = m_face_normals[f];
    if (n.squaredNorm() > 0)
      m_face_tangent[f] = surface_tangent(p.tangent.norm() > 0 ? p.tangent : params.comb, n);
    else
      m_face_tangent[f] = Vec3::Zero();
    m_grow[f] = !m_excluded[f] && p.density > 0 && m_face_area[f] > 0 && n.squaredNorm() > 0;
  }

  // Smooth variation: area-weighted vertex averages over the incident non-excluded triangles.
  if (params.smooth) {
    m_vertex.assign(nv, Corner{0, 0, 0, 0, 0, 0, Vec3::Zero(), Vec3::Zero(), 0});
    std::vector<double> wsum(nv, 0.0);
    struct CurveWeight {
      uint32_t v;
      uint16_t curve;
      double w;
    };
    std::vector<CurveWeight> cw;
    cw.reserve(3 * nf);
    for (std::size_t f = 0; f < nf; ++f) {
      if (m_excluded[f] || !(m_face_area[f] > 0)) continue;
      const double w = m_face_area[f];
      const TriangleHairParams& p = m_tri[f];
      for (int k = 0; k < 3; ++k) {
        const std::size_t v = std::size_t(m_faces[f][k]);
        Corner& c = m_vertex[v];
        c.jitter += w * p.jitter;
        c.angle_deg += w * p.angle_deg;
        c.angle_var_deg += w * p.angle_variation_deg;
        c.scale += w * p.scale;
        c.scale_var += w * p.scale_variation;
        c.density += w * p.density;
        c.tangent += w * m_face_tangent[f];
        wsum[v] += w;
        cw.push_back({uint32_t(v), m_curve[f], w});
      }
    }
    for (std::size_t v = 0; v < nv; ++v) {
      Corner& c = m_vertex[v];
      c.normal = m_vertex_normals[v];
      c.shape = 0;
      if (!(wsum[v] > 0)) continue;
      const double s = 1.0 / wsum[v];
      c.jitter *= s;
      c.angle_deg *= s;
      c.angle_var_deg *= s;
      c.scale *= s;
      c.scale_var *= s;
      c.density *= s;
      Vec3 t = c.tangent - c.tangent.dot(c.normal) * c.normal;
      c.tangent = t.norm() > 1e-12 ? Vec3(t.normalized()) : Vec3::Zero();
    }
    // Vertex curve shapes: the curve of the incident triangles, blended by area where they differ.
    std::sort(cw.begin(), cw.end(), [](const CurveWeight& a, const CurveWeight& b) {
      return a.v != b.v ? a.v < b.v : a.curve < b.curve;
    });
    for (std::size_t i = 0; i < cw.size();) {
      std::size_t j = i;
      while (j < cw.size() && cw[j].v == cw[i].v) ++j;
      const uint32_t v = cw[i].v;
      bool mixed = false;
      for (std::size_t k = i + 1; k < j; ++k) mixed = mixed || cw[k].curve != cw[i].curve;
      if (!mixed) {
        m_vertex[v].shape = cw[i].curve;
      } else {
        std::vector<Vec3> shape(P, Vec3::Zero());
        double total = 0.0;
        for (std::size_t k = i; k < j; ++k) total += cw[k].w;
        for (std::size_t k = i; k < j; ++k)
          for (std::size_t q = 0; q < P; ++q)
            shape[q] += (cw[k].w / total) * m_shapes[cw[k].curve][q];
        normalize_shape(shape);
        m_vertex[v].shape = uint32_t(m_shapes.size());
        m_shapes.push_back(std::move(shape));
      }
      i = j;
    }
  }
}

Vec3 HairStyler::surface_tangent(const Vec3& t, const Vec3& n) const {
  Vec3 p = t - t.dot(n) * n;
  if (p.norm() > 1e-9 * std::max(1.0, t.norm())) return p.normalized();
  p = m_params.comb - m_params.comb.dot(n) * n;
  if (p.norm() > 1e-6 * m_params.comb.norm()) return p.normalized();
  p = m_params.comb_fallback - m_params.comb_fallback.dot(n) * n;
  if (p.norm() > 1e-6 * m_params.comb_fallback.norm()) return p.normalized();
  return any_perpendicular(n);
}

void HairStyler::corners(std::size_t face, std::array<Corner, 3>& c) const {
  const Vec3i& t = m_faces[face];
  if (m_params.smooth) {
    for (int k = 0; k < 3; ++k) {
      c[std::size_t(k)] = m_vertex[std::size_t(t[k])];
      if (!m_params.blend_curves) c[std::size_t(k)].shape = m_curve[face];
    }
    return;
  }
  const TriangleHairParams& p = m_tri[face];
  const Corner k{p.jitter,          p.angle_deg, p.angle_variation_deg, p.scale,
                 p.scale_variation, p.density,   m_face_tangent[face],  m_face_normals[face],
                 m_curve[face]};
  c = {k, k, k};
}

TriangleHairParams HairStyler::triangle_params(std::size_t face) const {
  return m_tri.at(face);
}

Vec3 HairStyler::normal_at(std::size_t face, const Vec3& b) const {
  std::array<Corner, 3> c;
  corners(face, c);
  const Vec3 n = b[0] * c[0].normal + b[1] * c[1].normal + b[2] * c[2].normal;
  const double len = n.norm();
  return len > 1e-12 ? Vec3(n / len) : m_face_normals[face];
}

TriangleHairParams HairStyler::params_at(std::size_t face, const Vec3& b) const {
  if (m_excluded.at(face)) {  // no smoothed values: the triangle's own, without hairs
    TriangleHairParams p = m_tri[face];
    p.tangent = m_face_tangent[face];
    p.density = 0.0;
    return p;
  }
  std::array<Corner, 3> c;
  corners(face, c);
  auto lerp = [&](double Corner::*m) { return b[0] * c[0].*m + b[1] * c[1].*m + b[2] * c[2].*m; };
  TriangleHairParams p = m_tri.at(face);
  p.jitter = lerp(&Corner::jitter);
  p.angle_deg = lerp(&Corner::angle_deg);
  p.angle_variation_deg = lerp(&Corner::angle_var_deg);
  p.scale = lerp(&Corner::scale);
  p.scale_variation = lerp(&Corner::scale_var);
  p.density = m_grow[face] ? lerp(&Corner::density) : 0.0;
  const Vec3 n = normal_at(face, b);
  p.tangent = surface_tangent(b[0] * c[0].tangent + b[1] * c[1].tangent + b[2] * c[2].tangent, n);
  return p;
}

double HairStyler::expected_hairs(std::size_t face) const {
  if (!m_grow[face]) return 0.0;
  double d = m_tri[face].density;
  if (m_params.smooth) {
    const Vec3i& t = m_faces[face];
    d = (m_vertex[std::size_t(t[0])].density + m_vertex[std::size_t(t[1])].density +
         m_vertex[std::size_t(t[2])].density) /
        3.0;  // exact integral of the linearly interpolated density
  }
  return d * m_face_area[face] * m_params.density_scale;
}

double HairStyler::expected_total() const {
  double s = 0.0;
  for (std::size_t f = 0; f < m_faces.size(); ++f) s += expected_hairs(f);
  return s;
}

uint64_t HairStyler::face_key(std::size_t face) const {
  return Rng::stream(mix_seed(m_params.seed, m_tri[face].seed), face).next_u64();
}

std::vector<uint32_t> HairStyler::hair_counts(const Context& ctx) const {
  std::vector<uint32_t> counts(m_faces.size(), 0);
  parallel_for(
      ctx, 0, m_faces.size(),
      [&](std::size_t f) {
        const double e = expected_hairs(f);
        if (!(e > 0)) return;
        Rng rng = Rng::stream(face_key(f), 0);
        const double fl = std::floor(e);
        counts[f] = uint32_t(fl) + (rng.uniform() < e - fl ? 1u : 0u);  // stochastic rounding
      },
      512);
  return counts;
}

const std::vector<Vec3>& HairStyler::curve_shape(const std::string& name) const {
  for (std::size_t i = 0; i < m_curve_names.size(); ++i)
    if (m_curve_names[i] == name) return m_shapes[i];
  fail("hairstyler: unknown curve \"{}\"; known curves: {}", name, name_list(m_curve_names));
}

Groom HairStyler::grow(const Context& ctx) const {
  return grow_impl(ctx, nullptr);
}

Groom HairStyler::grow(const Context& ctx, const geom::TriMesh& deformed) const {
  if (deformed.positions.size() != m_positions.size() || deformed.faces != m_faces)
    fail(
        "hairstyler: the deformed mesh must have the rest mesh's topology ({} vertices, {} "
        "faces), got {} vertices, {} faces (or other face indices)",
        m_positions.size(), m_faces.size(), deformed.positions.size(), deformed.faces.size());
  return grow_impl(ctx, &deformed);
}

Groom HairStyler::grow_impl(const Context& ctx, const geom::TriMesh* deformed) const {
  const double expected = expected_total();
  if (expected > double(m_params.max_hairs))
    fail(
        "hairstyler: the style would grow about {:.0f} hairs (density × area × density_scale), "
        "more than max_hairs = {}; lower the densities or density_scale, or raise max_hairs",
        expected, m_params.max_hairs);
  const std::vector<uint32_t> counts = hair_counts(ctx);
  const std::size_t nf = m_faces.size();
  std::vector<uint64_t> first(nf + 1, 0);
  for (std::size_t f = 0; f < nf; ++f) first[f + 1] = first[f] + counts[f];
  const uint64_t total = first[nf];
  if (total > m_params.max_hairs)
    fail("hairstyler: the style grows {} hairs, more than max_hairs = {}", total,
         m_params.max_hairs);
  const std::size_t P = std::size_t(m_params.points_per_hair);
  if (total * P > std::numeric_limits<uint32_t>::max())
    fail("hairstyler: {} hairs × {} points exceed the strand set's 32-bit point offsets", total, P);

  std::vector<Vec3> def_normals;
  if (deformed) def_normals = vertex_normals_of(*deformed);

  Groom g;
  g.strands.offsets.resize(total + 1);
  g.strands.points.resize(total * P);
  g.strands.radius.resize(total * P);
  g.strands.color.resize(total * P);
  g.roots.resize(total);
  g.material.resize(total);
  for (uint64_t s = 0; s <= total; ++s) g.strands.offsets[s] = uint32_t(s * P);

  parallel_for(
      ctx, 0, nf,
      [&](std::size_t f) {
        const uint32_t n = counts[f];
        if (n == 0) return;
        std::array<Corner, 3> c;
        corners(f, c);
        const Vec3i& tri = m_faces[f];
        const std::array<Vec3, 3> X{m_positions[std::size_t(tri[0])],
                                    m_positions[std::size_t(tri[1])],
                                    m_positions[std::size_t(tri[2])]};
        std::array<Vec3, 3> Y = X, ND;
        Mat3 J = Mat3::Identity();
        if (deformed) {
          for (int k = 0; k < 3; ++k) {
            Y[std::size_t(k)] = deformed->positions[std::size_t(tri[k])];
            ND[std::size_t(k)] =
                m_params.smooth ? def_normals[std::size_t(tri[k])] : deformed->face_normal(f);
          }
          if (m_params.transport_tangent) J = triangle_jacobian(X[0], X[1], X[2], Y[0], Y[1], Y[2]);
        }
        const HairMaterial& mat = m_params.materials[m_material[f]];
        const Vec3f color = mat.color.cast<float>();
        const float radius = float(mat.radius);
        const bool same_shape = c[0].shape == c[1].shape && c[1].shape == c[2].shape;
        std::vector<Vec3> blended;
        if (!same_shape) blended.resize(P);
        const uint64_t key = face_key(f);
        const double length_scale = m_params.length_scale;
        for (uint32_t i = 0; i < n; ++i) {
          Rng rng = Rng::stream(key, uint64_t(i) + 1);
          const double r1 = rng.uniform(), r2 = rng.uniform(), r3 = rng.uniform(),
                       r4 = rng.uniform();
          // Root: lattice site i (the initial "symmetrical position"), jittered (§2).
          const double u = (i + 0.5) / n, v = wrap01(0.5 + i * kGolden);
          const Vec3 site = square_to_triangle(u, v);
          const double jit = site[0] * c[0].jitter + site[1] * c[1].jitter + site[2] * c[2].jitter;
          const Vec3 bd =
              square_to_triangle(wrap01(u + jit * (r1 - 0.5)), wrap01(v + jit * (r2 - 0.5)));
          const float b1 = float(bd[1]), b2 = float(bd[2]);
          const float b0 = std::max(0.0f, 1.0f - b1 - b2);
          const Vec3 b(b0, b1, b2);
          // Interpolated parameters at the root.
          auto lerp = [&](double Corner::*m) {
            return b[0] * c[0].*m + b[1] * c[1].*m + b[2] * c[2].*m;
          };
          Vec3 nrm = b[0] * c[0].normal + b[1] * c[1].normal + b[2] * c[2].normal;
          nrm = nrm.norm() > 1e-12 ? Vec3(nrm.normalized()) : m_face_normals[f];
          Vec3 t =
              surface_tangent(b[0] * c[0].tangent + b[1] * c[1].tangent + b[2] * c[2].tangent, nrm);
          // Orientation: rotation about the normal by the angle plus its random variation.
          const double ang =
              (lerp(&Corner::angle_deg) + lerp(&Corner::angle_var_deg) * (2.0 * r3 - 1.0)) *
              (kPi / 180.0);
          t = std::cos(ang) * t + std::sin(ang) * nrm.cross(t);
          // Scale with its random variation.
          const double len = lerp(&Corner::scale) * length_scale *
                             (1.0 + lerp(&Corner::scale_var) * (2.0 * r4 - 1.0));
          Vec3 root = b[0] * X[0] + b[1] * X[1] + b[2] * X[2];
          if (deformed) {
            Vec3 nd = b[0] * ND[0] + b[1] * ND[1] + b[2] * ND[2];
            nd = nd.norm() > 1e-12 ? Vec3(nd.normalized()) : nrm;
            t = correct_tangent(m_params.transport_tangent ? Vec3(J * t) : t, nd);
            nrm = nd;
            root = b[0] * Y[0] + b[1] * Y[1] + b[2] * Y[2];
          }
          const Vec3 bn = t.cross(nrm);
          const std::vector<Vec3>* shape = &m_shapes[c[0].shape];
          if (!same_shape) {
            const auto& s0 = m_shapes[c[0].shape];
            const auto& s1 = m_shapes[c[1].shape];
            const auto& s2 = m_shapes[c[2].shape];
            for (std::size_t q = 0; q < P; ++q)
              blended[q] = b[0] * s0[q] + b[1] * s1[q] + b[2] * s2[q];
            normalize_shape(blended);
            shape = &blended;
          }
          const std::size_t s = std::size_t(first[f] + i);
          Vec3f* out = g.strands.points.data() + s * P;
          for (std::size_t q = 0; q < P; ++q) {
            const Vec3& l = (*shape)[q];
            out[q] = (root + len * (l.x() * t + l.y() * nrm + l.z() * bn)).cast<float>();
          }
          std::fill_n(g.strands.radius.data() + s * P, P, radius);
          std::fill_n(g.strands.color.data() + s * P, P, color);
          g.roots[s] = RootBinding{int32_t(f), Vec3f(b0, b1, b2)};
          g.material[s] = m_material[f];
        }
      },
      16);
  return g;
}

Groom grow_hairstyler(const Context& ctx, const geom::TriMesh& mesh, const HairStylerParams& params,
                      const StylerInputs& inputs) {
  return HairStyler(mesh, params, inputs).grow(ctx);
}

// ---- presets ---------------------------------------------------------------------------------

HeadLandmarks head_landmarks(const geom::TriMesh& mesh, const Vec3& up_in, const Vec3& front_in) {
  if (mesh.positions.empty()) fail("head_landmarks: the mesh has no vertices");
  if (!(up_in.norm() > 0)) fail("head_landmarks: the up direction is zero");
  HeadLandmarks L;
  L.up = up_in.normalized();
  const Vec3 fr = front_in - front_in.dot(L.up) * L.up;
  if (!(fr.norm() > 1e-9 * std::max(1.0, front_in.norm())))
    fail("head_landmarks: the front direction is zero or parallel to up");
  L.front = fr.normalized();
  L.left = L.up.cross(L.front);
  double top = -1e300, bottom = 1e300, lat_min = 1e300, lat_max = -1e300;
  for (const Vec3& p : mesh.positions) {
    const double h = p.dot(L.up), l = p.dot(L.left);
    if (h > top) {
      top = h;
      L.top = p;
    }
    bottom = std::min(bottom, h);
    lat_min = std::min(lat_min, l);
    lat_max = std::max(lat_max, l);
  }
  const double mid = 0.5 * (lat_min + lat_max);
  double best = -1e300;
  for (const Vec3& p : mesh.positions)
    if (p.dot(L.up) >= bottom + 0.25 * (top - bottom) && p.dot(L.front) > best) {
      best = p.dot(L.front);
      L.nose_tip = p;
    }
  L.nose_tip += (mid - L.nose_tip.dot(L.left)) * L.left;
  const double nose_h = L.nose_tip.dot(L.up), nose_f = L.nose_tip.dot(L.front);
  L.unit = top - nose_h;
  if (!(L.unit > 0)) fail("head_landmarks: the nose tip is at the top of the mesh");
  L.back = nose_f;
  for (const Vec3& p : mesh.positions)
    if (p.dot(L.up) >= nose_h) L.back = std::min(L.back, p.dot(L.front));
  double lmax = -1e300, lmin = 1e300;
  L.left_ear = L.right_ear = L.nose_tip;
  for (const Vec3& p : mesh.positions) {
    const double h = p.dot(L.up), f = p.dot(L.front), l = p.dot(L.left);
    if (h < nose_h - 0.1 * L.unit || h > nose_h + 0.4 * L.unit) continue;
    if (f > nose_f - 0.3 * L.unit) continue;
    if (l > lmax) {
      lmax = l;
      L.left_ear = p;
    }
    if (l < lmin) {
      lmin = l;
      L.right_ear = p;
    }
  }
  return L;
}

std::vector<std::string> styler_preset_names() {
  return {"long", "beard", "moustache", "eyebrows", "fur"};
}

namespace {

HairRegion all_excluded() {
  HairRegion r;
  r.name = "nothing";
  r.select = RegionSelect::All;
  r.exclude = true;
  return r;
}
HairRegion half_space(const char* name, const Vec3& point, const Vec3& normal,
                      std::optional<bool> exclude) {
  HairRegion r;
  r.name = name;
  r.select = RegionSelect::HalfSpace;
  r.point = point;
  r.normal = normal.normalized();
  r.exclude = exclude;
  return r;
}
HairRegion sphere(const char* name, const Vec3& centre, double radius,
                  std::optional<bool> exclude) {
  HairRegion r;
  r.name = name;
  r.select = RegionSelect::Sphere;
  r.centre = centre;
  r.radius = radius;
  r.exclude = exclude;
  return r;
}
// Normal of the plane through a and b containing `axis`, oriented along `towards`.
Vec3 plane_normal(const Vec3& a, const Vec3& b, const Vec3& axis, const Vec3& towards) {
  Vec3 n = (b - a).cross(axis).normalized();
  return n.dot(towards) >= 0 ? n : Vec3(-n);
}

}  // namespace

HairStylerParams styler_preset(std::string_view name, const geom::TriMesh& mesh, const Vec3& up,
                               const Vec3& front) {
  const HeadLandmarks L = head_landmarks(mesh, up, front);
  const double u = L.unit;
  const double nose_f = L.nose_tip.dot(L.front);
  // A point at (height above the nose tip, front coordinate) on the midline, in units of u.
  auto mid = [&](double height, double front_coord) {
    return Vec3(L.nose_tip + height * u * L.up + (front_coord - nose_f) * L.front);
  };
  HairStylerParams p;
  p.comb = -L.up;
  p.comb_fallback = -L.front;
  p.defaults.jitter = 1.0;
  HairMaterial mat;
  if (name == "long") {
    mat.name = "brown";
    p.defaults.curve = "swept";
    p.defaults.scale = 0.16;
    p.defaults.scale_variation = 0.15;
    p.defaults.angle_variation_deg = 6.0;
    p.defaults.density = 2.2e6;
    p.regions.push_back(all_excluded());
    // Scalp: above the plane through the front hairline and the nape (containing the lateral
    // axis), so the hair comes down to the nape at the back and stops at the forehead.
    const Vec3 hairline = mid(0.74, nose_f - 0.3 * u);
    const Vec3 nape = mid(-0.22, L.back + 0.2 * u);
    p.regions.push_back(
        half_space("scalp", nape, plane_normal(nape, hairline, L.left, L.up - L.front), false));
    p.regions.push_back(sphere("left ear", L.left_ear, 0.28 * u, true));
    p.regions.push_back(sphere("right ear", L.right_ear, 0.28 * u, true));
    HairRegion fringe = half_space("swept back", L.at(0.0, 0.0, -0.6), L.front, std::nullopt);
    fringe.tangent = -L.front - 0.3 * L.up;
    p.regions.push_back(fringe);
  } else if (name == "beard") {
    mat.name = "dark brown";
    mat.color = Vec3(0.12, 0.08, 0.05);
    mat.radius = 50e-6;
    p.defaults.curve = "beard";
    p.defaults.scale = 0.025;
    p.defaults.scale_variation = 0.3;
    p.defaults.angle_variation_deg = 12.0;
    p.defaults.density = 1.0e6;
    const double ear_f = 0.5 * (L.left_ear.dot(L.front) + L.right_ear.dot(L.front));
    p.regions.push_back(all_excluded());
    // Below the line from just under the mouth (front) to the sideburns (at the ears).
    const Vec3 chin_top = mid(-0.40, nose_f - 0.1 * u);
    const Vec3 sideburn = mid(0.1, ear_f + 0.15 * u);
    p.regions.push_back(
        half_space("jaw", chin_top, plane_normal(chin_top, sideburn, L.left, -L.up), false));
    p.regions.push_back(half_space("ears and behind", mid(0.0, ear_f + 0.05 * u), -L.front, true));
    p.regions.push_back(half_space("above the sideburns", mid(0.12, nose_f), L.up, true));
    p.regions.push_back(half_space("neck", mid(-0.85, nose_f), -L.up, true));
    p.regions.push_back(sphere("lips", L.at(0.0, -0.37, -0.15), 0.2 * u, true));
  } else if (name == "moustache") {
    mat.name = "dark brown";
    mat.color = Vec3(0.12, 0.08, 0.05);
    mat.radius = 50e-6;
    p.defaults.curve = "beard";
    p.defaults.scale = 0.014;
    p.defaults.scale_variation = 0.2;
    p.defaults.angle_variation_deg = 10.0;
    p.defaults.density = 2.0e6;
    p.regions.push_back(all_excluded());
    p.regions.push_back(half_space("upper lip", L.at(0.0, -0.3, 0.0), L.up, false));
    p.regions.push_back(half_space("nose", L.at(0.0, -0.1, 0.0), L.up, true));
    p.regions.push_back(half_space("left cheek", L.at(0.26, 0.0, 0.0), L.left, true));
    p.regions.push_back(half_space("right cheek", L.at(-0.26, 0.0, 0.0), -L.left, true));
    p.regions.push_back(half_space("cheeks", L.at(0.0, 0.0, -0.28), -L.front, true));
    HairRegion left = half_space("left half", L.nose_tip, L.left, std::nullopt);
    left.tangent = -L.up + 0.5 * L.left;
    HairRegion right = half_space("right half", L.nose_tip, -L.left, std::nullopt);
    right.tangent = -L.up - 0.5 * L.left;
    p.regions.push_back(left);
    p.regions.push_back(right);
  } else if (name == "eyebrows") {
    mat.name = "dark brown";
    mat.color = Vec3(0.12, 0.08, 0.05);
    mat.radius = 35e-6;
    p.defaults.curve = "eyebrow";
    p.defaults.scale = 0.011;
    p.defaults.scale_variation = 0.25;
    p.defaults.angle_variation_deg = 12.0;
    p.defaults.density = 2.5e6;
    p.regions.push_back(all_excluded());
    HairRegion left = sphere("left brow", L.at(0.27, 0.36, -0.2), 0.21 * u, false);
    left.tangent = L.left + 0.3 * L.up;
    HairRegion right = sphere("right brow", L.at(-0.27, 0.36, -0.2), 0.21 * u, false);
    right.tangent = -L.left + 0.3 * L.up;
    p.regions.push_back(left);
    p.regions.push_back(right);
    p.regions.push_back(half_space("above", L.at(0.0, 0.45, 0.0), L.up, true));
    p.regions.push_back(half_space("below", L.at(0.0, 0.29, 0.0), -L.up, true));
  } else if (name == "fur") {
    mat.name = "fur";
    mat.color = Vec3(0.35, 0.25, 0.15);
    mat.radius = 30e-6;
    p.defaults.curve = "fur";
    p.defaults.scale = 0.012;
    p.defaults.scale_variation = 0.2;
    p.defaults.angle_variation_deg = 20.0;
    p.defaults.density = 5.0e5;
  } else {
    const auto names = styler_preset_names();
    const std::string hint = did_you_mean(name, names);
    fail("unknown HairStyler preset \"{}\"{}; expected one of {}", name, hint_text(hint),
         name_list(names));
  }
  p.materials = {mat};
  return p;
}

}  // namespace follicle::hair
