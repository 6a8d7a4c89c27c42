// CPU versions of the hair splatting formulas of Bando 2003 §3.4 (the GLSL in
// shaders_splat_gl.hpp codes the same expressions) and the procedural hair texture.
#include "follicle/render/splat_bando2003.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "follicle/core/error.hpp"
#include "follicle/core/rng.hpp"

namespace follicle::render {

double goldman_kappa(const Vec3& t, const Vec3& to_light, const Vec3& to_eye) {
  // Goldman 1997: cosine of the angle between the planes (t, l) and (t, e).
  const Vec3 a = t.cross(to_light), b = t.cross(to_eye);
  const double d = a.norm() * b.norm();
  return d > 1e-12 ? std::clamp(a.dot(b) / d, -1.0, 1.0) : 0.0;
}

double goldman_directionality(const Vec3& t, const Vec3& to_light, const Vec3& to_eye,
                              double reflect, double transmit) {
  const double k = goldman_kappa(t, to_light, to_eye);
  return 0.5 * (1 + k) * reflect + 0.5 * (1 - k) * transmit;  // Goldman f_dir
}

Vec3 kajiya_goldman(const Vec3& t, const Vec3& to_light, const Vec3& to_eye, const Vec3& colour,
                    const SplatMaterial& m) {
  const double tl = t.dot(to_light), te = t.dot(to_eye);
  const double sl = std::sqrt(std::max(0.0, 1 - tl * tl));
  const double se = std::sqrt(std::max(0.0, 1 - te * te));
  // Kajiya-Kay 1989: diffuse ~ sin(t, l); specular: cosine between e and the reflection cone
  // around t (half-angle acos(-t.l)), raised to p.
  const double spec = std::pow(std::max(0.0, sl * se - tl * te), m.shininess);
  const double fdir = goldman_directionality(t, to_light, to_eye, m.reflect, m.transmit);
  return fdir * (m.diffuse * sl * colour + Vec3::Constant(m.specular * spec));
}

void splat_billboard_axes(const Vec3& t, const Vec3& d_p, double min_sin, Vec3& along, Vec3& across,
                          double& s) {
  Vec3 tp = t - t.dot(d_p) * d_p;
  double st = tp.norm();
  if (st < 1e-6) {
    tp = d_p.cross(std::abs(d_p.x()) < 0.9 ? Vec3(1, 0, 0) : Vec3(0, 1, 0));
    st = 0;
  }
  along = tp.normalized();
  across = d_p.cross(along).normalized();
  s = std::max(st, min_sin);
}

double splat_sin_theta(const Vec3& t, const Vec3& d_p, double min_sin) {
  const double c = std::clamp(t.normalized().dot(d_p.normalized()), -1.0, 1.0);
  return std::max(std::sqrt(1 - c * c), min_sin);
}

double splat_opacity(double alpha, const Vec3& t, const Vec3& d_p, double min_sin) {
  // Bando 2003 §3.4: opacity scaled by 1/sin(theta), cos(theta) = t_i . d_p.
  return std::clamp(alpha / splat_sin_theta(t, d_p, min_sin), 0.0, 1.0);
}

image::ImageRGBA8 make_hair_texture(int width, int height, int strands, uint64_t seed) {
  if (width < 4 || height < 4) fail("make_hair_texture: size {}x{} is below 4x4", width, height);
  if (strands < 1) fail("make_hair_texture: {} strands, expected at least 1", strands);
  struct Streak {
    double x, sigma, slope, alpha, bright, v0, v1;
  };
  std::vector<Streak> streaks;
  for (int k = 0; k < strands; ++k) {
    Rng r = Rng::stream(seed, uint64_t(k));
    Streak s{};
    s.x = r.uniform(0.2, 0.8);          // centre across, in [0,1] of the width
    s.sigma = r.uniform(0.012, 0.028);  // cross-section (a pixel or two at 64 px)
    s.slope = r.uniform(-0.06, 0.06);   // slight tilt against the axis
    s.alpha = r.uniform(0.55, 1.0);     // coverage at the centre of the streak
    s.bright = r.uniform(0.6, 1.0);     // brightness variation between fibres
    s.v0 = r.uniform(0.0, 0.25);        // fades in ...
    s.v1 = r.uniform(0.75, 1.0);        // ... and out along the length
    streaks.push_back(s);
  }
  image::ImageRGBA8 img(width, height);
  for (int y = 0; y < height; ++y) {
    const double v = (y + 0.5) / height;
    for (int x = 0; x < width; ++x) {
      const double u = (x + 0.5) / width;
      double transmit = 1, wsum = 0, bsum = 0;
      for (const Streak& s : streaks) {
        const double d = u - (s.x + s.slope * (v - 0.5));
        double a = s.alpha * std::exp(-0.5 * d * d / (s.sigma * s.sigma));
        // smooth fade in [v0, v0 + 0.15] and [v1 - 0.15, v1]
        const double fin = std::clamp((v - s.v0) / 0.15, 0.0, 1.0);
        const double fout = std::clamp((s.v1 - v) / 0.15, 0.0, 1.0);
        a *= fin * fin * (3 - 2 * fin) * fout * fout * (3 - 2 * fout);
        transmit *= 1 - a;
        wsum += a;
        bsum += a * s.bright;
      }
      // Soft envelope: zero at the billboard border so overlapping splats blend seamlessly.
      const double ex = std::max(0.0, 1 - std::pow(2 * u - 1, 2));
      const double ey = std::max(0.0, 1 - std::pow(2 * v - 1, 4));
      const double alpha = (1 - transmit) * ex * ey;
      const double bright = wsum > 1e-9 ? bsum / wsum : 1.0;
      uint8_t* p = img.pixel(x, y);
      const auto q = [](double c) { return uint8_t(std::lround(std::clamp(c, 0.0, 1.0) * 255)); };
      p[0] = p[1] = p[2] = q(bright);
      p[3] = q(alpha);
    }
  }
  return img;
}

RenderScene make_hair_sheet_scene(int particles, uint64_t seed, double radius) {
  if (particles < 1) fail("make_hair_sheet_scene: {} particles, expected at least 1", particles);
  if (!(radius > 0)) fail("make_hair_sheet_scene: particle radius {} is not > 0", radius);
  constexpr double R = 0.1;
  RenderScene sc;
  // Head: UV sphere.
  auto head = std::make_shared<geom::TriMesh>();
  head->name = "sphere-head";
  const int nu = 64, nv = 32;
  for (int j = 0; j <= nv; ++j) {
    const double th = kPi * j / nv;
    for (int i = 0; i <= nu; ++i) {
      const double ph = 2 * kPi * i / nu;
      const Vec3 n(std::sin(th) * std::cos(ph), std::cos(th), -std::sin(th) * std::sin(ph));
      head->positions.push_back(R * n);
      head->normals.push_back(n);
    }
  }
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const int a = j * (nu + 1) + i, b = a + nu + 1;
      head->faces.emplace_back(a, b, b + 1);
      head->faces.emplace_back(a, b + 1, a + 1);
    }
  MeshItem hm;
  hm.mesh = head;
  hm.material.base_color = Vec3(0.75, 0.55, 0.45);
  hm.material.specular = 0.05;
  sc.meshes.push_back(hm);

  // Hair: strands of `per` particles each; roots on a Fibonacci lattice over the crown and the
  // back (the face, around +z below the crown, stays bare).
  const int per = 16;
  const int nstrands = std::max(1, (particles + per - 1) / per);
  auto ps = std::make_shared<geom::ParticleSet>();
  const double golden = kPi * (3 - std::sqrt(5.0));
  int made = 0;
  for (int k = 0; made < particles; ++k) {
    Rng r = Rng::stream(seed, uint64_t(k));
    // cap from the pole down to 75 degrees, area-uniform
    const double c = 1 - (1 - std::cos(75 * kPi / 180)) * (k + 0.5) / (1.6 * nstrands);
    const double th0 = std::acos(std::clamp(c, -1.0, 1.0)) + r.uniform(-0.02, 0.02);
    const double ph = golden * k;
    const Vec3 radial(std::cos(ph), 0, -std::sin(ph));  // horizontal direction of the strand
    const bool face = radial.z() > 0.35 && th0 > 0.45;
    if (face || th0 > 80 * kPi / 180) {
      if (k > 100 * nstrands) break;  // cannot happen with the cap above; guards the loop
      continue;
    }
    const double lift = r.uniform(0.004, 0.025);  // layer above the scalp
    const double len = r.uniform(0.18, 0.26);
    const double step = len / per;
    const double arc = (kPi / 2 - th0) * (R + lift);  // along the sphere to the equator
    for (int s = 0; s < per && made < particles; ++s, ++made) {
      const double d = (s + 0.5) * step;
      Vec3 p, t;
      if (d < arc) {
        const double th = th0 + d / (R + lift);
        p = (R + lift) * (std::sin(th) * radial + std::cos(th) * Vec3::UnitY());
        t = std::cos(th) * radial - std::sin(th) * Vec3::UnitY();
      } else {
        const double flare = 0.08 * (d - arc);  // hanging hair spreads a little outwards
        p = (R + lift + flare) * radial - (d - arc) * Vec3::UnitY();
        t = (0.08 * radial - Vec3::UnitY()).normalized();
      }
      p += Vec3(r.uniform(-1, 1), r.uniform(-1, 1), r.uniform(-1, 1)) * 0.15 * radius;
      t = (t + Vec3(r.uniform(-1, 1), r.uniform(-1, 1), r.uniform(-1, 1)) * 0.08).normalized();
      ps->positions.push_back(p.cast<float>());
      ps->directions.push_back(t.cast<float>());
    }
  }
  ParticleItem hair;
  hair.particles = ps;
  hair.shading = ParticleShading::HairSplat;
  hair.color = Vec3(0.20, 0.105, 0.05);
  hair.radius = radius;
  hair.opacity = 0.7;
  sc.particles.push_back(hair);

  DirectionalLight key;
  key.direction = Vec3(-0.75, -0.6, 0.25);
  key.intensity = 2.0;
  sc.lights.push_back(key);
  DirectionalLight fill;
  fill.direction = Vec3(0.6, -0.3, 0.6);
  fill.intensity = 0.3;
  fill.cast_shadow = false;
  sc.lights.push_back(fill);
  sc.ambient_color = Vec3(0.35, 0.35, 0.4);
  sc.background = Vec3(0.55, 0.6, 0.65);
  sc.camera.eye = Vec3(-0.25, 0.08, -0.45);
  sc.camera.target = Vec3(0, -0.03, 0);
  sc.camera.fov_y = 0.75;
  sc.camera.z_near = 0.05;
  sc.camera.z_far = 5;
  return sc;
}

}  // namespace follicle::render
