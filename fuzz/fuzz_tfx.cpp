// libFuzzer target: TressFX .tfx, in memory, the steps of geom::load_strands: parse_tfx,
// tfx_to_strands, StrandSet::check; a parsed file is also serialized again.
#include "follicle/geom/strand_io.hpp"
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes = follicle::fuzz::as_string(data, size);
  follicle::fuzz::expect_ok_or_error([&] {
    const auto f = follicle::geom::parse_tfx(bytes, "fuzz.tfx");
    (void)follicle::geom::serialize_tfx(f);
    const auto s = follicle::geom::tfx_to_strands(f, follicle::LengthUnit::cm);
    if (s.num_strands() > 0) s.check("fuzz.tfx");
  });
  return 0;
}
