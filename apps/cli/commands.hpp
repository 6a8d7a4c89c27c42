#pragma once
// The `follicle` subcommands. main.cpp (the only file that includes CLI11, which is slow to
// compile) parses the command line into these structs and calls run_*; each run_* lives in its
// own cmd_*.cpp. A run_* returns the process exit code or throws: follicle::Error -> exit 1,
// UsageError -> exit 2, both printed as one line "follicle: error: <message>".
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "follicle/core/context.hpp"

namespace follicle::cli {

/// A command-line mistake the parser could not catch (e.g. a malformed --size); exit code 2.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct GlobalOptions {
  int threads = 0;  // 0 = all hardware threads
  uint64_t seed = 1;
  bool quiet = false;
  bool verbose = false;
};

/// The Context every command runs with (logger level from --quiet/--verbose).
std::unique_ptr<Context> make_context(const GlobalOptions& g);
/// Parses a --frames value "A-B" or "A" into [first, last] (both left unchanged when `s` is
/// empty); throws UsageError for anything else or when B < A.
void parse_frames(const std::string& s, int& first, int& last);

struct RenderArgs {
  std::string scene;
  std::string output;  // "" = the scene's outputs
  int width = 0;       // 0 = from the scene
  int height = 0;
  int frame = 0;
};
int run_render(const GlobalOptions& g, const RenderArgs& a);

struct FitArgs {
  std::string head;
  std::string units = "m";
  bool units_given = false;
  std::string output;             // folder
  std::vector<double> up, front;  // empty = found
  int image_size = 800;
};
int run_fit(const GlobalOptions& g, const FitArgs& a);

struct ValidateArgs {
  std::vector<std::string> scenes;
};
int run_validate(const GlobalOptions& g, const ValidateArgs& a);

struct InfoArgs {
  std::string file;
  std::string units = "m";   // for mesh files
  bool units_given = false;  // --units on the command line (else metres are assumed)
};
int run_info(const GlobalOptions& g, const InfoArgs& a);

struct ConvertArgs {
  std::string input, output;
  std::string in_units = "m", out_units = "m";
  bool ascii = false;
  int tfx_verts = 32;  // .tfx output: vertices per strand (power of two, 4..64)
};
int run_convert(const GlobalOptions& g, const ConvertArgs& a);

struct BenchArgs {
  std::vector<std::string> workloads;
  std::vector<std::string> sizes;  // "KEY=VALUE"
  bool list = false;
  double min_seconds = 1.0;
};
int run_bench(const GlobalOptions& g, const BenchArgs& a);

struct ExportArgs {
  std::string scene;
  std::string hair;  // output strand file (.hair, .tfx, .usda, .obj)
  int frame = 0;
  std::string units = "m";
  std::string cache;   // strand cache folder, "" = none
  std::string maps;    // wrinkle-map folder, "" = none (cmd_export_maps.cpp)
  std::string frames;  // "A-B" for --maps, "" = every frame
  std::string mesh;    // deformed face mesh (.obj, .ply, .gltf, .glb), "" = none
  std::string rig;     // --mesh: mesh asset name of the face rig, "" = the first rig
};
int run_export(const GlobalOptions& g, const ExportArgs& a);
/// The --maps part of `follicle export` (cmd_export_maps.cpp).
int run_export_maps(const GlobalOptions& g, const ExportArgs& a);
/// The --mesh part of `follicle export` (cmd_export_mesh.cpp).
int run_export_mesh(const GlobalOptions& g, const ExportArgs& a);

struct CompareArgs {
  std::string a, b;    // mesh files
  std::string output;  // error-coloured render of A (.png), "" = none
  std::string units = "m";
  int width = 800, height = 800;
  uint64_t samples = 100000;
};
int run_compare(const GlobalOptions& g, const CompareArgs& a);

struct AnimateArgs {
  std::string scene;
  std::string frames;  // "A-B", "" = every frame of the scene
  std::string output_dir;
  std::string mp4;    // "" = DIR/<scene name>.mp4
  std::string cache;  // strand cache folder, "" = none
  bool no_video = false;
  int width = 0, height = 0;
};
int run_animate(const GlobalOptions& g, const AnimateArgs& a);

struct HarnessArgs {
  std::string scene;
  std::string frames;        // "A-B", "" = every frame of the scene
  std::string models;        // "m1,m2", "" = every hair model
  std::string group;         // index or name of the hair group, "" = the first
  std::string sheet_frames;  // "f1,f2,...", "" = first, middle and last
  int thumb_size = 320;      // [px] width of each picture on the sheet
  std::string json;          // report (.json), required
  std::string sheet;         // comparison sheet (.png), required
};
int run_harness(const GlobalOptions& g, const HarnessArgs& a);

struct DocsArgs {
  std::string topic;   // "scene-format"
  std::string write;   // file to update in place, "" = print the tables
  bool check = false;  // exit 1 when the file is out of date
};
int run_docs(const GlobalOptions& g, const DocsArgs& a);

}  // namespace follicle::cli
