// libFuzzer target: USD ASCII BasisCurves (geom::usda_to_strands, in memory) + StrandSet::check.
#include "follicle/geom/strand_io.hpp"
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text = follicle::fuzz::as_string(data, size);
  follicle::fuzz::expect_ok_or_error([&] {
    follicle::geom::StrandFileInfo info;
    const auto s =
        follicle::geom::usda_to_strands(text, "fuzz.usda", follicle::LengthUnit::m, &info);
    if (s.num_strands() > 0) s.check("fuzz.usda");
  });
  return 0;
}
