// The OpenGL 3.3 core renderer: shadow pass (first shadow-casting light, orthographic depth map
// over meshes and strands), main pass into a k-times supersampled RGBA16F FBO (meshes, strands,
// particles), then a resolve pass that box-filters k x k samples in linear space and encodes
// sRGB into an RGBA8 FBO that is read back. All geometry goes up once per render in VBOs; every
// item is one draw call. Strand items of the Daldegan 1993 §4 CPU pass (StrandShading::
// Daldegan1993 or hair_shadow) are not drawn by GL: every shadow-casting light's scene depth
// map is read back and composed with the hair's (hair_blend_daldegan1993.hpp), the first
// shadow light's composite goes back into the shadow map before the mesh pass, and the hair is
// shaded and blended into the read-back frame after the GL passes.
#include <GL/gl.h>
#include <GL/glext.h>
#include <spdlog/spdlog.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <tuple>
#include <unordered_map>
#include <utility>

#include "follicle/core/parallel.hpp"
#include "follicle/core/resources.hpp"
#include "follicle/render/camera.hpp"
#include "follicle/render/egl_context.hpp"
#include "follicle/render/gl_util.hpp"
#include "follicle/render/hair_blend_daldegan1993.hpp"
#include "follicle/render/renderer.hpp"
#include "follicle/render/resolve_cpu.hpp"
#include "follicle/render/shaders_gl.hpp"
#include "follicle/render/splat_gl.hpp"

namespace follicle::render {
namespace {

constexpr int kMaxLights = 8;
constexpr int kMaxLobes = 4;

using namespace gl;

/// GL objects created for one render() and deleted at its end.
struct FrameObjects {
  std::vector<GLuint> buffers, vaos, textures;
  ~FrameObjects() {
    if (!buffers.empty()) glDeleteBuffers(GLsizei(buffers.size()), buffers.data());
    if (!vaos.empty()) glDeleteVertexArrays(GLsizei(vaos.size()), vaos.data());
    if (!textures.empty()) glDeleteTextures(GLsizei(textures.size()), textures.data());
  }
  // Resource guard: the size is checked against the available memory before the upload (a
  // software GL such as llvmpipe keeps buffers in system memory; 6.9 M strands once ended in
  // "OpenGL error 0x505 during upload" after minutes), and an out-of-memory answer of the driver
  // is reported with the size instead of as a bare error code.
  GLuint buffer(GLenum target, std::size_t bytes, const void* data) {
    return buffers.emplace_back(upload_buffer(target, bytes, data));
  }
  /// A new buffer object bound to `target` holding `bytes` of `data`; deleted again on failure.
  static GLuint upload_buffer(GLenum target, std::size_t bytes, const void* data) {
    check_memory("render", fmt::format("uploading {} of geometry", format_bytes(double(bytes))),
                 double(bytes), "draw fewer strands (hair[].density_scale) or a smaller mesh");
    GLuint b = 0;
    glGenBuffers(1, &b);
    glBindBuffer(target, b);
    glBufferData(target, GLsizeiptr(bytes), data, GL_STATIC_DRAW);
    const GLenum e = glGetError();
    if (e != GL_NO_ERROR) glDeleteBuffers(1, &b);
    if (e == GL_OUT_OF_MEMORY)
      fail("render: the GL driver ran out of memory uploading {} of geometry",
           format_bytes(double(bytes)));
    if (e != GL_NO_ERROR)
      fail("render: OpenGL error 0x{:x} uploading {} of geometry", unsigned(e),
           format_bytes(double(bytes)));
    return b;
  }
  GLuint vao() {
    GLuint a = 0;
    glGenVertexArrays(1, &a);
    vaos.push_back(a);
    glBindVertexArray(a);
    return a;
  }
};

void attrib(GLuint loc, int comps, std::size_t stride, std::size_t offset, GLuint divisor = 0) {
  glEnableVertexAttribArray(loc);
  glVertexAttribPointer(loc, comps, GL_FLOAT, GL_FALSE, GLsizei(stride),
                        reinterpret_cast<const void*>(offset));
  glVertexAttribDivisor(loc, divisor);
}

struct MeshVertex {
  float pos[3], normal[3], uv[2], color[3], pu[3], pv[3];
};
struct StrandVertex {
  float pos[3], color[3], tangent[3], radius;
};
struct ParticleInstance {
  float pos[3], color[3], radius, opacity, dir[3];
};

struct MeshDraw {
  GLuint vao = 0;
  GLsizei count = 0;
  const MeshItem* item = nullptr;
  bool has_uvs = false;
};
struct StrandDraw {
  GLuint vao = 0;
  std::vector<GLint> first;
  std::vector<GLsizei> count;
  const StrandItem* item = nullptr;
  bool ribbons = false;
};
struct ParticleDraw {
  GLuint vao = 0;
  GLsizei count = 0;
  const ParticleItem* item = nullptr;
  bool blend = false;
};

double linear_scale(const Affine3& xf) {
  return std::cbrt(std::abs(xf.linear().determinant()));
}

void extend(Eigen::AlignedBox3d& box, const Affine3& xf, const Vec3& p) {
  box.extend(xf * p);
}

/// Extends `box` by every face corner of the item's mesh, placed by its transform.
void extend_by_faces(Eigen::AlignedBox3d& box, const MeshItem& item) {
  const geom::TriMesh& m = *item.mesh;
  for (const Vec3i& f : m.faces)
    for (int k = 0; k < 3; ++k) extend(box, item.transform, m.positions[std::size_t(f[k])]);
}

/// The vertex and index arrays of a mesh: one vertex per distinct (position, UV) corner pair,
/// so UV seams split vertices and nothing else does (every attribute is a function of that pair:
/// the image is the one an unwelded corner array gives, with ~6x fewer vertex-shader runs).
struct MeshArrays {
  std::vector<MeshVertex> vertices;
  std::vector<uint32_t> indices;
};

/// Builds the vertex arrays of a mesh. Normals: the mesh's own, else area-weighted face normals.
/// Pu, Pv (dP/du, dP/dv) are averaged per UV vertex so the tangent frame is smooth within a UV
/// chart.
MeshArrays build_mesh_vertices(const MeshItem& item, std::size_t index) {
  const geom::TriMesh& m = *item.mesh;
  const std::string where = fmt::format("render: meshes[{}] '{}'", index, m.name);
  const std::size_t nv = m.positions.size();
  const bool vcol = !item.vertex_colors.empty();
  if (vcol && item.vertex_colors.size() != nv)
    fail_at(where, "{} vertex colours for {} vertices", item.vertex_colors.size(), nv);
  const bool uvs = !m.uvs.empty();
  if (uvs && m.uv_faces.size() != m.faces.size())
    fail_at(where, "{} UV faces for {} faces", m.uv_faces.size(), m.faces.size());
  for (std::size_t f = 0; f < m.faces.size(); ++f) {
    for (int k = 0; k < 3; ++k) {
      if (m.faces[f][k] < 0 || std::size_t(m.faces[f][k]) >= nv)
        fail_at(where, "face {} has vertex index {} out of range [0, {})", f, m.faces[f][k], nv);
      if (uvs && (m.uv_faces[f][k] < 0 || std::size_t(m.uv_faces[f][k]) >= m.uvs.size()))
        fail_at(where, "face {} has UV index {} out of range [0, {})", f, m.uv_faces[f][k],
                m.uvs.size());
    }
  }
  std::vector<Vec3> normals;
  if (m.normals.size() == nv) {
    normals = m.normals;
  } else {
    normals.assign(nv, Vec3::Zero());
    for (const Vec3i& f : m.faces) {
      const Vec3 n = (m.positions[std::size_t(f[1])] - m.positions[std::size_t(f[0])])
                         .cross(m.positions[std::size_t(f[2])] - m.positions[std::size_t(f[0])]);
      for (int k = 0; k < 3; ++k) normals[std::size_t(f[k])] += n;  // |n| = 2 * area
    }
  }
  std::vector<Vec3> pu, pv;
  if (uvs) {
    pu.assign(m.uvs.size(), Vec3::Zero());
    pv.assign(m.uvs.size(), Vec3::Zero());
    for (std::size_t f = 0; f < m.faces.size(); ++f) {
      const Vec3& p0 = m.positions[std::size_t(m.faces[f][0])];
      const Vec3 e1 = m.positions[std::size_t(m.faces[f][1])] - p0;
      const Vec3 e2 = m.positions[std::size_t(m.faces[f][2])] - p0;
      const Vec2& t0 = m.uvs[std::size_t(m.uv_faces[f][0])];
      const Vec2 d1 = m.uvs[std::size_t(m.uv_faces[f][1])] - t0;
      const Vec2 d2 = m.uvs[std::size_t(m.uv_faces[f][2])] - t0;
      const double det = d1.x() * d2.y() - d2.x() * d1.y();
      if (std::abs(det) < 1e-14) continue;
      // [e1 e2] = [Pu Pv] [d1 d2]  =>  [Pu Pv] = [e1 e2] [d1 d2]^-1
      const Vec3 fu = (e1 * d2.y() - e2 * d1.y()) / det;
      const Vec3 fv = (e2 * d1.x() - e1 * d2.x()) / det;
      for (int k = 0; k < 3; ++k) {
        pu[std::size_t(m.uv_faces[f][k])] += fu;
        pv[std::size_t(m.uv_faces[f][k])] += fv;
      }
    }
    // Averages, not sums: the magnitude matters for bump mapping.
    std::vector<int> cnt(m.uvs.size(), 0);
    for (std::size_t f = 0; f < m.faces.size(); ++f)
      for (int k = 0; k < 3; ++k) ++cnt[std::size_t(m.uv_faces[f][k])];
    for (std::size_t i = 0; i < cnt.size(); ++i)
      if (cnt[i] > 0) {
        pu[i] /= cnt[i];
        pv[i] /= cnt[i];
      }
  }
  MeshArrays out;
  out.indices.resize(m.faces.size() * 3);
  out.vertices.reserve(nv + nv / 8);
  std::unordered_map<uint64_t, uint32_t> slot;  // (position, UV) pair -> vertex
  slot.reserve(nv + nv / 8);
  for (std::size_t f = 0; f < m.faces.size(); ++f) {
    for (int k = 0; k < 3; ++k) {
      const std::size_t vi = std::size_t(m.faces[f][k]);
      const Vec3& p = m.positions[vi];
      if (!p.allFinite()) fail_at(where, "vertex {} is not finite", vi);
      const uint64_t key =
          uint64_t(vi) * (uint64_t(m.uvs.size()) + 1) + (uvs ? uint64_t(m.uv_faces[f][k]) + 1 : 0);
      const auto [it, fresh] = slot.try_emplace(key, uint32_t(out.vertices.size()));
      out.indices[f * 3 + std::size_t(k)] = it->second;
      if (!fresh) continue;
      MeshVertex& v = out.vertices.emplace_back();
      Vec3 n = normals[vi];
      n = n.norm() > 0 ? n.normalized() : Vec3(0, 0, 1);
      const Vec3 c = vcol ? item.vertex_colors[vi].cast<double>() : Vec3(1, 1, 1);
      Vec2 uv(0, 0);
      Vec3 a = Vec3::Zero(), b = Vec3::Zero();
      if (uvs) {
        const std::size_t ti = std::size_t(m.uv_faces[f][k]);
        uv = m.uvs[ti];
        a = pu[ti];
        b = pv[ti];
      }
      for (int j = 0; j < 3; ++j) {
        v.pos[j] = float(p[j]);
        v.normal[j] = float(n[j]);
        v.color[j] = float(c[j]);
        v.pu[j] = float(a[j]);
        v.pv[j] = float(b[j]);
      }
      v.uv[0] = float(uv.x());
      v.uv[1] = float(uv.y());
    }
  }
  return out;
}

class GlRenderer final : public Renderer {
 public:
  GlRenderer(const Context& ctx, std::unique_ptr<EglContext> egl)
      : m_log(ctx.logger_ptr()),
        m_arena(std::make_unique<tbb::task_arena>(ctx.threads())),
        m_hair_ctx(std::make_unique<Context>(ctx.threads(), ctx.seed(), ctx.logger_ptr())),
        m_egl(std::move(egl)) {
    if (m_egl) m_egl->make_current();
    init();
  }

  ~GlRenderer() override {
    try {
      if (m_egl) m_egl->make_current();
      m_splat.reset();
      for (GLuint p : {m_line_prog, m_ribbon_prog, m_depth_prog, m_particle_prog, m_resolve_prog})
        glDeleteProgram(p);
      for (auto& [key, p] : m_mesh_progs) glDeleteProgram(p);
      for (auto& [k, t] : m_tex_cache) glDeleteTextures(1, &t.tex);
      for (auto& [k, e] : m_mesh_cache) release(e);
      release_targets();
      glDeleteVertexArrays(1, &m_empty_vao);
      glDeleteBuffers(1, &m_quad_vbo);
    } catch (...) {  // destructors must not throw; the context may already be gone
    }
  }

  std::string device_description() const override {
    return m_description + (m_egl ? " [EGL " + m_egl->platform() + "]" : "");
  }

  image::ImageRGBA8 render(const RenderScene& scene, const RenderSettings& settings) override {
    if (m_egl) m_egl->make_current();
    image::ImageRGBA8 img(settings.width, settings.height);
    if (draw(scene, settings, &m_cpu_frame)) {
      // The frame came back for the CPU hair view pass: resolve it here too.
      m_arena->execute([&] {
        m_resolve.resolve(m_cpu_frame.data(), m_fb_w, m_fb_h, settings.supersample,
                          settings.transparent_background, img);
      });
      return img;
    }
    glBindFramebuffer(GL_READ_FRAMEBUFFER, m_out_fbo);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, settings.width, settings.height, GL_RGBA, GL_UNSIGNED_BYTE, img.data());
    check_gl("readback");
    // GL rows run bottom-up; Image row 0 is the top.
    const std::size_t row = std::size_t(settings.width) * 4;
    std::vector<uint8_t> tmp(row);
    for (int y = 0; y < settings.height / 2; ++y) {
      uint8_t* a = img.data() + std::size_t(y) * row;
      uint8_t* b = img.data() + std::size_t(settings.height - 1 - y) * row;
      std::copy(a, a + row, tmp.data());
      std::copy(b, b + row, a);
      std::copy(tmp.data(), tmp.data() + row, b);
    }
    return img;
  }

  void render_to_framebuffer(const RenderScene& scene, const RenderSettings& settings,
                             unsigned target_fbo) override {
    if (m_egl) m_egl->make_current();
    draw(scene, settings);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, m_out_fbo);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, target_fbo);
    glBlitFramebuffer(0, 0, settings.width, settings.height, 0, 0, settings.width, settings.height,
                      GL_COLOR_BUFFER_BIT, GL_NEAREST);
    glBindFramebuffer(GL_FRAMEBUFFER, target_fbo);
    check_gl("blit to target framebuffer");
  }

 private:
  void init() {
    const char* ver = reinterpret_cast<const char*>(glGetString(GL_VERSION));
    const char* ren = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    if (!ver) fail("render: no current OpenGL context");
    m_description = std::string(ver) + " / " + (ren ? ren : "?");
    int major = 0, minor = 0;
    glGetIntegerv(GL_MAJOR_VERSION, &major);
    glGetIntegerv(GL_MINOR_VERSION, &minor);
    if (major * 10 + minor < 33) fail("render: OpenGL 3.3 needed, got {}", m_description);
    (void)mesh_program(0);  // the plain Blinn-Phong variant; others compile on first use
    m_line_prog = link_program("strand-lines", "", glsl::kStrandVs, glsl::kStrandFs, nullptr, true);
    m_ribbon_prog = link_program("strand-ribbons", "#define RIBBONS\n", glsl::kStrandVs,
                                 glsl::kStrandFs, glsl::kStrandGs, true);
    m_depth_prog = link_program("depth", "", glsl::kDepthVs, glsl::kDepthFs);
    m_particle_prog = link_program("particles", "", glsl::kParticleVs, glsl::kParticleFs);
    m_resolve_prog = link_program("resolve", "", glsl::kResolveVs, glsl::kResolveFs);
    m_splat = std::make_unique<SplatPassGl>();
    glGenVertexArrays(1, &m_empty_vao);
    const float quad[] = {-1, -1, 1, -1, -1, 1, 1, 1};
    glGenBuffers(1, &m_quad_vbo);
    glBindBuffer(GL_ARRAY_BUFFER, m_quad_vbo);
    glBufferData(GL_ARRAY_BUFFER, sizeof(quad), quad, GL_STATIC_DRAW);
    glGetFloatv(GL_ALIASED_LINE_WIDTH_RANGE, m_line_width_range);
    // A forward-compatible core context (the viewer's GLFW window) refuses glLineWidth > 1 with
    // GL_INVALID_VALUE whatever the range reports (GL 3.3 core, appendix E.2.1), which stopped
    // the viewer on every Anjyo scene: there, strands wider than a pixel are drawn as ribbons.
    GLint flags = 0;
    glGetIntegerv(GL_CONTEXT_FLAGS, &flags);
    if (flags & GL_CONTEXT_FLAG_FORWARD_COMPATIBLE_BIT) m_line_width_range[1] = 1.0f;
    check_gl("initialisation");
    m_log->debug("render: {}", device_description());
  }

  void check_gl(const char* what) const {
    const GLenum e = glGetError();
    if (e != GL_NO_ERROR) fail("render: OpenGL error 0x{:x} during {}", unsigned(e), what);
  }

  void release_targets() {
    if (m_fbo) glDeleteFramebuffers(1, &m_fbo);
    if (m_color_tex) glDeleteTextures(1, &m_color_tex);
    if (m_depth_rb) glDeleteRenderbuffers(1, &m_depth_rb);
    if (m_out_fbo) glDeleteFramebuffers(1, &m_out_fbo);
    if (m_out_rb) glDeleteRenderbuffers(1, &m_out_rb);
    if (m_shadow_fbo) glDeleteFramebuffers(1, &m_shadow_fbo);
    if (m_shadow_tex) glDeleteTextures(1, &m_shadow_tex);
    m_fbo = m_color_tex = m_depth_rb = m_out_fbo = m_out_rb = m_shadow_fbo = m_shadow_tex = 0;
    m_fb_w = m_fb_h = m_out_w = m_out_h = m_shadow_size = 0;
  }

  void ensure_targets(int w, int h, int k, int shadow_size) {
    const int fw = w * k, fh = h * k;
    GLint max_rb = 0, max_tex = 0;
    glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &max_rb);
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_tex);
    const int lim = std::min(max_rb, max_tex);
    if (fw > lim || fh > lim)
      fail("render: {}x{} at supersample {} needs a {}x{} framebuffer; this GL allows {}", w, h, k,
           fw, fh, lim);
    if (shadow_size > max_tex)
      fail("render: shadow_map_size {} exceeds GL_MAX_TEXTURE_SIZE {}", shadow_size, max_tex);
    // The supersampled colour (RGBA16F) and depth, the output and its read-back, the shadow map.
    check_memory(
        "render", fmt::format("a {}x{} framebuffer at supersample {}", w, h, k),
        double(fw) * fh * (8 + 4) + double(w) * h * 8 + double(shadow_size) * shadow_size * 4,
        "lower render.supersample or the image size");
    if (fw != m_fb_w || fh != m_fb_h || w != m_out_w || h != m_out_h) {
      const int keep_shadow = m_shadow_size;
      GLuint sfbo = m_shadow_fbo, stex = m_shadow_tex;
      m_shadow_fbo = m_shadow_tex = 0;
      release_targets();
      m_shadow_fbo = sfbo;
      m_shadow_tex = stex;
      m_shadow_size = keep_shadow;
      glGenTextures(1, &m_color_tex);
      glBindTexture(GL_TEXTURE_2D, m_color_tex);
      glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA16F, fw, fh, 0, GL_RGBA, GL_FLOAT, nullptr);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
      glGenRenderbuffers(1, &m_depth_rb);
      glBindRenderbuffer(GL_RENDERBUFFER, m_depth_rb);
      glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, fw, fh);
      glGenFramebuffers(1, &m_fbo);
      glBindFramebuffer(GL_FRAMEBUFFER, m_fbo);
      glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, m_color_tex, 0);
      glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, m_depth_rb);
      if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        fail("render: the {}x{} RGBA16F framebuffer is incomplete", fw, fh);
      glGenRenderbuffers(1, &m_out_rb);
      glBindRenderbuffer(GL_RENDERBUFFER, m_out_rb);
      glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, w, h);
      glGenFramebuffers(1, &m_out_fbo);
      glBindFramebuffer(GL_FRAMEBUFFER, m_out_fbo);
      glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, m_out_rb);
      if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        fail("render: the {}x{} RGBA8 framebuffer is incomplete", w, h);
      m_fb_w = fw;
      m_fb_h = fh;
      m_out_w = w;
      m_out_h = h;
    }
    if (shadow_size != m_shadow_size) {
      if (m_shadow_fbo) glDeleteFramebuffers(1, &m_shadow_fbo);
      if (m_shadow_tex) glDeleteTextures(1, &m_shadow_tex);
      glGenTextures(1, &m_shadow_tex);
      glBindTexture(GL_TEXTURE_2D, m_shadow_tex);
      glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT24, shadow_size, shadow_size, 0,
                   GL_DEPTH_COMPONENT, GL_UNSIGNED_INT, nullptr);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
      glGenFramebuffers(1, &m_shadow_fbo);
      glBindFramebuffer(GL_FRAMEBUFFER, m_shadow_fbo);
      glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, m_shadow_tex, 0);
      glDrawBuffer(GL_NONE);
      glReadBuffer(GL_NONE);
      if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        fail("render: the shadow framebuffer is incomplete");
      m_shadow_size = shadow_size;
    }
    check_gl("framebuffer setup");
  }

  /// Textures are cached by image identity (shared_ptr<const Image> means the pixels are
  /// immutable); an entry is dropped when its image has been destroyed.
  template <class Img>
  GLuint texture(const std::shared_ptr<const Img>& img, GLenum internal, GLenum format, GLenum type,
                 bool mipmap) {
    auto it = m_tex_cache.find(img.get());
    if (it != m_tex_cache.end() && !it->second.owner.expired() &&
        it->second.owner.lock().get() == static_cast<const void*>(img.get())) {
      return it->second.tex;
    }
    if (it != m_tex_cache.end()) {
      glDeleteTextures(1, &it->second.tex);
      m_tex_cache.erase(it);
    }
    if (img->empty()) fail("render: empty texture image");
    GLint max_tex = 0;
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_tex);
    if (img->width() > max_tex || img->height() > max_tex)
      fail("render: a {}x{} texture exceeds this GL's GL_MAX_TEXTURE_SIZE of {}; scale it down",
           img->width(), img->height(), max_tex);
    GLuint t = 0;
    glGenTextures(1, &t);
    glBindTexture(GL_TEXTURE_2D, t);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTexImage2D(GL_TEXTURE_2D, 0, GLint(internal), img->width(), img->height(), 0, format, type,
                 img->data());
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER,
                    mipmap ? GL_LINEAR_MIPMAP_NEAREST : GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
    if (mipmap) glGenerateMipmap(GL_TEXTURE_2D);
    m_tex_cache[img.get()] = TexEntry{std::weak_ptr<const void>(img), t};
    return t;
  }

  void purge_texture_cache() {
    for (auto it = m_tex_cache.begin(); it != m_tex_cache.end();) {
      if (it->second.owner.expired()) {
        glDeleteTextures(1, &it->second.tex);
        it = m_tex_cache.erase(it);
      } else {
        ++it;
      }
    }
  }

  void set_lights(GLuint p, const RenderScene& scene) {
    const int n = int(std::min<std::size_t>(scene.lights.size(), kMaxLights));
    set_i(p, "uNumLights", n);
    for (int i = 0; i < n; ++i) {
      const DirectionalLight& l = scene.lights[std::size_t(i)];
      set_vec3(p, fmt::format("uLightDir[{}]", i).c_str(), -l.direction.normalized());
      set_vec3(p, fmt::format("uLightColor[{}]", i).c_str(), l.color * l.intensity);
    }
    set_vec3(p, "uAmbientColor", scene.ambient_color);
    set_vec3(p, "uEye", scene.camera.eye);
  }

  /// Draws the frame. With `cpu_frame` and a CPU hair view pass, the colour buffer is read back
  /// into it before the hair is drawn there, and the GL resolve is skipped: returns true, the
  /// caller resolves *cpu_frame. Otherwise the result is in m_out_fbo and it returns false.
  bool draw(const RenderScene& scene, const RenderSettings& settings,
            std::vector<float>* cpu_frame = nullptr) {
    settings.validate();
    scene.camera.validate();
    if (scene.lights.size() > std::size_t(kMaxLights))
      fail_at("render.lights", "{} lights given, at most {} are supported", scene.lights.size(),
              kMaxLights);
    for (std::size_t i = 0; i < scene.lights.size(); ++i) {
      const auto& l = scene.lights[i];
      if (!l.direction.allFinite() || l.direction.norm() < 1e-12)
        fail_at(fmt::format("render.lights[{}].direction", i), "must be a non-zero finite vector");
      if (!l.color.allFinite() || !std::isfinite(l.intensity))
        fail_at(fmt::format("render.lights[{}]", i), "colour and intensity must be finite");
    }
    const int k = settings.supersample;
    ensure_targets(settings.width, settings.height, k, settings.shadow_map_size);
    purge_texture_cache();
    FrameObjects fo;

    int shadow_light = -1;
    for (std::size_t i = 0; i < scene.lights.size(); ++i)
      if (scene.lights[i].cast_shadow) {
        shadow_light = int(i);
        break;
      }
    Eigen::AlignedBox3d shadow_box;
    Eigen::AlignedBox3d* sb = shadow_light >= 0 ? &shadow_box : nullptr;

    // ---- upload -------------------------------------------------------------------------------
    std::vector<MeshDraw> meshes;
    for (auto& [key, e] : m_mesh_cache) e.used = false;
    for (std::size_t i = 0; i < scene.meshes.size(); ++i) {
      const MeshItem& item = scene.meshes[i];
      if (!item.mesh || item.mesh->faces.empty()) continue;
      MeshDraw d;
      std::tie(d.vao, d.count) = mesh_buffer(fo, item, i, item.cast_shadow ? sb : nullptr);
      d.item = &item;
      d.has_uvs = item.mesh->has_uvs();
      meshes.push_back(d);
    }
    // Buffers of meshes not drawn this frame go (an animation makes a new mesh every frame).
    for (auto it = m_mesh_cache.begin(); it != m_mesh_cache.end();) {
      if (!it->second.used) {
        release(it->second);
        it = m_mesh_cache.erase(it);
      } else {
        ++it;
      }
    }
    std::vector<StrandDraw> strands;
    clear_cpu_hair();
    for (std::size_t i = 0; i < scene.strands.size(); ++i) {
      const StrandItem& item = scene.strands[i];
      if (!item.strands || item.strands->points.empty()) continue;
      if (is_cpu_hair(item, settings)) {
        gather_cpu_hair(item, i, k, item.hair_shadow || item.cast_shadow ? sb : nullptr);
        continue;
      }
      strands.push_back(upload_strands(fo, item, i, item.cast_shadow ? sb : nullptr));
    }
    const Mat4 view = view_matrix(scene.camera);
    const Mat4 proj = projection_matrix(scene.camera, double(settings.width) / settings.height);
    const Mat4 view_proj = proj * view;
    std::vector<ParticleDraw> particles;
    m_splat->prepare(scene, sb);  // the HairSplat items (Bando 2003 §3.4)
    for (std::size_t i = 0; i < scene.particles.size(); ++i) {
      const ParticleItem& item = scene.particles[i];
      if (!item.particles || item.particles->positions.empty()) continue;
      if (item.shading == ParticleShading::HairSplat) continue;
      particles.push_back(upload_particles(fo, item, i, view));
    }
    check_gl("upload");

    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDisable(GL_CULL_FACE);
    glDisable(GL_BLEND);
    glDepthMask(GL_TRUE);

    // ---- shadow pass --------------------------------------------------------------------------
    Mat4 light_vp = Mat4::Identity();
    double shadow_texel_world = 0, shadow_depth_range = 1;
    const bool shadows = shadow_light >= 0 && !shadow_box.isEmpty();
    // Orthographic view-projection of a directional light over the shadow box.
    auto light_matrix = [&](std::size_t li) {
      const Vec3 c = shadow_box.center();
      const double r = std::max(0.5 * shadow_box.diagonal().norm(), 1e-6);
      const Vec3 dir = scene.lights[li].direction.normalized();
      const Vec3 up = std::abs(dir.y()) < 0.9 ? Vec3(0, 1, 0) : Vec3(1, 0, 0);
      const Mat4 lv = look_at(c - dir * (2 * r), c, up);
      return Mat4(orthographic(-r, r, -r, r, r * 0.5, r * 3.5) * lv);
    };
    // The scene's depth map seen through `vp` (meshes and GL strands that cast shadows).
    auto draw_shadow_casters = [&](const Mat4& vp) {
      glBindFramebuffer(GL_FRAMEBUFFER, m_shadow_fbo);
      glViewport(0, 0, settings.shadow_map_size, settings.shadow_map_size);
      glClear(GL_DEPTH_BUFFER_BIT);
      glEnable(GL_POLYGON_OFFSET_FILL);
      glPolygonOffset(1.5f, 2.0f);
      glUseProgram(m_depth_prog);
      set_mat4(m_depth_prog, "uLightVP", vp);
      for (const MeshDraw& d : meshes) {
        if (!d.item->cast_shadow) continue;
        set_mat4(m_depth_prog, "uModel", d.item->transform.matrix());
        glBindVertexArray(d.vao);
        glDrawElements(GL_TRIANGLES, d.count, GL_UNSIGNED_INT, nullptr);
      }
      glDisable(GL_POLYGON_OFFSET_FILL);
      glLineWidth(1.0f);
      for (const StrandDraw& d : strands) {
        if (!d.item->cast_shadow) continue;
        set_mat4(m_depth_prog, "uModel", d.item->transform.matrix());
        glBindVertexArray(d.vao);
        glMultiDrawArrays(GL_LINE_STRIP, d.first.data(), d.count.data(), GLsizei(d.first.size()));
      }
      check_gl("shadow pass");
    };
    const bool cpu_hair = !m_hair_items.empty();
    // Hair shadow buffers: every shadow light's when some item is shadowed by them, the mesh
    // pass's light's also when some item only casts (onto the meshes).
    const bool hair_shadowed =
        std::any_of(m_hair_items.begin(), m_hair_items.end(),
                    [](const CpuHairItem& h) { return is_shadowed_hair(*h.item); });
    const bool hair_casts = std::any_of(m_hair.casts_shadow.begin(), m_hair.casts_shadow.end(),
                                        [](uint8_t c) { return c != 0; });
    m_hair_shadow.resize(scene.lights.size());
    for (ShadowBuffer& b : m_hair_shadow) b.size = 0;  // none yet (the memory is kept)
    if (shadows && hair_shadowed) {
      // Daldegan 1993 §4 steps (1)-(3) for the other shadow-casting lights; they share the
      // shadow framebuffer, so they go first and the mesh pass's light comes last.
      for (std::size_t li = 0; li < scene.lights.size(); ++li) {
        if (!scene.lights[li].cast_shadow || int(li) == shadow_light) continue;
        const Mat4 vp = light_matrix(li);
        draw_shadow_casters(vp);
        hair_shadow_buffer(li, vp, settings.shadow_map_size, hair_casts, false);
      }
    }
    if (shadows) {
      const Vec3 dir = scene.lights[std::size_t(shadow_light)].direction.normalized();
      const double r = std::max(0.5 * shadow_box.diagonal().norm(), 1e-6);
      light_vp = light_matrix(std::size_t(shadow_light));
      shadow_texel_world = 2 * r / settings.shadow_map_size;
      shadow_depth_range = 3 * r;
      draw_shadow_casters(light_vp);
      // The composite buffer replaces the scene's, so the hair shadows the meshes (step 4).
      if (hair_shadowed || hair_casts)
        hair_shadow_buffer(std::size_t(shadow_light), light_vp, settings.shadow_map_size,
                           hair_casts, true);
      if (!m_splat->empty()) {
        SplatPassGl::Light sl;
        sl.index = shadow_light;
        sl.travel = dir;
        sl.light_vp = light_vp;
        sl.shadow_tex = m_shadow_tex;
        sl.shadow_texel = 1.0 / settings.shadow_map_size;
        sl.shadow_bias = 2.0 * shadow_texel_world / shadow_depth_range;
        m_splat->light_pass(sl, settings, m_empty_vao, *m_arena);
      }
    }

    // ---- main pass ----------------------------------------------------------------------------
    glBindFramebuffer(GL_FRAMEBUFFER, m_fbo);
    glViewport(0, 0, m_fb_w, m_fb_h);
    const Vec3 bg = scene.background;
    if (settings.transparent_background)
      glClearColor(0, 0, 0, 0);
    else
      glClearColor(float(bg.x()), float(bg.y()), float(bg.z()), 1.0f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);

    if (!meshes.empty()) {
      MeshPassState st;
      st.scene = &scene;
      st.view_proj = view_proj;
      st.shadow_light = shadows ? shadow_light : -1;
      st.light_vp = light_vp;
      st.shadow_texel = 1.0 / settings.shadow_map_size;
      st.shadow_normal_offset = 1.5 * shadow_texel_world;
      st.shadow_bias = 1.0 * shadow_texel_world / shadow_depth_range;
      st.light_map = shadows ? m_splat->light_map() : 0;
      for (const MeshDraw& d : meshes) draw_mesh(st, d);
      check_gl("mesh pass");
    }
    if (!strands.empty()) draw_strands(scene, settings, strands, view_proj, proj);
    if (!particles.empty()) {
      const GLuint p = m_particle_prog;
      glUseProgram(p);
      set_mat4(p, "uView", view);
      set_mat4(p, "uProj", proj);
      glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
      for (const ParticleDraw& d : particles) {
        set_mat4(p, "uModel", d.item->transform.matrix());
        set_f(p, "uModelScale", linear_scale(d.item->transform));
        set_i(p, "uShading", d.item->shading == ParticleShading::HairSplat ? 1 : 0);
        const bool blend = d.blend || d.item->shading == ParticleShading::HairSplat;
        if (blend) {
          glEnable(GL_BLEND);
          glDepthMask(GL_FALSE);
        }
        glBindVertexArray(d.vao);
        glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, d.count);
        glDisable(GL_BLEND);
        glDepthMask(GL_TRUE);
      }
      check_gl("particle pass");
    }
    if (!m_splat->empty() && settings.hair_view_pass == "gpu")
      m_splat->view_pass(scene, view, view_proj, m_empty_vao);
    // Daldegan 1993 §4 step (5): the CPU-pass hair blended into the rendered scene.
    const bool frame_on_cpu =
        cpu_hair && blend_cpu_hair(scene, view_proj, shadow_light, k, cpu_frame);
    if (!m_splat->empty() && settings.hair_view_pass != "gpu") {
      if (cpu_frame) {
        if (!frame_on_cpu) read_frame(*cpu_frame);
        m_splat->view_pass_cpu(scene, view, view_proj, m_color_tex, m_fb_w, m_fb_h, *m_arena,
                               cpu_frame);
        glBindVertexArray(0);
        return true;
      } else {
        m_splat->view_pass_cpu(scene, view, view_proj, m_color_tex, m_fb_w, m_fb_h, *m_arena);
      }
    }
    if (frame_on_cpu) {
      glBindVertexArray(0);
      return true;
    }

    // ---- resolve ------------------------------------------------------------------------------
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
    glBindFramebuffer(GL_FRAMEBUFFER, m_out_fbo);
    glViewport(0, 0, settings.width, settings.height);
    glUseProgram(m_resolve_prog);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, m_color_tex);
    set_i(m_resolve_prog, "uSrc", 0);
    set_i(m_resolve_prog, "uK", k);
    set_i(m_resolve_prog, "uUnpremultiply", settings.transparent_background ? 1 : 0);
    glBindVertexArray(m_empty_vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glBindVertexArray(0);
    check_gl("resolve");
    return false;
  }

  /// The whole colour buffer of the bound framebuffer into `frame` (fb_w x fb_h linear RGBA
  /// floats, rows bottom up): read as half floats (a plain copy in llvmpipe, where converting
  /// to float costs 1 ms at 512²), widened exactly on the CPU.
  void read_frame(std::vector<float>& frame) {
    const std::size_t nf = 4 * std::size_t(m_fb_w) * std::size_t(m_fb_h);
    m_cpu_half.resize(nf);
    frame.resize(nf);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glReadPixels(0, 0, m_fb_w, m_fb_h, GL_RGBA, GL_HALF_FLOAT, m_cpu_half.data());
    check_gl("frame read-back");
    m_arena->execute([&] { m_resolve.half_to_float(m_cpu_half.data(), nf, frame.data()); });
  }

  // ---- Daldegan 1993 §4 CPU hair pass ---------------------------------------------------------

  static bool is_cpu_hair(const StrandItem& item, const RenderSettings& settings) {
    return settings.strand_pass == "cpu" || item.material.shading == StrandShading::Daldegan1993 ||
           item.hair_shadow;
  }

  /// Whether the CPU pass shades `item` with the shadow buffers (S_i of eq. 7, or the key
  /// light's S of the shadowed vertex colours); the other items are lit without shadows, as
  /// the GL strand pass lights them.
  static bool is_shadowed_hair(const StrandItem& item) {
    return item.hair_shadow || item.material.shading == StrandShading::Daldegan1993;
  }

  struct CpuHairItem {
    const StrandItem* item = nullptr;
    std::size_t index = 0;                         // in RenderScene::strands
    std::size_t strand_begin = 0, strand_end = 0;  // in m_hair
  };

  void clear_cpu_hair() {
    m_hair_items.clear();
    m_hair.points.clear();
    m_hair.offsets.assign(1, 0);
    m_hair.radius.clear();
    m_hair.width_px.clear();
    m_hair.opacity.clear();
    m_hair.casts_shadow.clear();
    m_hair_base.clear();
  }

  /// Appends a CPU-pass item to m_hair in world space (widths in framebuffer pixels for
  /// supersampling k), checking it like upload_strands; extends `shadow_box` by its points.
  void gather_cpu_hair(const StrandItem& item, std::size_t index, int k,
                       Eigen::AlignedBox3d* shadow_box) {
    const geom::StrandSet& s = *item.strands;
    const StrandMaterial& mat = item.material;
    const std::string where = fmt::format("render: strands[{}]", index);
    const std::size_t np = s.points.size();
    if (s.offsets.empty() || s.offsets.front() != 0 || s.offsets.back() != np)
      fail_at(where, "offsets do not cover the {} points", np);
    if (!s.color.empty() && s.color.size() != np)
      fail_at(where, "{} colours for {} points", s.color.size(), np);
    if (!s.radius.empty() && s.radius.size() != np)
      fail_at(where, "{} radii for {} points", s.radius.size(), np);
    if (!(std::isfinite(mat.width_px) && mat.width_px > 0))
      fail_at(where + ".material.width_px", "{} must be a finite value > 0", mat.width_px);
    if (!(mat.opacity >= 0 && mat.opacity <= 1))
      fail_at(where + ".material.opacity", "{} is outside [0, 1]", mat.opacity);
    if (!mat.color.allFinite() || mat.color.minCoeff() < 0)
      fail_at(where + ".material.color", "must be finite and >= 0");
    if (!item.transform.matrix().allFinite()) fail_at(where, "the transform is not finite");
    const std::size_t ns = s.num_strands();
    for (std::size_t st = 0; st < ns; ++st)
      if (s.offsets[st + 1] < s.offsets[st]) fail_at(where, "offsets decrease at strand {}", st);
    for (std::size_t i = 0; i < np; ++i)
      if (!s.points[i].allFinite()) fail_at(where, "point {} is not finite", i);
    for (std::size_t i = 0; i < s.radius.size(); ++i)
      if (!(std::isfinite(s.radius[i]) && s.radius[i] >= 0))
        fail_at(where, "radius {} of point {} is not a finite value >= 0", s.radius[i], i);
    if (s.color.size() == np)
      for (std::size_t i = 0; i < np; ++i)
        if (!s.color[i].allFinite()) fail_at(where, "colour of point {} is not finite", i);
    if (m_hair.points.size() + np > std::size_t(std::numeric_limits<uint32_t>::max()))
      fail_at(where, "the CPU hair pass holds at most 2^32 - 1 points");
    CpuHairItem h;
    h.item = &item;
    h.index = index;
    h.strand_begin = m_hair.num_strands();
    const std::size_t p0 = m_hair.points.size();
    m_hair.points.resize(p0 + np);
    m_hair_base.resize(p0 + np);
    const Affine3 xf = item.transform;
    const Vec3f mc = mat.color.cast<float>();
    parallel_for(
        *m_hair_ctx, 0, np,
        [&](std::size_t i) {
          m_hair.points[p0 + i] = (xf * s.points[i].cast<double>()).cast<float>();
          m_hair_base[p0 + i] = s.color.empty() ? mc : s.color[i];
        },
        4096);
    // Radii: per point when any item has them; the points of items without keep their
    // strand's screen width (HairSegments::kNoRadius).
    if (!s.radius.empty() && m_hair.radius.empty())
      m_hair.radius.assign(p0, HairSegments::kNoRadius);
    if (!m_hair.radius.empty()) {
      const float scale = float(linear_scale(xf));
      m_hair.radius.resize(p0 + np, HairSegments::kNoRadius);
      if (!s.radius.empty())
        for (std::size_t i = 0; i < np; ++i) m_hair.radius[p0 + i] = s.radius[i] * scale;
    }
    for (std::size_t st = 0; st < ns; ++st)
      m_hair.offsets.push_back(uint32_t(p0 + s.offsets[st + 1]));
    m_hair.width_px.resize(m_hair.num_strands(), float(mat.width_px * k));
    m_hair.opacity.resize(m_hair.num_strands(), float(mat.opacity));
    // Cast into the hair shadow buffers (and so onto the meshes and the shadowed hair):
    // hair_shadow items and those with cast_shadow (as GL lines cast into the shadow map).
    m_hair.casts_shadow.resize(m_hair.num_strands(), item.hair_shadow || item.cast_shadow ? 1 : 0);
    h.strand_end = m_hair.num_strands();
    m_hair_items.push_back(h);
    if (shadow_box && np > 0) {
      Eigen::AlignedBox3f b;
      for (std::size_t i = p0; i < p0 + np; ++i) b.extend(m_hair.points[i]);
      shadow_box->extend(b.min().cast<double>());
      shadow_box->extend(b.max().cast<double>());
    }
  }

  /// Steps (1)-(3) for light `li`: the scene's depth map just drawn into the shadow framebuffer
  /// read back, the hair's drawn on the CPU, their composite kept in m_hair_shadow[li]; with
  /// `upload` (the mesh pass's light) the composite replaces the shadow map. Without `casts`
  /// (no item casts) the composite is the scene's map itself.
  void hair_shadow_buffer(std::size_t li, const Mat4& vp, int size, bool casts, bool upload) {
    ShadowBuffer& buf = m_hair_shadow[li];
    buf.size = size;
    buf.light_vp = vp;
    buf.depth.resize(std::size_t(size) * std::size_t(size));
    glBindFramebuffer(GL_FRAMEBUFFER, m_shadow_fbo);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glReadPixels(0, 0, size, size, GL_DEPTH_COMPONENT, GL_FLOAT, buf.depth.data());
    check_gl("shadow map read-back");
    if (!casts) return;
    m_hair_rasterizer.rasterize(*m_hair_ctx, m_hair, vp, size, m_hair_depth_map);
    compose_shadow_buffers_into(*m_hair_ctx, buf, m_hair_depth_map);
    if (!upload) return;
    glBindTexture(GL_TEXTURE_2D, m_shadow_tex);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, size, size, GL_DEPTH_COMPONENT, GL_FLOAT,
                    m_hair_shadow[li].depth.data());
    glBindTexture(GL_TEXTURE_2D, 0);
    check_gl("composite shadow map upload");
  }

  /// Step (5): shades the CPU-pass hair (eq. 7, or the shadowed vertex colours) and blends it
  /// into the colour buffer of m_fbo, tested against its depth. With `cpu_frame` the whole
  /// frame is read into it and the hair drawn there (returns true: the caller resolves it);
  /// otherwise only the hair's rectangle is read back and uploaded again (returns false).
  bool blend_cpu_hair(const RenderScene& scene, const Mat4& view_proj, int shadow_light, int k,
                      std::vector<float>* cpu_frame) {
    const Context& ctx = *m_hair_ctx;
    std::vector<HairLight> lights;
    for (std::size_t li = 0; li < scene.lights.size(); ++li) {
      const DirectionalLight& l = scene.lights[li];
      HairLight h;
      h.to_light = -l.direction.normalized();
      h.radiance = l.color * l.intensity;
      h.shadow = m_hair_shadow[li].size > 0 ? &m_hair_shadow[li] : nullptr;
      lights.push_back(h);
    }
    std::vector<HairLight> unshadowed = lights;  // for the items that hair does not shadow
    for (HairLight& h : unshadowed) h.shadow = nullptr;
    m_hair_color.resize(m_hair.num_points());
    for (const CpuHairItem& h : m_hair_items) {
      const StrandMaterial& mat = h.item->material;
      HairShading sh;
      sh.mode = mat.shading == StrandShading::VertexColor ? HairShadingMode::ShadowedColor
                                                          : HairShadingMode::Daldegan1993;
      sh.ambient_light = scene.ambient_color;
      sh.color = mat.color;
      sh.k_a = mat.ambient;
      sh.k_d = mat.diffuse;
      sh.k_s = mat.specular;
      sh.n = mat.shininess;
      sh.shadow_bias = mat.shadow_bias;
      sh.shadow_slope_bias = mat.shadow_slope_bias;
      sh.shadow_filter_radius = mat.shadow_filter_radius;
      const bool shadowed = is_shadowed_hair(*h.item);
      sh.key_light = shadowed ? shadow_light : -1;
      const std::string where = fmt::format("render: strands[{}].material", h.index);
      sh.check(where);
      shade_hair_vertices(ctx, m_hair, h.strand_begin, h.strand_end, m_hair_base, sh,
                          shadowed ? lights : unshadowed, scene.camera.eye, m_hair_color);
    }
    m_hair_blender.prepare(ctx, view_proj, m_hair, m_fb_w, m_fb_h, k);
    const std::array<int, 4> box = m_hair_blender.bounds();
    glBindFramebuffer(GL_FRAMEBUFFER, m_fbo);
    if (cpu_frame) read_frame(*cpu_frame);
    if (box[0] >= box[2]) return cpu_frame != nullptr;  // no hair on screen
    HairFrame tg;
    tg.samples = k;
    tg.fb_width = m_fb_w;
    tg.fb_height = m_fb_h;
    tg.x0 = box[0];
    tg.y0 = box[1];
    tg.width = box[2] - box[0];
    tg.height = box[3] - box[1];
    const std::size_t npix = std::size_t(tg.width) * std::size_t(tg.height);
    m_hair_depth.resize(npix);
    if (cpu_frame) {
      tg.rgba =
          cpu_frame->data() + 4 * (std::size_t(tg.y0) * std::size_t(m_fb_w) + std::size_t(tg.x0));
      tg.rgba_stride = m_fb_w;
    } else {
      m_hair_rgba.resize(4 * npix);
      glPixelStorei(GL_PACK_ALIGNMENT, 4);
      glReadPixels(tg.x0, tg.y0, tg.width, tg.height, GL_RGBA, GL_FLOAT, m_hair_rgba.data());
      tg.rgba = m_hair_rgba.data();
    }
    glReadPixels(tg.x0, tg.y0, tg.width, tg.height, GL_DEPTH_COMPONENT, GL_FLOAT,
                 m_hair_depth.data());
    check_gl("hair pass read-back");
    tg.depth = m_hair_depth.data();
    m_hair_blender.blend(ctx, m_hair, m_hair_color, tg);
    if (cpu_frame) return true;
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glBindTexture(GL_TEXTURE_2D, m_color_tex);
    glTexSubImage2D(GL_TEXTURE_2D, 0, tg.x0, tg.y0, tg.width, tg.height, GL_RGBA, GL_FLOAT,
                    m_hair_rgba.data());
    glBindTexture(GL_TEXTURE_2D, 0);
    check_gl("hair pass upload");
    return false;
  }

  struct MeshPassState {
    const RenderScene* scene = nullptr;
    Mat4 view_proj, light_vp;
    int shadow_light = -1;
    double shadow_texel = 0, shadow_normal_offset = 0, shadow_bias = 0;
    GLuint light_map = 0;  // hair light map (Bando 2003 §3.4), 0: none
  };

  enum MeshFeature { kAlbedo = 4, kHeight = 8, kNormalMap = 16, kShadow = 32, kLightMap = 64 };

  /// Mesh program variant: bits 0-1 shading (0 Blinn-Phong, 1 Lafortune, 2 unlit), then
  /// MeshFeature bits. Compiled on first use and kept.
  GLuint mesh_program(int key) {
    auto it = m_mesh_progs.find(key);
    if (it != m_mesh_progs.end()) return it->second;
    std::string defs = fmt::format("#define SHADING {}\n", key & 3);
    if (key & kAlbedo) defs += "#define HAS_ALBEDO\n";
    if (key & kHeight) defs += "#define HAS_HEIGHT\n";
    if (key & kNormalMap) defs += "#define HAS_NORMALMAP\n";
    if (key & kShadow) defs += "#define HAS_SHADOW\n";
    if (key & kLightMap) defs += "#define HAS_LIGHTMAP\n";
    const GLuint p = link_program("mesh", defs, glsl::kMeshVs, glsl::kMeshFs, nullptr, true);
    m_mesh_progs[key] = p;
    return p;
  }

  void draw_mesh(const MeshPassState& st, const MeshDraw& d) {
    const MeshItem& item = *d.item;
    const MeshMaterial& mat = item.material;
    const int shading = mat.shading == MeshShading::BlinnPhong      ? 0
                        : mat.shading == MeshShading::LafortuneSkin ? 1
                                                                    : 2;
    const bool albedo = mat.albedo_map && d.has_uvs;
    const bool height = mat.height_map && d.has_uvs && shading != 2;
    const bool nmap = mat.normal_map && d.has_uvs && shading != 2;
    const bool shadow = st.shadow_light >= 0 && shading != 2;
    const bool lmap = shadow && st.light_map != 0;
    const int key = shading | (albedo ? kAlbedo : 0) | (height ? kHeight : 0) |
                    (nmap ? kNormalMap : 0) | (shadow ? kShadow : 0) | (lmap ? kLightMap : 0);
    const GLuint p = mesh_program(key);
    glUseProgram(p);
    set_mat4(p, "uViewProj", st.view_proj);
    set_lights(p, *st.scene);
    set_mat4(p, "uModel", item.transform.matrix());
    set_mat3(p, "uNormalMat", item.transform.linear().inverse().transpose());
    if (shadow) {
      set_i(p, "uShadowTex", 3);
      glActiveTexture(GL_TEXTURE3);
      glBindTexture(GL_TEXTURE_2D, m_shadow_tex);
      set_i(p, "uShadowLight", st.shadow_light);
      set_mat4(p, "uLightVP", st.light_vp);
      set_f(p, "uShadowTexel", st.shadow_texel);
      set_f(p, "uShadowNormalOffset", st.shadow_normal_offset);
      set_f(p, "uShadowBias", st.shadow_bias);
    }
    if (lmap) {
      set_i(p, "uLightMap", 4);
      glActiveTexture(GL_TEXTURE4);
      glBindTexture(GL_TEXTURE_2D, st.light_map);
    }
    // Albedo: per-vertex colours, else the base colour (rho_d for Lafortune), times the
    // texture when there is one (the texture alone when there are no vertex colours).
    const Vec3 base =
        albedo ? Vec3(1, 1, 1) : (shading == 1 ? mat.lafortune.rho_d : mat.base_color);
    set_vec3(p, "uBaseColor", base);
    set_i(p, "uUseVertexColor", item.vertex_colors.empty() ? 0 : 1);
    set_f(p, "uSpecular", mat.specular);
    set_f(p, "uShininess", mat.shininess);
    set_f(p, "uAmbient", mat.ambient);
    if (mat.lafortune.lobes.size() > std::size_t(kMaxLobes))
      fail("render: at most {} Lafortune lobes are supported", kMaxLobes);
    set_i(p, "uNumLobes", int(mat.lafortune.lobes.size()));
    for (std::size_t l = 0; l < mat.lafortune.lobes.size(); ++l) {
      set_vec3(p, fmt::format("uCxy[{}]", l).c_str(), mat.lafortune.lobes[l].cxy);
      set_vec3(p, fmt::format("uCz[{}]", l).c_str(), mat.lafortune.lobes[l].cz);
      set_vec3(p, fmt::format("uN[{}]", l).c_str(), mat.lafortune.lobes[l].n);
    }
    if (albedo) {
      set_i(p, "uAlbedoTex", 0);
      glActiveTexture(GL_TEXTURE0);
      glBindTexture(GL_TEXTURE_2D,
                    texture(mat.albedo_map, GL_SRGB8_ALPHA8, GL_RGBA, GL_UNSIGNED_BYTE, true));
    }
    if (height) {
      set_i(p, "uHeightTex", 1);
      glActiveTexture(GL_TEXTURE1);
      glBindTexture(GL_TEXTURE_2D, texture(mat.height_map, GL_R32F, GL_RED, GL_FLOAT, false));
      glUniform2f(glGetUniformLocation(p, "uHeightTexel"), 1.0f / mat.height_map->width(),
                  1.0f / mat.height_map->height());
      set_f(p, "uBumpStrength", mat.bump_strength);
    }
    if (nmap) {
      set_i(p, "uNormalTex", 2);
      glActiveTexture(GL_TEXTURE2);
      glBindTexture(GL_TEXTURE_2D, texture(mat.normal_map, GL_RGB16F, GL_RGB, GL_FLOAT, true));
    }
    glBindVertexArray(d.vao);
    glDrawElements(GL_TRIANGLES, d.count, GL_UNSIGNED_INT, nullptr);
  }

  StrandDraw upload_strands(FrameObjects& fo, const StrandItem& item, std::size_t index,
                            Eigen::AlignedBox3d* shadow_box) {
    const geom::StrandSet& s = *item.strands;
    const std::string where = fmt::format("render: strands[{}]", index);
    const std::size_t np = s.points.size();
    if (s.offsets.empty() || s.offsets.front() != 0 || s.offsets.back() != np)
      fail_at(where, "offsets do not cover the {} points", np);
    if (!s.color.empty() && s.color.size() != np)
      fail_at(where, "{} colours for {} points", s.color.size(), np);
    if (!s.radius.empty() && s.radius.size() != np)
      fail_at(where, "{} radii for {} points", s.radius.size(), np);
    StrandDraw d;
    d.item = &item;
    d.ribbons = !s.radius.empty() || item.material.width_px > m_line_width_range[1] / 2;
    std::vector<StrandVertex> v(np);
    const Vec3f mc = item.material.color.cast<float>();
    for (std::size_t st = 0; st < s.num_strands(); ++st) {
      const uint32_t b = s.offsets[st], e = s.offsets[st + 1];
      if (e < b) fail_at(where, "offsets decrease at strand {}", st);
      if (e - b >= 2) {
        d.first.push_back(GLint(b));
        d.count.push_back(GLsizei(e - b));
      }
      for (uint32_t i = b; i < e; ++i) {
        const Vec3f& p = s.points[i];
        if (!p.allFinite()) fail_at(where, "point {} is not finite", i);
        if (shadow_box) extend(*shadow_box, item.transform, p.cast<double>());
        const Vec3f t = (s.points[std::min(i + 1, e - 1)] - s.points[i > b ? i - 1 : b]);
        const Vec3f tn = t.norm() > 0 ? Vec3f(t.normalized()) : Vec3f(0, 1, 0);
        const Vec3f c = s.color.empty() ? mc : s.color[i];
        StrandVertex& sv = v[i];
        for (int j = 0; j < 3; ++j) {
          sv.pos[j] = p[j];
          sv.color[j] = c[j];
          sv.tangent[j] = tn[j];
        }
        sv.radius = s.radius.empty() ? -1.0f : s.radius[i];
      }
    }
    d.vao = fo.vao();
    fo.buffer(GL_ARRAY_BUFFER, v.size() * sizeof(StrandVertex), v.data());
    const std::size_t sz = sizeof(StrandVertex);
    attrib(0, 3, sz, offsetof(StrandVertex, pos));
    attrib(1, 3, sz, offsetof(StrandVertex, color));
    attrib(2, 3, sz, offsetof(StrandVertex, tangent));
    attrib(3, 1, sz, offsetof(StrandVertex, radius));
    return d;
  }

  void draw_strands(const RenderScene& scene, const RenderSettings& settings,
                    const std::vector<StrandDraw>& strands, const Mat4& view_proj,
                    const Mat4& proj) {
    const int k = settings.supersample;
    for (const StrandDraw& d : strands) {
      const StrandMaterial& mat = d.item->material;
      const GLuint p = d.ribbons ? m_ribbon_prog : m_line_prog;
      glUseProgram(p);
      set_mat4(p, "uViewProj", view_proj);
      set_lights(p, scene);
      set_mat4(p, "uModel", d.item->transform.matrix());
      set_f(p, "uModelScale", linear_scale(d.item->transform));
      set_f(p, "uPixelScale", proj(1, 1) * 0.5 * m_fb_h);
      set_f(p, "uWidthPx", mat.width_px * k);
      if (d.ribbons)
        glUniform2f(glGetUniformLocation(p, "uViewport"), float(m_fb_w), float(m_fb_h));
      set_i(p, "uShading", mat.shading == StrandShading::KajiyaKay ? 1 : 0);
      set_f(p, "uDiffuse", mat.diffuse);
      set_f(p, "uSpecular", mat.specular);
      set_f(p, "uShininess", mat.shininess);
      set_f(p, "uAmbient", mat.ambient);
      double opacity = mat.opacity;
      if (!d.ribbons) {
        // GL lines narrower than one framebuffer pixel: keep 1 px, scale the opacity.
        const double w = mat.width_px * k;
        glLineWidth(float(std::clamp(w, 1.0, double(m_line_width_range[1]))));
        if (w < 1.0) opacity *= w;
      }
      set_f(p, "uOpacity", opacity);
      const bool blend = opacity < 1.0 || d.ribbons;
      if (blend) {
        glEnable(GL_BLEND);
        glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
      }
      glBindVertexArray(d.vao);
      glMultiDrawArrays(GL_LINE_STRIP, d.first.data(), d.count.data(), GLsizei(d.first.size()));
      glDisable(GL_BLEND);
    }
    glLineWidth(1.0f);
    check_gl("strand pass");
  }

  ParticleDraw upload_particles(FrameObjects& fo, const ParticleItem& item, std::size_t index,
                                const Mat4& view) {
    const geom::ParticleSet& s = *item.particles;
    const std::string where = fmt::format("render: particles[{}]", index);
    const std::size_t n = s.positions.size();
    auto check_size = [&](std::size_t got, const char* what) {
      if (got != 0 && got != n) fail_at(where, "{} {} for {} particles", got, what, n);
    };
    check_size(s.directions.size(), "directions");
    check_size(s.radius.size(), "radii");
    check_size(s.color.size(), "colours");
    check_size(s.opacity.size(), "opacities");
    ParticleDraw d;
    d.item = &item;
    std::vector<ParticleInstance> inst(n);
    std::vector<double> depth(n);
    const Mat4 mv = view * item.transform.matrix();
    for (std::size_t i = 0; i < n; ++i) {
      const Vec3f& p = s.positions[i];
      if (!p.allFinite()) fail_at(where, "particle {} is not finite", i);
      ParticleInstance& q = inst[i];
      const Vec3f c = s.color.empty() ? Vec3f(item.color.cast<float>()) : s.color[i];
      const Vec3f t = s.directions.empty() ? Vec3f(0, 1, 0) : s.directions[i];
      for (int j = 0; j < 3; ++j) {
        q.pos[j] = p[j];
        q.color[j] = c[j];
        q.dir[j] = t[j];
      }
      q.radius = s.radius.empty() ? float(item.radius) : s.radius[i];
      q.opacity = float(item.opacity) * (s.opacity.empty() ? 1.0f : s.opacity[i]);
      if (q.opacity < 1.0f) d.blend = true;
      depth[i] = (mv * p.cast<double>().homogeneous()).z();  // view z: more negative = farther
    }
    if (d.blend || item.shading == ParticleShading::HairSplat) {
      // Back to front; stable sort keeps equal depths in input order (deterministic).
      std::vector<std::size_t> order(n);
      std::iota(order.begin(), order.end(), std::size_t(0));
      std::stable_sort(order.begin(), order.end(),
                       [&](std::size_t a, std::size_t b) { return depth[a] < depth[b]; });
      std::vector<ParticleInstance> sorted(n);
      for (std::size_t i = 0; i < n; ++i) sorted[i] = inst[order[i]];
      inst.swap(sorted);
    }
    d.vao = fo.vao();
    glBindBuffer(GL_ARRAY_BUFFER, m_quad_vbo);
    attrib(0, 2, 2 * sizeof(float), 0);
    fo.buffer(GL_ARRAY_BUFFER, inst.size() * sizeof(ParticleInstance), inst.data());
    const std::size_t sz = sizeof(ParticleInstance);
    attrib(1, 3, sz, offsetof(ParticleInstance, pos), 1);
    attrib(2, 3, sz, offsetof(ParticleInstance, color), 1);
    attrib(3, 1, sz, offsetof(ParticleInstance, radius), 1);
    attrib(4, 1, sz, offsetof(ParticleInstance, opacity), 1);
    attrib(5, 3, sz, offsetof(ParticleInstance, dir), 1);
    d.count = GLsizei(n);
    return d;
  }

  struct TexEntry {
    std::weak_ptr<const void> owner;
    GLuint tex = 0;
  };
  // The vertex buffer of a mesh drawn in the previous frame, kept while the same mesh (same
  // object, alive, same vertex colours) is drawn again: a still scene seen by a moving camera
  // (the viewer) uploads nothing. A TriMesh behind a shared_ptr<const> is not changed in place.
  struct MeshEntry {
    std::weak_ptr<const geom::TriMesh> owner;
    std::vector<Vec3f> colors;
    GLuint vao = 0, buffer = 0, index_buffer = 0;
    GLsizei count = 0;  // indices
    bool used = false;
  };
  static void release(MeshEntry& e) {
    if (e.vao) glDeleteVertexArrays(1, &e.vao);
    if (e.buffer) glDeleteBuffers(1, &e.buffer);
    if (e.index_buffer) glDeleteBuffers(1, &e.index_buffer);
    e.buffer = e.index_buffer = e.vao = 0;
  }
  /// The vertex array (and its vertex count) of one mesh item: cached, or for a second item of
  /// the same mesh with other colours in one frame, a one-frame buffer.
  std::pair<GLuint, GLsizei> mesh_buffer(FrameObjects& fo, const MeshItem& item, std::size_t index,
                                         Eigen::AlignedBox3d* shadow_box) {
    const auto drawn = mesh_buffer(fo, item, index);  // checks the mesh when it builds arrays
    if (shadow_box) extend_by_faces(*shadow_box, item);
    return drawn;
  }
  std::pair<GLuint, GLsizei> mesh_buffer(FrameObjects& fo, const MeshItem& item,
                                         std::size_t index) {
    auto it = m_mesh_cache.find(item.mesh.get());
    if (it != m_mesh_cache.end() && it->second.used && it->second.colors != item.vertex_colors) {
      const MeshArrays a = build_mesh_vertices(item, index);
      const GLuint vao = fo.vao();
      fo.buffer(GL_ARRAY_BUFFER, a.vertices.size() * sizeof(MeshVertex), a.vertices.data());
      fo.buffer(GL_ELEMENT_ARRAY_BUFFER, a.indices.size() * sizeof(uint32_t), a.indices.data());
      mesh_attribs();
      return {vao, GLsizei(a.indices.size())};
    }
    if (it != m_mesh_cache.end() && it->second.owner.lock() == item.mesh &&
        it->second.colors == item.vertex_colors) {
      it->second.used = true;
      return {it->second.vao, it->second.count};
    }
    if (it != m_mesh_cache.end()) {
      release(it->second);
      m_mesh_cache.erase(it);
    }
    const MeshArrays a = build_mesh_vertices(item, index);
    MeshEntry e;
    e.owner = item.mesh;
    e.colors = item.vertex_colors;
    glGenVertexArrays(1, &e.vao);
    glBindVertexArray(e.vao);
    try {
      e.buffer = FrameObjects::upload_buffer(
          GL_ARRAY_BUFFER, a.vertices.size() * sizeof(MeshVertex), a.vertices.data());
      // The element buffer binding is recorded in the vertex array.
      e.index_buffer = FrameObjects::upload_buffer(
          GL_ELEMENT_ARRAY_BUFFER, a.indices.size() * sizeof(uint32_t), a.indices.data());
    } catch (...) {
      release(e);
      throw;
    }
    mesh_attribs();
    e.count = GLsizei(a.indices.size());
    e.used = true;
    const MeshEntry& kept = m_mesh_cache[item.mesh.get()] = std::move(e);
    return {kept.vao, kept.count};
  }
  static void mesh_attribs() {
    const std::size_t s = sizeof(MeshVertex);
    attrib(0, 3, s, offsetof(MeshVertex, pos));
    attrib(1, 3, s, offsetof(MeshVertex, normal));
    attrib(2, 2, s, offsetof(MeshVertex, uv));
    attrib(3, 3, s, offsetof(MeshVertex, color));
    attrib(4, 3, s, offsetof(MeshVertex, pu));
    attrib(5, 3, s, offsetof(MeshVertex, pv));
  }

  std::shared_ptr<spdlog::logger> m_log;
  std::unique_ptr<tbb::task_arena> m_arena;  // the CPU hair view pass's threads (ctx.threads())
  std::vector<float> m_cpu_frame;            // the frame read back for the CPU view pass
  std::vector<uint16_t> m_cpu_half;          // ... as read (half floats)
  std::unique_ptr<Context> m_hair_ctx;       // threads of the Daldegan 1993 CPU hair pass
  // The Daldegan 1993 §4 CPU hair pass: its items, their world-space segments, base and shaded
  // colours per point, composite shadow buffers per light (size 0: none), the blender and the
  // read-back window.
  std::vector<CpuHairItem> m_hair_items;
  HairSegments m_hair;
  std::vector<Vec3f> m_hair_base, m_hair_color;
  std::vector<ShadowBuffer> m_hair_shadow;
  HairDepthRasterizer m_hair_rasterizer;
  ShadowBuffer m_hair_depth_map;  // the hair's own depth map of the light being composed
  HairBlender m_hair_blender;
  std::vector<float> m_hair_rgba, m_hair_depth;
  CpuResolve m_resolve;  // its resolve tables
  std::unique_ptr<EglContext> m_egl;
  std::string m_description;
  std::map<int, GLuint> m_mesh_progs;
  GLuint m_line_prog = 0, m_ribbon_prog = 0, m_depth_prog = 0, m_particle_prog = 0,
         m_resolve_prog = 0;
  GLuint m_empty_vao = 0, m_quad_vbo = 0;
  GLuint m_fbo = 0, m_color_tex = 0, m_depth_rb = 0, m_out_fbo = 0, m_out_rb = 0;
  GLuint m_shadow_fbo = 0, m_shadow_tex = 0;
  int m_fb_w = 0, m_fb_h = 0, m_out_w = 0, m_out_h = 0, m_shadow_size = 0;
  float m_line_width_range[2] = {1, 1};
  std::map<const void*, TexEntry> m_tex_cache;
  std::map<const void*, MeshEntry> m_mesh_cache;
  std::unique_ptr<SplatPassGl> m_splat;
};

}  // namespace

std::unique_ptr<Renderer> Renderer::create_headless(const Context& ctx) {
  auto egl = EglContext::create();
  return std::make_unique<GlRenderer>(ctx, std::move(egl));
}

std::unique_ptr<Renderer> Renderer::create_with_current_context(const Context& ctx) {
  return std::make_unique<GlRenderer>(ctx, nullptr);
}

}  // namespace follicle::render
