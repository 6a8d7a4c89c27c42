#include "follicle/geom/strand_io.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <functional>

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

// ---------------------------------------------------------------------------------------------
// Text formats (USD ASCII, OBJ polylines), round trips, units and lying files.

namespace {

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "<no error>";
}

// Expects follicle::Error whose message contains every piece.
void expect_error(const std::function<void()>& f, std::initializer_list<std::string> pieces) {
  const std::string msg = error_of(f);
  for (const auto& p : pieces) EXPECT_NE(msg.find(p), std::string::npos) << msg;
}

StrandSet usda(const std::string& text, LengthUnit unit = LengthUnit::m,
               StrandFileInfo* info = nullptr) {
  return usda_to_strands(text, "t.usda", unit, info);
}

std::string curves_prim(const std::string& body) {
  return "#usda 1.0\ndef BasisCurves \"C\"\n{\n" + body + "}\n";
}

double polyline_length(const StrandSet& s, std::size_t h) {
  double L = 0;
  for (uint32_t i = s.strand_begin(h) + 1; i < s.offsets[h + 1]; ++i)
    L += (s.points[i] - s.points[i - 1]).cast<double>().norm();
  return L;
}

// Within `tol` metres per coordinate (binary formats in a unit other than metres round once).
void expect_near(const StrandSet& a, const StrandSet& b, float tol) {
  EXPECT_EQ(a.offsets, b.offsets);
  ASSERT_EQ(a.points.size(), b.points.size());
  for (std::size_t i = 0; i < a.points.size(); ++i)
    ASSERT_LE((a.points[i] - b.points[i]).cwiseAbs().maxCoeff(), tol) << "point " << i;
}

void expect_same(const StrandSet& a, const StrandSet& b) {
  EXPECT_EQ(a.offsets, b.offsets);
  ASSERT_EQ(a.points.size(), b.points.size());
  for (std::size_t i = 0; i < a.points.size(); ++i)
    ASSERT_TRUE(a.points[i] == b.points[i])
        << "point " << i << ": " << a.points[i].transpose() << " vs " << b.points[i].transpose();
}

}  // namespace

TEST(StrandIo, UsdaRoundTripIsExactInEveryUnit) {
  for (LengthUnit u : {LengthUnit::m, LengthUnit::dm, LengthUnit::cm, LengthUnit::mm}) {
    const StrandSet s = sample_strands(true);
    StrandFileInfo info;
    const StrandSet r = usda(strands_to_usda(s, u), LengthUnit::m, &info);
    expect_same(s, r);
    EXPECT_TRUE(r.radius == s.radius) << to_string(u);
    EXPECT_TRUE(r.color == s.color) << to_string(u);
    EXPECT_TRUE(info.unit_from_file);  // metersPerUnit wins over the argument (m here)
    EXPECT_DOUBLE_EQ(info.metres_per_unit, unit_to_metres(u));
  }
  // Without radii the writer puts a constant 80 µm width, read back as a 40 µm radius.
  const StrandSet s = sample_strands(false);
  const StrandSet r = usda(strands_to_usda(s, LengthUnit::mm));
  expect_same(s, r);
  ASSERT_EQ(r.radius.size(), r.points.size());
  for (float x : r.radius) EXPECT_NEAR(x, 40e-6f, 1e-12f);
  EXPECT_TRUE(r.color.empty());
}

TEST(StrandIo, ObjRoundTripIsExactAndKeepsColours) {
  for (LengthUnit u : {LengthUnit::m, LengthUnit::cm, LengthUnit::mm}) {
    const StrandSet s = sample_strands(true);
    const StrandSet r = obj_to_strands(strands_to_obj(s, u), "t.obj", u);
    expect_same(s, r);
    EXPECT_TRUE(r.color == s.color);
    EXPECT_TRUE(r.radius.empty());  // OBJ has no radius convention
  }
  const StrandSet s = sample_strands(false);
  const StrandSet r = obj_to_strands(strands_to_obj(s, LengthUnit::m), "t.obj", LengthUnit::m);
  expect_same(s, r);
  EXPECT_TRUE(r.color.empty());
}

TEST(StrandIo, FileRoundTripsThroughEveryFormat) {
  const auto dir = test::scratch_dir("strand_io_files");
  const StrandSet s = sample_strands(true);
  for (const char* name : {"a.hair", "a.usda", "a.obj"}) {
    save_strands(s, dir / name, LengthUnit::cm);
    StrandFileInfo info;
    const StrandSet r = load_strands(dir / name, LengthUnit::cm, &info);
    if (info.format == "hair") {  // float32 in cm: one rounding; exact in metres
      expect_near(s, r, 1e-8f);
      save_strands(s, dir / name, LengthUnit::m);
      expect_same(s, load_strands(dir / name, LengthUnit::m));
    } else {
      expect_same(s, r);
    }
    EXPECT_EQ("a." + info.format, std::string(name));
    EXPECT_TRUE(is_strand_file(dir / name));
  }
  // .tfx: resampled to a power-of-two count, ends exact, interior points on the polyline.
  save_strands(s, dir / "a.tfx", LengthUnit::cm, 16);
  const StrandSet t = load_strands(dir / "a.tfx", LengthUnit::cm);
  ASSERT_EQ(t.num_strands(), s.num_strands());
  for (std::size_t h = 0; h < s.num_strands(); ++h) {
    ASSERT_EQ(t.strand_size(h), 16u);
    const Vec3f* p = s.points.data() + s.strand_begin(h);
    const Vec3f* q = t.points.data() + t.strand_begin(h);
    EXPECT_LT((q[0] - p[0]).norm(), 1e-7f);
    EXPECT_LT((q[15] - p[s.strand_size(h) - 1]).norm(), 1e-7f);
    EXPECT_NEAR(polyline_length(t, h), polyline_length(s, h), 1e-6);  // straight sample strands
    for (int i = 1; i < 15; ++i)                                      // uniform arc-length spacing
      EXPECT_NEAR((q[i] - q[i - 1]).norm(), polyline_length(s, h) / 15, 1e-6);
  }
  EXPECT_THROW(save_strands(StrandSet{}, dir / "e.hair", LengthUnit::m), Error);
  EXPECT_THROW(save_strands(s, dir / "a.ply", LengthUnit::m), Error);
  EXPECT_FALSE(std::filesystem::exists(dir / "e.hair"));
}

TEST(StrandIo, UnitsConvertToMetres) {
  // OBJ and a USD layer without metersPerUnit are read in the given unit.
  const std::string obj = "v 1000 0 0\nv 1000 10 -5\nl 1 2\n";
  const StrandSet o = obj_to_strands(obj, "t.obj", LengthUnit::mm);
  EXPECT_TRUE(o.points[0].isApprox(Vec3f(1, 0, 0)));
  EXPECT_TRUE(o.points[1].isApprox(Vec3f(1, 0.01f, -0.005f)));
  const std::string body =
      "uniform token type = \"linear\"\nint[] curveVertexCounts = [2]\n"
      "point3f[] points = [(1000, 0, 0), (1000, 10, -5)]\nfloat[] widths = [0.1] (interpolation "
      "= \"constant\")\n";
  StrandFileInfo info;
  const StrandSet u = usda(curves_prim(body), LengthUnit::mm, &info);
  EXPECT_FALSE(info.unit_from_file);
  EXPECT_DOUBLE_EQ(info.metres_per_unit, 1e-3);
  EXPECT_TRUE(u.points[1].isApprox(Vec3f(1, 0.01f, -0.005f)));
  EXPECT_NEAR(u.radius[0], 0.05e-3f, 1e-12f);  // width 0.1 mm
  // The layer's metersPerUnit wins over the argument.
  const std::string cm =
      "#usda 1.0\n(\n    metersPerUnit = 0.01\n)\ndef BasisCurves \"C\"\n{\n" + body + "}\n";
  const StrandSet c = usda(cm, LengthUnit::mm, &info);
  EXPECT_TRUE(info.unit_from_file);
  EXPECT_TRUE(c.points[1].isApprox(Vec3f(10, 0.1f, -0.05f)));
  // A .hair written in millimetres stores millimetres.
  const CyHairFile f = strands_to_cyhair(o, LengthUnit::mm);
  EXPECT_FLOAT_EQ(f.points[0], 1000.0f);
  EXPECT_FLOAT_EQ(f.points[4], 10.0f);
}

TEST(StrandIo, UsdaToleratesTheFullSyntax) {
  const std::string text = R"usda(#usda 1.0
(
    "A layer doc string"
    customLayerData = {
        dictionary tool = { string name = "hand (written)" int version = 3 }
        string note = "braces } and ) inside strings"
    }
    defaultPrim = "Root"
    upAxis = "Y"
)
/* a block
   comment */
def Xform "Root" (
    kind = "component"
    prepend apiSchemas = ["SomeAPI"]
)
{
    // a C++ comment
    rel material:binding = </Mats/Hair>
    custom string userNote = """triple
quoted"""
    variantSet "lod" = {
        "high" { def BasisCurves "Ignored" { int[] curveVertexCounts = [2] } }
    }
    def BasisCurves "A" (doc = "first prim")
    {
        uniform token type = "linear"
        int[] curveVertexCounts = [2, 3]   # two curves
        point3f[] points = [(0, 0, 0), (0, 1, 0),
                            (1, 0, 0), (1, 1, 0), (1, 2, 0),]
        float[] widths = [0.2, 0.4] (
            interpolation = "uniform"
            customData = { bool x = 1 }
        )
        color3f[] primvars:displayColor = [(1, 0, 0), (0, 1, 0)]
        int[] primvars:displayColor:indices = [0, 1, 1, 0, 1]
        texCoord2f[] primvars:st = [(0, 0)] (interpolation = "constant")
        float3[] extent = [(0, 0, 0), (1, 2, 0)]
    }
    over "NotDefined" { def BasisCurves "Skipped" { int[] curveVertexCounts = [1] } }
    class BasisCurves "Abstract" { }
    def BasisCurves "Off" ( active = false ) { }
    def BasisCurves "B"
    {
        uniform token type = "linear"
        int[] curveVertexCounts = [2]
        point3f[] points.timeSamples = { 24: [(9, 9, 9), (9, 9, 9)], 1: [(5, 0, 0), (5, 1, 0)], }
        float[] widths = [0.1, 0.3]
        color3f[] primvars:displayColor = [(0, 0, 1)] (interpolation = "constant")
    }
}
)usda";
  StrandFileInfo info;
  const StrandSet s = usda(text, LengthUnit::m, &info);
  ASSERT_EQ(s.num_strands(), 3u);  // A's two curves + B (earliest time sample)
  EXPECT_EQ(s.offsets, (std::vector<uint32_t>{0, 2, 5, 7}));
  EXPECT_EQ(s.points[4], Vec3f(1, 2, 0));
  EXPECT_EQ(s.points[5], Vec3f(5, 0, 0));
  ASSERT_EQ(s.radius.size(), 7u);
  EXPECT_FLOAT_EQ(s.radius[0], 0.1f);   // uniform: curve 0 width 0.2
  EXPECT_FLOAT_EQ(s.radius[4], 0.2f);   // curve 1 width 0.4
  EXPECT_FLOAT_EQ(s.radius[6], 0.15f);  // B: vertex widths (no interpolation given)
  ASSERT_EQ(s.color.size(), 7u);
  EXPECT_EQ(s.color[0], Vec3f(1, 0, 0));  // indexed colours
  EXPECT_EQ(s.color[1], Vec3f(0, 1, 0));
  EXPECT_EQ(s.color[3], Vec3f(1, 0, 0));
  EXPECT_EQ(s.color[6], Vec3f(0, 0, 1));
  std::string notes;
  for (const auto& n : info.notes) notes += n + "\n";
  EXPECT_NE(notes.find("variant sets of </Root>"), std::string::npos) << notes;
  EXPECT_NE(notes.find("</Root/NotDefined>"), std::string::npos) << notes;
  EXPECT_NE(notes.find("inactive prim </Root/Off>"), std::string::npos) << notes;
}

TEST(StrandIo, UsdaTransformsOfPrimAndParentsAreApplied) {
  const std::string text = R"usda(#usda 1.0
(
    metersPerUnit = 0.01
)
def Xform "Root"
{
    double3 xformOp:translate = (1, 2, 3)
    float3 xformOp:scale = (2, 2, 2)
    uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:scale"]
    def BasisCurves "C"
    {
        uniform token type = "linear"
        int[] curveVertexCounts = [2]
        point3f[] points = [(0, 0, 0), (1, 0, 0)]
        float[] widths = [0.1] (interpolation = "constant")
        double xformOp:rotateZ = 90
        uniform token[] xformOpOrder = ["xformOp:rotateZ"]
    }
    def BasisCurves "Reset"
    {
        uniform token type = "linear"
        int[] curveVertexCounts = [2]
        point3f[] points = [(0, 0, 0), (1, 0, 0)]
        float[] widths = [0.1] (interpolation = "constant")
        matrix4d xformOp:transform = ( (1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 1, 0), (5, 6, 7, 1) )
        float3 xformOp:rotateXYZ = (90, 0, 90)
        uniform token[] xformOpOrder = ["!resetXformStack!", "xformOp:transform", "xformOp:rotateXYZ"]
    }
}
def BasisCurves "Other"
{
    uniform token type = "linear"
    int[] curveVertexCounts = [2, 2]
    point3f[] points = [(1, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 0)]
    float[] widths = [0.1] (interpolation = "constant")
    float3 xformOp:rotateZYX = (90, 0, 90)
    quatf xformOp:orient = (0.70710678, 0, 0, 0.70710678)
    double3 xformOp:translate:pivot = (3, 0, 0)
    uniform token[] xformOpOrder = ["xformOp:translate:pivot", "!invert!xformOp:translate:pivot", "xformOp:rotateZYX", "xformOp:orient"]
}
)usda";
  const StrandSet s = usda(text);
  ASSERT_EQ(s.num_strands(), 4u);
  auto near = [](const Vec3f& a, const Vec3f& b) { return (a - b).norm() < 1e-7f; };
  // Root: T(1,2,3) S(2) Rz(90); points in cm.
  EXPECT_TRUE(near(s.points[0], Vec3f(0.01f, 0.02f, 0.03f))) << s.points[0].transpose();
  EXPECT_TRUE(near(s.points[1], Vec3f(0.01f, 0.04f, 0.03f))) << s.points[1].transpose();
  EXPECT_NEAR(s.radius[0], 0.05f * 2 * 0.01f, 1e-9f);  // scaled with the prim
  // Reset: no parent transform; the rotateXYZ applies X first, then Z: (1,0,0) -> (0,1,0).
  EXPECT_TRUE(near(s.points[2], Vec3f(0.05f, 0.06f, 0.07f))) << s.points[2].transpose();
  EXPECT_TRUE(near(s.points[3], Vec3f(0.05f, 0.07f, 0.07f))) << s.points[3].transpose();
  EXPECT_NEAR(s.radius[2], 0.05f * 0.01f, 1e-9f);
  // Other: pivot and its inverse cancel; orient (90 deg about z) applies first, then rotateZYX
  // (Z first, then X): (1,0,0) -> (0,1,0) -> (-1,0,0) -> (-1,0,0); (0,1,0) -> (-1,0,0) ->
  // (0,-1,0) -> (0,0,-1).
  EXPECT_TRUE(near(s.points[4], Vec3f(-0.01f, 0, 0))) << s.points[4].transpose();
  EXPECT_TRUE(near(s.points[6], Vec3f(0, 0, -0.01f))) << s.points[6].transpose();
  EXPECT_TRUE(near(s.points[7], Vec3f(0, 0, 0)));
}

TEST(StrandIo, UsdaCubicBezierOfCollinearPointsIsAStraightLine) {
  // Two bezier spans along (1,2,2)/3 at distances 0 .. 6, unevenly spaced but in order.
  const Vec3 d = Vec3(1, 2, 2) / 3;
  std::string pts;
  for (double t : {0.0, 0.5, 2.9, 3.0, 3.2, 5.5, 6.0}) {
    const Vec3 p = t * d;
    pts += fmt::format("({:.17g}, {:.17g}, {:.17g}), ", p.x(), p.y(), p.z());
  }
  const StrandSet s =
      usda(curves_prim("uniform token type = \"cubic\"\nuniform token basis = "
                       "\"bezier\"\nint[] curveVertexCounts = [7]\npoint3f[] "
                       "points = [" +
                       pts +
                       "]\nfloat[] widths = [2, 4, 6] "
                       "(interpolation = \"varying\")\n"));
  UsdReadOptions opt;
  ASSERT_EQ(s.num_strands(), 1u);
  ASSERT_EQ(s.strand_size(0), 2 * opt.cubic_samples_per_span + 1);
  EXPECT_NEAR(polyline_length(s, 0), 6.0, 1e-5);
  for (const Vec3f& p : s.points) EXPECT_LT((p.cast<double>().cross(d)).norm(), 2e-6);
  EXPECT_TRUE(s.points.front() == Vec3f::Zero());
  EXPECT_TRUE(s.points.back().isApprox((6.0 * d).cast<float>()));
  // Varying widths: linear across each span, one value per span end.
  EXPECT_FLOAT_EQ(s.radius[0], 1.0f);
  EXPECT_FLOAT_EQ(s.radius[4], 1.5f);
  EXPECT_FLOAT_EQ(s.radius[8], 2.0f);
  EXPECT_FLOAT_EQ(s.radius[16], 3.0f);
}

TEST(StrandIo, UsdaCubicBasesEvaluateTheirFormulas) {
  auto curve = [](const std::string& basis, const std::string& wrap, const std::string& pts, int n,
                  const std::string& extra = "") {
    return usda(curves_prim("uniform token type = \"cubic\"\nuniform token basis = \"" + basis +
                            "\"\nuniform token wrap = \"" + wrap +
                            "\"\nint[] curveVertexCounts = [" + std::to_string(n) +
                            "]\npoint3f[] points = [" + pts + "]\n" + extra));
  };
  auto near = [](const Vec3f& a, const Vec3f& b) { return (a - b).norm() < 1e-6f; };
  // Bezier: B(1/2) = (P0 + 3 P1 + 3 P2 + P3) / 8; vertex widths follow the same weights.
  const StrandSet bz = curve("bezier", "nonperiodic", "(0,0,0), (0,1,0), (1,1,0), (1,0,0)", 4,
                             "float[] widths = [2, 2, 2, 10]\n");
  ASSERT_EQ(bz.strand_size(0), 9u);
  EXPECT_TRUE(near(bz.points[4], Vec3f(0.5f, 0.75f, 0))) << bz.points[4].transpose();
  EXPECT_FLOAT_EQ(bz.radius[0], 1.0f);
  EXPECT_FLOAT_EQ(bz.radius[4], 0.5f * (2.0f * 7 / 8 + 10.0f / 8));
  EXPECT_FLOAT_EQ(bz.radius[8], 5.0f);
  // B-spline (nonperiodic): collinear evenly spaced points give the line from P1 to P(n-2).
  const std::string line6 = "(0,0,0), (0.1,0,0), (0.2,0,0), (0.3,0,0), (0.4,0,0), (0.5,0,0)";
  const StrandSet bs = curve("bspline", "nonperiodic", line6, 6);
  ASSERT_EQ(bs.strand_size(0), 3 * 8 + 1u);
  EXPECT_TRUE(near(bs.points.front(), Vec3f(0.1f, 0, 0)));
  EXPECT_TRUE(near(bs.points.back(), Vec3f(0.4f, 0, 0)));
  EXPECT_NEAR(polyline_length(bs, 0), 0.3, 1e-6);
  // Catmull-Rom interpolates P1 .. P(n-2) at the span ends.
  const std::string wiggle = "(0,0,0), (1,1,0), (2,0,0), (3,1,0), (4,0,0)";
  const StrandSet cr = curve("catmullRom", "nonperiodic", wiggle, 5);
  ASSERT_EQ(cr.strand_size(0), 2 * 8 + 1u);
  EXPECT_TRUE(near(cr.points[0], Vec3f(1, 1, 0)));
  EXPECT_TRUE(near(cr.points[8], Vec3f(2, 0, 0)));
  EXPECT_TRUE(near(cr.points[16], Vec3f(3, 1, 0)));
  // Pinned: the curve reaches the first and last control points.
  const StrandSet pb = curve("bspline", "pinned", "(0,0,0), (1,1,0), (2,0,0), (3,1,0)", 4);
  ASSERT_EQ(pb.strand_size(0), 5 * 8 + 1u);  // n + 1 spans
  EXPECT_TRUE(near(pb.points.front(), Vec3f(0, 0, 0)));
  EXPECT_TRUE(near(pb.points.back(), Vec3f(3, 1, 0)));
  const StrandSet pl = curve("bspline", "pinned", line6, 6);
  EXPECT_NEAR(polyline_length(pl, 0), 0.5, 1e-6);  // P0 .. P5 along the line
  const StrandSet pc = curve("catmullRom", "pinned", "(0,0,0), (1,1,0), (2,0,0)", 3);
  ASSERT_EQ(pc.strand_size(0), 2 * 8 + 1u);  // n - 1 spans
  EXPECT_TRUE(near(pc.points[0], Vec3f(0, 0, 0)));
  EXPECT_TRUE(near(pc.points[8], Vec3f(1, 1, 0)));
  EXPECT_TRUE(near(pc.points[16], Vec3f(2, 0, 0)));
  // The span sample count is an option.
  const StrandSet b3 = usda_to_strands(
      curves_prim("uniform token type = \"cubic\"\nint[] curveVertexCounts = [4]\npoint3f[] "
                  "points = [(0,0,0), (0,1,0), (1,1,0), (1,0,0)]\n"),
      "t.usda", LengthUnit::m, nullptr, UsdReadOptions{3});
  EXPECT_EQ(b3.strand_size(0), 4u);
}

TEST(StrandIo, ObjPolylinesReader) {
  const std::string obj =
      "# comment\nmtllib x.mtl\no hair\nv 0 0 0\nv 1 0 0\nv 2 0 0 # trailing\nvt 0 0\n"
      "v 3 0 0\nl 1 2 \\\n 3 4\nf 1 2 3\nl -2/1 -1\ng other\nl 2 3\n";
  const StrandSet s = obj_to_strands(obj, "t.obj", LengthUnit::m);
  ASSERT_EQ(s.num_strands(), 3u);
  EXPECT_EQ(s.offsets, (std::vector<uint32_t>{0, 4, 6, 8}));
  EXPECT_EQ(s.points[3], Vec3f(3, 0, 0));  // continued line
  EXPECT_EQ(s.points[4], Vec3f(2, 0, 0));  // negative indices
  EXPECT_EQ(s.points[7], Vec3f(2, 0, 0));
  const auto dir = test::scratch_dir("strand_io_obj");
  write_file_atomically(dir / "mixed.obj", obj);
  EXPECT_FALSE(is_strand_file(dir / "mixed.obj"));  // faces: a mesh
  write_file_atomically(dir / "lines.obj", "v 0 0 0\nv 1 0 0\nl 1 2\n");
  EXPECT_TRUE(is_strand_file(dir / "lines.obj"));
  EXPECT_EQ(load_strands(dir / "lines.obj", LengthUnit::m).num_points(), 2u);
  // Only the first word of a logical line counts: an "f" continuing a line, in a comment or in
  // a name is no face; an indented one, one right before a continuation, or CRLF ends are.
  write_file_atomically(dir / "cont.obj", "v 0 0 0\nv 1 0 0\nl 1 \\\nf\ng f\n# f 1 2 3\nl 2 1\n");
  EXPECT_TRUE(is_strand_file(dir / "cont.obj"));
  write_file_atomically(dir / "indented.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\n\t f 1 2 3\n");
  EXPECT_FALSE(is_strand_file(dir / "indented.obj"));
  write_file_atomically(dir / "fcont.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\nf\\\n 1 2 3\n");
  EXPECT_FALSE(is_strand_file(dir / "fcont.obj"));
  write_file_atomically(dir / "crlf.obj", "v 0 0 0\r\nv 1 0 0\r\nl 1 2\r\n");
  EXPECT_TRUE(is_strand_file(dir / "crlf.obj"));
  write_file_atomically(dir / "nolines.obj", "v 0 0 0\nv 1 0 0\n");
  EXPECT_FALSE(is_strand_file(dir / "nolines.obj"));
}

TEST(StrandIo, LyingAndTruncatedFilesFailWithWhereAndWhat) {
  const auto dir = test::scratch_dir("strand_io_lies");
  // .hair: header claims one point more than the file holds; a billion points; no strands.
  std::string hair = serialize_cyhair(strands_to_cyhair(sample_strands(false), LengthUnit::m));
  std::string bad = hair;
  uint32_t n;
  std::memcpy(&n, bad.data() + 8, 4);
  ++n;
  std::memcpy(bad.data() + 8, &n, 4);
  expect_error([&] { parse_cyhair(bad, "t.hair"); }, {"t.hair", "truncated or a count is wrong"});
  n = 1000000000;
  std::memcpy(bad.data() + 8, &n, 4);
  expect_error([&] { parse_cyhair(bad, "t.hair"); }, {"t.hair", "12000000000 bytes of points"});
  CyHairFile empty;
  empty.arrays = CyHairFile::kPoints | CyHairFile::kSegments;
  write_file_atomically(dir / "empty.hair", serialize_cyhair(empty));
  expect_error([&] { load_strands(dir / "empty.hair", LengthUnit::m); },
               {"empty.hair", "no strands"});
  // .tfx: offsets past the end of the file.
  const std::string tfx = serialize_tfx(strands_to_tfx(sample_strands(false), LengthUnit::m, 8));
  for (std::size_t field : {12u, 28u}) {  // positions, vertex colours
    bad = tfx;
    const uint32_t off = uint32_t(tfx.size() + 16);
    std::memcpy(bad.data() + field, &off, 4);
    expect_error([&] { parse_tfx(bad, "t.tfx"); }, {"t.tfx", "truncated or a count is wrong"});
  }
  // .usda
  const std::string ok = "uniform token type = \"linear\"\n";
  expect_error(
      [&] {
        usda(curves_prim(ok + "int[] curveVertexCounts = [2, 3]\npoint3f[] points = "
                              "[(0,0,0), (1,0,0), (2,0,0), (3,0,0)]\n"));
      },
      {"t.usda:5:", "sum to 5", "holds 4 points"});
  expect_error(
      [&] {
        usda(curves_prim(ok + "int[] curveVertexCounts = [4000000000]\npoint3f[] points = "
                              "[(0,0,0), (1,0,0)]\n"));
      },
      {"t.usda:5:", "sum to 4000000000"});
  expect_error(
      [&] {
        usda(curves_prim(ok + "int[] curveVertexCounts = [2]\npoint3f[] points = "
                              "[(0,0,0),\n (nan, 0, 0)]\n"));
      },
      {"t.usda:7:", "not finite"});
  expect_error(
      [&] {
        usda(curves_prim(
            ok + "int[] curveVertexCounts = [2]\npoint3f[] points = [(0,0,0), (inf,0,0)]\n"));
      },
      {"t.usda:6:", "not finite"});
  expect_error(
      [&] {
        usda(
            "#usda 1.0\ndef BasisCurves \"C\"\n{\n    int[] curveVertexCounts = [2]\n"
            "    point3f[] points = [(0,0,0), (1,");
      },
      {"t.usda:5:", "expected a number"});
  expect_error([&] { usda("#usda 1.0\ndef BasisCurves \"C\"\n{\n"); },
               {"t.usda:2:", "never closed"});
  expect_error(
      [&] {
        usda(
            curves_prim("uniform token wrap = \"periodic\"\nint[] curveVertexCounts = "
                        "[4]\npoint3f[] points = [(0,0,0),(1,0,0),(2,0,0),(3,0,0)]\n"));
      },
      {"t.usda:4:", "periodic"});
  expect_error(
      [&] {
        usda(
            curves_prim("int[] curveVertexCounts = [5]\npoint3f[] points = "
                        "[(0,0,0),(1,0,0),(2,0,0),(3,0,0),(4,0,0)]\n"));
      },
      {"t.usda:4:", "bezier", "4, 7, 10"});  // type defaults to cubic bezier (USD fallback)
  const std::string two =
      ok + "int[] curveVertexCounts = [2]\npoint3f[] points = [(0,0,0), (1,0,0)]\n";
  expect_error(
      [&] { usda(curves_prim(two + "float[] widths = [1, 2, 3] (interpolation = \"vertex\")\n")); },
      {"t.usda:7:", "widths", "needs 2"});
  expect_error(
      [&] {
        usda(curves_prim(two + "float3 xformOp:shear = (1, 1, 1)\n"
                               "uniform token[] xformOpOrder = [\"xformOp:shear\"]\n"));
      },
      {"t.usda:7:", "unsupported xformOp type 'shear'"});
  expect_error([&] { usda(curves_prim(ok + "point3f[] points = [(((((((((((1)))))))))))]\n")); },
               {"t.usda:5:", "nested"});
  std::string deep = "#usda 1.0\n";
  for (int i = 0; i < 300; ++i) deep += "def \"a\" {\n";
  expect_error([&] { usda(deep); }, {"nested deeper"});
  expect_error([&] { usda("PXR-USDC\x01\x02"); }, {"t.usda", "usdc"});
  expect_error([&] { usda("def BasisCurves \"C\" {}"); }, {"t.usda", "#usda 1.0"});
  expect_error([&] { usda("#usda 1.0\ndef Xform \"X\" {}\n"); }, {"t.usda", "no BasisCurves"});
  write_file_atomically(dir / "zero.usda",
                        curves_prim(ok + "int[] curveVertexCounts = []\npoint3f[] points = []\n"));
  expect_error([&] { load_strands(dir / "zero.usda", LengthUnit::m); },
               {"zero.usda", "no strands"});
  // .obj
  expect_error([&] { obj_to_strands("v 0 0 0\nv 1 0 0\nl 1 3\n", "t.obj", LengthUnit::m); },
               {"t.obj:3:", "index 3 is out of range", "2 vertices"});
  expect_error([&] { obj_to_strands("v 0 0 0\nl -2 1\nv 1 0 0\n", "t.obj", LengthUnit::m); },
               {"t.obj:2:", "-2 is out of range"});
  expect_error([&] { obj_to_strands("v 0 0 0\nv 1 nan 0\nl 1 2\n", "t.obj", LengthUnit::m); },
               {"t.obj:2:", "not finite"});
  expect_error([&] { obj_to_strands("v 0 0 0\nv 1 0\nl 1 2\n", "t.obj", LengthUnit::m); },
               {"t.obj:2:", "3 coordinates"});
  expect_error([&] { obj_to_strands("v 0 0 0\nv 1 0 0\nl 1 0\n", "t.obj", LengthUnit::m); },
               {"t.obj:3:", "not a valid OBJ index"});
  expect_error([&] { obj_to_strands("v 0 0 0\nv 1 0 0\nf 1 2 1\n", "t.obj", LengthUnit::m); },
               {"t.obj", "no polylines"});
}

TEST(StrandIo, SintelConvertsExactlyThroughUsdaAndObj) {
  FOLLICLE_REQUIRE_SHARED("sintel-lite-hair/GEO-sintel_hair_emit.001-sintel_hair.tfx");
  const auto path =
      test::shared_data_dir() / "sintel-lite-hair/GEO-sintel_hair_emit.001-sintel_hair.tfx";
  const StrandSet s = load_strands(path, LengthUnit::cm);
  // SOURCE.md: 228 strands x 32 vertices = 7296 points; strand length 3.80 / 10.53 / 20.63 units.
  ASSERT_EQ(s.num_strands(), 228u);
  EXPECT_EQ(s.num_points(), 7296u);
  double lmin = 1e9, lmax = 0, lsum = 0;
  for (std::size_t h = 0; h < s.num_strands(); ++h) {
    const double L = polyline_length(s, h) * 100;  // cm = Blender units here
    lmin = std::min(lmin, L);
    lmax = std::max(lmax, L);
    lsum += L;
  }
  EXPECT_NEAR(lmin, 3.80, 0.006);
  EXPECT_NEAR(lsum / 228, 10.53, 0.006);
  EXPECT_NEAR(lmax, 20.63, 0.006);
  const auto dir = test::scratch_dir("strand_io_sintel");
  for (const char* name : {"s.usda", "s.obj"}) {
    save_strands(s, dir / name, LengthUnit::cm);
    expect_same(s, load_strands(dir / name, LengthUnit::cm));
  }
  // Binary formats store float32 in the file unit: within one rounding (3e-8 m at 0.5 m).
  save_strands(s, dir / "s.hair", LengthUnit::cm);
  expect_near(s, load_strands(dir / "s.hair", LengthUnit::cm), 6e-8f);
  save_strands(s, dir / "s.tfx", LengthUnit::cm, 32);  // 32 per strand already: no resampling
  expect_near(s, load_strands(dir / "s.tfx", LengthUnit::cm), 6e-8f);
}
