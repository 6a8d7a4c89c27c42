// libFuzzer target: PNG through stb and JPEG through libjpeg-turbo (image::read_png_rgba,
// read_gray_map). stb_image is compiled into this target instrumented (stb_image_instrumented.c)
// so libFuzzer sees its coverage; it is the same header the library uses through Debian's libstb.
// libjpeg-turbo is Debian's shared library, not instrumented: for JPEG inputs coverage counts
// Follicle's code only.
#include "follicle/image/image_io.hpp"
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto path = follicle::fuzz::write_input(data, size, ".png");
  follicle::fuzz::expect_ok_or_error([&] { (void)follicle::image::read_png_rgba(path); });
  follicle::fuzz::expect_ok_or_error([&] { (void)follicle::image::read_gray_map(path); });
  return 0;
}
