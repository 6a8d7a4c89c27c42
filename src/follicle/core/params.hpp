#pragma once
// Parameter structs: plain aggregates with SI defaults and one list of fields, visit(), used for
// JSON reading/writing, validation, documentation and viewer sliders:
//
//   struct GustParams {
//     double speed = 5.0;  // [m/s]
//     template <class V> void visit(V&& v) {
//       v("speed", speed, ParamInfo{"peak wind speed", "m/s", 0.0, 100.0});
//     }
//     void validate() const { validate_params(*this, "gust"); }
//   };
//
// Supported field types: double, float, int, unsigned, uint64_t, bool, std::string, Vec2, Vec3
// and nested parameter structs (which have their own visit()).
#include <cmath>
#include <limits>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "follicle/core/error.hpp"
#include "follicle/core/types.hpp"

namespace follicle {

struct ParamInfo {
  const char* doc = "";
  const char* unit = "";
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
};

/// Checks every numeric field is finite and inside [min, max]; throws follicle::Error naming
/// `where.field`, the value and the bound.
class ParamValidator {
 public:
  explicit ParamValidator(std::string where) : m_where(std::move(where)) {}

  template <class T>
  void operator()(const char* name, T& value, const ParamInfo& info = {}) {
    const std::string path = m_where.empty() ? name : m_where + "." + name;
    if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>) {
      check(path, double(value), info);
    } else if constexpr (std::is_same_v<T, Vec2> || std::is_same_v<T, Vec3>) {
      for (int i = 0; i < value.size(); ++i) check(path, value[i], info);
    } else if constexpr (std::is_class_v<T> && !std::is_same_v<T, std::string>) {
      if constexpr (requires { value.visit(*this); }) {
        ParamValidator inner(path);
        value.visit(inner);
      }
    }
  }

 private:
  static void check(const std::string& path, double v, const ParamInfo& info) {
    if (!std::isfinite(v)) fail_at(path, "value {} is not a finite number", v);
    if (v < info.min || v > info.max)
      fail_at(path, "value {} is out of range: expected {} in [{}, {}]{}", v, info.doc, info.min,
              info.max, *info.unit ? std::string(" ") + info.unit : std::string());
  }
  std::string m_where;
};

template <class P>
void validate_params(const P& p, const std::string& where) {
  ParamValidator v(where);
  const_cast<P&>(p).visit(v);
}

/// Edit distance (Levenshtein), for did-you-mean suggestions.
std::size_t edit_distance(std::string_view a, std::string_view b);
/// The closest candidate to `key` when it is close enough to be a plausible typo, else "".
std::string did_you_mean(std::string_view key, const std::vector<std::string>& candidates);

}  // namespace follicle
