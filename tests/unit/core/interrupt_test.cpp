// SIGINT / SIGTERM cleanup (issue 24): an interrupted write leaves neither the final file nor its
// temporary, a registered child process is stopped, the process still dies of the signal it got
// (so a shell sees 128 + signal) and says so on stderr.
#include "follicle/core/interrupt.hpp"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>

#include "follicle/core/atomic_file.hpp"
#include "testing/testing.hpp"

using namespace follicle;
namespace fs = std::filesystem;

namespace {

bool alive(pid_t pid) {
  return ::kill(pid, 0) == 0;
}

}  // namespace

TEST(InterruptDeathTest, SigtermDuringAnAtomicWriteLeavesNoFileAndReRaises) {
  // "fast": the child is forked at EXPECT_EXIT and writes where the parent looks (a
  // re-executed child would name its own scratch folder by its own pid).
  GTEST_FLAG_SET(death_test_style, "fast");
  const fs::path dir = test::scratch_dir("interrupt_write");
  const fs::path out = dir / "image.png";
  EXPECT_EXIT(
      {
        install_interrupt_handlers();
        write_atomically(out, [](const fs::path& tmp) {
          std::ofstream(tmp) << "half of an image";
          ::raise(SIGTERM);
        });
      },
      ::testing::KilledBySignal(SIGTERM),
      "terminated \\(SIGTERM\\); removed the unfinished output");
  EXPECT_FALSE(fs::exists(out));
  EXPECT_TRUE(fs::is_empty(dir)) << "a temporary file was left in " << dir;
}

TEST(InterruptDeathTest, SigintStopsTheRegisteredChildBeforeRemovingItsOutput) {
  GTEST_FLAG_SET(death_test_style, "fast");
  const fs::path dir = test::scratch_dir("interrupt_child");
  const fs::path pid_file = dir / "child.pid";
  const fs::path tmp = dir / "video.mp4.tmp-1";
  EXPECT_EXIT(
      {
        install_interrupt_handlers();
        const pid_t child = ::fork();
        if (child == 0) {  // a stand-in for ffmpeg: keeps its output open and waits
          std::ofstream(tmp) << "partial video";
          ::pause();
          ::_exit(0);
        }
        std::ofstream(pid_file) << child;
        while (!fs::exists(tmp)) std::this_thread::sleep_for(std::chrono::milliseconds(1));
        const InterruptCleanupFile f(tmp);
        const InterruptCleanupChild c(child);
        ::raise(SIGINT);
      },
      ::testing::KilledBySignal(SIGINT), "interrupted \\(SIGINT\\)");
  EXPECT_FALSE(fs::exists(tmp));
  pid_t child = 0;
  std::ifstream(pid_file) >> child;
  ASSERT_GT(child, 0);
  EXPECT_FALSE(alive(child)) << "the child process " << child << " still runs";
}

TEST(Interrupt, FilesAreForgottenWhenTheirGuardEnds) {
  const fs::path dir = test::scratch_dir("interrupt_forget");
  const fs::path kept = dir / "finished.png";
  { const InterruptCleanupFile f(kept); }
  std::ofstream(kept) << "done";
  // A registration that ended must not be removed by a later signal: check in a child process.
  const pid_t pid = ::fork();
  if (pid == 0) {
    install_interrupt_handlers();
    ::raise(SIGTERM);
    ::_exit(0);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM);
  EXPECT_TRUE(fs::exists(kept));
}
