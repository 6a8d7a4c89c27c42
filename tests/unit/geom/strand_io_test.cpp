#include "follicle/geom/strand_io.hpp"

#include <gtest/gtest.h>

#include <cstring>

#include "follicle/core/atomic_file.hpp"
#include "follicle/core/error.hpp"
#include "testing/testing.hpp"

using namespace follicle;
using namespace follicle::geom;

static StrandSet sample_strands(bool extras) {
  StrandSet s;
  for (int h = 0; h < 5; ++h) {
    const int n = 3 + h * 2;
    for (int i = 0; i < n; ++i) {
      s.points.push_back(Vec3f(0.01f * h, 0.1f - 0.013f * i, 0.002f * i * h));
      if (extras) {
        s.radius.push_back(4e-5f + 1e-6f * i);
        s.color.push_back(Vec3f(0.1f * h, 0.05f * i, 0.3f));
      }
    }
    s.offsets.push_back(uint32_t(s.points.size()));
  }
  return s;
}

TEST(StrandIo, HairRoundTripIsBitExact) {
  const auto dir = test::scratch_dir("strand_io_hair");
  for (bool extras : {false, true}) {
    const StrandSet s = sample_strands(extras);
    const auto path = dir / (extras ? "a.hair" : "b.hair");
    save_strands(s, path, LengthUnit::m);
    const std::string bytes = read_file(path);
    EXPECT_EQ(bytes.compare(0, 4, "HAIR"), 0);
    const StrandSet r = load_strands(path, LengthUnit::m);
    EXPECT_EQ(r.offsets, s.offsets);
    EXPECT_TRUE(r.points == s.points);
    EXPECT_TRUE(r.color == s.color);
    // File -> raw -> file is byte-identical.
    EXPECT_EQ(serialize_cyhair(parse_cyhair(bytes, "x")), bytes);
  }
}

TEST(StrandIo, TfxRoundTripIsBitExact) {
  const StrandSet s = sample_strands(false);
  const TfxFile f = strands_to_tfx(s, LengthUnit::cm, 8);
  EXPECT_EQ(f.num_strands, 5u);
  EXPECT_EQ(f.verts_per_strand, 8u);
  const std::string bytes = serialize_tfx(f);
  EXPECT_EQ(bytes.size(), 160u + 5 * 8 * 16);
  EXPECT_EQ(serialize_tfx(parse_tfx(bytes, "x")), bytes);
  const StrandSet r = tfx_to_strands(parse_tfx(bytes, "x"), LengthUnit::cm);
  ASSERT_EQ(r.num_strands(), 5u);
  // Resampling keeps the end points exactly (up to the unit conversion).
  for (std::size_t h = 0; h < 5; ++h) {
    EXPECT_NEAR((r.points[r.strand_begin(h)] - s.points[s.strand_begin(h)]).norm(), 0, 1e-7);
    EXPECT_NEAR((r.points[r.strand_begin(h) + 7] - s.points[s.offsets[h + 1] - 1]).norm(), 0, 1e-7);
  }
  // A second write of the resampled set does not resample again: identical bytes.
  EXPECT_EQ(serialize_tfx(strands_to_tfx(tfx_to_strands(parse_tfx(bytes, "x"), LengthUnit::m),
                                         LengthUnit::m, 8)),
            bytes);
  EXPECT_THROW(strands_to_tfx(s, LengthUnit::m, 12), Error);
}

TEST(StrandIo, SintelImports228By32) {
  FOLLICLE_REQUIRE_SHARED("sintel-lite-hair/GEO-sintel_hair_emit.001-sintel_hair.tfx");
  const auto path =
      test::shared_data_dir() / "sintel-lite-hair/GEO-sintel_hair_emit.001-sintel_hair.tfx";
  const std::string bytes = read_file(path);
  const TfxFile f = parse_tfx(bytes, path.string());
  EXPECT_EQ(f.num_strands, 228u);
  EXPECT_EQ(f.verts_per_strand, 32u);
  EXPECT_EQ(serialize_tfx(f), bytes);  // bit-exact round trip of a real file
  // Blender units, read as centimetres (head ~20 units tall).
  const StrandSet s = load_strands(path, LengthUnit::cm);
  EXPECT_EQ(s.num_strands(), 228u);
  for (std::size_t h = 0; h < s.num_strands(); ++h) EXPECT_EQ(s.strand_size(h), 32u);
  Eigen::AlignedBox3f box;
  for (const auto& p : s.points) box.extend(p);
  EXPECT_NEAR(box.min().y(), 0.2072f, 1e-3f);
  EXPECT_NEAR(box.max().y(), 0.4769f, 1e-3f);
  for (std::size_t h = 0; h < 228; ++h)
    EXPECT_EQ(f.positions[4 * 32 * h + 3], 0.0f);  // pinned roots
}

TEST(StrandIo, MalformedFilesFailCleanly) {
  const std::string hair = serialize_cyhair(strands_to_cyhair(sample_strands(true), LengthUnit::m));
  for (std::size_t cut : {0ul, 3ul, 100ul, 130ul, hair.size() - 1})
    EXPECT_THROW(parse_cyhair(hair.substr(0, cut), "t.hair"), Error) << cut;
  std::string bad = hair;
  bad[0] = 'X';
  EXPECT_THROW(parse_cyhair(bad, "t.hair"), Error);
  bad = hair;
  uint32_t huge = 0x7fffffff;
  std::memcpy(bad.data() + 8, &huge, 4);  // point count
  EXPECT_THROW(parse_cyhair(bad, "t.hair"), Error);
  bad = hair;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(bad.data() + 128 + 10 + 4, &nan, 4);  // first point's y
  EXPECT_THROW(parse_cyhair(bad, "t.hair"), Error);
  try {
    parse_cyhair(hair.substr(0, 140), "t.hair");
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("t.hair"), std::string::npos);
  }

  const std::string tfx = serialize_tfx(strands_to_tfx(sample_strands(false), LengthUnit::m, 8));
  for (std::size_t cut : {0ul, 159ul, 200ul, tfx.size() - 4})
    EXPECT_THROW(parse_tfx(tfx.substr(0, cut), "t.tfx"), Error) << cut;
  bad = tfx;
  uint32_t v = 7;
  std::memcpy(bad.data() + 8, &v, 4);  // not a power of two
  EXPECT_THROW(parse_tfx(bad, "t.tfx"), Error);
  bad = tfx;
  uint32_t n = 0xffffffffu;
  std::memcpy(bad.data() + 4, &n, 4);  // strand count beyond the file
  EXPECT_THROW(parse_tfx(bad, "t.tfx"), Error);
  EXPECT_THROW(load_strands("x.abc", LengthUnit::m), Error);
}

TEST(StrandIo, UsdaAndObjWriters) {
  const StrandSet s = sample_strands(true);
  const std::string usda = strands_to_usda(s, LengthUnit::cm);
  EXPECT_EQ(usda.rfind("#usda 1.0", 0), 0u);
  EXPECT_NE(usda.find("def BasisCurves"), std::string::npos);
  EXPECT_NE(usda.find("int[] curveVertexCounts = [3, 5, 7, 9, 11]"), std::string::npos);
  EXPECT_NE(usda.find("metersPerUnit = 0.01"), std::string::npos);
  const std::string obj = strands_to_obj(s, LengthUnit::m);
  std::size_t nv = 0, nl = 0;
  for (std::size_t i = 0; i < obj.size(); ++i)
    if (i == 0 || obj[i - 1] == '\n') {
      nv += obj.compare(i, 2, "v ") == 0;
      nl += obj.compare(i, 2, "l ") == 0;
    }
  EXPECT_EQ(nv, s.num_points());
  EXPECT_EQ(nl, s.num_strands());
}
