// libFuzzer target: Cem Yuksel .hair, in memory, the steps of geom::load_strands: parse_cyhair,
// cyhair_to_strands, StrandSet::check; a parsed file is also serialized again.
#include "follicle/geom/strand_io.hpp"
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes = follicle::fuzz::as_string(data, size);
  follicle::fuzz::expect_ok_or_error([&] {
    const auto f = follicle::geom::parse_cyhair(bytes, "fuzz.hair");
    (void)follicle::geom::serialize_cyhair(f);
    const auto s = follicle::geom::cyhair_to_strands(f, follicle::LengthUnit::mm);
    if (s.num_strands() > 0) s.check("fuzz.hair");
  });
  return 0;
}
