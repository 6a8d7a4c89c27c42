// follicle harness SCENE [--frames A-B] [--models m1,m2] [--group G] [--sheet-frames f1,f2,...]
// [--thumb-size PX] --json REPORT.json --sheet SHEET.png: every hair model on the scene's groom
// under the same motion (scene/harness.hpp); writes the numbers as JSON and a comparison sheet
// (pictures of each model at the sheet frames, stretch and energy plots) as PNG, both atomically.
// Exit 1 after writing them when a model's dynamics stopped.
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>

#include "commands.hpp"
#include "follicle/core/atomic_file.hpp"
#include "follicle/core/log.hpp"
#include "follicle/core/progress.hpp"
#include "follicle/image/image_io.hpp"
#include "follicle/scene/harness.hpp"
#include "follicle/scene/session.hpp"

namespace follicle::cli {

namespace {

std::string lower_extension(const std::string& path) {
  auto ext = std::filesystem::path(path).extension().string();
  for (auto& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

std::vector<std::string> split_list(const std::string& s) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : s + ",") {
    if (c == ',') {
      while (!cur.empty() && std::isspace(static_cast<unsigned char>(cur.back()))) cur.pop_back();
      if (!cur.empty()) out.push_back(cur);
      cur.clear();
    } else if (!(cur.empty() && std::isspace(static_cast<unsigned char>(c)))) {
      cur += c;
    }
  }
  return out;
}

bool all_digits(const std::string& s) {
  if (s.empty() || s.size() > 9) return false;
  for (char c : s)
    if (!std::isdigit(static_cast<unsigned char>(c))) return false;
  return true;
}

std::string joined(const std::vector<std::string>& v) {
  std::string out;
  for (const auto& s : v) out += (out.empty() ? "" : ", ") + s;
  return out;
}

}  // namespace

int run_harness(const GlobalOptions& g, const HarnessArgs& a) {
  auto ctx = make_context(g);
  if (a.json.empty()) throw UsageError("give the report file with --json REPORT.json");
  if (lower_extension(a.json) != ".json")
    throw UsageError(fmt::format("--json must end in .json, got '{}'", a.json));
  if (a.sheet.empty()) throw UsageError("give the comparison sheet with --sheet SHEET.png");
  if (lower_extension(a.sheet) != ".png")
    throw UsageError(fmt::format("--sheet must end in .png, got '{}'", a.sheet));
  if (a.thumb_size < 16 || a.thumb_size > 4096)
    throw UsageError(fmt::format("--thumb-size must be in 16-4096 px, got {}", a.thumb_size));

  scene::HarnessOptions opt;
  opt.thumb_size = a.thumb_size;
  int first = -1, last = -1;
  parse_frames(a.frames, first, last);
  const auto known = scene::hair_model_names();
  for (const auto& m : split_list(a.models)) {
    if (std::find(known.begin(), known.end(), m) == known.end())
      throw UsageError(
          fmt::format("--models: unknown hair model '{}' (known: {})", m, joined(known)));
    if (std::find(opt.models.begin(), opt.models.end(), m) == opt.models.end())
      opt.models.push_back(m);
  }
  if (!a.models.empty() && opt.models.empty())
    throw UsageError(fmt::format("--models lists no model (known: {})", joined(known)));
  for (const auto& f : split_list(a.sheet_frames)) {
    if (!all_digits(f))
      throw UsageError(fmt::format(
          "--sheet-frames expects frame numbers separated by commas (e.g. 0,12,24), got '{}'",
          a.sheet_frames));
    opt.sheet_frames.push_back(std::stoi(f));
  }

  auto session = scene::Session::load(a.scene, *ctx);
  const auto& sc = session.scene();
  if (!sc.animation)
    fail_at(a.scene,
            "a still scene (no \"animation\" section): the harness compares hair models over "
            "time; add an animation (fps, frames or duration, head_motion, wind)");
  if (sc.hair.empty()) fail_at(a.scene, "the scene has no hair groups (\"hair\": [...])");
  check_output_writable(a.json);  // before the simulations, not after
  check_output_writable(a.sheet);
  // --group: an index into hair[] or a group's name.
  if (!a.group.empty()) {
    bool found = false;
    if (all_digits(a.group)) {
      opt.group = std::size_t(std::stoi(a.group));
      found = opt.group < sc.hair.size();
    } else {
      for (std::size_t i = 0; i < sc.hair.size() && !found; ++i)
        if (sc.hair[i].name == a.group) {
          opt.group = i;
          found = true;
        }
    }
    if (!found) {
      std::vector<std::string> groups;
      for (std::size_t i = 0; i < sc.hair.size(); ++i)
        groups.push_back(fmt::format("{} \"{}\"", i, sc.hair[i].name));
      throw UsageError(fmt::format("--group {}: no such hair group (the scene has: {})", a.group,
                                   joined(groups)));
    }
  }
  const int count = session.frame_count();
  if (first < 0) {
    first = 0;
    last = count - 1;
  }
  if (last >= count)
    throw UsageError(
        fmt::format("--frames {}-{}: the scene has frames 0-{}", first, last, count - 1));
  if (last == first)
    throw UsageError(
        fmt::format("--frames {}-{}: the harness needs at least two frames (velocities come from "
                    "consecutive frames)",
                    first, last));
  for (int f : opt.sheet_frames)
    if (f < first || f > last)
      throw UsageError(
          fmt::format("--sheet-frames: frame {} is outside the frames {}-{}", f, first, last));
  opt.first_frame = first;
  opt.last_frame = last;

  const std::size_t nmodels = opt.models.empty() ? known.size() : opt.models.size();
  Progress progress("harness", nmodels * std::size_t(last - first + 1), !g.quiet);
  const scene::HarnessReport report =
      scene::run_harness(sc, session.base_dir(), session.source_name(), *ctx, opt, &progress);
  progress.finish();

  // Both outputs are made before either is written; each is written atomically.
  const std::string json = scene::harness_json(report).dump(1) + "\n";
  const image::ImageRGB8 sheet = scene::harness_sheet(report);
  write_file_atomically(a.json, json);
  image::write_png(a.sheet, sheet);

  std::vector<std::string> stopped;
  if (!g.quiet) {
    const auto num = [](double v, int decimals) {
      return std::isfinite(v) ? fmt::format("{:.{}f}", v, decimals) : std::string("-");
    };
    for (const auto& r : report.models)
      fmt::print(
          "{}: max stretch {} %, max penetration {} mm, root drift {} mm, {} ms per simulated "
          "second{}\n",
          r.model, num(r.max_stretch_percent, 4), num(r.max_penetration_mm, 2),
          num(r.root_drift_mm, 4), num(r.ms_per_simulated_second, 0),
          r.error.empty() ? "" : fmt::format(" (stopped after {} frames)", r.frames));
    fmt::print("wrote {} ({} models, frames {}-{})\n", a.json, report.models.size(),
               report.first_frame, report.last_frame);
    fmt::print("wrote {} ({}x{})\n", a.sheet, sheet.width(), sheet.height());
  }
  for (const auto& r : report.models)
    if (!r.error.empty()) stopped.push_back(r.model + ": " + r.error);
  if (!stopped.empty()) fail("hair model(s) stopped: {}", joined(stopped));
  return 0;
}

}  // namespace follicle::cli
