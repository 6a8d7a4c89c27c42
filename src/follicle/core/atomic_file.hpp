#pragma once
// Outputs are never half-written: write to "<path>.tmp-<pid>" then rename over the target.
#include <filesystem>
#include <functional>
#include <string>

namespace follicle {

/// Calls write(tmp_path); on success renames tmp_path to `path`, otherwise removes it and
/// rethrows. Creates the parent directory if needed.
void write_atomically(const std::filesystem::path& path,
                      const std::function<void(const std::filesystem::path& tmp)>& write);

/// Checks up front that `path` can be written, before any long work: creates its folder like
/// write_atomically, refuses a path that is a folder, and creates and removes the temporary file
/// the write will use. Throws follicle::Error naming `path` and the system's reason.
void check_output_writable(const std::filesystem::path& path);

/// The same for an output folder (created if missing): a probe file is created and removed in it.
void check_output_folder(const std::filesystem::path& dir);

/// Writes a byte string atomically.
void write_file_atomically(const std::filesystem::path& path, const std::string& bytes);

/// Reads a whole file; throws follicle::Error("<path>: cannot open ...") when it cannot.
std::string read_file(const std::filesystem::path& path);

}  // namespace follicle
