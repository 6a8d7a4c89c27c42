// Mesh I/O: round trips in every format, units, the shipped head, malformed inputs.
#include "follicle/geom/mesh_io.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <fstream>

#include "follicle/core/atomic_file.hpp"
#include "follicle/core/error.hpp"
#include "follicle/core/rng.hpp"
#include "testing/testing.hpp"

using namespace follicle;
using namespace follicle::geom;
namespace fs = std::filesystem;

namespace {

// A unit cube with separately indexed UVs (seams: 14 UVs for 8 vertices).
TriMesh make_cube() {
  TriMesh m;
  m.name = "cube";
  for (int i = 0; i < 8; ++i) m.positions.emplace_back(i & 1, (i >> 1) & 1, (i >> 2) & 1);
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (int q = 0; q < 6; ++q) {
    m.faces.emplace_back(quads[q][0], quads[q][1], quads[q][2]);
    m.faces.emplace_back(quads[q][0], quads[q][2], quads[q][3]);
  }
  for (int i = 0; i < 14; ++i) m.uvs.emplace_back(0.05 * i, 1.0 - 0.03 * i);
  for (std::size_t f = 0; f < m.faces.size(); ++f)
    m.uv_faces.emplace_back(int(f % 14), int((f + 3) % 14), int((f + 7) % 14));
  m.compute_normals();
  return m;
}

void write_text(const fs::path& p, const std::string& s) {
  std::ofstream f(p, std::ios::binary);
  f << s;
}

// Compares surfaces corner by corner (positions and UVs), allowing vertex splits at seams.
void expect_same_surface(const TriMesh& a, const TriMesh& b, double tol, bool uvs = true) {
  ASSERT_EQ(a.num_faces(), b.num_faces());
  for (std::size_t f = 0; f < a.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) {
      const Vec3 pa = a.positions[std::size_t(a.faces[f][k])];
      const Vec3 pb = b.positions[std::size_t(b.faces[f][k])];
      ASSERT_LE((pa - pb).norm(), tol) << "face " << f << " corner " << k;
      if (uvs && a.has_uvs()) {
        ASSERT_TRUE(b.has_uvs());
        const Vec2 ua = a.uvs[std::size_t(a.uv_faces[f][k])];
        const Vec2 ub = b.uvs[std::size_t(b.uv_faces[f][k])];
        ASSERT_LE((ua - ub).norm(), 1e-6) << "face " << f << " corner " << k;
      }
    }
}

}  // namespace

TEST(MeshIO, ObjRoundTripKeepsSeparateUvIndices) {
  const auto dir = test::scratch_dir("obj");
  const TriMesh cube = make_cube();
  save_mesh(cube, dir / "c.obj", LengthUnit::m);
  const TriMesh back = load_mesh(dir / "c.obj", LengthUnit::m);
  EXPECT_EQ(back.num_vertices(), cube.num_vertices());  // no seam splitting in OBJ
  EXPECT_EQ(back.uvs.size(), cube.uvs.size());
  EXPECT_EQ(back.faces, cube.faces);
  EXPECT_EQ(back.uv_faces, cube.uv_faces);
  expect_same_surface(cube, back, 1e-12);
}

TEST(MeshIO, ObjVertexNormalsAreReadAndSurviveConversion) {
  // Before: `vn` lines were ignored, so an OBJ's normals were lost and a glTF converted from it
  // had none (flat shading in glTF readers: Blender split the Sintel bust into 3 x its faces).
  const auto dir = test::scratch_dir("obj-normals");
  write_text(dir / "n.obj",
             "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n"
             "vn 0 0.6 0.8\nvn 0 0 1\n"
             "f 1//1 2//1 3//1\nf 2//2 4//2 3//2\n");
  const TriMesh m = load_mesh(dir / "n.obj", LengthUnit::m);
  ASSERT_TRUE(m.has_normals());
  EXPECT_TRUE(m.normals[0].isApprox(Vec3(0, 0.6, 0.8)));  // one corner: the file's normal
  EXPECT_TRUE(m.normals[3].isApprox(Vec3(0, 0, 1)));
  EXPECT_TRUE(m.normals[1].isApprox(Vec3(0, 0.6, 1.8).normalized()));  // two: their blend
  save_mesh(m, dir / "n.glb", LengthUnit::m);
  const TriMesh g = load_mesh(dir / "n.glb", LengthUnit::m);
  ASSERT_TRUE(g.has_normals());
  EXPECT_EQ(g.num_vertices(), m.num_vertices());
  // A file whose faces name normals only in part keeps none (computed later by the user).
  write_text(dir / "part.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3\n");
  EXPECT_FALSE(load_mesh(dir / "part.obj", LengthUnit::m).has_normals());
}

TEST(MeshIO, UnitsConvertOnLoadAndSave) {
  const auto dir = test::scratch_dir("units");
  const TriMesh cube = make_cube();  // 1 m cube
  save_mesh(cube, dir / "mm.obj", LengthUnit::mm);
  // Text holds millimetres.
  EXPECT_NE(read_file(dir / "mm.obj").find("v 1000 1000 1000"), std::string::npos);
  const TriMesh as_mm = load_mesh(dir / "mm.obj", LengthUnit::mm);
  expect_same_surface(cube, as_mm, 1e-12);
  const TriMesh as_cm = load_mesh(dir / "mm.obj", LengthUnit::cm);  // 1000 cm = 10 m
  EXPECT_NEAR(as_cm.bounds().sizes().x(), 10.0, 1e-12);
}

class PlyRoundTrip : public ::testing::TestWithParam<bool> {};

TEST_P(PlyRoundTrip, PositionsUvsNormalsSurvive) {
  const bool ascii = GetParam();
  const auto dir = test::scratch_dir(ascii ? "ply-ascii" : "ply-bin");
  const TriMesh cube = make_cube();
  save_mesh(cube, dir / "c.ply", LengthUnit::cm, ascii);
  const std::string head = read_file(dir / "c.ply").substr(0, 40);
  EXPECT_NE(head.find(ascii ? "format ascii" : "format binary_little_endian"), std::string::npos);
  const TriMesh back = load_mesh(dir / "c.ply", LengthUnit::cm);
  expect_same_surface(cube, back, 1e-12);
  EXPECT_EQ(back.uv_faces, back.faces);                 // per-vertex UVs
  EXPECT_GT(back.num_vertices(), cube.num_vertices());  // split at UV seams
  ASSERT_TRUE(back.has_normals());
}
INSTANTIATE_TEST_SUITE_P(AsciiAndBinary, PlyRoundTrip, ::testing::Values(true, false));

TEST(MeshIO, PlyBigEndianAndQuadsAndExtraElements) {
  const auto dir = test::scratch_dir("ply-be");
  std::string s =
      "ply\nformat binary_big_endian 1.0\ncomment hand made\nelement vertex 4\n"
      "property float x\nproperty float y\nproperty float z\nproperty uchar red\n"
      "element face 1\nproperty list uchar uint vertex_indices\n"
      "element material 1\nproperty int id\nend_header\n";
  auto be32 = [&](uint32_t v) {
    for (int k = 3; k >= 0; --k) s.push_back(char((v >> (8 * k)) & 0xFF));
  };
  auto bef = [&](float f) {
    uint32_t v;
    std::memcpy(&v, &f, 4);
    be32(v);
  };
  const float xy[4][2] = {{0, 0}, {2, 0}, {2, 1}, {0, 1}};
  for (auto& p : xy) {
    bef(p[0]);
    bef(p[1]);
    bef(0.5f);
    s.push_back(char(200));
  }
  s.push_back(4);
  for (uint32_t i = 0; i < 4; ++i) be32(i);
  be32(7);
  write_text(dir / "q.ply", s);
  const TriMesh m = load_mesh(dir / "q.ply", LengthUnit::m);
  ASSERT_EQ(m.num_vertices(), 4u);
  ASSERT_EQ(m.num_faces(), 2u);  // quad fan-triangulated
  EXPECT_EQ(m.positions[2], Vec3(2, 1, 0.5));
  EXPECT_NEAR(m.face_area(0) + m.face_area(1), 2.0, 1e-12);
}

// Sum of face areas and the number of faces whose normal points against `n`.
std::pair<double, int> area_and_flipped(const TriMesh& m, const Vec3& n) {
  double area = 0;
  int flipped = 0;
  for (std::size_t f = 0; f < m.num_faces(); ++f) {
    area += m.face_area(f);
    flipped += m.face_normal(f).dot(n) < 0.99;
  }
  return {area, flipped};
}

std::string ply_ascii_header(std::size_t nv, const std::string& face_element) {
  return "ply\nformat ascii 1.0\nelement vertex " + std::to_string(nv) +
         "\nproperty float x\nproperty float y\nproperty float z\n" + face_element + "end_header\n";
}

TEST(MeshIO, PlyTriangleStripsGiveTheSameSurfaceAsTheirTriangles) {
  // A 4 x 3 vertex grid in the z = 0 plane as two strips (one per row of quads) separated by -1,
  // and the same grid as explicit triangles. Strips alternate winding; all faces must face +z.
  const auto dir = test::scratch_dir("ply-strips");
  const int nx = 4, ny = 3;
  std::string verts;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) verts += fmt::format("{} {} 0\n", i, j);
  std::string strip, tris;
  int nstrip = 0, ntri = 0;
  for (int j = 0; j + 1 < ny; ++j) {
    if (j) {
      strip += " -1";
      ++nstrip;
    }
    for (int i = 0; i < nx; ++i) {
      strip += fmt::format(" {} {}", (j + 1) * nx + i, j * nx + i);
      nstrip += 2;
    }
    for (int i = 0; i + 1 < nx; ++i) {
      const int a = j * nx + i, b = a + 1, c = a + nx, d = c + 1;
      tris += fmt::format("3 {} {} {}\n3 {} {} {}\n", a, b, d, a, d, c);
      ntri += 2;
    }
  }
  write_text(
      dir / "strips.ply",
      ply_ascii_header(nx * ny, "element tristrips 1\nproperty list int int vertex_indices\n") +
          verts + std::to_string(nstrip) + strip + "\n");
  write_text(dir / "tris.ply",
             ply_ascii_header(nx * ny, fmt::format("element face {}\nproperty list uchar int "
                                                   "vertex_indices\n",
                                                   ntri)) +
                 verts + tris);
  const TriMesh s = load_mesh(dir / "strips.ply", LengthUnit::m);
  const TriMesh t = load_mesh(dir / "tris.ply", LengthUnit::m);
  ASSERT_EQ(s.num_faces(), t.num_faces());
  ASSERT_EQ(s.num_faces(), std::size_t(2 * (nx - 1) * (ny - 1)));
  const auto [sa, sflip] = area_and_flipped(s, Vec3::UnitZ());
  EXPECT_NEAR(sa, double((nx - 1) * (ny - 1)), 1e-12);
  EXPECT_EQ(sflip, 0);
  // Same triangles as sets of vertices.
  auto sorted = [](const TriMesh& m) {
    std::vector<std::array<int, 3>> out;
    for (const auto& f : m.faces) {
      std::array<int, 3> a{f[0], f[1], f[2]};
      std::sort(a.begin(), a.end());
      out.push_back(a);
    }
    std::sort(out.begin(), out.end());
    return out;
  };
  EXPECT_EQ(sorted(s), sorted(t));

  // A stitched single strip (repeated vertices between rows) gives the same triangles: the
  // degenerate stitch triangles are dropped.
  write_text(
      dir / "stitched.ply",
      ply_ascii_header(nx * ny, "element tristrips 1\nproperty list int int vertex_indices\n") +
          verts + "18 4 0 5 1 6 2 7 3 3 8 8 4 9 5 10 6 11 7\n");
  const TriMesh st = load_mesh(dir / "stitched.ply", LengthUnit::m);
  EXPECT_EQ(sorted(st), sorted(t));
  EXPECT_EQ(area_and_flipped(st, Vec3::UnitZ()).second, 0);

  // An index that is neither a vertex nor the -1 separator is refused with its place.
  write_text(
      dir / "bad.ply",
      ply_ascii_header(nx * ny, "element tristrips 1\nproperty list int int vertex_indices\n") +
          verts + "4 0 4 -2 5\n");
  try {
    (void)load_mesh(dir / "bad.ply", LengthUnit::m);
    ADD_FAILURE() << "no error for an index of -2";
  } catch (const Error& e) {
    const std::string msg = e.what();
    for (const char* part :
         {"bad.ply:", "strip list 0 references vertex -2", "or -1 between strips"})
      EXPECT_NE(msg.find(part), std::string::npos) << msg;
  }
}

TEST(MeshIO, PlyPolygonsAreCutAlongTheirInsideIncludingConcaveOnes) {
  const auto dir = test::scratch_dir("ply-polygons");
  auto load_polygon = [&](const std::vector<Vec2>& pts, const std::string& name) {
    std::string body;
    for (const auto& p : pts) body += fmt::format("{} {} 0\n", p.x(), p.y());
    body += fmt::format("{}", pts.size());
    for (std::size_t i = 0; i < pts.size(); ++i) body += fmt::format(" {}", i);
    body += "\n";
    write_text(
        dir / name,
        ply_ascii_header(pts.size(), "element face 1\nproperty list uchar int vertex_indices\n") +
            body);
    return load_mesh(dir / name, LengthUnit::m);
  };
  auto shoelace = [](const std::vector<Vec2>& p) {
    double a = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      const Vec2& u = p[i];
      const Vec2& v = p[(i + 1) % p.size()];
      a += u.x() * v.y() - v.x() * u.y();
    }
    return 0.5 * a;
  };
  // A concave quad (an arrow head) whose reflex corner is the last vertex: a fan from the first
  // would cut along a diagonal outside the polygon and flip one triangle.
  const std::vector<Vec2> arrow = {{0, 0}, {2, 1}, {0, 2}, {0.5, 1}};
  // An L-shaped hexagon, a concave octagon (a "U"), and a convex 10-gon.
  const std::vector<Vec2> ell = {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
  const std::vector<Vec2> u = {{0, 0}, {3, 0}, {3, 2}, {2, 2}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
  std::vector<Vec2> round;
  for (int k = 0; k < 10; ++k)
    round.emplace_back(std::cos(0.2 * M_PI * k), std::sin(0.2 * M_PI * k));
  for (const auto& [poly, name] : {std::pair{arrow, "arrow.ply"}, std::pair{ell, "ell.ply"},
                                   std::pair{u, "u.ply"}, std::pair{round, "round.ply"}}) {
    const double want = std::abs(shoelace(poly));
    for (const bool reversed : {false, true}) {
      auto p = poly;
      if (reversed) std::reverse(p.begin(), p.end());
      const TriMesh m = load_polygon(p, std::string(reversed ? "r" : "") + name);
      EXPECT_EQ(m.num_faces(), p.size() - 2) << name;
      const auto [area, flipped] =
          area_and_flipped(m, reversed ? Vec3(-Vec3::UnitZ()) : Vec3(Vec3::UnitZ()));
      EXPECT_NEAR(area, want, 1e-9) << name << (reversed ? " reversed" : "");
      EXPECT_EQ(flipped, 0) << name << (reversed ? " reversed" : "");
    }
  }
  // The same polygons standing in the y-z plane (the projection follows the polygon's normal).
  {
    std::string body;
    for (const auto& p : u) body += fmt::format("0 {} {}\n", p.x(), p.y());
    body += "8 0 1 2 3 4 5 6 7\n";
    write_text(
        dir / "u_yz.ply",
        ply_ascii_header(8, "element face 1\nproperty list uchar int vertex_indices\n") + body);
    const TriMesh m = load_mesh(dir / "u_yz.ply", LengthUnit::m);
    const auto [area, flipped] = area_and_flipped(m, Vec3::UnitX());
    EXPECT_NEAR(area, 5.0, 1e-9);
    EXPECT_EQ(flipped, 0);
  }
}

class GltfRoundTrip : public ::testing::TestWithParam<std::string> {};

TEST_P(GltfRoundTrip, PositionsUvsNormalsSurvive) {
  const auto dir = test::scratch_dir("gltf");
  const TriMesh cube = make_cube();
  const auto path = dir / ("c" + GetParam());
  save_mesh(cube, path, LengthUnit::m);
  const TriMesh back = load_mesh(path, LengthUnit::m);
  expect_same_surface(cube, back, 1e-6);  // glTF stores float32
  EXPECT_EQ(back.uv_faces, back.faces);
  ASSERT_TRUE(back.has_normals());
  if (GetParam() == ".glb") {
    EXPECT_EQ(read_file(path).substr(0, 4), "glTF");
  }
}
INSTANTIATE_TEST_SUITE_P(TextAndBinary, GltfRoundTrip, ::testing::Values(".gltf", ".glb"));

TEST(MeshIO, ConvertBetweenAllFormatsKeepsGeometry) {
  const auto dir = test::scratch_dir("convert");
  TriMesh m = make_cube();
  const char* chain[] = {"a.obj", "b.ply", "c.glb", "d.gltf", "e.obj"};
  for (const char* name : chain) {
    // OBJ and PLY in mm; glTF in metres, as its specification fixes.
    const bool gltf =
        std::string_view(name).ends_with("gltf") || std::string_view(name).ends_with("glb");
    const LengthUnit u = gltf ? LengthUnit::m : LengthUnit::mm;
    save_mesh(m, dir / name, u);
    m = load_mesh(dir / name, u);
  }
  expect_same_surface(make_cube(), m, 1e-6);
  try {
    save_mesh(m, dir / "mm.glb", LengthUnit::mm);
    FAIL() << "a glTF in mm was written";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("glTF stores metres by specification"), std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "mm.glb"));
}

TEST(MeshIO, DefaultHeadLoads) {
  const auto path = test::source_dir() / "data/meshes/lee_perry_smith/head.obj";
  ASSERT_TRUE(fs::exists(path)) << path;
  const TriMesh m = load_mesh(path, LengthUnit::mm);
  EXPECT_EQ(m.num_vertices(), 8838u);
  EXPECT_EQ(m.num_faces(), 17672u);
  EXPECT_TRUE(m.has_uvs());
  const Vec3 size = m.bounds().sizes();
  // A human head in metres: between 10 cm and 50 cm along its largest axis.
  EXPECT_GT(size.maxCoeff(), 0.10);
  EXPECT_LT(size.maxCoeff(), 0.50);
}

TEST(MeshIO, SplitUvSeamsPreservesCorners) {
  const TriMesh cube = make_cube();
  const TriMesh s = split_uv_seams(cube);
  EXPECT_EQ(s.uv_faces, s.faces);
  EXPECT_EQ(s.uvs.size(), s.positions.size());
  expect_same_surface(cube, s, 0.0);
}

// ---------------------------------------------------------------------------- malformed input

namespace {
void expect_error(const fs::path& p, const std::string& needle = "") {
  try {
    (void)load_mesh(p, LengthUnit::m);
    ADD_FAILURE() << "no error for " << p;
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(p.filename().string()), std::string::npos) << msg;
    if (!needle.empty()) {
      EXPECT_NE(msg.find(needle), std::string::npos) << msg;
    }
  }
}
}  // namespace

TEST(MeshIOMalformed, ObjErrorsNameFileAndLine) {
  const auto dir = test::scratch_dir("bad-obj");
  write_text(dir / "nan.obj", "v 0 0 0\nv 1 0 0\nv 0 nan 0\nf 1 2 3\n");
  expect_error(dir / "nan.obj", ":3");
  write_text(dir / "inf.obj", "v 0 0 0\nv 1 0 0\nv 0 inf 0\nf 1 2 3\n");
  expect_error(dir / "inf.obj", "not finite");
  write_text(dir / "range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n");
  expect_error(dir / "range.obj", ":4");
  write_text(dir / "neg.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n");
  expect_error(dir / "neg.obj", ":4");
  write_text(dir / "uvrange.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/2\n");
  expect_error(dir / "uvrange.obj", "texture");
  write_text(dir / "trunc.obj", "v 0 0 0\nv 1 0 0\nv 0 1");
  expect_error(dir / "trunc.obj", ":3");
  write_text(dir / "truncface.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2");
  expect_error(dir / "truncface.obj", ":4");
  write_text(dir / "empty.obj", "");
  expect_error(dir / "empty.obj", "empty");
  write_text(dir / "nofaces.obj", "# only a comment\nv 1 2 3\n");
  expect_error(dir / "nofaces.obj", "no faces");
  expect_error(dir / "missing.obj", "");
}

TEST(MeshIOMalformed, HugeCoordinatesAreRefusedBeforeTheyOverflow) {
  // 1e308 is a finite double, but every area and normal of it overflows to inf.
  const auto dir = test::scratch_dir("huge-obj");
  write_text(dir / "huge.obj", "v 0 0 0\nv 1e308 0 0\nv 0 1 0\nf 1 2 3\n");
  expect_error(dir / "huge.obj", "vertex 1 has coordinate (1e+308, 0, 0), beyond +-1e+09");
  // Large but plausible coordinates still load (1e8 mm = 100 km).
  write_text(dir / "big_mm.obj", "v 0 0 0\nv 1e8 0 0\nv 0 1 0\nf 1 2 3\n");
  EXPECT_NO_THROW(load_mesh(dir / "big_mm.obj", LengthUnit::mm));
}

TEST(MeshIO, AFaceWithAHundredThousandVerticesIsFannedInLinearTime) {
  // Before: tinyobjloader's ear clipping took 8.7 s on this face (no timing is asserted here;
  // ctest's timeout and the sanitizer run catch a return of the quadratic path).
  const auto dir = test::scratch_dir("big-face");
  const int n = 100000;
  std::string text;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    text += fmt::format("v {} {} 0\n", std::cos(a), std::sin(a));
  }
  text += "f";
  for (int i = 1; i <= n; ++i) {  // two appends: GCC 12's -Wrestrict misfires on " " + string
    text += ' ';
    text += std::to_string(i);
  }
  text += "\nv 0 0 1\nv 1 0 1\nv 0 1 1\nf -3 -2 -1\n";
  write_text(dir / "disc.obj", text);
  const TriMesh m = load_mesh(dir / "disc.obj", LengthUnit::m);
  EXPECT_EQ(m.num_faces(), std::size_t(n - 2 + 1));
  double area = 0;
  for (std::size_t f = 0; f < m.num_faces(); ++f) area += m.face_area(f);
  EXPECT_NEAR(area, M_PI + 0.5, 1e-6);  // the fan covers the convex disc exactly once
}

TEST(MeshIOMalformed, PlyErrors) {
  const auto dir = test::scratch_dir("bad-ply");
  const std::string head =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  write_text(dir / "nan.ply", head + "0 0 0\n1 0 0\n0 nan 0\n3 0 1 2\n");
  expect_error(dir / "nan.ply", ":12");
  write_text(dir / "range.ply", head + "0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n");
  expect_error(dir / "range.ply", ":13");
  write_text(dir / "trunc.ply", head + "0 0 0\n1 0 0\n0 1");
  expect_error(dir / "trunc.ply", "truncated");
  write_text(dir / "noend.ply", "ply\nformat ascii 1.0\nelement vertex 3\n");
  expect_error(dir / "noend.ply", "end_header");
  write_text(dir / "empty.ply", "");
  expect_error(dir / "empty.ply", "empty");
  // Binary, truncated mid-vertex and with an absurd element count.
  TriMesh tri;
  tri.positions = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  tri.faces = {Vec3i(0, 1, 2)};
  save_mesh(tri, dir / "ok.ply", LengthUnit::m);
  const std::string bin = read_file(dir / "ok.ply");
  write_text(dir / "truncbin.ply", bin.substr(0, bin.size() - 7));
  expect_error(dir / "truncbin.ply", "truncated");
  std::string huge = bin;
  huge.replace(huge.find("element vertex 3"), 16, "element vertex 300000000");
  write_text(dir / "huge.ply", huge);
  expect_error(dir / "huge.ply", "truncated");
  // Binary NaN coordinate.
  std::string nanbin = bin;
  const std::size_t body = nanbin.find("end_header\n") + 11;
  const double qnan = std::numeric_limits<double>::quiet_NaN();
  std::memcpy(nanbin.data() + body + 8, &qnan, 8);
  write_text(dir / "nanbin.ply", nanbin);
  expect_error(dir / "nanbin.ply", "not finite");
}

TEST(MeshIOMalformed, GltfErrors) {
  const auto dir = test::scratch_dir("bad-gltf");
  write_text(dir / "empty.gltf", "");
  expect_error(dir / "empty.gltf", "empty");
  write_text(dir / "json.gltf", "{\"asset\": {\"version\": \"2.0\"}, \"meshes\": [");
  expect_error(dir / "json.gltf");
  TriMesh tri;
  tri.positions = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  tri.faces = {Vec3i(0, 1, 2)};
  save_mesh(tri, dir / "ok.glb", LengthUnit::m);
  const std::string glb = read_file(dir / "ok.glb");
  write_text(dir / "trunc.glb", glb.substr(0, glb.size() / 2));
  expect_error(dir / "trunc.glb");
  // Out-of-range index: patch the last uint32 index (2) to 9.
  std::string bad = glb;
  const uint32_t two = 2, nine = 9;
  const std::size_t pos = bad.rfind(std::string(reinterpret_cast<const char*>(&two), 4));
  ASSERT_NE(pos, std::string::npos);
  std::memcpy(bad.data() + pos, &nine, 4);
  write_text(dir / "range.glb", bad);
  expect_error(dir / "range.glb", "index");
}

TEST(MeshIOMalformed, RandomBytesNeverCrash) {
  const auto dir = test::scratch_dir("random");
  Rng rng(1234);
  for (const char* ext : {".obj", ".ply", ".gltf", ".glb"})
    for (int trial = 0; trial < 8; ++trial) {
      std::string bytes(64 + rng.below(2048), '\0');
      for (char& c : bytes) c = char(rng.below(256));
      if (trial % 2) bytes = std::string(ext == std::string(".ply") ? "ply\n" : "glTF") + bytes;
      const auto p = dir / (std::string("r") + std::to_string(trial) + ext);
      write_text(p, bytes);
      expect_error(p);
    }
}

TEST(MeshIOMalformed, UnknownExtension) {
  const auto dir = test::scratch_dir("ext");
  write_text(dir / "m.stl", "solid x\n");
  expect_error(dir / "m.stl", "extension");
  EXPECT_THROW(save_mesh(make_cube(), dir / "m.fbx", LengthUnit::m), Error);
}

TEST(MeshIO, WritesAreAtomic) {
  const auto dir = test::scratch_dir("atomic");
  save_mesh(make_cube(), dir / "c.ply", LengthUnit::m);
  for (const auto& e : fs::directory_iterator(dir))
    EXPECT_EQ(e.path().filename(), "c.ply");  // no temp files left behind
}
