#pragma once
// ParamEditor: a visit() visitor that draws Dear ImGui widgets for a parameter struct, so every
// struct with `template <class V> void visit(V&&)` gets a panel for free (the same field lists
// drive JSON, validation and docs):
//   double/float/int/unsigned -> slider when ParamInfo has a finite [min, max], else a drag field
//   bool -> checkbox, Vec2/Vec3 -> DragFloat2/3 (colour picker for "*color"/"background" in
//   [0, 1]), std::string -> text field, named enums -> combo, nested structs and vectors of
//   structs -> tree nodes. ParamInfo::doc and ::unit appear as a tooltip and in the number format.
//
// Adding a panel for new parameters (hair, skin, ...) is one line:
//   changed |= edit_params("Anjyo 1992 cantilever", group.params);
// followed by `params.validate()` in a try/catch when `changed` is true.
#include <imgui.h>
#include <imgui_stdlib.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "follicle/core/params.hpp"
#include "follicle/core/types.hpp"
#include "follicle/scene/json_params.hpp"

namespace follicle::viewer {

class ParamEditor {
 public:
  /// `hidden`: field names of the top level not shown (e.g. width/height that the window size
  /// controls); nested structs show every field (hair[].render is not the scene's render).
  explicit ParamEditor(std::vector<std::string> hidden = {}) : m_hidden(std::move(hidden)) {}

  /// True when any widget changed a value since construction.
  bool changed() const { return m_changed; }

  template <class T>
  void operator()(const char* name, T& value, const ParamInfo& info = {}) {
    for (const auto& h : m_hidden)
      if (h == name) return;
    ImGui::PushID(name);
    m_changed |= edit(name, value, info);
    ImGui::PopID();
  }

 private:
  static bool finite_range(const ParamInfo& info) {
    return std::isfinite(info.min) && std::isfinite(info.max) && info.min < info.max;
  }
  static void tooltip(const ParamInfo& info) {
    if (*info.doc && ImGui::IsItemHovered()) {
      if (*info.unit)
        ImGui::SetTooltip("%s [%s]", info.doc, info.unit);
      else
        ImGui::SetTooltip("%s", info.doc);
    }
  }
  static std::string number_format(const ParamInfo& info, const char* base) {
    std::string f = base;
    if (*info.unit) (f += " ") += info.unit;
    return f;
  }
  /// A logarithmic slider for ranges over several decades (clip planes, light intensity
  /// 0..100, shadow map size), so the usual values are not squeezed into the first pixels.
  static ImGuiSliderFlags slider_flags(double lo, double hi) {
    const bool decades = lo > 0 ? hi / lo >= 1000 : (lo == 0 && hi >= 50);
    return (decades ? ImGuiSliderFlags_Logarithmic : ImGuiSliderFlags_None) |
           ImGuiSliderFlags_AlwaysClamp;
  }
  static std::string fmt_label(const char* name, const char* unit) {
    return std::string(name) + " [" + unit + "]";
  }
  static bool looks_like_color(std::string_view name, const ParamInfo& info) {
    const bool unit_range = info.min == 0.0 && info.max == 1.0;
    return unit_range && (name.ends_with("color") || name == "background" || name == "rho_d");
  }

  template <class T>
  bool edit(const char* name, T& value, const ParamInfo& info) {
    bool ch = false;
    if constexpr (std::is_same_v<T, bool>) {
      ch = ImGui::Checkbox(name, &value);
      tooltip(info);
    } else if constexpr (std::is_floating_point_v<T>) {
      double v = double(value);
      const std::string fmt = number_format(info, "%.4g");
      if (finite_range(info)) {
        const double lo = info.min, hi = info.max;
        const ImGuiSliderFlags flags = slider_flags(lo, hi);
        ch = ImGui::SliderScalar(name, ImGuiDataType_Double, &v, &lo, &hi, fmt.c_str(), flags);
      } else {
        const double speed = std::max(1e-4, std::abs(v) * 0.01);
        const double lo = std::isfinite(info.min) ? info.min : -1e300;
        const double hi = std::isfinite(info.max) ? info.max : 1e300;
        ch = ImGui::DragScalar(name, ImGuiDataType_Double, &v, float(speed), &lo, &hi, fmt.c_str(),
                               ImGuiSliderFlags_AlwaysClamp);
      }
      tooltip(info);
      if (ch) value = T(v);
    } else if constexpr (std::is_integral_v<T>) {
      // int, unsigned, uint64_t: edited as a 64-bit signed value, clamped to the field's type.
      int64_t v = int64_t(value);
      const int64_t type_lo = std::is_signed_v<T> ? int64_t(std::numeric_limits<T>::min()) : 0;
      const int64_t type_hi =
          int64_t(std::min<uint64_t>(uint64_t(std::numeric_limits<T>::max()), INT64_MAX));
      const int64_t lo = std::isfinite(info.min) ? int64_t(std::ceil(info.min)) : type_lo;
      const int64_t hi = std::isfinite(info.max) ? int64_t(std::floor(info.max)) : type_hi;
      const std::string fmt = number_format(info, "%lld");
      if (finite_range(info)) {
        const ImGuiSliderFlags flags = slider_flags(double(lo), double(hi));
        ch = ImGui::SliderScalar(name, ImGuiDataType_S64, &v, &lo, &hi, fmt.c_str(), flags);
      } else {
        ch = ImGui::DragScalar(name, ImGuiDataType_S64, &v, 1.0f, &lo, &hi, fmt.c_str(),
                               ImGuiSliderFlags_AlwaysClamp);
      }
      tooltip(info);
      if (ch) value = T(v);
    } else if constexpr (std::is_same_v<T, Vec3> || std::is_same_v<T, Vec2>) {
      constexpr int n = int(T::RowsAtCompileTime);
      float f[3];
      for (int i = 0; i < n; ++i) f[i] = float(value[i]);
      if (n == 3 && looks_like_color(name, info)) {
        ch = ImGui::ColorEdit3(name, f, ImGuiColorEditFlags_Float);
      } else {
        const float lo = std::isfinite(info.min) ? float(info.min) : 0.0f;
        const float hi = std::isfinite(info.max) ? float(info.max) : 0.0f;  // 0, 0 = unbounded
        float speed = 0.005f;
        for (int i = 0; i < n; ++i) speed = std::max(speed, 0.005f * std::abs(f[i]));
        // The unit goes into the label: three numbers plus units do not fit the fields.
        const std::string label = *info.unit ? fmt_label(name, info.unit) : std::string(name);
        ch = n == 3 ? ImGui::DragFloat3(label.c_str(), f, speed, lo, hi, "%.4g")
                    : ImGui::DragFloat2(label.c_str(), f, speed, lo, hi, "%.4g");
      }
      tooltip(info);
      if (ch)
        for (int i = 0; i < n; ++i) value[i] = double(f[i]);
    } else if constexpr (std::is_same_v<T, std::string>) {
      // Edited in a copy and committed on Enter / focus loss, so a half-typed path is not used.
      std::string buf = value;
      if (ImGui::InputText(name, &buf, ImGuiInputTextFlags_EnterReturnsTrue) ||
          (ImGui::IsItemDeactivatedAfterEdit() && buf != value)) {
        ch = buf != value;
        value = buf;
      }
      tooltip(info);
    } else if constexpr (scene::detail::NamedEnum<T>) {
      const char* current = "?";
      for (const auto& [e, n] : follicle_enum_names(T{}))
        if (e == value) current = n;
      if (ImGui::BeginCombo(name, current)) {
        for (const auto& [e, n] : follicle_enum_names(T{})) {
          if (ImGui::Selectable(n, e == value) && e != value) {
            value = e;
            ch = true;
          }
        }
        ImGui::EndCombo();
      }
      tooltip(info);
    } else if constexpr (requires(T & t, ParamEditor & ed) { t.visit(ed); }) {
      if (ImGui::TreeNodeEx(name, ImGuiTreeNodeFlags_None)) {
        tooltip(info);
        ParamEditor inner;  // `hidden` names fields of the top level only
        value.visit(inner);
        ch = inner.changed();
        ImGui::TreePop();
      } else {
        tooltip(info);
      }
    } else if constexpr (requires(T & t) {
                           t.has_value();
                           *t;
                           typename T::value_type;
                         }) {
      // std::optional of an editable struct: edited when present (absent sections are added in
      // the scene file).
      if (value.has_value()) {
        ch = edit(name, *value, info);
      } else {
        ImGui::TextDisabled("%s (absent)", name);
        tooltip(info);
      }
    } else if constexpr (scene::detail::vector_of_visitable<T>::value) {
      if (ImGui::TreeNodeEx(name, ImGuiTreeNodeFlags_None, "%s (%zu)", name, value.size())) {
        tooltip(info);
        for (std::size_t i = 0; i < value.size(); ++i) {
          const std::string label = std::string(name) + "[" + std::to_string(i) + "]";
          ch |= edit(label.c_str(), value[i], ParamInfo{});
        }
        ImGui::TreePop();
      } else {
        tooltip(info);
      }
    } else {
      ImGui::TextDisabled("%s (not editable here)", name);
    }
    return ch;
  }

  std::vector<std::string> m_hidden;
  bool m_changed = false;
};

/// Draws the fields of `params` and returns true when one changed. `hidden` lists names to skip.
template <class P>
bool edit_params(P& params, std::vector<std::string> hidden = {}) {
  ParamEditor ed(std::move(hidden));
  params.visit(ed);
  return ed.changed();
}

}  // namespace follicle::viewer
