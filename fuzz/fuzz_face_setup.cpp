// libFuzzer target: face-setup JSON (data/muscles/*.json): skin::face_setup_from_json_text and
// the wrinkle-list reader skin::wrinkles_from_json_text on the same bytes.
#include "follicle/skin/skin_json.hpp"
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text = follicle::fuzz::as_string(data, size);
  follicle::fuzz::expect_ok_or_error(
      [&] { (void)follicle::skin::face_setup_from_json_text(text, "fuzz.json"); });
  follicle::fuzz::expect_ok_or_error(
      [&] { (void)follicle::skin::wrinkles_from_json_text(text, "fuzz.json"); });
  return 0;
}
