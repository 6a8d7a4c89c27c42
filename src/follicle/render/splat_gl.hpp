#pragma once
// The GL 3.3 hair splat passes of Bando 2003 §3.4 (internal to the render module; used by
// renderer_gl.cpp for ParticleItems with ParticleShading::HairSplat). Per render():
//   prepare()     gathers every HairSplat item into one world-space particle array;
//   light_pass()  pseudo-code lines 6-12 (the renderer's shadow pass did lines 1-5): particles
//                 sorted by depth from the light each read the attenuated light, then are
//                 splatted into the light buffer, which ends as the light map for the meshes.
//                 "cpu" (default): the objects' visibility of all particles in one GL point
//                 draw read back once, then splat_light_bando2003() exactly per particle on
//                 the CPU, uploaded as the light map and the per-particle intensities;
//                 "gpu": in `hair_light_slices` depth slices on the GPU;
//   view_pass()   lines 17-21: back-to-front textured billboards, Kajiya-Kay x Goldman, drawn
//                 with GL ("gpu");
//   view_pass_cpu() the same on the CPU (default "cpu"): the particles shaded per particle as
//                 in kSplatViewVs, the colour and depth of the billboards' screen rectangle read
//                 back, splat_view_bando2003() blends them, the rectangle goes back up.
// See docs/adr/0005-cpu-splat-light-pass.md, docs/adr/0003-splat-light-pass.md and
// docs/adr/0007-cpu-splat-view-pass.md.
#include <GL/gl.h>
#include <GL/glext.h>
#include <tbb/task_arena.h>

#include <Eigen/Geometry>
#include <memory>
#include <vector>

#include "follicle/render/render_scene.hpp"
#include "follicle/render/splat_light_bando2003.hpp"
#include "follicle/render/splat_view_bando2003.hpp"

namespace follicle::render {

class SplatPassGl {
 public:
  static constexpr int kMaxItems = 8;

  SplatPassGl();  // compiles the programs; needs the current GL context
  ~SplatPassGl();
  SplatPassGl(const SplatPassGl&) = delete;
  SplatPassGl& operator=(const SplatPassGl&) = delete;

  /// Validates and collects the HairSplat items of `scene` (throws follicle::Error naming the
  /// item); extends `shadow_box` (when given) by the billboards of the casting particles.
  void prepare(const RenderScene& scene, Eigen::AlignedBox3d* shadow_box);
  bool empty() const { return m_count == 0; }

  struct Light {
    int index = -1;         // light of the light pass (the renderer's shadow light)
    Vec3 travel{0, 0, -1};  // unit direction the light travels
    Mat4 light_vp = Mat4::Identity();
    GLuint shadow_tex = 0;  // objects' depth map (compare mode), over the same light_vp
    double shadow_texel = 0, shadow_bias = 0;
  };
  /// Lines 6-12. Changes the framebuffer binding, viewport, blend state and texture units; the
  /// "cpu" pass runs its threads in `arena`.
  void light_pass(const Light& light, const RenderSettings& settings, GLuint empty_vao,
                  tbb::task_arena& arena);
  /// The light map (R: light transmitted through the hair) of the last light_pass(), 0 if none
  /// was made this frame. Same projection as the shadow map.
  GLuint light_map() const { return m_light_done ? m_light_tex : 0; }

  /// Lines 17-21 into the bound framebuffer (depth test on, depth writes off while drawing).
  void view_pass(const RenderScene& scene, const Mat4& view, const Mat4& view_proj,
                 GLuint empty_vao);
  /// Lines 17-21 on the CPU for the bound framebuffer, whose colour attachment is `color_tex`
  /// (RGBA16F, fb_w x fb_h) with a depth attachment; runs its threads in `arena`. Without
  /// `frame` the billboards' rectangle is read back, drawn and uploaded again; with it the
  /// caller has read the whole colour buffer into *frame (fb_w x fb_h RGBA floats, rows bottom
  /// up), the hair is drawn there and not uploaded (the caller resolves it on the CPU).
  void view_pass_cpu(const RenderScene& scene, const Mat4& view, const Mat4& view_proj,
                     GLuint color_tex, int fb_w, int fb_h, tbb::task_arena& arena,
                     std::vector<float>* frame = nullptr);

 private:
  GLuint hair_texture();
  const SplatAlphaTexture& cpu_hair_texture();
  const SplatColorTexture& cpu_hair_color_texture();
  void light_slices_gpu(const Light& light, std::size_t slices);
  void light_exact_cpu(const Light& light, tbb::task_arena& arena);
  void ensure_intensity(std::size_t n);
  void ensure_light_buffer(int size);
  void bind_common(GLuint prog, int order_base);

  struct Info {
    const ParticleItem* item = nullptr;
    std::size_t first = 0, count = 0;
  };
  std::vector<Info> m_items;
  std::vector<float> m_data;  // 16 floats per particle (see shaders_splat_gl.hpp)
  std::size_t m_count = 0;
  bool m_light_done = false, m_any_cast = false;
  std::shared_ptr<const image::ImageRGBA8> m_custom_tex_src;

  GLuint m_gather_prog = 0, m_light_prog = 0, m_view_prog = 0;
  GLuint m_particle_buf = 0, m_particle_tbo = 0, m_order_buf = 0, m_order_tbo = 0;
  std::size_t m_particle_cap = 0, m_order_cap = 0;
  GLuint m_intensity_tex = 0, m_intensity_fbo = 0;
  int m_intensity_w = 0, m_intensity_h = 0;
  GLuint m_light_tex = 0, m_light_fbo = 0;
  int m_light_size = 0;
  GLuint m_default_tex = 0, m_custom_tex = 0;
  std::weak_ptr<const image::ImageRGBA8> m_custom_owner;
  const void* m_custom_ptr = nullptr;
  int m_max_tbo = 0;
  // The "cpu" light pass: its particles (the light order and the read-back visibility), the
  // hair texture's alpha mip chain, the result and the read-back / upload staging.
  std::vector<LightSplatParticle> m_cpu_particles;
  std::unique_ptr<SplatAlphaTexture> m_cpu_default_tex, m_cpu_custom_tex;
  std::shared_ptr<const image::ImageRGBA8> m_cpu_custom_src;
  SplatLightResult m_cpu_result;
  std::vector<float> m_staging;
  // The "cpu" view pass: the hair texture's RGBA mip chains, the particles and the read-back
  // window.
  std::unique_ptr<SplatColorTexture> m_cpu_default_color, m_cpu_custom_color;
  std::shared_ptr<const image::ImageRGBA8> m_cpu_custom_color_src;
  std::vector<ViewSplatParticle> m_view_particles;
  // (visibility, light through the hair) per particle are in m_staging[2i], m_staging[2i + 1]
  bool m_intensity_on_cpu = false;
  std::vector<float> m_view_rgba, m_view_depth;
};

}  // namespace follicle::render
