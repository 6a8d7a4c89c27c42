#pragma once
// Shared helpers of the scene tests: the shipped scenes folder, reading a shipped scene as JSON,
// the error message read_scene gives for a JSON document ("" when it is accepted), and the one
// building skin rig 0 gives.
#include <filesystem>
#include <string>

#include "follicle/core/error.hpp"
#include "follicle/scene/scene.hpp"
#include "follicle/scene/session.hpp"
#include "testing/testing.hpp"

namespace follicle::scene::testutil {

inline std::filesystem::path scenes_dir() {
  return test::source_dir() / "data" / "scenes";
}

inline Json scene_json(const std::string& name) {
  return parse_json_file(scenes_dir() / (name + ".json"));
}

inline std::string read_error(const Json& j) {
  try {
    read_scene(j, JsonSource{"x.json"});
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

/// The error building skin rig 0 of the scene `j` (its first frame) gives; "" when it builds.
inline std::string rig_error(const Json& j) {
  Context ctx(1);
  try {
    auto s = Session::from_json(j, scenes_dir(), "x.json", ctx);
    (void)s.skin_mesh(0, 0);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace follicle::scene::testutil
