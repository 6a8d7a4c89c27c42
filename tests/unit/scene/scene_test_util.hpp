#pragma once
// Shared helpers of the scene tests: the shipped scenes folder, reading a shipped scene as JSON,
// and the error message read_scene gives for a JSON document ("" when it is accepted).
#include <filesystem>
#include <string>

#include "follicle/core/error.hpp"
#include "follicle/scene/scene.hpp"
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

}  // namespace follicle::scene::testutil
