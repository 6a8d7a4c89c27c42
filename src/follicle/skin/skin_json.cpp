#include "follicle/skin/skin_json.hpp"

#include <nlohmann/json.hpp>
#include <set>
#include <type_traits>

#include "follicle/core/atomic_file.hpp"
#include "follicle/core/error.hpp"

namespace follicle::skin {

namespace {

using Json = nlohmann::json;

template <class T>
struct is_vec : std::false_type {};
template <class T, class A>
struct is_vec<std::vector<T, A>> : std::true_type {};
template <class T>
struct is_map : std::false_type {};
template <class T>
struct is_map<std::map<std::string, T>> : std::true_type {};

std::string describe(const Json& j) {
  if (j.is_string()) return "a string \"" + j.get<std::string>() + "\"";
  if (j.is_number()) return "a number " + j.dump();
  if (j.is_boolean()) return "a boolean";
  if (j.is_array()) return "an array";
  if (j.is_object()) return "an object";
  return "null";
}

// Hand-written instead of scene/json_params: skin may not include scene (layering).
struct Reader {
  const std::string& file;
  [[noreturn]] void bad(const std::string& path, const std::string& what) const {
    throw Error(file.empty() ? path : file + ": " + path, what);
  }
  double num(const Json& j, const std::string& path) const {
    if (!j.is_number()) bad(path, "expected a number, got " + describe(j));
    return j.get<double>();
  }
  template <class T>
  void read(const Json& j, const std::string& path, T& out, const ParamInfo& info) const {
    if constexpr (std::is_same_v<T, bool>) {
      if (!j.is_boolean()) bad(path, "expected true or false, got " + describe(j));
      out = j.get<bool>();
    } else if constexpr (std::is_same_v<T, std::string>) {
      if (!j.is_string()) bad(path, "expected a string, got " + describe(j));
      out = j.get<std::string>();
    } else if constexpr (std::is_integral_v<T>) {
      const double v = num(j, path);
      if (v != std::floor(v)) bad(path, "expected an integer, got " + j.dump());
      range(path, v, info);
      out = T(v);
    } else if constexpr (std::is_floating_point_v<T>) {
      const double v = num(j, path);
      range(path, v, info);
      out = T(v);
    } else if constexpr (std::is_same_v<T, Vec2> || std::is_same_v<T, Vec3>) {
      if (!j.is_array() || j.size() != std::size_t(out.size()))
        bad(path,
            "expected an array of " + std::to_string(out.size()) + " numbers, got " + describe(j));
      for (int k = 0; k < out.size(); ++k) {
        out[k] = num(j[std::size_t(k)], path + "[" + std::to_string(k) + "]");
        range(path, out[k], info);
      }
    } else if constexpr (is_vec<T>::value) {
      if (!j.is_array()) bad(path, "expected an array, got " + describe(j));
      out.clear();
      for (std::size_t i = 0; i < j.size(); ++i) {
        typename T::value_type x{};
        read(j[i], path + "[" + std::to_string(i) + "]", x, info);
        out.push_back(std::move(x));
      }
    } else if constexpr (is_map<T>::value) {
      if (!j.is_object()) bad(path, "expected an object, got " + describe(j));
      out.clear();
      for (auto it = j.begin(); it != j.end(); ++it) {
        if (it.key().rfind("//", 0) == 0) continue;
        typename T::mapped_type x{};
        read(it.value(), path + "." + it.key(), x, info);
        out[it.key()] = x;
      }
    } else {
      read_struct(j, path, out);
    }
  }
  static void range(const std::string& path, double v, const ParamInfo& info) {
    if (!std::isfinite(v)) fail_at(path, "value is not finite");
    if (v < info.min || v > info.max)
      fail_at(path, "value {} is out of range: expected {} in [{}, {}]{}", v, info.doc, info.min,
              info.max, *info.unit ? std::string(" ") + info.unit : std::string());
  }
  template <class S>
  void read_struct(const Json& j, const std::string& path, S& s) const {
    if (!j.is_object())
      bad(path.empty() ? "(top level)" : path, "expected an object, got " + describe(j));
    std::vector<std::string> known;
    std::set<std::string> found;
    auto join = [&](const char* k) { return path.empty() ? std::string(k) : path + "." + k; };
    s.visit([&](const char* name, auto& field, const ParamInfo& info = {}) {
      known.emplace_back(name);
      auto it = j.find(name);
      if (it == j.end()) return;
      found.insert(name);
      try {
        read(*it, join(name), field, info);
      } catch (const Error& e) {
        if (!file.empty() && std::string(e.what()).rfind(file, 0) != 0) throw Error(file, e.what());
        throw;
      }
    });
    for (auto it = j.begin(); it != j.end(); ++it) {
      if (it.key().rfind("//", 0) == 0 || found.count(it.key())) continue;
      const std::string d = did_you_mean(it.key(), known);
      std::string list;
      for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
      bad(join(it.key().c_str()), "unknown key" +
                                      (d.empty() ? std::string() : " (did you mean '" + d + "'?)") +
                                      "; expected one of: " + list);
    }
    if constexpr (requires { S::kRequired; }) {
      for (const char* k : S::kRequired)
        if (!j.contains(k))
          bad(path.empty() ? "(top level)" : path, std::string("missing required key '") + k + "'");
    }
  }
};

Json parse(const std::string& text, const std::string& file) {
  try {
    return Json::parse(text);
  } catch (const Json::parse_error& e) {
    throw Error(file.empty() ? "json" : file, std::string("JSON syntax error: ") + e.what());
  } catch (const Json::exception& e) {  // e.g. out_of_range 406: 1e9999 overflows a double
    throw Error(file.empty() ? "json" : file, std::string("invalid JSON: ") + e.what());
  }
}

struct Writer {
  template <class T>
  static Json write(const T& v) {
    if constexpr (std::is_same_v<T, Vec2> || std::is_same_v<T, Vec3>) {
      Json a = Json::array();
      for (int k = 0; k < v.size(); ++k) a.push_back(v[k]);
      return a;
    } else if constexpr (is_vec<T>::value) {
      Json a = Json::array();
      for (const auto& x : v) a.push_back(write(x));
      return a;
    } else if constexpr (is_map<T>::value) {
      Json o = Json::object();
      for (const auto& [k, x] : v) o[k] = write(x);
      return o;
    } else if constexpr (std::is_class_v<T> && !std::is_same_v<T, std::string>) {
      Json o = Json::object();
      const_cast<T&>(v).visit(
          [&](const char* name, auto& f, const ParamInfo& = {}) { o[name] = write(f); });
      return o;
    } else {
      return Json(v);
    }
  }
};

}  // namespace

FaceSetup face_setup_from_json_text(const std::string& text, const std::string& file) {
  const Json j = parse(text, file);
  FaceSetup s;
  Reader{file}.read_struct(j, "", s);
  try {
    s.muscles.validate();
    for (const auto& w : s.wrinkles) w.validate();
    for (const auto& w : s.surface_wrinkles) w.validate();
    if (s.up.norm() < 1e-9 || s.front.norm() < 1e-9 ||
        s.up.normalized().cross(s.front.normalized()).norm() < 1e-3)
      fail("up and front must be non-zero and not parallel, got [{}, {}, {}] and [{}, {}, {}]",
           s.up.x(), s.up.y(), s.up.z(), s.front.x(), s.front.y(), s.front.z());
  } catch (const Error& e) {
    throw Error(file, e.what());
  }
  return s;
}

FaceSetup load_face_setup(const std::filesystem::path& path) {
  return face_setup_from_json_text(read_file(path), path.string());
}

std::vector<LargeWrinkle> wrinkles_from_json_text(const std::string& text,
                                                  const std::string& file) {
  const Json j = parse(text, file);
  std::vector<LargeWrinkle> w;
  Reader{file}.read(j, "wrinkles", w, ParamInfo{});
  for (const auto& x : w) x.validate();
  return w;
}

std::string face_setup_to_json(const FaceSetup& s) {
  return Writer::write(s).dump(2);
}

}  // namespace follicle::skin
