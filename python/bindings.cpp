// The Python module `follicle` (pybind11): meshes and grooms as NumPy arrays, scenes that render,
// step their hair and take expressions frame by frame. A thin layer over the library: every
// check and message is the library's, so a Python user sees the CLI's errors as follicle.Error.
//
// Threads: long calls (loading, simulating, rendering) release the GIL; each Scene serialises its
// own calls with a mutex (a Session and its GL renderer are used by one thread at a time).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "follicle/core/context.hpp"
#include "follicle/core/error.hpp"
#include "follicle/core/units.hpp"
#include "follicle/geom/mesh_io.hpp"
#include "follicle/geom/strand_io.hpp"
#include "follicle/geom/strands.hpp"
#include "follicle/geom/trimesh.hpp"
#include "follicle/image/image_io.hpp"
#include "follicle/render/renderer.hpp"
#include "follicle/scene/session.hpp"

namespace py = pybind11;
using namespace follicle;

namespace {

using ConstMesh = std::shared_ptr<const geom::TriMesh>;
using ConstStrands = std::shared_ptr<const geom::StrandSet>;

// --- arrays -------------------------------------------------------------------------------------

template <class T>
py::array_t<T> array2(std::size_t rows, std::size_t cols) {
  return py::array_t<T>({py::ssize_t(rows), py::ssize_t(cols)});
}

template <class T, class V>
py::array_t<T> rows_of(const std::vector<V>& v, std::size_t cols) {
  auto a = array2<T>(v.size(), cols);
  auto m = a.template mutable_unchecked<2>();
  for (std::size_t i = 0; i < v.size(); ++i)
    for (std::size_t k = 0; k < cols; ++k) m(py::ssize_t(i), py::ssize_t(k)) = T(v[i][k]);
  return a;
}

// An (N, cols) array from any array-like (lists, other dtypes are converted by NumPy).
template <class T>
py::array_t<T, py::array::c_style | py::array::forcecast> as_rows(const py::handle& h,
                                                                  std::size_t cols,
                                                                  const char* what) {
  auto a = py::array_t<T, py::array::c_style | py::array::forcecast>::ensure(h);
  if (!a) throw Error(fmt::format("{}: expected an array of shape (N, {})", what, cols));
  if (a.ndim() != 2 || std::size_t(a.shape(1)) != cols)
    throw Error(fmt::format(
        "{}: expected shape (N, {}), got {} dimension(s){}", what, cols, a.ndim(),
        a.ndim() == 2 ? fmt::format(" ({}, {})", a.shape(0), a.shape(1)) : std::string()));
  return a;
}

LengthUnit unit_of(const std::string& s) {
  return parse_length_unit(s);
}

// --- Mesh ---------------------------------------------------------------------------------------

struct PyMesh {
  ConstMesh m;
};

PyMesh mesh_from_arrays(const py::handle& vertices, const py::handle& faces) {
  const auto v = as_rows<double>(vertices, 3, "vertices");
  const auto f = as_rows<long long>(faces, 3, "faces");
  auto mesh = std::make_shared<geom::TriMesh>();
  mesh->positions.resize(std::size_t(v.shape(0)));
  for (py::ssize_t i = 0; i < v.shape(0); ++i)
    mesh->positions[std::size_t(i)] = Vec3(v.at(i, 0), v.at(i, 1), v.at(i, 2));
  mesh->faces.resize(std::size_t(f.shape(0)));
  for (py::ssize_t i = 0; i < f.shape(0); ++i) {
    for (int k = 0; k < 3; ++k) {
      const long long idx = f.at(i, k);
      if (idx < 0 || idx >= v.shape(0))
        throw Error(fmt::format("faces[{}][{}] = {} is not a vertex index (0..{})", i, k, idx,
                                v.shape(0) - 1));
    }
    mesh->faces[std::size_t(i)] = Vec3i(int(f.at(i, 0)), int(f.at(i, 1)), int(f.at(i, 2)));
  }
  mesh->check("Mesh");
  mesh->compute_normals();
  return PyMesh{mesh};
}

// --- Strands ------------------------------------------------------------------------------------

struct PyStrands {
  ConstStrands s;
};

PyStrands strands_from_arrays(const py::handle& points, const py::handle& sizes) {
  const auto p = as_rows<float>(points, 3, "points");
  auto n = py::array_t<long long, py::array::c_style | py::array::forcecast>::ensure(sizes);
  if (!n || n.ndim() != 1) throw Error("strand_sizes: expected a 1-D array of point counts");
  auto s = std::make_shared<geom::StrandSet>();
  long long total = 0;
  for (py::ssize_t i = 0; i < n.shape(0); ++i) {
    const long long k = n.at(i);
    if (k < 2) throw Error(fmt::format("strand_sizes[{}] = {}: a strand needs 2 points", i, k));
    total += k;
    if (total > p.shape(0)) break;
    s->offsets.push_back(uint32_t(total));
  }
  if (total != p.shape(0))
    throw Error(
        fmt::format("strand_sizes add up to {} but there are {} points", total, p.shape(0)));
  s->points.resize(std::size_t(p.shape(0)));
  for (py::ssize_t i = 0; i < p.shape(0); ++i)
    s->points[std::size_t(i)] = Vec3f(p.at(i, 0), p.at(i, 1), p.at(i, 2));
  s->check("Strands");
  return PyStrands{s};
}

py::array_t<uint32_t> strand_sizes(const geom::StrandSet& s) {
  py::array_t<uint32_t> a(py::ssize_t(s.num_strands()));
  auto m = a.mutable_unchecked<1>();
  for (std::size_t i = 0; i < s.num_strands(); ++i) m(py::ssize_t(i)) = s.strand_size(i);
  return a;
}

// --- Scene --------------------------------------------------------------------------------------

class PyScene {
 public:
  PyScene(const std::filesystem::path& path, int threads, uint64_t seed)
      : m_ctx(std::make_unique<Context>(threads, seed)),
        m_session(scene::Session::load(path, *m_ctx)) {}

  std::mutex& mutex() { return m_mu; }
  scene::Session& session() { return m_session; }

  image::ImageRGBA8 render(int frame, int width, int height) {
    auto& sc = m_session.scene();
    const int w0 = sc.render.width, h0 = sc.render.height;
    if (width > 0) sc.render.width = width;
    if (height > 0) sc.render.height = height;
    try {
      m_session.validate();
      const auto rs = m_session.render_scene(frame);
      if (!m_renderer) m_renderer = render::Renderer::create_headless(*m_ctx);
      auto img = m_renderer->render(rs, m_session.render_settings());
      sc.render.width = w0;
      sc.render.height = h0;
      return img;
    } catch (...) {
      sc.render.width = w0;
      sc.render.height = h0;
      throw;
    }
  }

 private:
  std::mutex m_mu;
  std::unique_ptr<Context> m_ctx;  // before the session: it holds a reference
  scene::Session m_session;
  std::unique_ptr<render::Renderer> m_renderer;  // made on the first render, then reused
};

// Runs `f` with the GIL released and the scene's mutex held.
template <class F>
auto locked(PyScene& s, F&& f) {
  py::gil_scoped_release nogil;
  std::lock_guard<std::mutex> lock(s.mutex());
  return f(s.session());
}

void check_frame(int frame) {
  if (frame < 0) throw Error(fmt::format("frame must be >= 0, got {}", frame));
}

}  // namespace

PYBIND11_MODULE(_follicle, m) {
  m.doc() =
      "Follicle: skin wrinkles and hair (Anjyo 1992, Daldegan 1993, Bando 2002/2003) from Python.\n"
      "Lengths are metres; meshes and strands convert from their file's units on load.";
  m.attr("__version__") = FOLLICLE_VERSION;

  static py::exception<Error> error_type(m, "Error", PyExc_RuntimeError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const Error& e) {
      error_type(e.what());
    }
  });

  // Mesh
  py::class_<PyMesh>(m, "Mesh",
                     "A triangle mesh in metres (vertices (N, 3) float64, faces (M, 3) int32).")
      .def(py::init(&mesh_from_arrays), py::arg("vertices"), py::arg("faces"),
           "A mesh from arrays: vertices (N, 3) [m], faces (M, 3) vertex indices "
           "(counter-clockwise seen from outside). Normals are computed.")
      .def_property_readonly("vertices",
                             [](const PyMesh& p) { return rows_of<double>(p.m->positions, 3); })
      .def_property_readonly("faces",
                             [](const PyMesh& p) { return rows_of<int32_t>(p.m->faces, 3); })
      .def_property_readonly("normals",
                             [](const PyMesh& p) { return rows_of<double>(p.m->normals, 3); })
      .def_property_readonly("uvs", [](const PyMesh& p) { return rows_of<double>(p.m->uvs, 2); })
      .def_property_readonly("uv_faces",
                             [](const PyMesh& p) { return rows_of<int32_t>(p.m->uv_faces, 3); })
      .def_property_readonly(
          "bounds",
          [](const PyMesh& p) {
            const auto b = p.m->bounds();
            auto a = array2<double>(2, 3);
            auto w = a.mutable_unchecked<2>();
            for (int k = 0; k < 3; ++k) {
              w(0, k) = b.min()[k];
              w(1, k) = b.max()[k];
            }
            return a;
          },
          "[[min x, y, z], [max x, y, z]] in metres")
      .def_property_readonly("num_vertices", [](const PyMesh& p) { return p.m->num_vertices(); })
      .def_property_readonly("num_faces", [](const PyMesh& p) { return p.m->num_faces(); })
      .def(
          "save",
          [](const PyMesh& p, const std::filesystem::path& path, const std::string& units) {
            const auto u = unit_of(units);
            py::gil_scoped_release nogil;
            geom::save_mesh(*p.m, path, u);
          },
          py::arg("path"), py::arg("units") = "m",
          "Writes .obj, .ply, .gltf or .glb (by extension) atomically, coordinates in `units`.")
      .def("__repr__", [](const PyMesh& p) {
        return fmt::format("<follicle.Mesh {} vertices, {} faces>", p.m->num_vertices(),
                           p.m->num_faces());
      });

  m.def(
      "load_mesh",
      [](const std::filesystem::path& path, const std::string& units) {
        const auto u = unit_of(units);
        py::gil_scoped_release nogil;
        auto mesh = std::make_shared<geom::TriMesh>(geom::load_mesh(path, u));
        if (!mesh->has_normals()) mesh->compute_normals();
        return PyMesh{mesh};
      },
      py::arg("path"), py::arg("units") = "m",
      "Loads an OBJ, PLY, glTF or GLB mesh whose coordinates are in `units` (mm, cm, dm, m); the "
      "result is in metres.");

  // Strands
  py::class_<PyStrands>(m, "Strands",
                        "Hair strands in metres: points (P, 3) float32, root first, and "
                        "strand_sizes (S,) points per strand.")
      .def(py::init(&strands_from_arrays), py::arg("points"), py::arg("strand_sizes"),
           "Strands from arrays: points (P, 3) [m] and strand_sizes (S,) summing to P.")
      .def_property_readonly("points",
                             [](const PyStrands& p) { return rows_of<float>(p.s->points, 3); })
      .def_property_readonly("strand_sizes", [](const PyStrands& p) { return strand_sizes(*p.s); })
      .def_property_readonly(
          "offsets",
          [](const PyStrands& p) {
            return py::array_t<uint32_t>(py::ssize_t(p.s->offsets.size()), p.s->offsets.data());
          },
          "(S + 1,) start of each strand in points, then P")
      .def_property_readonly("roots",
                             [](const PyStrands& p) {
                               std::vector<Vec3f> r;
                               r.reserve(p.s->num_strands());
                               for (std::size_t i = 0; i < p.s->num_strands(); ++i)
                                 r.push_back(p.s->points[p.s->strand_begin(i)]);
                               return rows_of<float>(r, 3);
                             })
      .def_property_readonly("num_strands", [](const PyStrands& p) { return p.s->num_strands(); })
      .def_property_readonly("num_points", [](const PyStrands& p) { return p.s->num_points(); })
      .def(
          "strand",
          [](const PyStrands& p, std::size_t i) {
            if (i >= p.s->num_strands())
              throw py::index_error(
                  fmt::format("strand {} out of range ({} strands)", i, p.s->num_strands()));
            const std::vector<Vec3f> pts(p.s->points.begin() + p.s->strand_begin(i),
                                         p.s->points.begin() + p.s->offsets[i + 1]);
            return rows_of<float>(pts, 3);
          },
          py::arg("index"), "The points of one strand, (n, 3), root first.")
      .def(
          "save",
          [](const PyStrands& p, const std::filesystem::path& path, const std::string& units) {
            const auto u = unit_of(units);
            py::gil_scoped_release nogil;
            geom::save_strands(*p.s, path, u);
          },
          py::arg("path"), py::arg("units") = "m",
          "Writes .hair, .tfx, .usda or .obj (by extension) atomically, coordinates in `units`.")
      .def("__len__", [](const PyStrands& p) { return p.s->num_strands(); })
      .def("__repr__", [](const PyStrands& p) {
        return fmt::format("<follicle.Strands {} strands, {} points>", p.s->num_strands(),
                           p.s->num_points());
      });

  m.def(
      "load_strands",
      [](const std::filesystem::path& path, const std::string& units) {
        const auto u = unit_of(units);
        py::gil_scoped_release nogil;
        return PyStrands{std::make_shared<geom::StrandSet>(geom::load_strands(path, u))};
      },
      py::arg("path"), py::arg("units") = "m",
      "Loads a groom (.hair, .tfx, .usda/.usd BasisCurves, OBJ polylines) whose coordinates are "
      "in `units` (a .usda's metersPerUnit wins); the result is in metres.");

  m.def(
      "write_png",
      [](const std::filesystem::path& path, const py::handle& pixels) {
        auto a = py::array_t<uint8_t, py::array::c_style | py::array::forcecast>::ensure(pixels);
        if (!a || a.ndim() != 3 || (a.shape(2) != 3 && a.shape(2) != 4))
          throw Error("write_png: expected an (H, W, 3) or (H, W, 4) uint8 array");
        const int h = int(a.shape(0)), w = int(a.shape(1)), c = int(a.shape(2));
        if (w < 1 || h < 1) throw Error("write_png: the image is empty");
        if (c == 4) {
          image::ImageRGBA8 img(w, h);
          std::memcpy(img.data(), a.data(), std::size_t(w) * std::size_t(h) * 4);
          py::gil_scoped_release nogil;
          image::write_png(path, img);
        } else {
          image::ImageRGB8 img(w, h);
          std::memcpy(img.data(), a.data(), std::size_t(w) * std::size_t(h) * 3);
          py::gil_scoped_release nogil;
          image::write_png(path, img);
        }
      },
      py::arg("path"), py::arg("pixels"),
      "Writes an (H, W, 3|4) uint8 array (row 0 at the top, sRGB) as PNG, atomically.");

  // Scene
  py::class_<PyScene>(m, "Scene",
                      "A scene file, validated like `follicle validate`: render it, step its hair, "
                      "pose its faces frame by frame and read the results back.")
      .def(py::init([](const std::filesystem::path& path, int threads, uint64_t seed) {
             py::gil_scoped_release nogil;
             return std::make_unique<PyScene>(path, threads, seed);
           }),
           py::arg("path"), py::arg("threads") = 0, py::arg("seed") = 1,
           "Loads and validates a scene file; threads <= 0 uses every hardware thread (results "
           "are the same for any thread count).")
      .def_property_readonly(
          "frame_count",
          [](PyScene& s) { return locked(s, [](scene::Session& x) { return x.frame_count(); }); })
      .def(
          "frame_time",
          [](PyScene& s, int frame) {
            check_frame(frame);
            return locked(s, [&](scene::Session& x) { return x.frame_time(frame); });
          },
          py::arg("frame"), "Time of a frame [s].")
      .def_property_readonly(
          "size",
          [](PyScene& s) {
            return locked(s, [](scene::Session& x) {
              return std::pair<int, int>(x.scene().render.width, x.scene().render.height);
            });
          },
          "(width, height) of the scene's images")
      .def_property_readonly("mesh_names",
                             [](PyScene& s) {
                               return locked(s, [](scene::Session& x) {
                                 std::vector<std::string> n;
                                 for (const auto& a : x.scene().assets.meshes) n.push_back(a.name);
                                 return n;
                               });
                             })
      .def_property_readonly(
          "hair_groups",
          [](PyScene& s) {
            return locked(s, [](scene::Session& x) {
              std::vector<std::string> n;
              for (const auto& h : x.scene().hair) n.push_back(h.name);
              return n;
            });
          },
          "names of the hair[] groups, in order")
      .def_property_readonly(
          "skin_rigs",
          [](PyScene& s) {
            return locked(s, [](scene::Session& x) {
              std::vector<std::string> n;
              for (const auto& r : x.scene().skin) n.push_back(r.mesh);
              return n;
            });
          },
          "the mesh name of each skin[] rig, in order")
      .def(
          "summary",
          [](PyScene& s) { return locked(s, [](scene::Session& x) { return x.summary(); }); },
          "What `follicle info` prints about the scene.")
      .def(
          "render",
          [](PyScene& s, int frame, int width, int height) {
            check_frame(frame);
            if (width < 0 || height < 0)
              throw Error(fmt::format("width and height must be > 0, got {} x {}", width, height));
            image::ImageRGBA8 img = [&] {
              py::gil_scoped_release nogil;
              std::lock_guard<std::mutex> lock(s.mutex());
              return s.render(frame, width, height);
            }();
            py::array_t<uint8_t> a(
                {py::ssize_t(img.height()), py::ssize_t(img.width()), py::ssize_t(4)});
            std::memcpy(a.mutable_data(), img.data(),
                        std::size_t(img.width()) * std::size_t(img.height()) * 4);
            return a;
          },
          py::arg("frame") = 0, py::arg("width") = 0, py::arg("height") = 0,
          "Renders a frame like `follicle render` (headless OpenGL): an (H, W, 4) uint8 sRGB "
          "array, row 0 at the top. width/height 0 keep the scene's size.")
      .def(
          "mesh",
          [](PyScene& s, const std::string& name) {
            return PyMesh{locked(s, [&](scene::Session& x) { return x.mesh(x.mesh_index(name)); })};
          },
          py::arg("name"),
          "The mesh asset `name` as loaded (metres, the asset transform not applied).")
      .def(
          "skin_mesh",
          [](PyScene& s, std::size_t rig, int frame) {
            check_frame(frame);
            return PyMesh{locked(s, [&](scene::Session& x) { return x.skin_mesh(rig, frame); })};
          },
          py::arg("rig") = 0, py::arg("frame") = 0,
          "The deformed, wrinkled mesh of skin[rig] at `frame` (mesh-file coordinates in metres, "
          "refined; the asset transform not applied).")
      .def(
          "set_expression",
          [](PyScene& s, std::size_t rig, const std::string& expression, double weight,
             const std::map<std::string, double>& contractions, std::optional<double> jaw) {
            locked(s, [&](scene::Session& x) {
              x.set_skin_pose(rig, expression, weight, contractions, jaw);
              return 0;
            });
          },
          py::arg("rig"), py::arg("expression"), py::arg("weight") = 1.0,
          py::arg("contractions") = std::map<std::string, double>{},
          py::arg("jaw_angle") = py::none(),
          "Poses skin[rig] from now on: the face setup's `expression` * `weight`, then the named "
          "muscle `contractions` and `jaw_angle` [rad] when given (expression '' = no "
          "expression). Replaces the scene's expression or track until clear_pose().")
      .def(
          "set_contractions",
          [](PyScene& s, std::size_t rig, const std::map<std::string, double>& contractions,
             std::optional<double> jaw) {
            locked(s, [&](scene::Session& x) {
              x.set_skin_pose(rig, "", 0.0, contractions, jaw);
              return 0;
            });
          },
          py::arg("rig"), py::arg("contractions"), py::arg("jaw_angle") = py::none(),
          "Poses skin[rig] from now on by muscle contractions alone (others 0).")
      .def(
          "clear_pose",
          [](PyScene& s, std::size_t rig) {
            locked(s, [&](scene::Session& x) {
              x.clear_skin_pose(rig);
              return 0;
            });
          },
          py::arg("rig") = 0, "Back to the scene file's expression or track for skin[rig].")
      .def(
          "muscle_names",
          [](PyScene& s, std::size_t rig) {
            return locked(s, [&](scene::Session& x) { return x.skin_muscle_names(rig); });
          },
          py::arg("rig") = 0)
      .def(
          "expression_names",
          [](PyScene& s, std::size_t rig) {
            return locked(s, [&](scene::Session& x) { return x.skin_expression_names(rig); });
          },
          py::arg("rig") = 0)
      .def(
          "hair_strands",
          [](PyScene& s, std::size_t group, int frame) {
            check_frame(frame);
            return PyStrands{
                locked(s, [&](scene::Session& x) { return x.hair_strands(group, frame); })};
          },
          py::arg("group") = 0, py::arg("frame") = 0,
          "World-space strands of hair[group] at `frame`: the hair simulation is stepped "
          "deterministically from frame 0 (consecutive frames continue from the kept state).")
      .def(
          "hair_groom",
          [](PyScene& s, std::size_t group) {
            return PyStrands{locked(s, [&](scene::Session& x) {
              const auto g = x.hair_groom(group);
              return ConstStrands(g, &g->strands);
            })};
          },
          py::arg("group") = 0, "The groom of hair[group] at rest (scene coordinates).")
      .def(
          "hair_root_targets",
          [](PyScene& s, std::size_t group, int frame) {
            check_frame(frame);
            const auto t =
                locked(s, [&](scene::Session& x) { return x.hair_root_targets(group, frame); });
            return rows_of<double>(t, 3);
          },
          py::arg("group") = 0, py::arg("frame") = 0,
          "Where the roots of hair[group] belong at `frame` (on the moving, deforming scalp).")
      .def(
          "all_hair",
          [](PyScene& s, int frame) {
            check_frame(frame);
            return PyStrands{locked(s, [&](scene::Session& x) {
              return std::make_shared<const geom::StrandSet>(x.all_hair(frame));
            })};
          },
          py::arg("frame") = 0, "Every hair group at `frame`, concatenated.")
      .def(
          "set_strand_cache",
          [](PyScene& s, const std::filesystem::path& dir) {
            locked(s, [&](scene::Session& x) {
              x.set_strand_cache(dir);
              return 0;
            });
          },
          py::arg("dir"), "Per-frame strand cache folder, as `follicle animate --cache`.")
      .def(
          "lcp_particles",
          [](PyScene& s, int frame) {
            check_frame(frame);
            const auto p = locked(s, [&](scene::Session& x) { return x.lcp_particles(frame); });
            py::dict d;
            d["positions"] = rows_of<float>(p->positions, 3);
            d["directions"] = rows_of<float>(p->directions, 3);
            return d;
          },
          py::arg("frame") = 0,
          "The loosely connected particles of the `lcp` section at `frame`: a dict of "
          "positions (N, 3) [m] and unit directions (N, 3).")
      .def(
          "hand_mesh",
          [](PyScene& s, int frame) {
            check_frame(frame);
            return PyMesh{locked(s, [&](scene::Session& x) { return x.hand_frame(frame).mesh; })};
          },
          py::arg("frame") = 0, "The skinned, wrinkled hand of the `hand` section at `frame`.")
      .def("__repr__", [](PyScene& s) {
        return locked(s, [](scene::Session& x) {
          return fmt::format("<follicle.Scene '{}', {} frame(s)>", x.source_name(),
                             x.frame_count());
        });
      });

  // Shown as follicle.X (not follicle._follicle.X) in messages and help().
  for (const char* name : {"Error", "Mesh", "Strands", "Scene"})
    m.attr(name).attr("__module__") = "follicle";
}
