#include "viewer_app.hpp"

#define GLFW_INCLUDE_GLCOREARB
#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <fmt/format.h>
#include <imgui.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "follicle/core/atomic_file.hpp"
#include "follicle/core/context.hpp"
#include "follicle/core/error.hpp"
#include "follicle/core/log.hpp"
#include "follicle/image/image_io.hpp"
#include "follicle/render/preview_scene.hpp"
#include "follicle/render/renderer.hpp"
#include "follicle/scene/session.hpp"
#include "orbit_camera.hpp"
#include "param_editor.hpp"

namespace follicle::viewer {

namespace {

constexpr float kPanelWidth = 400.0f;  // [screen coordinates], on the right of the window
constexpr double kPlaybackFps = 30.0;
constexpr double kPollSeconds = 0.5;  // scene file mtime poll interval

/// Frames in the scene's animation (1 = static). Scene files have no animation section yet;
/// when one is added, return its frame count here and the frame slider, Space and Left/Right
/// come alive (Session::render_scene(frame) already takes the frame).
bool same_camera(const scene::CameraSpec& a, const scene::CameraSpec& b) {
  return a.eye == b.eye && a.target == b.target && a.up == b.up && a.fov_deg == b.fov_deg &&
         a.near == b.near && a.far == b.far;
}

/// Bounding box of everything drawn, in world coordinates.
Eigen::AlignedBox3d scene_bounds(const render::RenderScene& rs) {
  Eigen::AlignedBox3d box;
  box.setEmpty();
  for (const auto& m : rs.meshes)
    if (m.mesh)
      for (const auto& p : m.mesh->positions) box.extend(m.transform * p);
  return box;
}

/// Reads the bound read framebuffer (w x h from (0, 0)) into a top-row-first image.
image::ImageRGBA8 read_pixels(int w, int h, bool opaque) {
  image::ImageRGBA8 img(w, h);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, img.data());
  const std::size_t row = std::size_t(w) * 4;
  std::vector<uint8_t> tmp(row);
  for (int y = 0; y < h / 2; ++y) {
    uint8_t* a = img.data() + std::size_t(y) * row;
    uint8_t* b = img.data() + std::size_t(h - 1 - y) * row;
    std::copy(a, a + row, tmp.data());
    std::copy(b, b + row, a);
    std::copy(tmp.data(), tmp.data() + row, b);
  }
  if (opaque)
    for (std::size_t i = 3; i < img.storage().size(); i += 4) img.storage()[i] = 255;
  return img;
}

/// "hair[0].style.length" -> the JSON pointer "/hair/0/style/length".
std::string json_pointer_of(const std::string& path) {
  std::string ptr, tok;
  auto flush = [&] {
    if (tok.empty()) fail("--set: empty key in the path '{}'", path);
    std::string esc;
    for (char c : tok)
      esc += c == '~' ? std::string("~0") : c == '/' ? std::string("~1") : std::string(1, c);
    ptr += "/" + esc;
    tok.clear();
  };
  for (std::size_t i = 0; i < path.size(); ++i) {
    const char c = path[i];
    if (c == '.') {
      flush();
    } else if (c == '[') {
      if (!tok.empty()) flush();
      const std::size_t j = path.find(']', i);
      const std::string idx = j == std::string::npos ? "" : path.substr(i + 1, j - i - 1);
      if (idx.empty() || idx.find_first_not_of("0123456789") != std::string::npos)
        fail("--set: expected an index [N] in the path '{}'", path);
      ptr += "/" + idx;
      i = j;
      if (i + 1 < path.size() && path[i + 1] == '.') ++i;
    } else {
      tok += c;
    }
  }
  if (!tok.empty()) flush();
  if (ptr.empty()) fail("--set: empty path");
  return ptr;
}

/// Applies "PATH=VALUE" to a scene's JSON: VALUE is JSON (0.5, true, [1, 2, 3], "text"), or a
/// string when it does not parse as JSON. The section the key belongs to must exist; whether
/// the key and the value are valid is for the scene reader to say (with the JSON path).
void apply_set(scene::Json& j, const std::string& assignment) {
  const std::size_t eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    fail("--set: expected PATH=VALUE (e.g. hair[0].density_scale=0.5), got '{}'", assignment);
  const std::string path = assignment.substr(0, eq), text = assignment.substr(eq + 1);
  scene::Json v;
  try {
    v = scene::Json::parse(text);
  } catch (const std::exception&) {
    v = text;
  }
  const scene::Json::json_pointer ptr(json_pointer_of(path));
  if (!j.contains(ptr.parent_pointer()))
    fail_at(path, "the scene has no '{}' to set a value in",
            ptr.parent_pointer().to_string().empty() ? std::string("/")
                                                     : ptr.parent_pointer().to_string());
  const scene::Json& parent = j.at(ptr.parent_pointer());
  if (parent.is_array() && !j.contains(ptr))
    fail_at(path, "index out of range: the list has {} entries", parent.size());
  j[ptr] = v;
}

/// Rewrites every relative string of j that names an existing file under `from` so that it
/// names the same file from `to` (a scene saved into another folder keeps its assets).
void rebase_paths(scene::Json& j, const std::filesystem::path& from,
                  const std::filesystem::path& to) {
  namespace fs = std::filesystem;
  if (j.is_object() || j.is_array()) {
    for (auto& e : j) rebase_paths(e, from, to);
  } else if (j.is_string()) {
    const std::string s = j.get<std::string>();
    if (s.empty() || fs::path(s).is_absolute()) return;
    std::error_code ec;
    const fs::path file = from / s;
    if (!fs::is_regular_file(file, ec)) return;
    const fs::path a = fs::weakly_canonical(file), b = fs::weakly_canonical(to);
    // Relative when the two share a folder below the root, else absolute.
    auto ai = a.begin(), bi = b.begin();
    int common = 0;
    for (; ai != a.end() && bi != b.end() && *ai == *bi; ++ai, ++bi) ++common;
    j = (common > 1 ? fs::relative(a, b) : a).generic_string();
  }
}

double now_seconds() {
  using clock = std::chrono::steady_clock;
  return std::chrono::duration<double>(clock::now().time_since_epoch()).count();
}

/// A key press (or auto-repeat) with its modifiers, as GLFW reported it.
struct KeyPress {
  int key;
  int mods;
  bool repeat;
};

/// GLFW needs process-wide init/terminate; this owns it and the window for one run.
/// Key presses are queued by our own callback (installed before ImGui's, which chains it):
/// ImGui 1.86 keeps only a per-frame "key down" state, so a press and release between two
/// frames (xdotool, fast typing while a frame renders) would otherwise be lost, and Shift
/// could be released before the frame sees "S".
struct GlfwWindow {
  GLFWwindow* window = nullptr;
  std::vector<KeyPress> keys;
  GlfwWindow(int w, int h, const std::string& title, bool visible) {
    glfwSetErrorCallback([](int code, const char* msg) {
      fmt::print(stderr, "follicle-viewer: GLFW error {}: {}\n", code, msg);
    });
    if (!glfwInit())
      fail("cannot initialise GLFW (no display? set DISPLAY, or run under xvfb-run)");
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfwWindowHint(GLFW_VISIBLE, visible ? GLFW_TRUE : GLFW_FALSE);
    window = glfwCreateWindow(w, h, title.c_str(), nullptr, nullptr);
    if (!window) {
      glfwTerminate();
      fail("cannot create a {}x{} window with an OpenGL 3.3 core context", w, h);
    }
    glfwMakeContextCurrent(window);
    glfwSetWindowUserPointer(window, this);
    glfwSetKeyCallback(window, [](GLFWwindow* win, int key, int, int action, int mods) {
      auto* self = static_cast<GlfwWindow*>(glfwGetWindowUserPointer(win));
      if (self && action != GLFW_RELEASE) self->keys.push_back({key, mods, action == GLFW_REPEAT});
    });
  }
  ~GlfwWindow() {
    glfwDestroyWindow(window);
    glfwTerminate();
  }
  GlfwWindow(const GlfwWindow&) = delete;
  GlfwWindow& operator=(const GlfwWindow&) = delete;
};

struct ImGuiBackend {
  explicit ImGuiBackend(GLFWwindow* w) {
    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGuiIO& io = ImGui::GetIO();
    io.IniFilename = nullptr;  // no imgui.ini in the user's working directory
    const char* font = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
    if (std::filesystem::exists(font)) io.Fonts->AddFontFromFileTTF(font, 15.0f);
    ImGui::StyleColorsDark();
    ImGui::GetStyle().WindowRounding = 0.0f;
    ImGui_ImplGlfw_InitForOpenGL(w, true);
    ImGui_ImplOpenGL3_Init("#version 330 core");
  }
  ~ImGuiBackend() {
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
  }
  ImGuiBackend(const ImGuiBackend&) = delete;
  ImGuiBackend& operator=(const ImGuiBackend&) = delete;
};

/// An extra parameter panel in the side bar: a title and a draw function returning "changed".
/// Hair and skin panels go here, e.g. add_panel("Hair: Anjyo 1992", [&] { return
/// edit_params(params); }).
struct Panel {
  std::string title;
  std::function<bool()> draw;
};

enum class Shot { None, View, Window };

class Viewer {
 public:
  explicit Viewer(const ViewerOptions& opt)
      : m_opt(opt),
        m_ctx(opt.threads, 1),
        m_window(opt.width, opt.height, "Follicle viewer - " + opt.scene.filename().string(), true),
        m_imgui(m_window.window) {
    m_renderer = render::Renderer::create_with_current_context(m_ctx);
    m_device = m_renderer->device_description();
    glfwSwapInterval(batch() ? 0 : 1);
    glGenFramebuffers(1, &m_fbo);
    glGenRenderbuffers(1, &m_rb);
    load(true);
  }
  ~Viewer() {
    m_renderer.reset();  // GL objects go while the context is still current
    glDeleteRenderbuffers(1, &m_rb);
    glDeleteFramebuffers(1, &m_fbo);
  }
  Viewer(const Viewer&) = delete;
  Viewer& operator=(const Viewer&) = delete;

  /// Hook for future parameter panels (hair groups, skin layers).
  void add_panel(std::string title, std::function<bool()> draw) {
    m_panels.push_back({std::move(title), std::move(draw)});
  }

  int run() {
    int drawn = 0;
    while (!glfwWindowShouldClose(m_window.window)) {
      // Sleep until input (or the next file poll) when nothing changes; ImGui gets a few frames
      // after each input to settle hover/click states.
      const bool busy = batch() || m_dirty || m_refine || m_playing || m_idle_frames < 4;
      if (busy)
        glfwPollEvents();
      else
        glfwWaitEventsTimeout(kPollSeconds);
      poll_scene_file();

      ImGui_ImplOpenGL3_NewFrame();
      ImGui_ImplGlfw_NewFrame();
      ImGui::NewFrame();
      handle_input();
      advance_playback();
      draw_panel();
      ImGui::Render();

      render_view();
      present_view();
      ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());

      ++drawn;
      if (batch() && drawn >= std::max(1, m_opt.frames)) {
        if (!m_session || !m_has_image) {
          fmt::print(stderr, "follicle-viewer: {}\n",
                     m_error.empty() ? "nothing was rendered" : m_error);
          return 1;
        }
        if (!m_opt.save.empty()) save_scene(m_opt.save);
        take_screenshot(m_opt.screenshot_ui ? Shot::Window : Shot::View, m_opt.screenshot);
        if (!m_error.empty()) {
          fmt::print(stderr, "follicle-viewer: {}\n", m_error);
          return 1;
        }
        fmt::print("wrote {}\n", m_opt.screenshot.string());
        return 0;
      }
      if (m_shot != Shot::None) {
        take_screenshot(m_shot, next_screenshot_path());
        m_shot = Shot::None;
      }
      glfwSwapBuffers(m_window.window);
    }
    return 0;
  }

 private:
  bool batch() const { return !m_opt.screenshot.empty(); }

  // ---- scene file ----------------------------------------------------------------------------

  void load(bool initial) {
    std::error_code ec;
    m_mtime = std::filesystem::last_write_time(m_opt.scene, ec);
    try {
      auto s = scene::Session::load(m_opt.scene, m_ctx);
      s.load_all_assets();  // malformed meshes/textures fail here, not mid-frame
      const bool camera_changed =
          !m_session || !same_camera(m_session->scene().camera, s.scene().camera);
      m_session.emplace(std::move(s));
      m_error.clear();
      m_frame_count = std::max(1, m_session->frame_count());
      if (initial) m_frame = m_opt.frame;
      m_frame = std::clamp(m_frame, 0, m_frame_count - 1);
      if (m_frame_count <= 1) m_playing = false;
      if (initial && m_opt.frame >= m_frame_count)
        m_error = fmt::format("--frame {}: the scene has {} frame(s), 0 to {}", m_opt.frame,
                              m_frame_count, m_frame_count - 1);
      m_file_camera = m_session->render_scene(0).camera;
      if (initial || camera_changed) m_orbit.set_from(m_file_camera);
      m_edit = m_session->scene();
      m_edit_pending = false;
      m_dirty = true;
      if (!initial) m_status = "reloaded " + m_opt.scene.filename().string();
    } catch (const std::exception& e) {
      // Keep showing the last good scene; the panel shows why the new one did not load.
      m_error = e.what();
      m_ctx.log().warn("{}", m_error);
    }
    if (initial && m_session && !m_opt.sets.empty() && m_error.empty()) {
      try {
        scene::Json j = scene::write_scene(m_session->scene());
        for (const auto& a : m_opt.sets) apply_set(j, a);
        if (rebuild(j)) m_status = fmt::format("{} edit(s) applied", m_opt.sets.size());
      } catch (const std::exception& e) {
        m_error = e.what();
      }
    }
  }

  /// A new session from the edited scene's JSON, through the same reader as the scene file (so
  /// an error names the JSON path); the last good session stays when it fails. The camera stays.
  bool rebuild(const scene::Json& j) {
    try {
      auto s = scene::Session::from_json(j, m_opt.scene.parent_path(),
                                         m_opt.scene.filename().string(), m_ctx);
      s.load_all_assets();
      m_session.emplace(std::move(s));
      m_frame_count = std::max(1, m_session->frame_count());
      m_frame = std::clamp(m_frame, 0, m_frame_count - 1);
      if (m_frame_count <= 1) m_playing = false;
      m_edit = m_session->scene();
      m_error.clear();
      m_dirty = true;
      return true;
    } catch (const std::exception& e) {
      m_error = e.what();
      m_ctx.log().warn("{}", m_error);
      return false;
    }
  }

  /// Writes the scene as it is now (with every edit) to `path`; asset paths are made relative
  /// to the new file's folder. `follicle validate` accepts it and `follicle render` draws the
  /// view (tests/integration/viewer_edit_save.sh).
  bool save_scene(const std::filesystem::path& path) {
    namespace fs = std::filesystem;
    try {
      if (!m_session) fail("no scene loaded");
      scene::Json j = scene::write_scene(m_session->scene());
      const fs::path from = fs::absolute(m_opt.scene).parent_path();
      const fs::path to = fs::absolute(path).parent_path();
      // Output files stay relative to the scene (they are written next to it).
      if (fs::weakly_canonical(from) != fs::weakly_canonical(to))
        for (auto& [key, section] : j.items())
          if (key != "outputs") rebase_paths(section, from, to);
      write_file_atomically(path, j.dump(2) + "\n");
      if (fs::weakly_canonical(path) == fs::weakly_canonical(m_opt.scene)) {
        std::error_code ec;
        m_mtime = fs::last_write_time(m_opt.scene, ec);  // our own write: no reload
      }
      m_status = "saved " + path.string();
      return true;
    } catch (const std::exception& e) {
      m_error = "save: " + std::string(e.what());
      return false;
    }
  }

  void poll_scene_file() {
    const double t = now_seconds();
    if (t - m_last_poll < kPollSeconds) return;
    m_last_poll = t;
    std::error_code ec;
    const auto mtime = std::filesystem::last_write_time(m_opt.scene, ec);
    if (!ec && mtime != m_mtime) load(false);
  }

  /// Applies an edit made through the panel; an invalid edit is undone and reported.
  void commit_edit(const scene::Scene& before) {
    try {
      m_session->validate();
      m_dirty = true;
    } catch (const std::exception& e) {
      m_session->scene() = before;
      m_error = e.what();
    }
  }

  // ---- input ---------------------------------------------------------------------------------

  void handle_input() {
    ImGuiIO& io = ImGui::GetIO();
    const bool any_input =
        io.MouseDelta.x != 0 || io.MouseDelta.y != 0 || io.MouseWheel != 0 ||
        ImGui::IsAnyMouseDown() || !io.InputQueueCharacters.empty() ||
        std::any_of(std::begin(io.KeysDown), std::end(io.KeysDown), [](bool k) { return k; });
    m_idle_frames = any_input ? 0 : m_idle_frames + 1;
    m_moving = false;
    const float view_w = io.DisplaySize.x - kPanelWidth;
    if (!io.WantCaptureMouse && m_session) {
      const ImVec2 d = io.MouseDelta;
      const bool pan = ImGui::IsMouseDown(ImGuiMouseButton_Right) ||
                       ImGui::IsMouseDown(ImGuiMouseButton_Middle) ||
                       (ImGui::IsMouseDown(ImGuiMouseButton_Left) && io.KeyShift);
      if ((d.x != 0 || d.y != 0) && pan) {
        m_orbit.pan(d.x, d.y, io.DisplaySize.y);
        m_moving = true;
      } else if ((d.x != 0 || d.y != 0) && ImGui::IsMouseDown(ImGuiMouseButton_Left)) {
        m_orbit.orbit(d.x, d.y);
        m_moving = true;
      }
      if (io.MouseWheel != 0 && io.MousePos.x < view_w) {
        m_orbit.zoom(io.MouseWheel);
        m_moving = true;
      }
    }
    std::vector<KeyPress> keys;
    keys.swap(m_window.keys);
    if (!keys.empty()) m_idle_frames = 0;
    if (io.WantCaptureKeyboard) keys.clear();  // typing into a panel field
    for (const KeyPress& k : keys) {
      if (k.repeat && k.key != GLFW_KEY_LEFT && k.key != GLFW_KEY_RIGHT) continue;
      switch (k.key) {
        case GLFW_KEY_R: reset_camera(); break;
        case GLFW_KEY_F: frame_all(); break;
        case GLFW_KEY_S: m_shot = (k.mods & GLFW_MOD_SHIFT) ? Shot::Window : Shot::View; break;
        case GLFW_KEY_SPACE: toggle_play(); break;
        case GLFW_KEY_LEFT: step_frame(-1); break;
        case GLFW_KEY_RIGHT: step_frame(+1); break;
        case GLFW_KEY_ESCAPE: glfwSetWindowShouldClose(m_window.window, GLFW_TRUE); break;
        default: break;
      }
    }
    if (m_moving) m_dirty = true;
  }

  void reset_camera() {
    if (!m_session) return;
    m_orbit.set_from(m_file_camera);
    m_dirty = true;
  }

  void frame_all() {
    if (!m_session) return;
    try {
      const auto box = scene_bounds(m_session->render_scene(m_frame));
      if (box.isEmpty()) {
        m_status = "nothing to frame";
        return;
      }
      m_orbit.frame(box);
      m_dirty = true;
    } catch (const std::exception& e) {
      m_error = e.what();
    }
  }

  void toggle_play() {
    if (m_frame_count > 1) m_playing = !m_playing;
  }
  void step_frame(int d) {
    if (m_frame_count <= 1) return;
    m_playing = false;
    m_frame = (m_frame + d + m_frame_count) % m_frame_count;
    m_dirty = true;
  }
  void advance_playback() {
    if (!m_playing) {
      m_play_time = 0;
      return;
    }
    m_play_time += ImGui::GetIO().DeltaTime;
    const int steps = int(m_play_time * kPlaybackFps);
    if (steps > 0) {
      m_play_time -= steps / kPlaybackFps;
      m_frame = (m_frame + steps) % m_frame_count;
      m_dirty = true;
    }
  }

  // ---- rendering -----------------------------------------------------------------------------

  /// Renders the 3D view into m_fbo when something changed (llvmpipe is slow; an idle viewer
  /// only blits). While the camera moves it renders without supersampling, then refines.
  void render_view() {
    int fb_w = 0, fb_h = 0, win_w = 0, win_h = 0;
    glfwGetFramebufferSize(m_window.window, &fb_w, &fb_h);
    glfwGetWindowSize(m_window.window, &win_w, &win_h);
    const double scale = win_w > 0 ? double(fb_w) / win_w : 1.0;
    const int vw = std::max(1, fb_w - int(std::lround(kPanelWidth * scale)));
    const int vh = std::max(1, fb_h);
    if (vw != m_view_w || vh != m_view_h) {
      m_view_w = vw;
      m_view_h = vh;
      glBindRenderbuffer(GL_RENDERBUFFER, m_rb);
      glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, vw, vh);
      glBindFramebuffer(GL_FRAMEBUFFER, m_fbo);
      glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, m_rb);
      glBindFramebuffer(GL_FRAMEBUFFER, 0);
      m_has_image = false;
      m_dirty = true;
    }
    if (!m_session || !(m_dirty || (m_refine && !m_moving))) return;
    const bool fast = (m_moving && m_fast_preview && !batch()) || m_opt.preview;
    try {
      auto rs = m_session->render_scene(m_frame);
      rs.camera = m_orbit.camera();
      auto settings = m_session->render_settings();
      settings.width = vw;
      settings.height = vh;
      // While the camera moves: a smaller image, fewer strands and particles (drawn wider), no
      // supersampling (render::PreviewReducer); the full view follows when it stops.
      if (fast) m_preview.reduce(rs, settings, m_preview_params);
      m_last_settings = settings;
      m_img_w = settings.width;
      m_img_h = settings.height;
      const double t0 = now_seconds();
      m_renderer->render_to_framebuffer(rs, settings, m_fbo);
      glFinish();  // so the time below is the real render time
      m_render_ms = 1000.0 * (now_seconds() - t0);
      m_has_image = true;
      m_refine = fast && m_session->render_settings().supersample > 1;
    } catch (const std::exception& e) {
      m_error = e.what();
      m_refine = false;
    }
    m_dirty = false;
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
  }

  void present_view() {
    int fb_w = 0, fb_h = 0;
    glfwGetFramebufferSize(m_window.window, &fb_w, &fb_h);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, fb_w, fb_h);
    // The renderer's output is sRGB-encoded; clear the margin (before the first image) to match.
    const Vec3 bg = m_session ? m_session->scene().render.background : Vec3(0.01, 0.01, 0.01);
    const auto srgb = [](double c) {
      c = std::clamp(c, 0.0, 1.0);
      return float(c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1 / 2.4) - 0.055);
    };
    glClearColor(srgb(bg.x()), srgb(bg.y()), srgb(bg.z()), 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    if (m_has_image) {
      glBindFramebuffer(GL_READ_FRAMEBUFFER, m_fbo);
      const bool scaled = m_img_w != m_view_w || m_img_h != m_view_h;
      glBlitFramebuffer(0, 0, m_img_w, m_img_h, 0, 0, m_view_w, m_view_h, GL_COLOR_BUFFER_BIT,
                        scaled ? GL_LINEAR : GL_NEAREST);
      glBindFramebuffer(GL_FRAMEBUFFER, 0);
    }
  }

  std::filesystem::path next_screenshot_path() const {
    const std::string stem = m_opt.scene.stem().string();
    for (int i = 1;; ++i) {
      std::filesystem::path p = fmt::format("{}-{:03d}.png", stem, i);
      if (!std::filesystem::exists(p)) return p;
    }
  }

  /// View: the 3D view as rendered. Window: the back buffer with the panel. The PNG writer is
  /// atomic (temporary file + rename).
  void take_screenshot(Shot kind, const std::filesystem::path& path) {
    try {
      image::ImageRGBA8 img;
      if (kind == Shot::View) {
        if (!m_has_image) fail("no image rendered yet");
        glBindFramebuffer(GL_READ_FRAMEBUFFER, m_fbo);
        img = read_pixels(m_img_w, m_img_h, true);
      } else {
        int fb_w = 0, fb_h = 0;
        glfwGetFramebufferSize(m_window.window, &fb_w, &fb_h);
        glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
        glReadBuffer(GL_BACK);
        img = read_pixels(fb_w, fb_h, true);
      }
      glBindFramebuffer(GL_FRAMEBUFFER, 0);
      image::write_png(path, img);
      m_status = fmt::format("saved {} ({}x{})", path.string(), img.width(), img.height());
    } catch (const std::exception& e) {
      m_error = "screenshot: " + std::string(e.what());
    }
  }

  // ---- panel ---------------------------------------------------------------------------------

  void draw_panel() {
    ImGuiIO& io = ImGui::GetIO();
    ImGui::SetNextWindowPos(ImVec2(io.DisplaySize.x - kPanelWidth, 0));
    ImGui::SetNextWindowSize(ImVec2(kPanelWidth, io.DisplaySize.y));
    ImGui::Begin("Follicle", nullptr,
                 ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse |
                     ImGuiWindowFlags_NoSavedSettings);
    ImGui::PushItemWidth(-150.0f);  // room for the labels

    ImGui::TextDisabled("Scene");
    ImGui::TextWrapped("%s", m_opt.scene.string().c_str());
    if (m_session && !m_session->scene().description.empty())
      ImGui::TextWrapped("%s", m_session->scene().description.c_str());
    if (!m_error.empty()) {
      ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.0f, 0.45f, 0.4f, 1.0f));
      ImGui::TextWrapped("Error: %s", m_error.c_str());
      ImGui::PopStyleColor();
      if (ImGui::SmallButton("Dismiss")) m_error.clear();
    }
    if (ImGui::Button("Reload")) load(false);
    ImGui::SameLine();
    if (ImGui::Button("Reset (R)")) reset_camera();
    ImGui::SameLine();
    if (ImGui::Button("Frame (F)")) frame_all();
    ImGui::SameLine();
    if (ImGui::Button("Save PNG (S)")) m_shot = Shot::View;
    if (ImGui::Button("Save scene")) save_scene(m_opt.scene);
    if (ImGui::IsItemHovered())
      ImGui::SetTooltip("write every edit into %s", m_opt.scene.string().c_str());
    ImGui::SameLine();
    if (ImGui::Button("Save copy")) {
      const auto copy = m_opt.scene.parent_path() / (m_opt.scene.stem().string() + "-edited.json");
      save_scene(copy);
    }
    if (!m_status.empty()) ImGui::TextDisabled("%s", m_status.c_str());

    ImGui::Separator();
    ImGui::TextWrapped("Device: %s", m_device.c_str());
    ImGui::Text("Render: %.1f ms (%.1f fps) at %dx%d, x%d", m_render_ms,
                m_render_ms > 0 ? 1000.0 / m_render_ms : 0.0, m_last_settings.width,
                m_last_settings.height, m_last_settings.supersample);
    ImGui::Text("UI: %.0f fps", io.Framerate);

    if (m_session) {
      draw_camera_panel();
      draw_lights_panel();
      draw_render_panel();
      draw_animation_panel();
      draw_contents_panel();
      for (auto& p : m_panels)
        if (ImGui::CollapsingHeader(p.title.c_str()) && p.draw()) m_dirty = true;
    }
    if (ImGui::CollapsingHeader("Controls")) {
      ImGui::BulletText("Left drag: orbit   Right/Middle or Shift+Left drag: pan");
      ImGui::BulletText("Wheel: zoom   R: reset camera   F: frame all");
      ImGui::BulletText("S: save view PNG   Shift+S: save window PNG");
      ImGui::BulletText("Space: play/pause   Left/Right: step frame   Esc: quit");
      ImGui::BulletText("Save scene writes every edit; the file is reloaded when it changes.");
    }
    ImGui::PopItemWidth();
    ImGui::End();
  }

  void draw_camera_panel() {
    if (!ImGui::CollapsingHeader("Camera", ImGuiTreeNodeFlags_DefaultOpen)) return;
    const Vec3 e = m_orbit.eye(), t = m_orbit.target();
    ImGui::Text("eye    %7.3f %7.3f %7.3f m", e.x(), e.y(), e.z());
    ImGui::Text("target %7.3f %7.3f %7.3f m", t.x(), t.y(), t.z());
    ImGui::Text("distance %.3f m  yaw %.1f deg  pitch %.1f deg", m_orbit.distance(),
                m_orbit.yaw() * 180.0 / kPi, m_orbit.pitch() * 180.0 / kPi);
    if (ImGui::TreeNode("Edit camera")) {
      render::Camera cam = m_orbit.camera();
      if (edit_params(cam)) {
        try {
          cam.validate();
          m_orbit.set_from(cam);
          m_dirty = true;
        } catch (const std::exception& ex) {
          m_status = ex.what();
        }
      }
      ImGui::TreePop();
    }
  }

  void draw_lights_panel() {
    if (!ImGui::CollapsingHeader("Lights", ImGuiTreeNodeFlags_DefaultOpen)) return;
    auto& lights = m_session->scene().lights;
    if (lights.empty()) ImGui::TextDisabled("no lights (ambient only)");
    for (std::size_t i = 0; i < lights.size(); ++i) {
      ImGui::PushID(int(i));
      const std::string label =
          lights[i].name.empty() ? fmt::format("light {}", i) : lights[i].name;
      const auto before = m_session->scene();
      auto& l = lights[i];
      bool ch = false;
      if (ImGui::TreeNodeEx("light", ImGuiTreeNodeFlags_DefaultOpen, "%s", label.c_str())) {
        ch = edit_params(l, {"name"});
        ImGui::TreePop();
      }
      if (ch) commit_edit(before);
      ImGui::PopID();
    }
  }

  void draw_render_panel() {
    if (!ImGui::CollapsingHeader("Render settings", ImGuiTreeNodeFlags_DefaultOpen)) return;
    const auto before = m_session->scene();
    // The window decides the size; the rest comes from the scene's "render" section.
    if (edit_params(m_session->scene().render, {"width", "height"})) commit_edit(before);
    ImGui::Checkbox("fast preview while moving", &m_fast_preview);
    if (ImGui::IsItemHovered())
      ImGui::SetTooltip(
          "while the camera moves: a smaller image, fewer strands, no supersampling; the full "
          "view follows when it stops");
    if (m_fast_preview && ImGui::TreeNode("preview while moving")) {
      {
        render::PreviewParams p = m_preview_params;
        if (edit_params(p)) {
          try {
            p.validate();
            m_preview_params = p;
          } catch (const std::exception& e) {
            m_error = e.what();
          }
        }
      }
      ImGui::TreePop();
    }
  }

  /// Everything else the scene file holds (hair groups and their models, skin rigs with
  /// expressions and wrinkles, the hand, the LCP hair, the animation), edited through the same
  /// visit() descriptions that parse the JSON. A change is applied when the widget is let go
  /// (a slider drag re-styles or re-simulates once, not every frame): the scene is rebuilt
  /// through the scene reader, and an invalid value is undone and reported with its JSON path.
  void draw_contents_panel() {
    if (ImGui::CollapsingHeader("Scene contents")) {
      if (edit_params(m_edit, {"follicle_scene", "description", "assets", "camera", "lights",
                               "render", "outputs"}))
        m_edit_pending = true;
    }
    if (m_edit_pending && !ImGui::IsAnyItemActive()) {
      m_edit_pending = false;
      scene::Scene next = m_session->scene();  // lights and render settings as edited above
      next.hair = m_edit.hair;
      next.animation = m_edit.animation;
      next.skin = m_edit.skin;
      next.hand = m_edit.hand;
      next.lcp = m_edit.lcp;
      try {
        if (!rebuild(scene::write_scene(next))) m_edit = m_session->scene();
      } catch (const std::exception& e) {
        m_error = e.what();
        m_edit = m_session->scene();
      }
    }
  }

  void draw_animation_panel() {
    if (m_frame_count <= 1) return;
    if (!ImGui::CollapsingHeader("Animation", ImGuiTreeNodeFlags_DefaultOpen)) return;
    if (ImGui::Button(m_playing ? "Pause" : "Play")) toggle_play();
    ImGui::SameLine();
    if (ImGui::SliderInt("frame", &m_frame, 0, m_frame_count - 1)) {
      m_playing = false;
      m_dirty = true;
    }
  }

  ViewerOptions m_opt;
  Context m_ctx;
  GlfwWindow m_window;
  ImGuiBackend m_imgui;
  std::unique_ptr<render::Renderer> m_renderer;
  std::string m_device;
  std::optional<scene::Session> m_session;
  scene::Scene m_edit;  // the panel's working copy of the scene contents
  bool m_edit_pending = false;
  std::string m_error;   // last load/edit/render error, shown in red
  std::string m_status;  // last action (screenshot saved, reloaded)
  std::filesystem::file_time_type m_mtime{};
  double m_last_poll = 0;
  render::Camera m_file_camera;
  OrbitCamera m_orbit;
  std::vector<Panel> m_panels;
  int m_frame = 0, m_frame_count = 1;
  bool m_playing = false;
  double m_play_time = 0;
  bool m_dirty = true, m_refine = false, m_moving = false, m_fast_preview = true;
  int m_idle_frames = 0;
  unsigned m_fbo = 0, m_rb = 0;
  int m_view_w = 0, m_view_h = 0;
  int m_img_w = 0, m_img_h = 0;  // size of the last image in m_fbo (smaller while moving)
  render::PreviewReducer m_preview;
  render::PreviewParams m_preview_params;
  bool m_has_image = false;
  double m_render_ms = 0;
  render::RenderSettings m_last_settings;
  Shot m_shot = Shot::None;
};

}  // namespace

int run_viewer(const ViewerOptions& opt) {
  Viewer v(opt);
  return v.run();
}

}  // namespace follicle::viewer
