#include "follicle/core/progress.hpp"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>

namespace follicle {

bool Progress::terminal_attached() {
  const char* ci = std::getenv("CI");
  if (ci != nullptr && *ci != '\0') return false;
  return isatty(fileno(stderr)) != 0;
}

Progress::Progress(std::string label, std::size_t total, bool enabled)
    : m_label(std::move(label)),
      m_total(total),
      m_enabled(enabled && terminal_attached()),
      m_start(std::chrono::steady_clock::now()),
      m_last_draw(m_start) {}

Progress::~Progress() {
  finish();
}

void Progress::tick(std::size_t n) {
  m_done += n;
  if (!m_enabled) return;
  auto now = std::chrono::steady_clock::now();
  std::lock_guard<std::mutex> lock(m_mutex);
  // Appear only for work that takes over a second; redraw at most 10 times a second.
  if (now - m_start < std::chrono::seconds(1)) return;
  if (now - m_last_draw < std::chrono::milliseconds(100)) return;
  m_last_draw = now;
  draw(false);
}

void Progress::finish() {
  if (m_finished) return;
  m_finished = true;
  if (!m_enabled) return;
  auto now = std::chrono::steady_clock::now();
  if (now - m_start < std::chrono::seconds(1)) return;
  std::lock_guard<std::mutex> lock(m_mutex);
  draw(true);
  std::fputc('\n', stderr);
}

void Progress::draw(bool final) {
  const std::size_t done = final ? m_total : std::min(m_done.load(), m_total);
  const double frac = m_total ? double(done) / double(m_total) : 1.0;
  const int width = 30;
  const int fill = int(frac * width + 0.5);
  const double secs =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - m_start).count();
  const double eta = frac > 0 ? secs / frac - secs : 0.0;
  std::string bar(std::size_t(fill), '#');
  bar.resize(width, '.');
  // \x1b[K clears the rest of the line: a bar drawn inside another (settling inside "render")
  // leaves no tail of the longer one.
  std::fprintf(stderr, "\r%s [%s] %zu/%zu %5.1fs eta %5.1fs\x1b[K", m_label.c_str(), bar.c_str(),
               done, m_total, secs, eta);
  std::fflush(stderr);
}

}  // namespace follicle
