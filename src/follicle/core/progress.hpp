#pragma once
// A terminal progress bar for long work. It draws only when stderr is a terminal and CI is not
// set, so logs in CI stay clean. Thread-safe tick().
#include <atomic>
#include <chrono>
#include <cstddef>
#include <mutex>
#include <string>

namespace follicle {

class Progress {
 public:
  Progress(std::string label, std::size_t total, bool enabled = true);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  void tick(std::size_t n = 1);
  void finish();
  /// True when a bar would be drawn (stderr is a TTY and $CI is unset).
  static bool terminal_attached();

 private:
  void draw(bool final);
  std::string m_label;
  std::size_t m_total;
  std::atomic<std::size_t> m_done{0};
  bool m_enabled;
  bool m_finished = false;
  std::chrono::steady_clock::time_point m_start;
  std::chrono::steady_clock::time_point m_last_draw;
  std::mutex m_mutex;
};

}  // namespace follicle
