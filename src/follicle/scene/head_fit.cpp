#include "follicle/scene/head_fit.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "follicle/core/atomic_file.hpp"
#include "follicle/core/error.hpp"
#include "follicle/geom/mesh_io.hpp"
#include "follicle/geom/spatial_embree.hpp"
#include "follicle/image/image_io.hpp"
#include "follicle/image/raster.hpp"
#include "follicle/render/camera.hpp"
#include "follicle/render/renderer.hpp"
#include "follicle/scene/session.hpp"
#include "follicle/skin/setup_transfer.hpp"
#include "follicle/skin/wrinkle_transfer.hpp"

namespace follicle::scene {

namespace {

const skin::SphincterMuscle* find_sphincter(const skin::FaceSetup& s, const std::string& name) {
  for (const auto& m : s.muscles.sphincter)
    if (m.name == name) return &m;
  return nullptr;
}

/// Most frontal (+z) region vertex passing `keep`; -1 when none does.
template <class Keep>
int most_frontal(const geom::TriMesh& m, Keep&& keep) {
  int best = -1;
  for (std::size_t i = 0; i < m.num_vertices(); ++i)
    if (keep(m.positions[i]) && (best < 0 || m.positions[i].z() > m.positions[best].z()))
      best = int(i);
  return best;
}

int nearest_vertex(const geom::TriMesh& m, const Vec3& p) {
  int best = -1;
  double bd = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < m.num_vertices(); ++i) {
    const double d = (m.positions[i] - p).squaredNorm();
    if (d < bd) bd = d, best = int(i);
  }
  return best;
}

/// Rotation taking the template's axes (y up, z front) to the given ones.
Mat3 frame_rotation(const Vec3& up, const Vec3& front) {
  const Vec3 u = up.normalized();
  const Vec3 f = (front - front.dot(u) * u).normalized();
  Mat3 dst;
  dst.col(0) = u.cross(f);  // x = y cross z
  dst.col(1) = u;
  dst.col(2) = f;
  return dst;  // source axes are the identity
}

Json vec_json(const Vec3& v) {
  return Json::array({v.x(), v.y(), v.z()});
}

}  // namespace

HeadTemplate load_head_template(const std::filesystem::path& mesh, LengthUnit units,
                                const std::filesystem::path& setup) {
  HeadTemplate t;
  t.mesh = geom::load_mesh(mesh, units);
  t.setup = skin::load_face_setup(setup);
  const auto* oris = find_sphincter(t.setup, "orbicularis_oris");
  const auto* eye_l = find_sphincter(t.setup, "orbicularis_oculi_L");
  const auto* eye_r = find_sphincter(t.setup, "orbicularis_oculi_R");
  if (!oris || !eye_l || !eye_r)
    fail(
        "{}: a fitting template needs the sphincters orbicularis_oris, orbicularis_oculi_L and "
        "orbicularis_oculi_R (they locate its mouth and eyes)",
        setup.string());
  const Vec3 mouth = oris->center, eyes = 0.5 * (eye_l->center + eye_r->center);
  const double mid_x = mouth.x();

  // The chin on the full mesh first: the region is cut below it.
  const int chin_full = most_frontal(t.mesh, [&](const Vec3& p) {
    return std::abs(p.x() - mid_x) < 0.015 && p.y() < mouth.y() - 0.015 && p.y() > mouth.y() - 0.07;
  });
  if (chin_full < 0) fail("{}: no chin found below the template's mouth", mesh.string());
  const double cut_y = t.mesh.positions[std::size_t(chin_full)].y() - 0.04;

  // Region: faces wholly above the cut (head and upper neck, no shoulders).
  std::vector<int> remap(t.mesh.num_vertices(), -1);
  for (const auto& f : t.mesh.faces) {
    bool in = true;
    for (int k = 0; k < 3; ++k) in = in && t.mesh.positions[std::size_t(f[k])].y() >= cut_y;
    if (!in) continue;
    Vec3i g;
    for (int k = 0; k < 3; ++k) {
      int& r = remap[std::size_t(f[k])];
      if (r < 0) {
        r = int(t.region.positions.size());
        t.region.positions.push_back(t.mesh.positions[std::size_t(f[k])]);
        t.region_vertex.push_back(f[k]);
      }
      g[k] = r;
    }
    t.region.faces.push_back(g);
  }
  t.region.name = "template region";

  const int nose = most_frontal(t.region, [&](const Vec3& p) {
    return std::abs(p.x() - mid_x) < 0.03 && p.y() > mouth.y() && p.y() < eyes.y();
  });
  const int chin = remap[std::size_t(chin_full)];
  if (nose < 0 || chin < 0) fail("{}: no nose tip found between mouth and eyes", mesh.string());
  t.landmarks = {{"nose_tip", nose},
                 {"chin", chin},
                 {"mouth", nearest_vertex(t.region, mouth)},
                 {"eye_L", nearest_vertex(t.region, eye_l->center)},
                 {"eye_R", nearest_vertex(t.region, eye_r->center)}};
  return t;
}

HeadFit fit_head(const Context& ctx, const HeadTemplate& tpl, const geom::TriMesh& head,
                 const std::optional<Vec3>& up, const std::optional<Vec3>& front,
                 const HeadFitParams& params) {
  head.check("head");
  HeadFit fit;
  fit.orientation_given = up.has_value() || front.has_value();
  std::optional<Mat3> R0;
  if (fit.orientation_given) {
    const Vec3 u = up.value_or(Vec3::UnitY()), f = front.value_or(Vec3::UnitZ());
    if (u.norm() < 1e-9 || f.norm() < 1e-9 || u.normalized().cross(f.normalized()).norm() < 1e-3)
      fail("fit: --up and --front must be non-zero and not parallel");
    R0 = frame_rotation(u, f);
  }
  const auto rigid = geom::register_rigid(ctx, tpl.region, head, params.rigid, R0 ? &*R0 : nullptr);
  fit.rigid = rigid.xf;
  fit.rigid_residual = rigid.residual;
  fit.overlap_template = rigid.overlap_source;
  fit.overlap_head = rigid.overlap_target;

  // The nose tip on the new head: its most frontal vertex within 2.5 cm (template) of where the
  // similarity puts the template's.
  const Vec3 front_new = fit.rigid.R * Vec3::UnitZ();
  const Vec3 nose_guess =
      fit.rigid.apply(tpl.region.positions[std::size_t(tpl.landmarks[0].vertex)]);
  const double radius = 0.025 * fit.rigid.s;
  int nose = -1;
  for (std::size_t i = 0; i < head.num_vertices(); ++i)
    if ((head.positions[i] - nose_guess).norm() < radius &&
        (nose < 0 || head.positions[i].dot(front_new) > head.positions[nose].dot(front_new)))
      nose = int(i);
  std::vector<geom::Landmark> constraints;
  if (nose >= 0)
    constraints.push_back({tpl.landmarks[0].vertex, head.positions[std::size_t(nose)]});

  const auto nr =
      geom::register_nonrigid(ctx, tpl.region, head, fit.rigid, constraints, params.nonrigid);
  fit.residual_rms = nr.rms;
  fit.residual_p95 = nr.p95;
  fit.matched_fraction = nr.matched_fraction;
  fit.deformed_region = nr.positions;

  const geom::MeshQuery hq(head);
  for (const auto& m : tpl.landmarks) {
    HeadFit::Landmark l;
    l.name = m.name;
    const auto cp = hq.closest_point(nr.positions[std::size_t(m.vertex)]);
    l.position = cp.face >= 0 ? cp.point : nr.positions[std::size_t(m.vertex)];
    if (m.name == "nose_tip" && nose >= 0) {
      l.position = head.positions[std::size_t(nose)];
      l.detected = true;
    }
    fit.landmarks.push_back(l);
  }

  const skin::HeadMap map(tpl.region, nr.positions, fit.rigid, head);
  // A wrinkle point is off the head where the deformed template lies more than 3 mm (template
  // scale) from it: past a face mask's rim.
  fit.setup = skin::transfer_face_setup(tpl.setup, tpl.mesh, map, "fit", 0.003 * fit.rigid.s,
                                        &fit.dropped_wrinkles);
  return fit;
}

Json fitted_scene_json(const HeadFit& fit, const std::string& head_path, LengthUnit units,
                       const std::string& mapping, const std::string& expression) {
  const auto& xf = fit.rigid;
  const Vec3 up = fit.setup.up, front = fit.setup.front;
  // The template scenes' close-up camera (skin_angry.json) and three lights, carried by the fit.
  const Vec3 eye = xf.apply(Vec3(0.14, 0.07, 0.46)), target = xf.apply(Vec3(-0.005, 0.06, 0.06));
  Json mesh = {{"name", "head"},
               {"path", head_path},
               {"units", to_string(units)},
               {"up", vec_json(up)},
               {"front", vec_json(front)},
               {"material", {{"specular", 0.12}, {"shininess", 24}, {"ambient", 0.12}}}};
  Json rig = {{"mesh", "head"}, {"muscles", "setup.json"}, {"expression", expression}};
  if (mapping != "uv")
    rig["mapping"] = {{"method", mapping}, {"up", vec_json(up)}, {"front", vec_json(front)}};
  Json lights = Json::array();
  const struct {
    const char* name;
    Vec3 dir, color;
    double intensity;
    bool shadow;
  } ls[] = {{"key", {0.16, -0.8, -1.32}, {1.0, 0.96, 0.9}, 1.1, true},
            {"fill", {-1.22, -0.1, -0.35}, {0.8, 0.87, 1.0}, 0.3, false},
            {"rim", {-0.24, -0.6, 1.38}, {1.0, 0.98, 0.95}, 0.9, false}};
  for (const auto& l : ls) {
    Json j = {{"name", l.name},
              {"direction", vec_json(xf.R * l.dir)},
              {"color", vec_json(l.color)},
              {"intensity", l.intensity}};
    if (l.shadow) j["shadow"] = true;
    lights.push_back(j);
  }
  Json hair = {{"name", "bob"},
               {"model", "anjyo1992"},
               {"mesh", "head"},
               {"style", "bob"},
               {"shading",
                {{"hair_color", {0.16, 0.09, 0.05}},
                 {"ka_mean", 0.8},
                 {"ka_sigma", 0.15},
                 {"ks", 0.25},
                 {"exponent", 120}}},
               {"render", {{"width_px", 0.7}, {"opacity", 1.0}, {"shadow", true}}},
               {"seed", 1}};
  Json scene{
      {"follicle_scene", 1},
      {"description",
       "Written by follicle fit: the bundled template's face setup fitted to this head "
       "(setup.json), an expression that wrinkles the forehead, and a bob."},
      {"assets", {{"meshes", Json::array({mesh})}}},
      {"camera",
       {{"eye", vec_json(eye)},
        {"target", vec_json(target)},
        {"up", vec_json(up)},
        {"fov_deg", 30},
        {"near", 0.05 * xf.s},
        {"far", 10.0 * xf.s}}},
      {"lights", lights},
      {"render",
       {{"width", 800}, {"height", 800}, {"supersample", 2}, {"background", {0.06, 0.065, 0.075}}}},
      {"skin", Json::array({rig})},
      {"hair", Json::array({hair})},
      {"outputs", Json::array({Json{{"type", "image"}, {"path", "fitted.png"}}})}};
  if (!fit.whole_head()) {
    scene.erase("hair");
    scene["description"] =
        "Written by follicle fit: the bundled template's face setup fitted to this face "
        "(setup.json) and an expression that wrinkles the forehead. The mesh is a face mask "
        "(no scalp), so the scene has no hair.";
  }
  return scene;
}

namespace {

/// Paints `colour` over `img` with the coverage of `cov` (same size).
void composite(image::ImageRGBA8& img, const image::ImageF& cov, const Vec3& colour) {
  for (int y = 0; y < img.height(); ++y)
    for (int x = 0; x < img.width(); ++x) {
      const double a = std::clamp(double(cov.at(x, y)), 0.0, 1.0);
      if (a <= 0) continue;
      for (int c = 0; c < 3; ++c)
        img.at(x, y, c) = uint8_t(std::lround((1 - a) * img.at(x, y, c) + a * 255.0 * colour[c]));
    }
}

}  // namespace

std::string fit_mapping(const HeadFit& fit, const geom::TriMesh& head) {
  if (!head.has_uvs()) return "auto";
  try {
    (void)skin::place_surface_wrinkles(head, fit.setup.surface_wrinkles, "fit");
    return "uv";
  } catch (const Error&) {
    return "cylindrical";  // the head's UV islands cut a furrow: a layout of the rig's own
  }
}

FitOutputs write_head_fit(const Context& ctx, const HeadFit& fit,
                          const std::filesystem::path& head_file, LengthUnit units,
                          const std::string& mapping, const std::filesystem::path& dir,
                          int image_size) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) fail("fit: cannot create {}: {}", dir.string(), ec.message());
  const fs::path abs_dir = fs::absolute(dir), abs_head = fs::absolute(head_file);
  std::string rel = abs_head.lexically_relative(abs_dir).generic_string();
  if (rel.empty()) rel = abs_head.generic_string();

  FitOutputs out{dir / "setup.json", dir / "scene.json", dir / "fit.png"};
  const Json scene = fitted_scene_json(fit, rel, units, mapping);

  // fit.png: the neutral head without hair, rendered through the scene it belongs to.
  Json view = scene;
  view.erase("hair");
  view["skin"][0]["expression"] = "neutral";
  view["render"]["width"] = image_size;
  view["render"]["height"] = image_size;
  view["render"]["supersample"] = 1;
  // The session reads the setup from disk: a hidden copy until the render has worked, so a
  // failure leaves no setup.json behind.
  const fs::path staged = dir / ".setup.fit-staging.json";
  write_file_atomically(staged, skin::face_setup_to_json(fit.setup) + "\n");
  struct Remove {
    fs::path p;
    ~Remove() {
      std::error_code e;
      fs::remove(p, e);
    }
  } cleanup{staged};
  view["skin"][0]["muscles"] = staged.filename().string();
  auto session = Session::from_json(view, dir, (dir / "scene.json").string(), ctx);
  const auto rs = session.render_scene(0);
  auto renderer = render::Renderer::create_headless(ctx);
  auto img = renderer->render(rs, session.render_settings());
  const int w = img.width(), h = img.height();
  const auto px = [&](const Vec3& p) { return render::project_to_pixel(rs.camera, w, h, p); };
  const double lw = std::max(1.5, w / 400.0);
  image::ImageF muscles(w, h, 0.f), rings(w, h, 0.f), furrows(w, h, 0.f), found(w, h, 0.f),
      carried(w, h, 0.f);
  for (const auto& m : fit.setup.muscles.linear) {
    const auto a = px(m.origin), b = px(m.insertion);
    if (a && b) image::draw_line(muscles, *a, *b, lw, 1.f, image::Blend::Max);
    if (b) image::draw_disc(muscles, *b, 1.5 * lw, 1.f, image::Blend::Max);
  }
  for (const auto& m : fit.setup.muscles.sphincter) {
    std::vector<Vec2> ring;
    for (int k = 0; k <= 48; ++k) {
      const double t = 2 * kPi * k / 48;
      if (auto p = px(m.center + std::cos(t) * m.semi_axis_a + std::sin(t) * m.semi_axis_b))
        ring.push_back(*p);
    }
    if (ring.size() > 1) image::draw_polyline(rings, ring, lw, 1.f, image::Blend::Max);
  }
  for (const auto& wr : fit.setup.surface_wrinkles) {
    std::vector<Vec2> line;
    for (const auto& p : wr.points)
      if (auto q = px(p)) line.push_back(*q);
    if (line.size() > 1) image::draw_polyline(furrows, line, lw, 1.f, image::Blend::Max);
  }
  for (const auto& l : fit.landmarks)
    if (auto p = px(l.position))
      image::draw_disc(l.detected ? found : carried, *p, 3 * lw, 1.f, image::Blend::Max);
  composite(img, muscles, {0.9, 0.15, 0.1});
  composite(img, rings, {1.0, 0.55, 0.1});
  composite(img, furrows, {0.2, 0.5, 1.0});
  composite(img, carried, {1.0, 0.9, 0.1});
  composite(img, found, {0.2, 0.95, 0.3});
  image::write_png(out.image, img);
  write_file_atomically(out.setup, skin::face_setup_to_json(fit.setup) + "\n");
  write_file_atomically(out.scene, scene.dump(2) + "\n");
  return out;
}

}  // namespace follicle::scene
