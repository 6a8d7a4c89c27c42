#include "follicle/render/framing.hpp"

#include <cmath>

#include "follicle/geom/mesh_io.hpp"
#include "follicle/image/image_io.hpp"
#include "follicle/render/lafortune.hpp"

namespace follicle::render {

Camera frame_box(const Eigen::AlignedBox3d& box, const Vec3& from_dir, double fov_y, double fill,
                 const Vec3& up) {
  if (box.isEmpty()) fail("frame_box: empty bounding box");
  if (from_dir.norm() <= 0) fail("frame_box: zero view direction");
  const double r = std::max(0.5 * box.diagonal().norm(), 1e-9);
  const double dist = r / std::sin(0.5 * fov_y * std::clamp(fill, 0.05, 1.0));
  Camera c;
  c.target = box.center();
  c.eye = c.target + from_dir.normalized() * dist;
  c.up = up;
  c.fov_y = fov_y;
  c.z_near = std::max(dist - 2 * r, dist * 1e-3);
  c.z_far = dist + 2 * r;
  return c;
}

RenderScene make_head_scene(const std::filesystem::path& head_dir, bool lafortune) {
  auto mesh =
      std::make_shared<geom::TriMesh>(geom::load_mesh(head_dir / "head.obj", LengthUnit::mm));
  RenderScene s;
  s.camera = frame_box(mesh->bounds(), Vec3(0.55, 0.12, 1.0), 0.5, 0.95);
  s.background = Vec3(0.05, 0.055, 0.065);
  s.ambient_color = Vec3(0.55, 0.6, 0.7);
  DirectionalLight key;
  key.direction = Vec3(0.45, -0.6, -0.75);  // from the upper left of the camera
  key.color = Vec3(1.0, 0.96, 0.9);
  key.intensity = 1.1;
  DirectionalLight fill;
  fill.direction = Vec3(-0.9, 0.0, -0.35);  // from the right
  fill.color = Vec3(0.55, 0.65, 0.9);
  fill.intensity = 0.3;
  fill.cast_shadow = false;
  s.lights = {key, fill};
  MeshItem m;
  m.mesh = mesh;
  m.material.albedo_map =
      std::make_shared<image::ImageRGBA8>(image::read_png_rgba(head_dir / "albedo.jpg"));
  const image::ImageRGBA8 n8 = image::read_png_rgba(head_dir / "normal_tangent.jpg");
  auto nm = std::make_shared<image::ImageRGBF>(n8.width(), n8.height());
  for (int y = 0; y < n8.height(); ++y)
    for (int x = 0; x < n8.width(); ++x)
      for (int c = 0; c < 3; ++c) nm->at(x, y, c) = n8.at(x, y, c) / 127.5f - 1.0f;
  m.material.normal_map = nm;
  m.material.specular = 0.12;
  m.material.shininess = 24;
  m.material.ambient = 0.25;
  if (lafortune) {
    m.material.shading = MeshShading::LafortuneSkin;
    m.material.lafortune = lafortune_skin_marschner();
  }
  s.meshes.push_back(m);
  return s;
}

}  // namespace follicle::render
