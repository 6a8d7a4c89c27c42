/* stb_image compiled with the fuzzer's instrumentation for fuzz_png: the executable's definitions
   take precedence over Debian's libstb.so, so the decoder the library calls is this one. */
#define STB_IMAGE_IMPLEMENTATION
#include <stb_image.h>
