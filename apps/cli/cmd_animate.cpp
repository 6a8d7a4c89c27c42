// follicle animate SCENE --frames A-B -o DIR [--mp4 FILE] [--cache DIR] [--no-video]: renders
// frames A..B to DIR/frame_0000.png ... (the number is the frame number) and encodes them to an
// MP4 with the ffmpeg command-line tool (libx264, yuv420p). With --cache, simulated strands are
// kept per frame, so running again re-renders without re-simulating.
#include <fmt/format.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "commands.hpp"
#include "follicle/core/atomic_file.hpp"
#include "follicle/core/interrupt.hpp"
#include "follicle/core/log.hpp"
#include "follicle/core/progress.hpp"
#include "follicle/image/image_io.hpp"
#include "follicle/render/renderer.hpp"
#include "follicle/scene/session.hpp"

namespace follicle::cli {

namespace {

// The ffmpeg executable on PATH, or "".
std::string find_ffmpeg() {
  const char* path = std::getenv("PATH");
  if (!path) return "";
  std::stringstream ss(path);
  std::string dir;
  while (std::getline(ss, dir, ':')) {
    if (dir.empty()) continue;
    const auto p = std::filesystem::path(dir) / "ffmpeg";
    if (::access(p.c_str(), X_OK) == 0) return p.string();
  }
  return "";
}

// Runs argv without a shell; returns the exit status (127 when it cannot start).
int run_process(const std::vector<std::string>& args) {
  const pid_t pid = ::fork();
  if (pid < 0) return 127;
  if (pid == 0) {
    std::vector<char*> argv;
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  const InterruptCleanupChild stop_on_interrupt(pid);  // SIGINT / SIGTERM stop it first
  int status = 0;
  if (::waitpid(pid, &status, 0) < 0) return 127;
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
}

}  // namespace

int run_animate(const GlobalOptions& g, const AnimateArgs& a) {
  auto ctx = make_context(g);
  if (a.output_dir.empty()) throw UsageError("give the output folder with -o DIR");
  int first = -1, last = -1;
  parse_frames(a.frames, first, last);
  std::string mp4 = a.mp4;
  if (!a.no_video && !mp4.empty()) {
    auto ext = std::filesystem::path(mp4).extension().string();
    for (auto& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (ext != ".mp4") throw UsageError(fmt::format("--mp4 must end in .mp4, got '{}'", mp4));
  }

  auto session = scene::Session::load(a.scene, *ctx);
  if (a.width > 0) session.scene().render.width = a.width;
  if (a.height > 0) session.scene().render.height = a.height;
  session.validate();
  const int count = session.frame_count();
  if (first < 0) {
    first = 0;
    last = count - 1;
  }
  if (last >= count)
    throw UsageError(
        fmt::format("--frames {}-{}: the scene has frames 0-{}", first, last, count - 1));
  std::string ffmpeg;
  if (!a.no_video) {
    ffmpeg = find_ffmpeg();
    if (ffmpeg.empty())
      fail(
          "ffmpeg not found on PATH: install it (apt-get install ffmpeg) or pass --no-video to "
          "write only the PNG frames");
    if (mp4.empty())
      mp4 = (std::filesystem::path(a.output_dir) /
             (std::filesystem::path(a.scene).stem().string() + ".mp4"))
                .string();
  }
  if (!a.cache.empty()) session.set_strand_cache(a.cache);
  const std::filesystem::path dir(a.output_dir);
  check_output_folder(dir);  // before the work, not after
  if (!a.no_video) check_output_writable(mp4);

  auto renderer = render::Renderer::create_headless(*ctx);
  ctx->log().info("renderer: {}", renderer->device_description());
  const auto settings = session.render_settings();
  Progress progress("animate", std::size_t(last - first + 1) + (a.no_video ? 0 : 1), !g.quiet);
  for (int f = first; f <= last; ++f) {
    const auto img = renderer->render(session.render_scene(f), settings);
    image::write_png(dir / fmt::format("frame_{:04d}.png", f), img);
    progress.tick();
  }
  if (!a.no_video) {
    const double fps = session.scene().animation ? session.scene().animation->fps : 24.0;
    // Temp file + rename, like every other output; yuv420p needs even sizes (pad by one pixel).
    write_atomically(mp4, [&](const std::filesystem::path& tmp) {
      const int rc = run_process({ffmpeg,
                                  "-nostdin",
                                  "-hide_banner",
                                  "-loglevel",
                                  "error",
                                  "-y",
                                  "-framerate",
                                  fmt::format("{}", fps),
                                  "-start_number",
                                  std::to_string(first),
                                  "-i",
                                  (dir / "frame_%04d.png").string(),
                                  "-frames:v",
                                  std::to_string(last - first + 1),
                                  "-vf",
                                  "pad=ceil(iw/2)*2:ceil(ih/2)*2",
                                  "-c:v",
                                  "libx264",
                                  "-pix_fmt",
                                  "yuv420p",
                                  "-f",
                                  "mp4",
                                  tmp.string()});
      if (rc != 0) fail_at(mp4, "ffmpeg failed (exit status {})", rc);
    });
    progress.tick();
  }
  progress.finish();
  if (!g.quiet) {
    fmt::print("wrote {} frames to {}/frame_{:04d}.png .. frame_{:04d}.png\n", last - first + 1,
               dir.string(), first, last);
    if (!a.no_video) fmt::print("wrote {}\n", mp4);
    const auto& st = session.hair_stats();
    if (!a.cache.empty())
      fmt::print("strand cache {}: {} frames read, {} written, {} dynamics steps\n", a.cache,
                 st.cache_reads, st.cache_writes, st.steps);
  }
  return 0;
}

}  // namespace follicle::cli
