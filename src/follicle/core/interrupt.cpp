#include "follicle/core/interrupt.hpp"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <climits>
#include <cstring>

namespace follicle {

namespace {

// Slot states: free, being filled (not yet visible to the handler), ready.
constexpr int kFree = 0, kFilling = 1, kReady = 2;
constexpr std::size_t kFileSlots = 64, kChildSlots = 8;

struct FileSlot {
  std::atomic<int> state{kFree};
  char path[PATH_MAX] = {};
};

// Process-wide by necessity (see the header): only a static object is reachable from a handler.
// std::atomic<int> and std::atomic<pid_t> are lock-free here, as a handler requires.
FileSlot g_files[kFileSlots];
std::atomic<pid_t> g_children[kChildSlots];
static_assert(std::atomic<int>::is_always_lock_free && std::atomic<pid_t>::is_always_lock_free);

void write_stderr(const char* s) {
  const std::size_t n = std::strlen(s);
  ssize_t r = ::write(STDERR_FILENO, s, n);
  (void)r;
}

extern "C" void on_interrupt(int sig) {
  const int saved_errno = errno;
  for (auto& c : g_children) {
    const pid_t pid = c.exchange(0);
    if (pid > 0) {
      ::kill(pid, SIGTERM);
      ::waitpid(pid, nullptr, 0);
    }
  }
  int removed = 0;
  for (auto& f : g_files)
    if (f.state.load() == kReady && ::unlink(f.path) == 0) ++removed;
  write_stderr(sig == SIGINT ? "follicle: interrupted (SIGINT)" : "follicle: terminated (SIGTERM)");
  write_stderr(removed > 0 ? "; removed the unfinished output\n" : "\n");
  errno = saved_errno;
  ::signal(sig, SIG_DFL);
  ::raise(sig);
}

}  // namespace

void install_interrupt_handlers() {
  for (const int sig : {SIGINT, SIGTERM}) {
    struct sigaction old {};
    if (::sigaction(sig, nullptr, &old) == 0 && old.sa_handler == SIG_IGN) continue;
    struct sigaction sa {};
    sa.sa_handler = on_interrupt;
    sigemptyset(&sa.sa_mask);
    sigaddset(&sa.sa_mask, SIGINT);  // one handler run at a time
    sigaddset(&sa.sa_mask, SIGTERM);
    ::sigaction(sig, &sa, nullptr);
  }
}

InterruptCleanupFile::InterruptCleanupFile(const std::filesystem::path& path) {
  const std::string& s = path.native();
  if (s.size() >= PATH_MAX) return;
  for (std::size_t i = 0; i < kFileSlots; ++i) {
    int expected = kFree;
    if (g_files[i].state.compare_exchange_strong(expected, kFilling)) {
      std::memcpy(g_files[i].path, s.c_str(), s.size() + 1);
      g_files[i].state.store(kReady);
      m_slot = int(i);
      return;
    }
  }
}

InterruptCleanupFile::~InterruptCleanupFile() {
  if (m_slot >= 0) g_files[m_slot].state.store(kFree);
}

InterruptCleanupChild::InterruptCleanupChild(pid_t pid) {
  for (std::size_t i = 0; i < kChildSlots; ++i) {
    pid_t expected = 0;
    if (g_children[i].compare_exchange_strong(expected, pid)) {
      m_slot = int(i);
      return;
    }
  }
}

InterruptCleanupChild::~InterruptCleanupChild() {
  if (m_slot >= 0) g_children[m_slot].store(0);
}

}  // namespace follicle
