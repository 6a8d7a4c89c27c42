// libFuzzer target: OpenEXR (image::read_exr_rgba, read_exr_gray). OpenEXR itself is Debian's
// shared library, not instrumented: coverage counts Follicle's code only.
#include "follicle/image/image_io.hpp"
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto path = follicle::fuzz::write_input(data, size, ".exr");
  follicle::fuzz::expect_ok_or_error([&] { (void)follicle::image::read_exr_rgba(path); });
  follicle::fuzz::expect_ok_or_error([&] { (void)follicle::image::read_exr_gray(path); });
  return 0;
}
