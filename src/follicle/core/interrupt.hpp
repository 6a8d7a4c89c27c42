#pragma once
// Cleanup on SIGINT and SIGTERM. Temporary outputs (write_atomically's "<path>.tmp-<pid>") and
// child processes (ffmpeg) are registered while they exist; the handler installed by
// install_interrupt_handlers() stops the children, removes the files, says so on stderr and
// re-raises the signal, so the process ends as the signal asked (exit status 128 + signal in a
// shell) and never leaves a half-written file behind.
//
// This is the one piece of process-wide state in Follicle: a signal handler reaches only static
// storage, and makes only async-signal-safe calls (kill, waitpid, unlink, write, raise).
#include <sys/types.h>

#include <filesystem>

namespace follicle {

/// Installs the SIGINT and SIGTERM handlers (a program's main calls it once; a library or the
/// Python module leaves signals to its host). A signal ignored when the program started (e.g.
/// SIGINT of a background job of a non-interactive shell) stays ignored.
void install_interrupt_handlers();

/// While alive, `path` is removed if the process is interrupted. Registration is best effort: at
/// most 64 files at once (more are written, just not cleaned up on a signal).
class InterruptCleanupFile {
 public:
  explicit InterruptCleanupFile(const std::filesystem::path& path);
  ~InterruptCleanupFile();
  InterruptCleanupFile(const InterruptCleanupFile&) = delete;
  InterruptCleanupFile& operator=(const InterruptCleanupFile&) = delete;

 private:
  int m_slot = -1;
};

/// While alive, the child process `pid` is sent SIGTERM and reaped if the process is interrupted
/// (before the temporary files are removed, so it cannot write them again).
class InterruptCleanupChild {
 public:
  explicit InterruptCleanupChild(pid_t pid);
  ~InterruptCleanupChild();
  InterruptCleanupChild(const InterruptCleanupChild&) = delete;
  InterruptCleanupChild& operator=(const InterruptCleanupChild&) = delete;

 private:
  int m_slot = -1;
};

}  // namespace follicle
