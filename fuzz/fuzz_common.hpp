#pragma once
// Shared helpers of the libFuzzer targets (fuzz_*.cpp). A target feeds the bytes to a reader; a
// follicle::Error is the expected outcome for bad input. Any other exception escapes
// LLVMFuzzerTestOneInput and libFuzzer reports it as a crash (uncaught exception), like a
// sanitizer report, a hang (-timeout) or running out of memory (-rss_limit_mb).
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>

#include "follicle/core/error.hpp"

namespace follicle::fuzz {

/// A private folder for this process (created on first use, removed at normal exit): in /dev/shm
/// when there is one (memory; on ext4, truncating and rewriting a file on every input makes the
/// kernel flush it at close, which makes file-based targets about ten times slower), else in
/// $TMPDIR. FOLLICLE_FUZZ_TMPDIR overrides the parent folder.
inline const std::filesystem::path& process_dir() {
  struct Dir {
    std::filesystem::path path;
    Dir() {
      std::filesystem::path parent = std::filesystem::temp_directory_path();
      std::error_code ec;
      if (const char* env = std::getenv("FOLLICLE_FUZZ_TMPDIR"))
        parent = env;
      else if (std::filesystem::is_directory("/dev/shm", ec) && access("/dev/shm", W_OK) == 0)
        parent = "/dev/shm";
      std::string tmpl = (parent / "follicle-fuzz-XXXXXX").string();
      if (!mkdtemp(tmpl.data())) {
        std::perror("follicle fuzz: mkdtemp");
        std::abort();
      }
      path = tmpl;
    }
    ~Dir() {
      std::error_code ec;
      std::filesystem::remove_all(path, ec);
    }
  };
  static const Dir dir;
  return dir.path;
}

/// Writes the input to <process dir>/input<ext> (one path per process and extension, rewritten
/// for every input) and returns that path. Readers that only take a path are fed this way.
inline std::filesystem::path write_input(const uint8_t* data, std::size_t size,
                                         const std::string& ext) {
  const std::filesystem::path p = process_dir() / ("input" + ext);
  std::FILE* f = std::fopen(p.c_str(), "wb");
  if (!f) {
    std::perror("follicle fuzz: fopen");
    std::abort();
  }
  if ((size && std::fwrite(data, 1, size, f) != size) || std::fclose(f) != 0) {
    std::perror("follicle fuzz: write");
    std::abort();
  }
  return p;
}

inline std::string as_string(const uint8_t* data, std::size_t size) {
  return std::string(reinterpret_cast<const char*>(data), size);
}

/// Runs `f`; a follicle::Error (the readers' documented failure) is an ordinary outcome.
template <class F>
void expect_ok_or_error(F&& f) {
  try {
    f();
  } catch (const follicle::Error&) {
  }
}

}  // namespace follicle::fuzz
