#include "follicle/scene/skin_section.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <set>

#include "follicle/anim/keyframe_track.hpp"
#include "follicle/core/error.hpp"

namespace follicle::scene {

skin::SkinColorParams SkinColorSpec::resolve() const {
  skin::SkinColorParams p = skin::skin_color_preset(preset);
  if (melanin) p.melanin = *melanin;
  if (hemoglobin) p.hemoglobin = *hemoglobin;
  return p;
}

void validate_skin_section(const std::vector<SkinSpec>& skin,
                           const std::vector<std::string>& mesh_names, bool has_animation,
                           const JsonSource& src) {
  const std::set<std::string> names(mesh_names.begin(), mesh_names.end());
  std::set<std::string> rigged;
  for (std::size_t i = 0; i < skin.size(); ++i) {
    const auto& s = skin[i];
    const std::string p = index_path("skin", i);
    if (s.mesh.empty()) json_fail(src, p + ".mesh", "mesh name is empty");
    if (!names.count(s.mesh)) {
      std::vector<std::string> known;
      for (const auto& n : mesh_names)
        if (!n.empty()) known.push_back(n);
      const std::string hint = suggest(s.mesh, known);
      json_fail(src, p + ".mesh",
                "no mesh asset named \"" + s.mesh + "\"" +
                    (hint.empty() ? "" : " (did you mean \"" + hint + "\"?)") +
                    "; a face rig deforms a mesh of assets.meshes with that name");
    }
    if (!rigged.insert(s.mesh).second)
      json_fail(src, p + ".mesh", "mesh \"" + s.mesh + "\" already has a face rig");
    if (s.muscles.empty() && s.blendshapes.empty())
      json_fail(src, p + ".muscles",
                "a face rig needs a face-setup file (\"muscles\") or blendshape targets "
                "(\"blendshapes\"), or both");
    // Blendshape targets: unique names, and every weight names one.
    std::vector<std::string> shape_names;
    for (std::size_t k = 0; k < s.blendshapes.size(); ++k) {
      const auto& b = s.blendshapes[k];
      const std::string bp = index_path(p + ".blendshapes", k);
      if (b.name.empty()) json_fail(src, bp + ".name", "target name is empty");
      if (b.path.empty()) json_fail(src, bp + ".path", "target path is empty");
      for (const auto& n : shape_names)
        if (n == b.name) json_fail(src, bp + ".name", "two targets are named \"" + b.name + "\"");
      shape_names.push_back(b.name);
    }
    auto check_shapes = [&](const std::map<std::string, double>& w, const std::string& at) {
      for (const auto& [name, value] : w) {
        (void)value;
        if (std::find(shape_names.begin(), shape_names.end(), name) != shape_names.end()) continue;
        const std::string hint = suggest(name, shape_names);
        json_fail(
            src, at + "." + name,
            "no blendshape target named \"" + name + "\"" +
                (hint.empty() ? "" : " (did you mean \"" + hint + "\"?)") +
                (shape_names.empty() ? "; skin[].blendshapes is empty"
                                     : "; the targets are " + detail::quoted_list(shape_names)));
      }
    };
    check_shapes(s.shapes, p + ".shapes");
    for (std::size_t k = 0; k < s.track.size(); ++k)
      check_shapes(s.track[k].shapes, index_path(p + ".track", k) + ".shapes");
    try {
      s.color.resolve();
    } catch (const Error& e) {
      json_fail(src, p + ".color.preset", e.what());
    }
    try {
      (void)anim::parse_interp(s.interp);
    } catch (const Error&) {
      json_fail(
          src, p + ".interp",
          "unknown value \"" + s.interp + "\"; expected one of \"step\", \"linear\", \"smooth\"");
    }
    try {
      s.mapping.validate();
    } catch (const Error& e) {
      json_fail(src, p + ".mapping", e.what());
    }
    for (std::size_t k = 0; k < s.add_surface_wrinkles.size(); ++k) {
      try {
        s.add_surface_wrinkles[k].validate();
      } catch (const Error& e) {
        json_fail(src, index_path(p + ".add_surface_wrinkles", k), e.what());
      }
    }
    const bool own_uvs = s.mapping.method == geom::MappingMethod::Uv ||
                         s.mapping.method == geom::MappingMethod::Auto;
    if (!own_uvs && s.albedo == SkinAlbedo::Texture)
      json_fail(src, p + ".albedo",
                fmt::format("\"texture\" needs the mesh's own texture coordinates, and "
                            "mapping.method is \"{}\": use \"skin_color\" or mapping \"uv\"",
                            geom::to_string(s.mapping.method)));
    if (!own_uvs && !s.tissue.thickness_map.empty())
      json_fail(src, p + ".tissue.thickness_map",
                fmt::format("a thickness map is painted in the mesh's own texture space, and "
                            "mapping.method is \"{}\": drop the map or use mapping \"uv\"",
                            geom::to_string(s.mapping.method)));
    std::set<std::string> over;
    for (std::size_t k = 0; k < s.wrinkle_overrides.size(); ++k)
      if (!over.insert(s.wrinkle_overrides[k].name).second)
        json_fail(src, index_path(p + ".wrinkle_overrides", k) + ".name",
                  "wrinkle \"" + s.wrinkle_overrides[k].name + "\" is overridden twice");
    if (!s.track.empty() && !has_animation)
      json_fail(src, p + ".track",
                "a contraction track needs an \"animation\" section (fps and frames or duration)");
    for (std::size_t k = 1; k < s.track.size(); ++k)
      if (!(s.track[k].t > s.track[k - 1].t))
        json_fail(src, index_path(p + ".track", k) + ".t",
                  fmt::format("key times must increase strictly ({} after {})", s.track[k].t,
                              s.track[k - 1].t));
    if (s.fine) {
      const std::string fp = p + ".fine";
      for (int f = 0; f < 2; ++f) {
        const auto& keys = f == 0 ? s.fine->field0 : s.fine->field1;
        const std::string kp = fp + (f == 0 ? ".field0" : ".field1");
        if (keys.empty())
          json_fail(src, kp, "a fine-wrinkle field needs at least one direction key");
        for (std::size_t k = 0; k < keys.size(); ++k) {
          const auto& key = keys[k];
          const std::string at = index_path(kp, k);
          if (int(key.vertex.has_value()) + int(key.uv.has_value()) + int(key.point.has_value()) !=
              1)
            json_fail(src, at,
                      "give exactly one of \"vertex\" (uv vertex index), \"uv\" (texture "
                      "position) or \"point\" (a point on the skin)");
          if (key.direction.has_value() == key.tangent.has_value())
            json_fail(src, at,
                      "give exactly one of \"direction\" (texture space) or \"tangent\" (on the "
                      "skin)");
          const double m = key.direction ? key.direction->norm() : key.tangent->norm();
          if (!(m <= 1.0 + 1e-9))
            json_fail(src, at + (key.direction ? ".direction" : ".tangent"),
                      fmt::format("direction magnitude {} is out of range: expected [0, 1]", m));
        }
      }
    }
  }
}

}  // namespace follicle::scene
