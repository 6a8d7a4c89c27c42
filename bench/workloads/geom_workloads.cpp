// Geometry workloads: mesh load, closest-point queries on the default head, neighbour search.
#include <fmt/format.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>

#include "follicle/core/atomic_file.hpp"
#include "follicle/core/error.hpp"
#include "follicle/core/rng.hpp"
#include "follicle/geom/grid.hpp"
#include "follicle/geom/mesh_io.hpp"
#include "follicle/geom/spatial_embree.hpp"
#include "workloads/data_path.hpp"
#include "workloads/workload.hpp"

namespace follicle::workloads {

namespace {

namespace fs = std::filesystem;

fs::path default_head_path() {
  return find_data("meshes/lee_perry_smith/head.obj");
}

std::size_t size_of(const Sizes& s, const char* key, double lo) {
  const double v = s.at(key);
  if (!(v >= lo) || !std::isfinite(v) || v > 1e10)
    fail("size '{}' = {} is out of range: expected a number >= {}", key, v, lo);
  return std::size_t(std::llround(v));
}

class MeshLoad : public WorkloadInstance {
 public:
  MeshLoad() : m_path(default_head_path()) {}
  void run_once() override {
    const geom::TriMesh m = geom::load_mesh(m_path, LengthUnit::mm);
    m_faces = m.num_faces();
  }
  double items_per_iter() const override { return 1.0; }

 private:
  fs::path m_path;
  std::size_t m_faces = 0;
};

// A large scan-sized mesh (issue 21: "a 1M-triangle mesh loads in under 2 s"): a latitude-
// longitude sphere of about `triangles` triangles written once, untimed, into a temporary folder
// in one of the formats users bring scans in; each iteration loads it.
class LargeMeshLoad : public WorkloadInstance {
 public:
  LargeMeshLoad(std::size_t triangles, int format) {
    const int n = int(std::ceil(std::sqrt(double(triangles) / 2.0))) + 1;
    geom::TriMesh m;
    for (int i = 0; i < n; ++i) {
      const double th = kPi * (i + 0.5) / n;
      for (int j = 0; j < n; ++j) {
        const double ph = 2 * kPi * j / (n - 1);
        m.positions.emplace_back(0.1 * std::sin(th) * std::cos(ph), 0.1 * std::cos(th),
                                 0.1 * std::sin(th) * std::sin(ph));
      }
    }
    for (int i = 0; i + 1 < n; ++i)
      for (int j = 0; j + 1 < n; ++j) {
        const int a = i * n + j, b = a + 1, c = a + n, d = c + 1;
        m.faces.emplace_back(a, c, b);
        m.faces.emplace_back(b, c, d);
      }
    m_dir = fs::temp_directory_path() / fmt::format("follicle-mesh-load-{}-{}", ::getpid(),
                                                    reinterpret_cast<std::uintptr_t>(this));
    fs::create_directories(m_dir);
    switch (format) {
      case 0:
        m_path = m_dir / "mesh.obj";
        save_mesh(m, m_path, LengthUnit::mm);
        break;
      case 1:
        m_path = m_dir / "mesh.ply";
        save_mesh(m, m_path, LengthUnit::mm);
        break;
      case 2:
        m_path = m_dir / "mesh.ply";
        save_mesh(m, m_path, LengthUnit::mm, true);
        break;
      case 3: {  // one strip per ring of quads, -1 between them
        std::string out = fmt::format(
            "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty float x\n"
            "property float y\nproperty float z\nelement tristrips 1\nproperty list int int "
            "vertex_indices\nend_header\n",
            m.positions.size());
        auto put = [&](auto v) { out.append(reinterpret_cast<const char*>(&v), sizeof v); };
        for (const Vec3& p : m.positions)
          for (int k = 0; k < 3; ++k) put(float(p[k] * 1000.0));
        put(int32_t((n - 1) * (2 * n + 1) - 1));
        for (int i = 0; i + 1 < n; ++i) {
          if (i) put(int32_t(-1));
          for (int j = 0; j < n; ++j) {
            put(int32_t(i * n + j));
            put(int32_t((i + 1) * n + j));
          }
        }
        m_path = m_dir / "mesh.ply";
        write_file_atomically(m_path, out);
        break;
      }
      default:
        fail(
            "size 'format' = {} is not one of 0 (OBJ), 1 (binary PLY), 2 (ASCII PLY), "
            "3 (PLY triangle strips)",
            format);
    }
    m_faces = m.num_faces();
  }
  ~LargeMeshLoad() override {
    std::error_code ec;
    fs::remove_all(m_dir, ec);
  }
  void run_once() override {
    const geom::TriMesh m = geom::load_mesh(m_path, LengthUnit::mm);
    if (m.num_faces() != m_faces)
      fail("large-mesh-load read {} triangles back, wrote {}", m.num_faces(), m_faces);
  }
  double items_per_iter() const override { return double(m_faces); }

 private:
  fs::path m_dir, m_path;
  std::size_t m_faces = 0;
};

class ClosestPointQueries : public WorkloadInstance {
 public:
  ClosestPointQueries(const Context& ctx, std::size_t n)
      : m_ctx(ctx), m_query(geom::load_mesh(default_head_path(), LengthUnit::mm)) {
    // Query points spread through the head's bounding box enlarged by 20%, so some lie inside,
    // some on and some away from the surface (as for hair roots and collision probes).
    Eigen::AlignedBox3d box;
    for (const Vec3& p : m_query.positions()) box.extend(p);
    const Vec3 lo = box.min() - 0.1 * box.sizes(), size = 1.2 * box.sizes();
    m_points.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      Rng rng = Rng::stream(ctx.seed(), i);
      m_points[i] = lo + Vec3(rng.uniform(), rng.uniform(), rng.uniform()).cwiseProduct(size);
    }
  }
  void run_once() override { m_result = m_query.closest_points(m_ctx, m_points); }
  double items_per_iter() const override { return double(m_points.size()); }

 private:
  const Context& m_ctx;
  geom::MeshQuery m_query;
  std::vector<Vec3> m_points;
  std::vector<geom::ClosestPoint> m_result;
};

class NeighbourSearch : public WorkloadInstance {
 public:
  NeighbourSearch(const Context& ctx, std::size_t n, double radius)
      : m_ctx(ctx), m_radius(float(radius)) {
    // Uniform random particles in a unit cube.
    m_points.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      Rng rng = Rng::stream(ctx.seed(), i);
      m_points[i] = Vec3f(float(rng.uniform()), float(rng.uniform()), float(rng.uniform()));
    }
  }
  // Build the grid and all neighbour lists (what an SPH step does).
  void run_once() override {
    m_grid.build(m_ctx, m_points, m_radius);
    m_lists = m_grid.neighbour_lists(m_ctx, m_radius);
  }
  double items_per_iter() const override { return double(m_points.size()); }
  double mean_neighbours() const {
    return m_points.empty() ? 0.0 : double(m_lists.index.size()) / double(m_points.size());
  }

 private:
  const Context& m_ctx;
  float m_radius;
  std::vector<Vec3f> m_points;
  geom::NeighbourGrid m_grid;
  geom::NeighbourList m_lists;
};

}  // namespace

void add_geom_workloads(std::vector<Workload>& out) {
  out.push_back({"mesh-load",
                 "load the default head OBJ (8838 vertices) and convert mm to m",
                 {},
                 "meshes/s",
                 [](const Context&, const Sizes&) {
                   return std::unique_ptr<WorkloadInstance>(new MeshLoad());
                 }});
  out.push_back({"large-mesh-load",
                 "load a scan-sized latitude-longitude sphere of ~`triangles` triangles in mm; "
                 "format 0 = OBJ, 1 = binary PLY, 2 = ASCII PLY, 3 = binary PLY triangle strips",
                 {{"triangles", 1e6}, {"format", 0}},
                 "triangles/s",
                 [](const Context&, const Sizes& s) {
                   const std::size_t t = size_of(s, "triangles", 2);
                   const double f = s.at("format");
                   if (!(f >= 0 && f <= 3 && f == std::floor(f)))
                     fail(
                         "size 'format' = {} is not one of 0 (OBJ), 1 (binary PLY), 2 (ASCII "
                         "PLY), 3 (PLY triangle strips)",
                         f);
                   return std::unique_ptr<WorkloadInstance>(new LargeMeshLoad(t, int(f)));
                 }});
  out.push_back({"closest-point",
                 "closest surface point on the default head (Embree) for random points around it",
                 {{"queries", 1e6}},
                 "queries/s",
                 [](const Context& ctx, const Sizes& s) {
                   return std::unique_ptr<WorkloadInstance>(
                       new ClosestPointQueries(ctx, size_of(s, "queries", 1)));
                 }});
  out.push_back({"neighbour-search",
                 "uniform-grid build + fixed-radius neighbour lists over random particles in a "
                 "unit cube; radius 0 = automatic, ~12 neighbours per particle",
                 {{"particles", 1e6}, {"radius", 0.0}},
                 "particles/s",
                 [](const Context& ctx, const Sizes& s) {
                   const std::size_t n = size_of(s, "particles", 1);
                   double r = s.at("radius");
                   if (!(r >= 0) || !std::isfinite(r))
                     fail("size 'radius' = {} must be a number >= 0 (0 = automatic)", r);
                   // ~12 neighbours among n uniform points in a unit cube: (4/3) pi r^3 n = 12.
                   if (r == 0) r = std::cbrt(12.0 * 3.0 / (4.0 * kPi * double(n)));
                   return std::unique_ptr<WorkloadInstance>(new NeighbourSearch(ctx, n, r));
                 }});
}

}  // namespace follicle::workloads
