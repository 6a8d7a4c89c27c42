#include "follicle/core/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

#include "follicle/core/error.hpp"
#include "follicle/core/interrupt.hpp"

namespace follicle {

namespace {

// The folder of an output, created if missing (write_atomically and check_output_writable).
void create_parent_folder(const std::filesystem::path& path) {
  if (!path.has_parent_path()) return;
  std::error_code ec;
  std::filesystem::create_directories(path.parent_path(), ec);
  if (ec)
    fail_at(path.string(), "cannot create directory {}: {}", path.parent_path().string(),
            ec.message());
}

// "<path>.tmp-<pid>": where an output is written before the rename.
std::filesystem::path temporary_path(const std::filesystem::path& path) {
  std::filesystem::path tmp = path;
  tmp += ".tmp-" + std::to_string(::getpid());
  return tmp;
}

}  // namespace

void write_atomically(const std::filesystem::path& path,
                      const std::function<void(const std::filesystem::path& tmp)>& write) {
  namespace fs = std::filesystem;
  create_parent_folder(path);
  const fs::path tmp = temporary_path(path);
  const InterruptCleanupFile cleanup(tmp);  // SIGINT / SIGTERM remove it too
  try {
    write(tmp);
  } catch (...) {
    std::error_code ec;
    fs::remove(tmp, ec);
    throw;
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    const std::string why = ec.message();
    fs::remove(tmp, ec);
    fail_at(path.string(), "cannot move finished output into place: {}", why);
  }
}

namespace {

// Creates and removes `probe`; throws naming `what` with the system's reason.
void probe_write(const std::filesystem::path& probe, const std::string& what) {
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) {
    const int err = errno;
    if (err == EEXIST) return;  // a leftover temporary of ours: the folder takes files
    fail_at(what, "cannot write here: {}", std::strerror(err));
  }
  ::close(fd);
  ::unlink(probe.c_str());
}

}  // namespace

void check_output_writable(const std::filesystem::path& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::is_directory(path, ec)) fail_at(path.string(), "is a folder, expected a file name");
  create_parent_folder(path);
  probe_write(temporary_path(path), path.string());
}

void check_output_folder(const std::filesystem::path& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) fail_at(dir.string(), "cannot create the output folder: {}", ec.message());
  if (!fs::is_directory(dir, ec)) fail_at(dir.string(), "is not a folder");
  probe_write(dir / (".follicle-probe-" + std::to_string(::getpid())), dir.string());
}

void write_file_atomically(const std::filesystem::path& path, const std::string& bytes) {
  // POSIX calls rather than std::ofstream: every write, the flush to the disk and the close are
  // checked and their errno reported (a stream on a full disk may fail only at close, and says
  // nothing about why). Errors name the requested path, not the temporary one.
  write_atomically(path, [&](const std::filesystem::path& tmp) {
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) fail_at(path.string(), "cannot open for writing: {}", std::strerror(errno));
    const char* p = bytes.data();
    std::size_t left = bytes.size();
    while (left > 0) {
      const ssize_t n = ::write(fd, p, left);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        const int err = n < 0 ? errno : ENOSPC;
        ::close(fd);
        fail_at(path.string(), "write failed: {}", std::strerror(err));
      }
      p += n;
      left -= std::size_t(n);
    }
    if (::fsync(fd) != 0 && errno != EINVAL && errno != EROFS) {
      const int err = errno;
      ::close(fd);
      fail_at(path.string(), "write failed: {}", std::strerror(err));
    }
    if (::close(fd) != 0) fail_at(path.string(), "write failed: {}", std::strerror(errno));
  });
}

std::string read_file(const std::filesystem::path& path) {
  std::error_code ec;
  const auto st = std::filesystem::status(path, ec);
  if (std::filesystem::is_directory(st)) fail_at(path.string(), "is a directory, not a file");
  std::ifstream f(path, std::ios::binary);
  if (!f) fail_at(path.string(), "cannot open file for reading: {}", std::strerror(errno));
  // One read into a string sized from the file's length: `ss << f.rdbuf()` through a
  // stringstream copied every byte twice and grew its buffer step by step (39% of loading a
  // 1M-triangle OBJ). Files without a length (pipes; /proc reports 0) are read in chunks, and
  // so is whatever a file grew by since its size was taken.
  std::string out;
  if (std::filesystem::is_regular_file(st)) {
    const auto len = std::filesystem::file_size(path, ec);
    if (!ec && len > 0) {
      out.resize(std::size_t(len));
      f.read(out.data(), std::streamsize(len));
      out.resize(std::size_t(f.gcount()));
      if (f.bad()) fail_at(path.string(), "read failed: {}", std::strerror(errno));
      f.clear();
    }
  }
  char buf[65536];
  while (f.read(buf, sizeof buf) || f.gcount() > 0) out.append(buf, std::size_t(f.gcount()));
  if (f.bad()) fail_at(path.string(), "read failed: {}", std::strerror(errno));
  return out;
}

}  // namespace follicle
