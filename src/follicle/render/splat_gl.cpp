// GL 3.3 hair splat passes of Bando 2003 §3.4 (see splat_gl.hpp).
//
// Light pass (pseudo-code lines 6-12), RenderSettings::hair_light_pass:
// - "cpu" (default; docs/adr/0005-cpu-splat-light-pass.md): the objects' shadow-map
//   visibility (line 8) does not depend on the hair, so one GL_POINTS draw of the gather program
//   writes it for every particle into the intensity texture, read back with one glReadPixels;
//   splat_light_pass_bando2003() then runs the paper's loop exactly, particle by particle, on
//   the CPU; the final buffer is uploaded as the light map and (visibility, light read) per
//   particle into the intensity texture the view pass reads.
// - "gpu" (docs/adr/0003-splat-light-pass.md): the reads stay on the GPU: particles sorted by
//   depth from the light are cut into `hair_light_slices` consecutive batches, and for every
//   batch a point draw writes, for each of its particles, the light buffer value at the
//   particle (and the objects' shadow-map visibility) into the particle's texel of the
//   intensity texture, then the batch's billboards are splatted into the light buffer.
//   Particles in the same batch do not shadow each other; with as many slices as particles
//   this is the paper's algorithm (tested against the CPU pass). 2 draws per slice, each a
//   framebuffer switch that flushes llvmpipe's rasteriser.
#include "follicle/render/splat_gl.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "follicle/render/gl_util.hpp"
#include "follicle/render/shaders_splat_gl.hpp"
#include "follicle/render/splat_bando2003.hpp"

namespace follicle::render {
namespace {

constexpr int kIntensityWidth = 1024;
constexpr int kMaxLights = 8;
// Texture units of the splat programs.
constexpr int kUnitParticles = 0, kUnitOrder = 1, kUnitHair = 2, kUnitIntensity = 3,
              kUnitShadow = 4, kUnitLightBuf = 5;

void check_gl(const char* what) {
  const GLenum e = glGetError();
  if (e != GL_NO_ERROR) fail("render: OpenGL error 0x{:x} during {}", unsigned(e), what);
}

GLuint make_2d_texture(GLenum internal, int w, int h, GLenum format, GLenum type, const void* data,
                       GLenum filter) {
  GLuint t = 0;
  glGenTextures(1, &t);
  glBindTexture(GL_TEXTURE_2D, t);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, GLint(internal), w, h, 0, format, type, data);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GLint(filter));
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER,
                  filter == GL_NEAREST ? GL_NEAREST : GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  return t;
}

GLuint upload_hair_texture(const image::ImageRGBA8& img) {
  if (img.empty()) fail("render: empty hair texture");
  const GLuint t = make_2d_texture(GL_RGBA8, img.width(), img.height(), GL_RGBA, GL_UNSIGNED_BYTE,
                                   img.data(), GL_LINEAR_MIPMAP_NEAREST);
  glGenerateMipmap(GL_TEXTURE_2D);
  return t;
}

GLuint make_fbo(GLuint color_tex, const char* what) {
  GLuint f = 0;
  glGenFramebuffers(1, &f);
  glBindFramebuffer(GL_FRAMEBUFFER, f);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, color_tex, 0);
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
    fail("render: the {} framebuffer is incomplete", what);
  return f;
}

/// The billboard of a particle record (16 floats, see shaders_splat_gl.hpp) into a particle of
/// a CPU pass (LightSplatParticle or ViewSplatParticle).
template <class P>
void billboard_from_record(const float* r, P& p) {
  p.pos = Vec3(r[0], r[1], r[2]);
  p.half_w = r[3];
  p.t = Vec3(r[4], r[5], r[6]);
  p.half_l = r[7];
  p.alpha = r[11];
  p.min_sin = r[12];
}

std::string stage(const char* a, const char* b, const char* c = "") {
  return std::string(a) + b + c;
}

}  // namespace

SplatPassGl::SplatPassGl() {
  using namespace glsl;
  const std::string common = kSplatCommon;
  const std::string gather_vs = common + kSplatGatherVs;
  const std::string gather_fs = common + kSplatGatherFs;
  const std::string light_vs = common + kSplatLightVs;
  const std::string light_fs = common + kSplatLightFs;
  const std::string view_vs = stage(kLightsBlock, kSplatCommon, kSplatViewVs);
  const std::string view_fs = common + kSplatViewFs;
  m_gather_prog = gl::link_program("splat-gather", "", gather_vs.c_str(), gather_fs.c_str());
  m_light_prog = gl::link_program("splat-light", "", light_vs.c_str(), light_fs.c_str());
  m_view_prog = gl::link_program("splat-view", "", view_vs.c_str(), view_fs.c_str());
  glGetIntegerv(GL_MAX_TEXTURE_BUFFER_SIZE, &m_max_tbo);
  glGenBuffers(1, &m_particle_buf);
  glGenBuffers(1, &m_order_buf);
  glGenTextures(1, &m_particle_tbo);
  glGenTextures(1, &m_order_tbo);
  const image::ImageRGBA8 hair = make_hair_texture();
  m_default_tex = upload_hair_texture(hair);
  m_cpu_default_tex = std::make_unique<SplatAlphaTexture>(hair);
  m_cpu_default_color = std::make_unique<SplatColorTexture>(hair);
  check_gl("hair splat initialisation");
}

SplatPassGl::~SplatPassGl() {
  for (GLuint p : {m_gather_prog, m_light_prog, m_view_prog}) glDeleteProgram(p);
  for (GLuint b : {m_particle_buf, m_order_buf}) glDeleteBuffers(1, &b);
  for (GLuint t :
       {m_particle_tbo, m_order_tbo, m_intensity_tex, m_light_tex, m_default_tex, m_custom_tex})
    if (t) glDeleteTextures(1, &t);
  for (GLuint f : {m_intensity_fbo, m_light_fbo})
    if (f) glDeleteFramebuffers(1, &f);
}

void SplatPassGl::prepare(const RenderScene& scene, Eigen::AlignedBox3d* shadow_box) {
  m_items.clear();
  m_data.clear();
  m_count = 0;
  m_light_done = false;
  m_any_cast = false;
  m_custom_tex_src.reset();
  for (std::size_t idx = 0; idx < scene.particles.size(); ++idx) {
    const ParticleItem& item = scene.particles[idx];
    if (item.shading != ParticleShading::HairSplat || !item.particles ||
        item.particles->positions.empty())
      continue;
    const std::string where = fmt::format("render.particles[{}]", idx);
    validate_params(item, where);
    if (m_items.size() >= std::size_t(kMaxItems))
      fail_at(where, "at most {} hair-splat particle items are supported", kMaxItems);
    if (item.hair_texture) {
      if (item.hair_texture->empty()) fail_at(where + ".hair_texture", "the image is empty");
      if (m_custom_tex_src && m_custom_tex_src != item.hair_texture)
        fail_at(where + ".hair_texture",
                "hair-splat items drawn together must share one hair texture");
      m_custom_tex_src = item.hair_texture;
    }
    const geom::ParticleSet& s = *item.particles;
    const std::size_t n = s.positions.size();
    auto check_size = [&](std::size_t got, const char* what) {
      if (got != 0 && got != n) fail_at(where, "{} {} for {} particles", got, what, n);
    };
    check_size(s.directions.size(), "directions");
    check_size(s.radius.size(), "radii");
    check_size(s.color.size(), "colours");
    check_size(s.opacity.size(), "opacities");
    const Mat3 lin = item.transform.linear();
    const double scale = std::cbrt(std::abs(lin.determinant()));
    if (!item.transform.matrix().allFinite() || scale <= 0)
      fail_at(where + ".transform", "must be finite and invertible");
    const SplatMaterial& m = item.splat;
    Info info;
    info.item = &item;
    info.first = m_count;
    info.count = n;
    m_data.reserve(m_data.size() + 16 * n);
    for (std::size_t i = 0; i < n; ++i) {
      const Vec3 p = item.transform * s.positions[i].cast<double>();
      if (!p.allFinite()) fail_at(where, "particle {} position is not finite", i);
      Vec3 t = s.directions.empty() ? Vec3(0, 1, 0) : Vec3(s.directions[i].cast<double>());
      t = lin * t;
      if (!t.allFinite() || t.norm() < 1e-12)
        fail_at(where, "particle {} direction must be a non-zero finite vector", i);
      t.normalize();
      const double r = (s.radius.empty() ? item.radius : double(s.radius[i])) * scale;
      if (!std::isfinite(r) || r <= 0) fail_at(where, "particle {} radius {} is not > 0", i, r);
      const Vec3 c = s.color.empty() ? item.color : Vec3(s.color[i].cast<double>());
      if (!c.allFinite() || c.minCoeff() < 0)
        fail_at(where, "particle {} colour is not a finite non-negative RGB", i);
      const double a = item.opacity * (s.opacity.empty() ? 1.0 : double(s.opacity[i]));
      if (!(a >= 0 && a <= 1)) fail_at(where, "particle {} opacity {} is not in [0, 1]", i, a);
      const double hw = r * m.width_scale, hl = r * m.length_scale;
      const float rec[16] = {float(p.x()),
                             float(p.y()),
                             float(p.z()),
                             float(hw),
                             float(t.x()),
                             float(t.y()),
                             float(t.z()),
                             float(hl),
                             float(c.x()),
                             float(c.y()),
                             float(c.z()),
                             float(a),
                             float(m.min_sin_theta),
                             m.cast_shadow ? 1.0f : 0.0f,
                             m.self_shadow ? 1.0f : 0.0f,
                             float(m_items.size())};
      m_data.insert(m_data.end(), rec, rec + 16);
      if (shadow_box) {
        const double e = std::max(hw, hl);
        shadow_box->extend(p - Vec3::Constant(e));
        shadow_box->extend(p + Vec3::Constant(e));
      }
    }
    m_any_cast = m_any_cast || m.cast_shadow;
    m_count += n;
    m_items.push_back(info);
  }
  if (m_count == 0) return;
  if (4 * m_count > std::size_t(m_max_tbo) || 2 * m_count > std::size_t(m_max_tbo))
    fail("render: {} hair-splat particles exceed this GL's texture buffer size {}", m_count,
         m_max_tbo / 4);
  glBindBuffer(GL_TEXTURE_BUFFER, m_particle_buf);
  if (m_data.size() > m_particle_cap) {
    m_particle_cap = m_data.size();
    glBufferData(GL_TEXTURE_BUFFER, GLsizeiptr(m_particle_cap * sizeof(float)), nullptr,
                 GL_DYNAMIC_DRAW);
  }
  glBufferSubData(GL_TEXTURE_BUFFER, 0, GLsizeiptr(m_data.size() * sizeof(float)), m_data.data());
  glBindTexture(GL_TEXTURE_BUFFER, m_particle_tbo);
  glTexBuffer(GL_TEXTURE_BUFFER, GL_RGBA32F, m_particle_buf);
  glBindBuffer(GL_TEXTURE_BUFFER, m_order_buf);
  if (2 * m_count > m_order_cap) {
    m_order_cap = 2 * m_count;
    glBufferData(GL_TEXTURE_BUFFER, GLsizeiptr(m_order_cap * sizeof(int32_t)), nullptr,
                 GL_DYNAMIC_DRAW);
  }
  glBindTexture(GL_TEXTURE_BUFFER, m_order_tbo);
  glTexBuffer(GL_TEXTURE_BUFFER, GL_R32I, m_order_buf);
  glBindBuffer(GL_TEXTURE_BUFFER, 0);
  check_gl("hair splat upload");
}

GLuint SplatPassGl::hair_texture() {
  if (!m_custom_tex_src) return m_default_tex;
  const bool same = m_custom_tex && m_custom_ptr == m_custom_tex_src.get() &&
                    !m_custom_owner.expired() && m_custom_owner.lock() == m_custom_tex_src;
  if (!same) {
    if (m_custom_tex) glDeleteTextures(1, &m_custom_tex);
    m_custom_tex = upload_hair_texture(*m_custom_tex_src);
    m_custom_owner = m_custom_tex_src;
    m_custom_ptr = m_custom_tex_src.get();
  }
  return m_custom_tex;
}

const SplatAlphaTexture& SplatPassGl::cpu_hair_texture() {
  if (!m_custom_tex_src) return *m_cpu_default_tex;
  if (!m_cpu_custom_tex || m_cpu_custom_src != m_custom_tex_src) {
    m_cpu_custom_tex = std::make_unique<SplatAlphaTexture>(*m_custom_tex_src);
    m_cpu_custom_src = m_custom_tex_src;
  }
  return *m_cpu_custom_tex;
}

const SplatColorTexture& SplatPassGl::cpu_hair_color_texture() {
  if (!m_custom_tex_src) return *m_cpu_default_color;
  if (!m_cpu_custom_color || m_cpu_custom_color_src != m_custom_tex_src) {
    m_cpu_custom_color = std::make_unique<SplatColorTexture>(*m_custom_tex_src);
    m_cpu_custom_color_src = m_custom_tex_src;
  }
  return *m_cpu_custom_color;
}

void SplatPassGl::ensure_intensity(std::size_t n) {
  const int w = int(std::min<std::size_t>(n, kIntensityWidth));
  const int h = int((n + kIntensityWidth - 1) / kIntensityWidth);
  if (w <= m_intensity_w && h <= m_intensity_h) return;
  GLint max_tex = 0;
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_tex);
  if (h > max_tex) fail("render: too many hair-splat particles ({}) for this GL", n);
  if (m_intensity_fbo) glDeleteFramebuffers(1, &m_intensity_fbo);
  if (m_intensity_tex) glDeleteTextures(1, &m_intensity_tex);
  m_intensity_w = std::max(w, m_intensity_w);
  m_intensity_h = std::max(h, m_intensity_h);
  m_intensity_tex =
      make_2d_texture(GL_RG32F, m_intensity_w, m_intensity_h, GL_RG, GL_FLOAT, nullptr, GL_NEAREST);
  m_intensity_fbo = make_fbo(m_intensity_tex, "hair intensity");
}

void SplatPassGl::ensure_light_buffer(int size) {
  if (size == m_light_size) return;
  GLint max_tex = 0;
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_tex);
  if (size > max_tex)
    fail("render: hair_light_map_size {} exceeds GL_MAX_TEXTURE_SIZE {}", size, max_tex);
  if (m_light_fbo) glDeleteFramebuffers(1, &m_light_fbo);
  if (m_light_tex) glDeleteTextures(1, &m_light_tex);
  m_light_tex = make_2d_texture(GL_R16F, size, size, GL_RED, GL_FLOAT, nullptr, GL_LINEAR);
  m_light_fbo = make_fbo(m_light_tex, "hair light buffer");
  m_light_size = size;
}

void SplatPassGl::bind_common(GLuint prog, int order_base) {
  glUseProgram(prog);
  gl::set_i(prog, "uParticles", kUnitParticles);
  gl::set_i(prog, "uOrder", kUnitOrder);
  gl::set_i(prog, "uOrderBase", order_base);
  gl::set_i(prog, "uHairTex", kUnitHair);
  gl::set_i(prog, "uIntensity", kUnitIntensity);
  gl::set_i(prog, "uIntensityWidth", m_intensity_w > 0 ? m_intensity_w : 1);
}

void SplatPassGl::light_pass(const Light& light, const RenderSettings& settings, GLuint empty_vao,
                             tbb::task_arena& arena) {
  m_light_done = false;
  m_intensity_on_cpu = false;
  if (m_count == 0) return;
  settings.validate();
  const std::size_t n = m_count;
  m_cpu_particles.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const float* r = &m_data[16 * i];
    LightSplatParticle& p = m_cpu_particles[i];
    billboard_from_record(r, p);
    p.casts = r[13] > 0.5f;
    p.opacity_scale = m_items[std::size_t(r[15] + 0.5f)].item->splat.shadow_opacity_scale;
    p.vis = 1;
  }
  // Line 7: ascending depth from the light (stable: ties keep input order -> deterministic).
  const std::vector<int32_t> order = splat_light_order(light.travel, m_cpu_particles);
  glBindBuffer(GL_TEXTURE_BUFFER, m_order_buf);
  glBufferSubData(GL_TEXTURE_BUFFER, 0, GLsizeiptr(n * sizeof(int32_t)), order.data());
  glBindBuffer(GL_TEXTURE_BUFFER, 0);
  ensure_intensity(n);
  ensure_light_buffer(settings.hair_light_map_size);

  glActiveTexture(GL_TEXTURE0 + kUnitParticles);
  glBindTexture(GL_TEXTURE_BUFFER, m_particle_tbo);
  glActiveTexture(GL_TEXTURE0 + kUnitOrder);
  glBindTexture(GL_TEXTURE_BUFFER, m_order_tbo);
  glActiveTexture(GL_TEXTURE0 + kUnitHair);
  glBindTexture(GL_TEXTURE_2D, hair_texture());
  glActiveTexture(GL_TEXTURE0 + kUnitIntensity);
  glBindTexture(GL_TEXTURE_2D, m_intensity_tex);
  glActiveTexture(GL_TEXTURE0 + kUnitShadow);
  glBindTexture(GL_TEXTURE_2D, light.shadow_tex);
  glActiveTexture(GL_TEXTURE0 + kUnitLightBuf);
  glBindTexture(GL_TEXTURE_2D, m_light_tex);

  bind_common(m_gather_prog, 0);
  gl::set_mat4(m_gather_prog, "uLightVP", light.light_vp);
  gl::set_vec3(m_gather_prog, "uLightTravel", light.travel);
  gl::set_i(m_gather_prog, "uShadowTex", kUnitShadow);
  gl::set_i(m_gather_prog, "uLightBuf", kUnitLightBuf);
  gl::set_f(m_gather_prog, "uShadowTexel", light.shadow_texel);
  gl::set_f(m_gather_prog, "uShadowBias", light.shadow_bias);
  gl::set_i(m_gather_prog, "uIntensityHeight", m_intensity_h);
  gl::set_i(m_gather_prog, "uVisibilityOnly", settings.hair_light_pass == "gpu" ? 0 : 1);

  glDisable(GL_DEPTH_TEST);
  glDepthMask(GL_FALSE);
  glBindVertexArray(empty_vao);
  if (settings.hair_light_pass == "gpu")
    light_slices_gpu(light, std::size_t(settings.hair_light_slices));
  else
    light_exact_cpu(light, arena);
  glDisable(GL_BLEND);
  glEnable(GL_DEPTH_TEST);
  glDepthMask(GL_TRUE);
  glBindVertexArray(0);
  check_gl("hair light pass");
  m_light_done = true;  // line 12: m_light_tex is the light map
}

void SplatPassGl::light_exact_cpu(const Light& light, tbb::task_arena& arena) {
  const std::size_t n = m_count;
  // Line 8's test, for all particles at once: the gather program's objects' visibility (with
  // uVisibilityOnly it skips the hair-light taps, which the CPU loop below computes).
  glBindFramebuffer(GL_FRAMEBUFFER, m_intensity_fbo);
  glViewport(0, 0, m_intensity_w, m_intensity_h);
  glDisable(GL_BLEND);
  glUseProgram(m_gather_prog);
  glDrawArrays(GL_POINTS, 0, GLsizei(n));
  const int w = m_intensity_w;
  const int rows = int((n + std::size_t(w) - 1) / std::size_t(w));
  m_staging.assign(2 * std::size_t(w) * std::size_t(rows), 0.0f);
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glReadPixels(0, 0, w, rows, GL_RG, GL_FLOAT, m_staging.data());
  check_gl("hair light pass visibility read-back");
  for (std::size_t i = 0; i < n; ++i)
    m_cpu_particles[i].vis = std::clamp(double(m_staging[2 * i]), 0.0, 1.0);
  if (!m_any_cast)  // nothing is splatted: the buffer stays white, every read is 1
    for (LightSplatParticle& p : m_cpu_particles) p.casts = false;

  // Lines 6-12, exactly per particle.
  SplatLightParams prm;
  prm.light_vp = light.light_vp;
  prm.travel = light.travel;
  prm.size = m_light_size;
  const SplatAlphaTexture& tex = cpu_hair_texture();
  arena.execute([&] { splat_light_pass_bando2003(prm, m_cpu_particles, tex, m_cpu_result); });

  // The view pass reads (visibility, light through the hair) per particle (line 20), the
  // meshes the light map (line 16).
  for (std::size_t i = 0; i < n; ++i) m_staging[2 * i + 1] = m_cpu_result.reach[i];
  m_intensity_on_cpu = true;
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glActiveTexture(GL_TEXTURE0 + kUnitIntensity);
  glBindTexture(GL_TEXTURE_2D, m_intensity_tex);
  glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, w, rows, GL_RG, GL_FLOAT, m_staging.data());
  glActiveTexture(GL_TEXTURE0 + kUnitLightBuf);
  glBindTexture(GL_TEXTURE_2D, m_light_tex);
  glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, m_light_size, m_light_size, GL_RED, GL_FLOAT,
                  m_cpu_result.light.data());
}

void SplatPassGl::light_slices_gpu(const Light& light, std::size_t slices_wanted) {
  const std::size_t n = m_count;
  bind_common(m_light_prog, 0);
  gl::set_mat4(m_light_prog, "uLightVP", light.light_vp);
  gl::set_vec3(m_light_prog, "uLightTravel", light.travel);
  for (std::size_t k = 0; k < m_items.size(); ++k)
    gl::set_f(m_light_prog, fmt::format("uShadowOpacity[{}]", k).c_str(),
              m_items[k].item->splat.shadow_opacity_scale);

  // Lines 1 and 6: a white light buffer, no depth test.
  glBindFramebuffer(GL_FRAMEBUFFER, m_light_fbo);
  glViewport(0, 0, m_light_size, m_light_size);
  glClearColor(1, 1, 1, 1);
  glClear(GL_COLOR_BUFFER_BIT);
  glBindFramebuffer(GL_FRAMEBUFFER, m_intensity_fbo);
  glClear(GL_COLOR_BUFFER_BIT);
  glBlendFunc(GL_ZERO, GL_ONE_MINUS_SRC_ALPHA);  // light *= (1 - alpha)

  const std::size_t slices = std::min<std::size_t>(n, slices_wanted);
  const std::size_t batch = (n + slices - 1) / slices;
  for (std::size_t b0 = 0; b0 < n; b0 += batch) {
    const std::size_t nb = std::min(batch, n - b0);
    // Lines 8-9: the light reaching each particle of the slice (and the objects' shadow).
    glBindFramebuffer(GL_FRAMEBUFFER, m_intensity_fbo);
    glViewport(0, 0, m_intensity_w, m_intensity_h);
    glDisable(GL_BLEND);
    glUseProgram(m_gather_prog);
    glDrawArrays(GL_POINTS, GLint(b0), GLsizei(nb));
    if (!m_any_cast) continue;
    // Line 10: the slice's billboards attenuate the light buffer.
    glBindFramebuffer(GL_FRAMEBUFFER, m_light_fbo);
    glViewport(0, 0, m_light_size, m_light_size);
    glEnable(GL_BLEND);
    glUseProgram(m_light_prog);
    glDrawArrays(GL_TRIANGLES, GLint(6 * b0), GLsizei(6 * nb));
  }
}

void SplatPassGl::view_pass(const RenderScene& scene, const Mat4& view, const Mat4& view_proj,
                            GLuint empty_vao) {
  if (m_count == 0) return;
  const std::size_t n = m_count;
  // Line 18: descending depth from the eye (far first).
  std::vector<double> z(n);
  for (std::size_t i = 0; i < n; ++i)
    z[i] = view(2, 0) * m_data[16 * i] + view(2, 1) * m_data[16 * i + 1] +
           view(2, 2) * m_data[16 * i + 2];
  std::vector<int32_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int32_t a, int32_t b) { return z[std::size_t(a)] < z[std::size_t(b)]; });
  glBindBuffer(GL_TEXTURE_BUFFER, m_order_buf);
  glBufferSubData(GL_TEXTURE_BUFFER, GLintptr(n * sizeof(int32_t)), GLsizeiptr(n * sizeof(int32_t)),
                  order.data());
  glBindBuffer(GL_TEXTURE_BUFFER, 0);

  glActiveTexture(GL_TEXTURE0 + kUnitParticles);
  glBindTexture(GL_TEXTURE_BUFFER, m_particle_tbo);
  glActiveTexture(GL_TEXTURE0 + kUnitOrder);
  glBindTexture(GL_TEXTURE_BUFFER, m_order_tbo);
  glActiveTexture(GL_TEXTURE0 + kUnitHair);
  glBindTexture(GL_TEXTURE_2D, hair_texture());
  glActiveTexture(GL_TEXTURE0 + kUnitIntensity);
  glBindTexture(GL_TEXTURE_2D, m_light_done ? m_intensity_tex : 0);

  const GLuint p = m_view_prog;
  bind_common(p, int(n));
  gl::set_mat4(p, "uViewProj", view_proj);
  const int nl = int(std::min<std::size_t>(scene.lights.size(), kMaxLights));
  gl::set_i(p, "uNumLights", nl);
  int shadow_light = -1;
  for (int i = 0; i < nl; ++i) {
    const DirectionalLight& l = scene.lights[std::size_t(i)];
    gl::set_vec3(p, fmt::format("uLightDir[{}]", i).c_str(), -l.direction.normalized());
    gl::set_vec3(p, fmt::format("uLightColor[{}]", i).c_str(), l.color * l.intensity);
    if (shadow_light < 0 && l.cast_shadow) shadow_light = i;
  }
  gl::set_vec3(p, "uAmbientColor", scene.ambient_color);
  gl::set_vec3(p, "uEye", scene.camera.eye);
  gl::set_i(p, "uShadowLight", m_light_done ? shadow_light : -1);
  gl::set_i(p, "uHasIntensity", m_light_done ? 1 : 0);
  for (std::size_t k = 0; k < m_items.size(); ++k) {
    const SplatMaterial& m = m_items[k].item->splat;
    auto set = [&](const char* name, double v) {
      gl::set_f(p, fmt::format("{}[{}]", name, k).c_str(), v);
    };
    set("uDiffuse", m.diffuse);
    set("uSpecular", m.specular);
    set("uShininess", m.shininess);
    set("uAmbient", m.ambient);
    set("uReflect", m.reflect);
    set("uTransmit", m.transmit);
  }
  // Lines 17-21: depth-tested against the objects, no depth writes, back to front.
  glEnable(GL_DEPTH_TEST);
  glDepthMask(GL_FALSE);
  glEnable(GL_BLEND);
  glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
  glBindVertexArray(empty_vao);
  glDrawArrays(GL_TRIANGLES, 0, GLsizei(6 * n));
  glBindVertexArray(0);
  glDisable(GL_BLEND);
  glDepthMask(GL_TRUE);
  check_gl("hair view pass");
}

void SplatPassGl::view_pass_cpu(const RenderScene& scene, const Mat4& view, const Mat4& view_proj,
                                GLuint color_tex, int fb_w, int fb_h, tbb::task_arena& arena,
                                std::vector<float>* frame) {
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  if (frame && frame->size() != 4 * std::size_t(fb_w) * std::size_t(fb_h))
    fail("render: the read-back frame has {} floats for {}x{} pixels", frame->size(), fb_w, fb_h);
  if (m_count == 0) return;
  const std::size_t n = m_count;
  if (m_light_done && !m_intensity_on_cpu) {  // the "gpu" light pass: read its intensities
    const int w = m_intensity_w;
    const int rows = int((n + std::size_t(w) - 1) / std::size_t(w));
    m_staging.assign(2 * std::size_t(w) * std::size_t(rows), 0.0f);
    GLint prev = 0;
    glGetIntegerv(GL_FRAMEBUFFER_BINDING, &prev);
    glBindFramebuffer(GL_FRAMEBUFFER, m_intensity_fbo);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glReadPixels(0, 0, w, rows, GL_RG, GL_FLOAT, m_staging.data());
    glBindFramebuffer(GL_FRAMEBUFFER, GLuint(prev));
    m_intensity_on_cpu = true;
  }
  // Line 20's colour, per particle as kSplatViewVs computes it.
  const int nl = int(std::min<std::size_t>(scene.lights.size(), kMaxLights));
  int shadow_light = -1;
  for (int i = 0; i < nl && m_light_done; ++i)
    if (scene.lights[std::size_t(i)].cast_shadow) {
      shadow_light = i;
      break;
    }
  const Vec3 eye = scene.camera.eye;
  m_view_particles.resize(n);
  arena.execute([&] {
    tbb::parallel_for(std::size_t(0), n, std::size_t(256), [&](std::size_t b) {
      const std::size_t e = std::min(n, b + 256);
      for (std::size_t i = b; i < e; ++i) {
        const float* r = &m_data[16 * i];
        ViewSplatParticle& p = m_view_particles[i];
        billboard_from_record(r, p);
        const Vec3 c(r[8], r[9], r[10]);
        const SplatMaterial& m = m_items[std::size_t(r[15] + 0.5f)].item->splat;
        const Vec3 to_eye = (eye - p.pos).normalized();
        double att = 1;
        if (m_light_done) att = m_staging[2 * i] * (r[14] > 0.5f ? m_staging[2 * i + 1] : 1.0f);
        Vec3 col = c.cwiseProduct(m.ambient * scene.ambient_color);
        for (int j = 0; j < nl; ++j) {
          const DirectionalLight& l = scene.lights[std::size_t(j)];
          const Vec3 ej = l.color * l.intensity * (j == shadow_light ? att : 1.0);
          col += ej.cwiseProduct(kajiya_goldman(p.t, -l.direction.normalized(), to_eye, c, m));
        }
        p.color = nl == 0 ? c : col;  // no lights: unlit hair colour
      }
    });
  });
  SplatViewParams prm;
  prm.view_proj = view_proj;
  prm.eye = eye;
  int box[4];
  splat_view_bounds(prm, m_view_particles, fb_w, fb_h, box);
  if (box[0] >= box[2]) return;  // nothing on screen
  SplatViewTarget tg;
  tg.fb_width = fb_w;
  tg.fb_height = fb_h;
  tg.x0 = box[0];
  tg.y0 = box[1];
  tg.width = box[2] - box[0];
  tg.height = box[3] - box[1];
  const std::size_t npix = std::size_t(tg.width) * std::size_t(tg.height);
  m_view_depth.resize(npix);
  // Line 17: the objects' depth (and the colour under the hair) of the billboards' rectangle.
  if (frame) {
    tg.rgba = frame->data() + 4 * (std::size_t(tg.y0) * std::size_t(fb_w) + std::size_t(tg.x0));
    tg.rgba_stride = fb_w;
  } else {
    m_view_rgba.resize(4 * npix);
    glReadPixels(tg.x0, tg.y0, tg.width, tg.height, GL_RGBA, GL_FLOAT, m_view_rgba.data());
    tg.rgba = m_view_rgba.data();
  }
  glReadPixels(tg.x0, tg.y0, tg.width, tg.height, GL_DEPTH_COMPONENT, GL_FLOAT,
               m_view_depth.data());
  check_gl("hair view pass read-back");
  tg.depth = m_view_depth.data();
  // Line 18: far first.
  const std::vector<int32_t> order = splat_view_order(view, m_view_particles);
  const SplatColorTexture& tex = cpu_hair_color_texture();
  arena.execute([&] { splat_view_pass_bando2003(prm, m_view_particles, order, tex, tg); });
  if (frame) return;
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glBindTexture(GL_TEXTURE_2D, color_tex);
  glTexSubImage2D(GL_TEXTURE_2D, 0, tg.x0, tg.y0, tg.width, tg.height, GL_RGBA, GL_FLOAT,
                  m_view_rgba.data());
  glBindTexture(GL_TEXTURE_2D, 0);  // the framebuffer's own attachment: leave no unit sampling it
  check_gl("hair view pass upload");
}

}  // namespace follicle::render
