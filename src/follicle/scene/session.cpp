#include "follicle/scene/session.hpp"

#include <fmt/format.h>

#include <set>

#include "follicle/core/log.hpp"
#include "follicle/geom/mesh_io.hpp"
#include "follicle/hair/shading_anjyo1992.hpp"
#include "follicle/image/image_io.hpp"
#include "follicle/render/camera.hpp"
#include "follicle/scene/hair_runtime.hpp"

namespace follicle::scene {

namespace {

render::MeshShading to_render(Shading s) {
  switch (s) {
    case Shading::BlinnPhong: return render::MeshShading::BlinnPhong;
    case Shading::Unlit: return render::MeshShading::Unlit;
  }
  return render::MeshShading::BlinnPhong;
}

}  // namespace

Session Session::load(const std::filesystem::path& scene_file, const Context& ctx) {
  const Json j = parse_json_file(scene_file);
  return from_json(j, scene_file.parent_path(), scene_file.string(), ctx);
}

Session Session::from_json(const Json& j, const std::filesystem::path& base_dir,
                           const std::string& name_for_errors, const Context& ctx) {
  return Session(read_scene(j, JsonSource{name_for_errors}), base_dir, name_for_errors, ctx);
}

Session::Session(Scene scene, std::filesystem::path base_dir, std::string source_name,
                 const Context& ctx)
    : m_scene(std::move(scene)),
      m_base_dir(std::move(base_dir)),
      m_source(std::move(source_name)),
      m_ctx(&ctx) {
  validate();
}

void Session::validate() const {
  const JsonSource src{m_source};
  validate_params(m_scene, "");  // per-key ranges again, in case scene() was edited
  m_scene.validate(src);
  // Referenced files must exist; the message names the JSON path and the resolved file.
  for (std::size_t i = 0; i < m_scene.assets.meshes.size(); ++i) {
    const auto& m = m_scene.assets.meshes[i];
    const std::string p = index_path("assets.meshes", i);
    const auto file = resolve(m.path);
    if (!std::filesystem::is_regular_file(file))
      json_fail(src, p + ".path", "mesh file not found: " + file.string());
    if (!m.material.texture.empty()) {
      const auto tex = resolve(m.material.texture);
      if (!std::filesystem::is_regular_file(tex))
        json_fail(src, p + ".material.texture", "texture file not found: " + tex.string());
    }
  }
  for (std::size_t i = 0; i < m_scene.assets.grooms.size(); ++i) {
    const auto file = resolve(m_scene.assets.grooms[i].path);
    if (!std::filesystem::is_regular_file(file))
      json_fail(src, index_path("assets.grooms", i) + ".path",
                "groom file not found: " + file.string());
  }
  if (m_scene.hand && !std::filesystem::is_directory(resolve(m_scene.hand->makehuman)))
    json_fail(src, "hand.makehuman",
              "MakeHuman folder not found: " + resolve(m_scene.hand->makehuman).string());
  validate_skin_files();  // session_skin.cpp
}

std::filesystem::path Session::resolve(const std::string& relative) const {
  const std::filesystem::path p(relative);
  if (p.is_absolute() || m_base_dir.empty()) return p;
  return m_base_dir / p;
}

std::shared_ptr<const geom::TriMesh> Session::mesh(std::size_t index) {
  if (index >= m_scene.assets.meshes.size())
    fail("mesh index {} out of range ({} meshes)", index, m_scene.assets.meshes.size());
  const auto& a = m_scene.assets.meshes[index];
  const auto file = resolve(a.path);
  const std::string key = file.lexically_normal().string() + "|" + to_string(a.units);
  if (auto it = m_meshes.find(key); it != m_meshes.end()) return it->second;
  m_ctx->log().info("loading mesh {} ({})", file.string(), to_string(a.units));
  auto mesh = std::make_shared<geom::TriMesh>(geom::load_mesh(file, a.units));
  if (!mesh->has_normals()) mesh->compute_normals();
  m_meshes.emplace(key, mesh);
  return mesh;
}

std::size_t Session::mesh_index(const std::string& name) const {
  std::vector<std::string> names;
  for (std::size_t i = 0; i < m_scene.assets.meshes.size(); ++i) {
    if (m_scene.assets.meshes[i].name == name) return i;
    names.push_back(m_scene.assets.meshes[i].name);
  }
  const std::string hint = did_you_mean(name, names);
  fail_at(m_source, "no mesh asset named \"{}\"{}", name,
          hint.empty() ? "" : fmt::format(" (did you mean \"{}\"?)", hint));
}

std::shared_ptr<const image::ImageRGBA8> Session::texture(const std::string& relative) {
  const auto file = resolve(relative);
  const std::string key = file.lexically_normal().string();
  if (auto it = m_textures.find(key); it != m_textures.end()) return it->second;
  m_ctx->log().info("loading texture {}", file.string());
  auto img = std::make_shared<image::ImageRGBA8>(image::read_png_rgba(file));
  m_textures.emplace(key, img);
  return img;
}

void Session::load_all_assets() {
  for (std::size_t i = 0; i < m_scene.assets.meshes.size(); ++i) {
    mesh(i);
    if (!m_scene.assets.meshes[i].material.texture.empty())
      texture(m_scene.assets.meshes[i].material.texture);
  }
  for (std::size_t i = 0; i < m_scene.assets.grooms.size(); ++i) groom_strands(i);
  load_skin_setups();  // session_skin.cpp
}

render::RenderScene Session::render_scene(int frame) {
  if (frame < 0) fail("frame {} is negative", frame);
  render::RenderScene rs;
  const auto& c = m_scene.camera;
  rs.camera.eye = c.eye;
  rs.camera.target = c.target;
  rs.camera.up = c.up;
  rs.camera.fov_y = c.fov_deg * kPi / 180.0;
  rs.camera.z_near = c.near;
  rs.camera.z_far = c.far;
  for (const auto& l : m_scene.lights) {
    render::DirectionalLight dl;
    dl.direction = l.direction.normalized();
    dl.color = l.color;
    dl.intensity = l.intensity;
    dl.cast_shadow = l.shadow;
    rs.lights.push_back(dl);
  }
  rs.ambient_color = m_scene.render.ambient_color;
  rs.background = m_scene.render.background;
  // Meshes that grow hair follow the head motion.
  const auto motion = head_motion_transform(frame);
  std::set<std::string> hair_meshes;
  for (const auto& h : m_scene.hair) hair_meshes.insert(h.mesh);
  for (std::size_t i = 0; i < m_scene.assets.meshes.size(); ++i) {
    const auto& a = m_scene.assets.meshes[i];
    if (!a.visible) continue;
    render::MeshItem item;
    item.mesh = mesh(i);
    item.transform = a.transform.matrix();
    if (motion && !a.name.empty() && hair_meshes.count(a.name))
      item.transform = *motion * item.transform;
    item.cast_shadow = a.cast_shadow;
    auto& mat = item.material;
    mat.shading = to_render(a.material.shading);
    mat.base_color = a.material.base_color;
    mat.specular = a.material.specular;
    mat.shininess = a.material.shininess;
    mat.ambient = a.material.ambient;
    if (!a.material.texture.empty()) mat.albedo_map = texture(a.material.texture);
    apply_skin(i, item, frame);  // face rig (session_skin.cpp)
    rs.meshes.push_back(std::move(item));
  }
  // Hair: Anjyo 1992 §4 shading per node (eqs. 8, 9; k_a per strand) on the CPU, drawn as
  // vertex-coloured z-buffered polylines; the key light is the first light.
  const Vec3 to_light = m_scene.lights.empty() ? (c.eye - c.target).normalized()
                                               : Vec3(-m_scene.lights[0].direction.normalized());
  for (std::size_t i = 0; i < m_scene.hair.size(); ++i) {
    const auto& h = m_scene.hair[i];
    if (h.model == HairModel::Daldegan1993) {
      add_daldegan_items(rs, i, frame);
      continue;
    }
    auto shaded = std::make_shared<geom::StrandSet>(*hair_strands(i, frame));
    hair::shade_anjyo1992(*m_ctx, *shaded, h.shading, c.eye, to_light, h.seed);
    render::StrandItem item;
    item.strands = std::move(shaded);
    item.material.shading = render::StrandShading::VertexColor;
    item.material.color = h.shading.hair_color;
    item.material.width_px = h.render.width_px;
    item.material.opacity = h.render.opacity;
    // Without the hair shadow buffers: 1-px lines make a speckled GL shadow map, and Anjyo 1992
    // has no shadows. With them (render.shadow), the CPU hair pass shadows hair and skin.
    item.cast_shadow = false;
    item.hair_shadow = h.render.shadow;
    rs.strands.push_back(std::move(item));
  }
  add_hand_items(rs, frame);  // session_hand.cpp
  add_lcp_items(rs, frame);   // session_lcp.cpp
  if (!m_view_checked) {
    m_view_checked = true;
    check_in_view(rs);
  }
  return rs;
}

void Session::check_in_view(const render::RenderScene& rs) const {
  // A mesh placed where the camera does not look (another unit, another origin, a camera from
  // another scene) renders as an empty background; name it once, with the likely fix.
  const double aspect = double(m_scene.render.width) / double(m_scene.render.height);
  std::size_t k = 0;
  for (std::size_t i = 0; i < m_scene.assets.meshes.size(); ++i) {
    const auto& a = m_scene.assets.meshes[i];
    if (!a.visible) continue;
    const render::MeshItem& item = rs.meshes[k++];
    Eigen::AlignedBox3d box;
    for (const auto& p : item.mesh->positions) box.extend(item.transform * p);
    if (render::box_in_view(rs.camera, aspect, box)) continue;
    const Vec3 c = box.center(), e = rs.camera.eye, t = rs.camera.target;
    m_ctx->log().warn(
        "{}: mesh \"{}\" (assets.meshes[{}]) is outside the camera's view: it is {:.3g} m across "
        "around [{:.3g}, {:.3g}, {:.3g}] m, the camera at [{:.3g}, {:.3g}, {:.3g}] looks at "
        "[{:.3g}, {:.3g}, {:.3g}] (fov {:.3g} deg, near {:.3g}, far {:.3g}); set camera.target to "
        "the mesh's centre, or check the mesh's units and transform",
        m_source, a.name, i, box.diagonal().norm(), c.x(), c.y(), c.z(), e.x(), e.y(), e.z(), t.x(),
        t.y(), t.z(), rs.camera.fov_y * 180.0 / kPi, rs.camera.z_near, rs.camera.z_far);
  }
}

void Session::add_daldegan_items(render::RenderScene& rs, std::size_t gi, int frame) {
  // Daldegan 1993 §4: one strand item per hair material (eq. (7) coefficients), drawn by the
  // shadow-buffer hair pass.
  const auto& h = m_scene.hair[gi];
  const auto strands = hair_strands(gi, frame);
  const auto groom = hair_groom(gi);
  std::vector<hair::HairMaterial> materials = hair_runtime().groups[gi].materials;
  if (materials.empty()) {  // an imported or Anjyo-styled groom: one material, the hair colour
    hair::HairMaterial m;
    m.color = h.shading.hair_color;
    materials.push_back(m);
  }
  std::vector<geom::StrandSet> parts(materials.size());
  for (std::size_t s = 0; s < strands->num_strands(); ++s) {
    const std::size_t m = groom->material.empty() ? 0 : groom->material[s];
    auto& part = parts[std::min(m, parts.size() - 1)];
    const uint32_t b = strands->strand_begin(s);
    part.points.insert(part.points.end(), strands->points.begin() + b,
                       strands->points.begin() + b + strands->strand_size(s));
    part.offsets.push_back(uint32_t(part.points.size()));
  }
  for (std::size_t m = 0; m < parts.size(); ++m) {
    if (parts[m].num_strands() == 0) continue;
    const auto& mat = materials[m];
    render::StrandItem item;
    item.strands = std::make_shared<const geom::StrandSet>(std::move(parts[m]));
    item.material.shading = render::StrandShading::Daldegan1993;
    item.material.color = mat.color;
    item.material.ambient = mat.ambient;
    item.material.diffuse = mat.diffuse;
    item.material.specular = mat.specular;
    item.material.shininess = mat.shininess;
    item.material.width_px = h.render.width_px;
    item.material.opacity = h.render.opacity;
    item.cast_shadow = false;
    item.hair_shadow = true;
    rs.strands.push_back(std::move(item));
  }
}

render::RenderSettings Session::render_settings() const {
  render::RenderSettings s;
  s.width = m_scene.render.width;
  s.height = m_scene.render.height;
  s.supersample = m_scene.render.supersample;
  s.shadow_map_size = m_scene.render.shadow_map_size;
  s.hair_light_pass = m_scene.render.hair_light_pass;
  s.hair_view_pass = m_scene.render.hair_view_pass;
  s.strand_pass = m_scene.render.strand_pass;
  return s;
}

std::string Session::summary() const {
  std::string out;
  out += fmt::format("scene: {} (format version {})\n", m_source, m_scene.follicle_scene);
  if (!m_scene.description.empty()) out += fmt::format("description: {}\n", m_scene.description);
  out += fmt::format("meshes: {}\n", m_scene.assets.meshes.size());
  for (const auto& m : m_scene.assets.meshes) {
    out +=
        fmt::format("  {} {} [{}]{}{}\n", m.name.empty() ? "-" : m.name, m.path, to_string(m.units),
                    m.material.texture.empty() ? "" : ", texture " + m.material.texture,
                    m.visible ? "" : ", hidden");
  }
  const auto& c = m_scene.camera;
  out += fmt::format(
      "camera: eye ({:.3f}, {:.3f}, {:.3f}) m, target ({:.3f}, {:.3f}, {:.3f}) m, "
      "fov {} deg\n",
      c.eye.x(), c.eye.y(), c.eye.z(), c.target.x(), c.target.y(), c.target.z(), c.fov_deg);
  out += fmt::format("lights: {}\n", m_scene.lights.size());
  out += fmt::format("render: {}x{} px, supersample {}\n", m_scene.render.width,
                     m_scene.render.height, m_scene.render.supersample);
  for (const auto& h : m_scene.hair)
    out += fmt::format(
        "hair: {} on mesh \"{}\", style {}, density scale {}\n", h.name, h.mesh,
        h.style.custom ? "\"" + h.style.custom->name + "\" (custom)" : "\"" + h.style.preset + "\"",
        h.density_scale);
  if (m_scene.hand)
    out += fmt::format("hand: MakeHuman ({}), wrinkles {}, flexion {}\n", m_scene.hand->makehuman,
                       m_scene.hand->wrinkles ? "on" : "off",
                       m_scene.hand->flexion ? fmt::format("{}", *m_scene.hand->flexion)
                                             : std::string("from the flexion track"));
  if (m_scene.lcp)
    out += fmt::format(
        "lcp hair: spacing {} m, hair-hair {}{}{}{}\n", m_scene.lcp->scenario.spacing,
        m_scene.lcp->dynamics.hair_hair ? "on" : "off",
        m_scene.lcp->scenario.shake ? ", head shake" : "",
        m_scene.lcp->scenario.wind ? ", SPH wind" : "", m_scene.lcp->part ? ", parting force" : "");
  if (m_scene.animation)
    out += fmt::format("animation: {} frames at {} fps\n", m_scene.animation->frame_count(),
                       m_scene.animation->fps);
  out += fmt::format("outputs: {}\n", m_scene.outputs.size());
  for (const auto& o : m_scene.outputs) out += fmt::format("  image {}\n", o.path);
  return out;
}

}  // namespace follicle::scene
