// libFuzzer target: scene JSON, the whole validation path of `follicle validate` up to the assets:
// scene::parse_json_text (syntax, duplicate keys) + Session::from_json (strict keys, types,
// ranges, cross-checks, referenced files). Relative asset paths resolve against an empty folder,
// so a missing asset is an ordinary follicle::Error.
#include "follicle/core/context.hpp"
#include "follicle/scene/json_params.hpp"
#include "follicle/scene/session.hpp"
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const follicle::Context ctx(1);
  static const std::filesystem::path base = follicle::fuzz::process_dir() / "scene-base";
  static const bool made = std::filesystem::create_directories(base);
  (void)made;
  const std::string text = follicle::fuzz::as_string(data, size);
  follicle::fuzz::expect_ok_or_error([&] {
    const auto j = follicle::scene::parse_json_text(text, "fuzz.json");
    (void)follicle::scene::Session::from_json(j, base, "fuzz.json", ctx);
  });
  return 0;
}
