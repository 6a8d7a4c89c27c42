#pragma once
// Strict JSON reading of skin parameter structs (muscle sets, expressions, wrinkles). The structs
// are visit()-able, so the scene layer can read them with its generic reader too; this small
// reader exists so skin assets (data/muscles/*.json) load without the scene module.
// Unknown keys, wrong types, out-of-range values and missing required keys fail with the file
// and JSON path. Keys starting with "//" are comments.
#include <filesystem>
#include <string>
#include <vector>

#include "follicle/skin/large_wrinkles_bando2002.hpp"
#include "follicle/skin/muscles_waters1987.hpp"
#include "follicle/skin/wrinkle_transfer.hpp"

namespace follicle::skin {

/// A face's skin setup as stored in data/muscles/<head>.json.
struct FaceSetup {
  int follicle_face = 1;  // format version
  MuscleSet muscles;
  std::vector<LargeWrinkle> wrinkles;
  std::vector<SurfaceWrinkle> surface_wrinkles;
  Vec3 up = Vec3::UnitY();     // the head's up in the mesh's frame (`follicle fit` finds it)
  Vec3 front = Vec3::UnitZ();  // the direction the face looks
  template <class V>
  void visit(V&& v) {
    v("follicle_face", follicle_face, ParamInfo{"format version", "", 1, 1});
    v("muscles", muscles, ParamInfo{"muscle set", ""});
    v("wrinkles", wrinkles,
      ParamInfo{"large-scale wrinkles: Bezier curves in the texture space of the mesh the setup "
                "was made for",
                ""});
    v("surface_wrinkles", surface_wrinkles,
      ParamInfo{"large-scale wrinkles given by points on the skin (metres, the mesh's frame): "
                "placed on whatever texture layout the mesh has or is given",
                ""});
    v("up", up,
      ParamInfo{"the head's up direction in the mesh's frame (written by follicle fit; a record "
                "of the fit, the scene's assets.meshes[].up is what hair and mapping use)",
                "", -1e3, 1e3});
    v("front", front,
      ParamInfo{"the direction the face looks, mesh frame (written by follicle fit)", "", -1e3,
                1e3});
  }
  static constexpr const char* kRequired[] = {"follicle_face", "muscles"};
};

FaceSetup face_setup_from_json_text(const std::string& text,
                                    const std::string& file_for_errors = "");
FaceSetup load_face_setup(const std::filesystem::path& path);
std::vector<LargeWrinkle> wrinkles_from_json_text(const std::string& text,
                                                  const std::string& file_for_errors = "");
std::string face_setup_to_json(const FaceSetup& s);

}  // namespace follicle::skin
