#pragma once
// Strict JSON <-> parameter struct mapping, driven by the same visit() field lists that
// core/params.hpp uses for validation (`v("name", field, ParamInfo{...})`).
//
//   read_json(json, "camera", camera, src)   JSON object -> struct. Rejects unknown keys (with the
//                                             JSON path and a did-you-mean), wrong types ("expected
//                                             a number, got a string \"x\""), out-of-range values
//                                             (ParamInfo min/max), missing required keys.
//   to_json(camera)                           struct -> JSON object (every field).
//   doc_rows<Camera>("camera")                struct -> markdown table rows (docs/scene-format.md).
//
// Supported field types: bool, integers, float/double, std::string, fixed-size Eigen vectors
// (Vec2, Vec3, Vec4, Vec3i, ...), enums with an ADL `follicle_enum_names(E)` table, nested
// parameter structs (with visit()), std::vector<T>, std::map<std::string, T>, std::optional<T>.
//
// A struct lists its required keys as `static constexpr const char* kRequired[] = {"path"};`.
// Keys starting with "//" are comments and are ignored everywhere.
#include <array>
#include <cmath>
#include <concepts>
#include <filesystem>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "follicle/core/error.hpp"
#include "follicle/core/params.hpp"
#include "follicle/core/types.hpp"
#include "follicle/core/units.hpp"

namespace follicle {
// Names for core's LengthUnit, found by ADL from the reader.
inline constexpr std::array<std::pair<LengthUnit, const char*>, 4> follicle_enum_names(LengthUnit) {
  return {{{LengthUnit::mm, "mm"},
           {LengthUnit::cm, "cm"},
           {LengthUnit::dm, "dm"},
           {LengthUnit::m, "m"}}};
}
}  // namespace follicle

namespace follicle::scene {

using Json = nlohmann::json;

/// Where JSON came from, for error messages ("scenes/x.json: camera.fov_deg: ...").
struct JsonSource {
  std::string file;  // may be empty (e.g. a string parsed in a test)
};

/// Parses a JSON file. Syntax errors become follicle::Error("<file>:<line>:<col>", ...);
/// duplicate keys in an object are an error too (nlohmann would silently keep the last one).
Json parse_json_file(const std::filesystem::path& path);
Json parse_json_text(const std::string& text, const std::string& file_for_errors);

/// "a string \"abc\"", "a number 3.5", "an array", ... for "expected X, got Y" messages.
std::string describe_json(const Json& j);
/// Child paths: join_path("a", "b") == "a.b", index_path("a", 2) == "a[2]".
std::string join_path(const std::string& path, const std::string& key);
std::string index_path(const std::string& path, std::size_t i);
/// Throws follicle::Error("<file>: <path>", what).
[[noreturn]] void json_fail(const JsonSource& src, const std::string& path,
                            const std::string& what);
/// The most plausible intended name for a mistyped `key` ("" when nothing is close).
std::string suggest(const std::string& key, const std::vector<std::string>& known);
/// Throws the unknown-key error with a did-you-mean and the list of accepted keys.
[[noreturn]] void json_fail_unknown_key(const JsonSource& src, const std::string& path,
                                        const std::string& key,
                                        const std::vector<std::string>& known);
inline bool is_comment_key(const std::string& k) {
  return k.size() >= 2 && k[0] == '/' && k[1] == '/';
}

namespace detail {

template <class T>
struct is_vector : std::false_type {};
template <class T, class A>
struct is_vector<std::vector<T, A>> : std::true_type {};
template <class T>
struct is_map : std::false_type {};
template <class T, class C, class A>
struct is_map<std::map<std::string, T, C, A>> : std::true_type {};
template <class T>
struct is_optional : std::false_type {};
template <class T>
struct is_optional<std::optional<T>> : std::true_type {};
template <class T>
struct is_eigen_vec : std::false_type {};
template <class S, int N, int O, int MR, int MC>
struct is_eigen_vec<Eigen::Matrix<S, N, 1, O, MR, MC>> : std::bool_constant<(N > 0)> {};

template <class E>
concept NamedEnum = std::is_enum_v<E> && requires(E e) {
  follicle_enum_names(e);
};

template <class T>
concept Visitable = std::is_class_v<T> && !std::is_base_of_v<Eigen::EigenBase<T>, T> &&
                    !std::is_same_v<T, std::string> && requires(T & t, ParamValidator& v) {
  t.visit(v);
};

template <class T>
struct vector_of_visitable : std::false_type {};
template <class T, class A>
struct vector_of_visitable<std::vector<T, A>> : std::bool_constant<Visitable<T>> {};
template <class T>
struct map_of_visitable : std::false_type {};
template <class T, class C, class A>
struct map_of_visitable<std::map<std::string, T, C, A>> : std::bool_constant<Visitable<T>> {};

template <class T>
concept HasRequired = requires {
  T::kRequired;
};

// A field type with its own JSON form (e.g. "a preset name or a full object"): it reads and
// writes itself and names its type for the docs. `DocObject` (a visitable struct) documents the
// object form's keys.
template <class T>
concept CustomJson = requires(T& t, const T& ct, const Json& j, const std::string& p,
                              const JsonSource& s) {
  t.read_json_custom(j, p, s);
  { ct.to_json_custom() } -> std::same_as<Json>;
  { T::doc_type_custom() } -> std::convertible_to<std::string>;
  typename T::DocObject;
};

template <NamedEnum E>
std::vector<std::string> enum_name_list() {
  std::vector<std::string> out;
  for (const auto& [e, n] : follicle_enum_names(E{})) out.emplace_back(n);
  return out;
}

template <NamedEnum E>
std::string enum_to_string(E value) {
  for (const auto& [e, n] : follicle_enum_names(E{}))
    if (e == value) return n;
  return "?";
}

std::string quoted_list(const std::vector<std::string>& names);
std::string format_bound(double v);
void check_number_range(const JsonSource& src, const std::string& path, double v,
                        const ParamInfo& info);

// Collects the field names of a struct (for unknown-key checks and required keys).
struct NameCollector {
  std::vector<std::string> names;
  template <class T>
  void operator()(const char* name, T&, const ParamInfo& = {}) {
    names.emplace_back(name);
  }
};

}  // namespace detail

template <class T>
void read_json(const Json& j, const std::string& path, T& out, const JsonSource& src,
               const ParamInfo& info = {});

namespace detail {

struct FieldReader {
  const Json& obj;
  const std::string& path;
  const JsonSource& src;
  template <class T>
  void operator()(const char* name, T& field, const ParamInfo& info = {}) {
    auto it = obj.find(name);
    if (it != obj.end()) read_json(*it, join_path(path, name), field, src, info);
  }
};

}  // namespace detail

/// Reads `j` into `out` (which keeps its defaults for absent keys). See the file comment.
template <class T>
void read_json(const Json& j, const std::string& path, T& out, const JsonSource& src,
               const ParamInfo& info) {
  using namespace detail;
  if constexpr (CustomJson<T>) {
    out.read_json_custom(j, path, src);
  } else if constexpr (std::is_same_v<T, bool>) {
    if (!j.is_boolean()) json_fail(src, path, "expected true or false, got " + describe_json(j));
    out = j.get<bool>();
  } else if constexpr (std::is_integral_v<T>) {
    if (!j.is_number()) json_fail(src, path, "expected an integer, got " + describe_json(j));
    const double d = j.get<double>();
    if (j.is_number_float() && (d != std::floor(d) || !std::isfinite(d)))
      json_fail(src, path, "expected an integer, got " + describe_json(j));
    if (d < double(std::numeric_limits<T>::lowest()) || d > double(std::numeric_limits<T>::max()))
      json_fail(src, path, "value " + j.dump() + " does not fit the integer field");
    check_number_range(src, path, d, info);
    out = j.is_number_float() ? T(d) : j.get<T>();
  } else if constexpr (std::is_floating_point_v<T>) {
    if (!j.is_number()) json_fail(src, path, "expected a number, got " + describe_json(j));
    const double d = j.get<double>();
    check_number_range(src, path, d, info);
    out = T(d);
  } else if constexpr (std::is_same_v<T, std::string>) {
    if (!j.is_string()) json_fail(src, path, "expected a string, got " + describe_json(j));
    out = j.get<std::string>();
  } else if constexpr (NamedEnum<T>) {
    const auto names = enum_name_list<T>();
    if (!j.is_string())
      json_fail(src, path, "expected one of " + quoted_list(names) + ", got " + describe_json(j));
    const auto s = j.get<std::string>();
    for (const auto& [e, n] : follicle_enum_names(T{})) {
      if (s == n) {
        out = e;
        return;
      }
    }
    const std::string hint = suggest(s, names);
    json_fail(src, path,
              "unknown value \"" + s + "\"" +
                  (hint.empty() ? "" : " (did you mean \"" + hint + "\"?)") + "; expected one of " +
                  quoted_list(names));
  } else if constexpr (is_eigen_vec<T>::value) {
    constexpr int n = T::RowsAtCompileTime;
    if (!j.is_array() || j.size() != std::size_t(n))
      json_fail(src, path,
                "expected an array of " + std::to_string(n) + " numbers, got " + describe_json(j));
    for (int i = 0; i < n; ++i)
      read_json(j[std::size_t(i)], index_path(path, std::size_t(i)), out[i], src, info);
  } else if constexpr (is_optional<T>::value) {
    typename T::value_type v{};
    if (out) v = *out;
    read_json(j, path, v, src, info);
    out = std::move(v);
  } else if constexpr (is_vector<T>::value) {
    if (!j.is_array()) json_fail(src, path, "expected an array, got " + describe_json(j));
    T result;
    result.resize(j.size());
    for (std::size_t i = 0; i < j.size(); ++i)
      read_json(j[i], index_path(path, i), result[i], src, info);
    out = std::move(result);
  } else if constexpr (is_map<T>::value) {
    if (!j.is_object()) json_fail(src, path, "expected an object, got " + describe_json(j));
    T result;
    for (const auto& [k, v] : j.items()) {
      if (is_comment_key(k)) continue;
      read_json(v, join_path(path, k), result[k], src, info);
    }
    out = std::move(result);
  } else if constexpr (Visitable<T>) {
    if (!j.is_object()) json_fail(src, path, "expected an object, got " + describe_json(j));
    NameCollector names;
    out.visit(names);
    for (const auto& [k, v] : j.items()) {
      if (is_comment_key(k)) continue;
      bool known = false;
      for (const auto& n : names.names) known = known || n == k;
      if (!known) json_fail_unknown_key(src, path, k, names.names);
    }
    if constexpr (HasRequired<T>) {
      for (const char* r : T::kRequired)
        if (!j.contains(r)) json_fail(src, path, std::string("missing required key \"") + r + "\"");
    }
    FieldReader reader{j, path, src};
    out.visit(reader);
  } else {
    static_assert(sizeof(T) == 0, "read_json: unsupported field type");
  }
}

// ---- writer ----

template <class T>
Json to_json(const T& value);

namespace detail {
struct FieldWriter {
  Json& obj;
  template <class T>
  void operator()(const char* name, T& field, const ParamInfo& = {}) {
    if constexpr (is_optional<T>::value) {
      if (!field) return;
    }
    obj[name] = to_json(field);
  }
};
}  // namespace detail

/// Struct (or any supported field type) -> JSON. Absent optionals are left out.
template <class T>
Json to_json(const T& value) {
  using namespace detail;
  if constexpr (CustomJson<T>) {
    return value.to_json_custom();
  } else if constexpr (std::is_same_v<T, bool> || std::is_arithmetic_v<T> ||
                       std::is_same_v<T, std::string>) {
    return Json(value);
  } else if constexpr (NamedEnum<T>) {
    return Json(enum_to_string(value));
  } else if constexpr (is_eigen_vec<T>::value) {
    Json a = Json::array();
    for (int i = 0; i < T::RowsAtCompileTime; ++i) a.push_back(value[i]);
    return a;
  } else if constexpr (is_optional<T>::value) {
    return value ? to_json(*value) : Json();
  } else if constexpr (is_vector<T>::value) {
    Json a = Json::array();
    for (const auto& e : value) a.push_back(to_json(e));
    return a;
  } else if constexpr (is_map<T>::value) {
    Json o = Json::object();
    for (const auto& [k, v] : value) o[k] = to_json(v);
    return o;
  } else if constexpr (Visitable<T>) {
    Json o = Json::object();
    FieldWriter w{o};
    const_cast<T&>(value).visit(w);
    return o;
  } else {
    static_assert(sizeof(T) == 0, "to_json: unsupported field type");
  }
}

// ---- documentation ----

/// One documented key: "camera.fov_deg", "number", "deg", "0.6", "[1, 179]", "vertical ...".
struct DocRow {
  std::string key, type, unit, default_value, range, doc;
};

namespace detail {

template <class T>
std::string doc_type_name() {
  if constexpr (CustomJson<T>)
    return T::doc_type_custom();
  else if constexpr (std::is_same_v<T, bool>)
    return "boolean";
  else if constexpr (std::is_integral_v<T>)
    return "integer";
  else if constexpr (std::is_floating_point_v<T>)
    return "number";
  else if constexpr (std::is_same_v<T, std::string>)
    return "string";
  else if constexpr (NamedEnum<T>)
    return "one of " + quoted_list(enum_name_list<T>());
  else if constexpr (is_eigen_vec<T>::value)
    return "array of " + std::to_string(T::RowsAtCompileTime) +
           (std::is_integral_v<typename T::Scalar> ? " integers" : " numbers");
  else if constexpr (is_optional<T>::value)
    return doc_type_name<typename T::value_type>();
  else if constexpr (is_vector<T>::value) {
    using E = typename T::value_type;
    if constexpr (Visitable<E>)
      return "array of objects";
    else
      return "array of " + doc_type_name<E>();
  } else if constexpr (is_map<T>::value)
    return "object (name → value)";
  else if constexpr (Visitable<T>)
    return "object";
  else
    static_assert(sizeof(T) == 0, "doc: unsupported field type");
}

std::string doc_range(const ParamInfo& info, bool numeric);
std::string doc_default(const Json& j);

template <class P>
void collect_doc_rows(const std::string& prefix, P& p, std::vector<DocRow>& rows);

struct DocCollector {
  std::string prefix;
  std::vector<DocRow>& rows;
  std::vector<std::string> required;
  template <class T>
  void operator()(const char* name, T& field, const ParamInfo& info = {}) {
    const std::string key = prefix.empty() ? name : prefix + "." + name;
    bool req = false;
    for (const auto& r : required) req = req || r == name;
    constexpr bool numeric = std::is_arithmetic_v<T> && !std::is_same_v<T, bool>;
    constexpr bool vec_numeric = is_eigen_vec<T>::value;
    DocRow row{key,
               doc_type_name<T>(),
               info.unit,
               req ? std::string("required") : doc_default(to_json(field)),
               doc_range(info, numeric || vec_numeric),
               info.doc};
    if constexpr (CustomJson<T>) {
      rows.push_back(row);
      typename T::DocObject elem{};
      collect_doc_rows(key, elem, rows);
    } else if constexpr (Visitable<T>) {
      row.default_value = "";
      rows.push_back(row);
      collect_doc_rows(key, field, rows);
    } else if constexpr (is_optional<T>::value) {
      if constexpr (Visitable<typename T::value_type>) {
        row.default_value = "absent";
        rows.push_back(row);
        typename T::value_type elem{};
        collect_doc_rows(key, elem, rows);
      } else {
        rows.push_back(row);
      }
    } else if constexpr (vector_of_visitable<T>::value) {
      rows.push_back(row);
      typename T::value_type elem{};
      collect_doc_rows(key + "[]", elem, rows);
    } else if constexpr (map_of_visitable<T>::value) {
      rows.push_back(row);
      typename T::mapped_type elem{};
      collect_doc_rows(key + ".<name>", elem, rows);
    } else {
      rows.push_back(row);
    }
  }
};

template <class P>
void collect_doc_rows(const std::string& prefix, P& p, std::vector<DocRow>& rows) {
  DocCollector c{prefix, rows, {}};
  if constexpr (HasRequired<P>)
    for (const char* r : P::kRequired) c.required.emplace_back(r);
  p.visit(c);
}

}  // namespace detail

/// Every key of P (recursively, `a.b`, `list[].c`), with type, unit, default, range and doc.
template <class P>
std::vector<DocRow> doc_rows(const std::string& prefix) {
  P p{};
  std::vector<DocRow> rows;
  detail::collect_doc_rows(prefix, p, rows);
  return rows;
}

/// A markdown table of rows (header included).
std::string doc_table(const std::vector<DocRow>& rows);

}  // namespace follicle::scene
