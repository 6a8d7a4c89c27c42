// The hair-model harness (harness.hpp): every model in its own Session on the same groom and
// motion; metrics from the output strands only.
#include "follicle/scene/harness.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>

#include "follicle/core/error.hpp"
#include "follicle/core/log.hpp"
#include "follicle/core/parallel.hpp"
#include "follicle/geom/mesh_sdf.hpp"
#include "follicle/hair/groom.hpp"
#include "follicle/image/plot.hpp"
#include "follicle/render/renderer.hpp"
#include "follicle/scene/session.hpp"

namespace follicle::scene {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kFloatEps = std::numeric_limits<float>::epsilon();
constexpr double kStretchUlps = 4.0;  // rounding allowance of a segment length, in float ulps

HairModel model_from_name(const std::string& name) {
  for (const auto& [e, n] : follicle_enum_names(HairModel{}))
    if (name == n) return e;
  std::string known;
  for (const auto& n : hair_model_names()) known += (known.empty() ? "" : ", ") + n;
  fail("unknown hair model \"{}\" (known: {})", name, known);
}

// Per-point data of the rest shape the metrics compare against.
struct RestData {
  std::vector<uint32_t> offsets;
  std::vector<double> seg_len;  // [i]: rest length of segment (i, i+1) within a strand, else 0
  std::vector<double> mass;     // [kg] per point
};

RestData rest_data(const geom::StrandSet& rest, double lambda) {
  RestData d;
  d.offsets = rest.offsets;
  d.seg_len.assign(rest.num_points(), 0.0);
  d.mass.assign(rest.num_points(), 0.0);
  for (std::size_t s = 0; s < rest.num_strands(); ++s) {
    const uint32_t b = rest.offsets[s], e = rest.offsets[s + 1];
    for (uint32_t i = b; i + 1 < e; ++i) {
      const double l = (rest.points[i + 1] - rest.points[i]).cast<double>().norm();
      d.seg_len[i] = l;
      d.mass[i] += 0.5 * lambda * l;
      d.mass[i + 1] += 0.5 * lambda * l;
    }
  }
  return d;
}

struct FrameMetrics {
  double stretch = 0.0;      // [%]
  double penetration = 0.0;  // [m]
  double drift = 0.0;        // [m]
  double potential = 0.0;    // [J]
};

// The growth mesh at rest (scene coordinates) as a signed distance: a grid over its box for a
// one-lookup "far outside" test, the exact distance near and inside the surface.
struct HeadDistance {
  std::unique_ptr<geom::MeshSignedDistance> exact;
  geom::SignedDistanceGrid grid;
  float near = 0.0f;  // grid values below this get the exact distance
};

HeadDistance head_distance(const Context& ctx, const geom::TriMesh& world) {
  HeadDistance h;
  h.exact = std::make_unique<geom::MeshSignedDistance>(world);
  geom::SignedDistanceGridParams gp;  // 2.5 mm cells, 12 mm band
  const auto box = world.bounds();
  const Vec3 grow = Vec3::Constant(gp.band + 2.0 * gp.cell);
  h.grid = geom::SignedDistanceGrid(ctx, *h.exact, box.min() - grow, box.max() + grow, gp);
  h.near = float(2.0 * gp.cell);  // trilinear error is well below a cell
  return h;
}

FrameMetrics measure(const Context& ctx, const geom::StrandSet& s, const RestData& rest,
                     const HeadDistance& head, const std::optional<Affine3>& motion,
                     const std::vector<Vec3>& root_targets, const Vec3& gravity) {
  const Affine3 to_rest = motion ? motion->inverse() : Affine3::Identity();
  return deterministic_reduce(
      ctx, s.num_strands(), 64, FrameMetrics{},
      [&](std::size_t s0, std::size_t s1) {
        FrameMetrics m;
        for (std::size_t k = s0; k < s1; ++k) {
          const uint32_t b = s.offsets[k], e = s.offsets[k + 1];
          for (uint32_t i = b; i < e; ++i) {
            const Vec3 x = s.points[i].cast<double>();
            m.potential -= rest.mass[i] * gravity.dot(x);
            if (i + 1 < e && rest.seg_len[i] > 0.0) {
              const Vec3 y = s.points[i + 1].cast<double>();
              const double l = (y - x).norm();
              // Length changes within the float32 rounding of the two end points are not stretch.
              const double tol = kStretchUlps * kFloatEps *
                                 (x.lpNorm<Eigen::Infinity>() + y.lpNorm<Eigen::Infinity>());
              const double dl = std::max(0.0, std::abs(l - rest.seg_len[i]) - tol);
              m.stretch = std::max(m.stretch, dl / rest.seg_len[i] * 100.0);
            }
            const Vec3 q = to_rest * x;
            if (head.grid.value(float(q.x()), float(q.y()), float(q.z())) < head.near) {
              const double d = head.exact->signed_distance(q);
              m.penetration = std::max(m.penetration, -d);
            }
          }
          if (!root_targets.empty())
            m.drift = std::max(m.drift, (s.points[b].cast<double>() - root_targets[k]).norm());
        }
        return m;
      },
      [](FrameMetrics a, const FrameMetrics& p) {
        a.stretch = std::max(a.stretch, p.stretch);
        a.penetration = std::max(a.penetration, p.penetration);
        a.drift = std::max(a.drift, p.drift);
        a.potential += p.potential;
        return a;
      });
}

// Kinetic energy sum(m |b - a|^2 / (2 dt^2)) [J].
double kinetic(const Context& ctx, const geom::StrandSet& a, const geom::StrandSet& b,
               const RestData& rest, double dt) {
  return deterministic_reduce(
      ctx, a.num_points(), 4096, 0.0,
      [&](std::size_t i0, std::size_t i1) {
        double e = 0.0;
        for (std::size_t i = i0; i < i1; ++i) {
          const Vec3 v = (b.points[i] - a.points[i]).cast<double>() / dt;
          e += 0.5 * rest.mass[i] * v.squaredNorm();
        }
        return e;
      },
      [](double x, double y) { return x + y; });
}

std::vector<int> choose_sheet_frames(const HarnessOptions& o, int first, int last) {
  std::vector<int> f = o.sheet_frames;
  if (f.empty()) f = {first, first + (last - first) / 2, last};
  for (int v : f)
    if (v < first || v > last)
      fail("sheet frame {} is outside the measured frames {}-{}", v, first, last);
  std::sort(f.begin(), f.end());
  f.erase(std::unique(f.begin(), f.end()), f.end());
  return f;
}

image::ImageRGB8 render_picture(render::Renderer& renderer, Session& session, int frame,
                                int width) {
  render::RenderSettings rs = session.render_settings();
  const double aspect = double(rs.height) / double(rs.width);
  rs.width = width;
  rs.height = std::max(1, int(std::lround(width * aspect)));
  const Vec3 bg = session.scene().render.background;
  const auto to8 = [](double v) {  // linear -> sRGB 8 bit, as the renderer encodes
    v = std::clamp(v, 0.0, 1.0);
    const double s = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
    return uint8_t(std::lround(s * 255.0));
  };
  return image::flatten(renderer.render(session.render_scene(frame), rs),
                        image::Rgb8{to8(bg.x()), to8(bg.y()), to8(bg.z())});
}

}  // namespace

std::vector<std::string> hair_model_names() {
  std::vector<std::string> out;
  for (const auto& [e, n] : follicle_enum_names(HairModel{})) out.emplace_back(n);
  return out;
}

HarnessReport run_harness(const Scene& scene, const std::filesystem::path& base_dir,
                          const std::string& source, const Context& ctx,
                          const HarnessOptions& options, Progress* progress,
                          render::Renderer* renderer) {
  options.validate();
  if (!scene.animation)
    fail_at(source,
            "a still scene (no \"animation\" section): the harness compares hair models over "
            "time; add an animation (fps, frames or duration, head_motion, wind)");
  if (scene.hair.empty()) fail_at(source, "the scene has no hair groups (\"hair\": [...])");
  if (options.group >= scene.hair.size())
    fail_at(source, "hair group {} out of range (the scene has {} groups: 0-{})", options.group,
            scene.hair.size(), scene.hair.size() - 1);
  const AnimationSpec& anim = *scene.animation;
  const int count = anim.frame_count();
  const int first = options.first_frame;
  const int last = options.last_frame < 0 ? count - 1 : options.last_frame;
  if (last >= count)
    fail_at(source, "frames {}-{}: the scene has frames 0-{}", first, last, count - 1);
  if (last <= first)
    fail_at(source,
            "frames {}-{}: the harness needs at least two frames (velocities come from "
            "consecutive frames)",
            first, last);
  std::vector<std::string> models = options.models.empty() ? hair_model_names() : options.models;
  for (const auto& m : models) model_from_name(m);

  HarnessReport rep;
  rep.scene = source;
  rep.group = options.group;
  rep.group_name = scene.hair[options.group].name;
  rep.first_frame = first;
  rep.last_frame = last;
  rep.fps = anim.fps;
  rep.gravity = anim.gravity;
  rep.hair_density = options.hair_density;
  rep.hair_radius = options.hair_radius;
  rep.linear_density = options.hair_density * kPi * options.hair_radius * options.hair_radius;
  if (options.thumb_size > 0) rep.sheet_frames = choose_sheet_frames(options, first, last);

  // The scene every model runs: hair[group] only, same head motion.
  Scene base = scene;
  if (options.group != 0 && anim.head_motion.kind != HeadMotionKind::None &&
      !anim.head_motion.pivot)
    base.animation->head_motion.pivot = Session(scene, base_dir, source, ctx).head_motion_pivot();
  base.hair = {scene.hair[options.group]};
  base.lcp.reset();
  base.hand.reset();

  std::unique_ptr<render::Renderer> own_renderer;
  if (options.thumb_size > 0 && !renderer) {
    own_renderer = render::Renderer::create_headless(ctx);
    renderer = own_renderer.get();
    ctx.log().info("harness renderer: {}", renderer->device_description());
  }

  std::optional<HeadDistance> head;
  for (const auto& name : models) {
    HarnessModelResult r;
    r.model = name;
    Scene sc = base;
    sc.hair[0].model = model_from_name(name);
    Session session(std::move(sc), base_dir, source, ctx);
    ctx.log().info("harness: {} on hair[{}] (\"{}\"), frames {}-{}", name, options.group,
                   rep.group_name, first, last);
    const auto groom = session.hair_groom(0);  // not timed
    if (!head) {
      const std::size_t mi = session.mesh_index(base.hair[0].mesh);
      geom::TriMesh world = *session.mesh(mi);
      world.transform(base.assets.meshes[mi].transform.matrix());
      head = head_distance(ctx, world);
      rep.groom_strands = groom->num_strands();
      rep.groom_points = groom->strands.num_points();
    }

    std::size_t ticks = 0;
    const auto tick = [&] {
      ++ticks;
      if (progress) progress->tick();
    };
    std::shared_ptr<const geom::StrandSet> prev, cur;
    RestData rest;
    std::size_t pic = 0;
    const auto picture = [&](int f) {
      if (pic < rep.sheet_frames.size() && rep.sheet_frames[pic] == f) {
        r.pictures.push_back(render_picture(*renderer, session, f, options.thumb_size));
        ++pic;
      }
    };
    const auto record = [&](int f, const geom::StrandSet& s) {
      const FrameMetrics m = measure(
          ctx, s, rest, *head, session.head_motion_transform(f),
          groom->bound() ? session.hair_root_targets(0, f) : std::vector<Vec3>{}, anim.gravity);
      r.time_s.push_back(session.frame_time(f));
      r.stretch_percent.push_back(m.stretch);
      r.penetration_mm.push_back(m.penetration * 1e3);
      r.drift_mm.push_back(m.drift * 1e3);
      r.potential_j.push_back(m.potential);
      r.kinetic_j.push_back(kNaN);  // filled once the neighbouring frames are known
      ++r.frames;
    };
    // Only the dynamics may stop a model (reported in its result); other errors propagate.
    const auto simulate = [&](int f) -> std::shared_ptr<const geom::StrandSet> {
      try {
        return session.hair_strands(0, f);
      } catch (const Error& e) {
        r.error = e.what();
        return nullptr;
      }
    };
    double wall = 0.0;
    cur = simulate(first);  // the model's set-up and frames 0..first: not timed
    if (cur && cur->num_strands() != groom->num_strands())
      r.error = fmt::format("the model output {} strands for a groom of {} strands",
                            cur->num_strands(), groom->num_strands());
    if (r.error.empty()) {
      r.rest_from_groom = cur->offsets == groom->strands.offsets;
      if (r.rest_from_groom) {
        rest = rest_data(groom->strands, rep.linear_density);
      } else if (const auto f0 = simulate(0)) {  // the model's own points: frame 0 is its rest
        rest = rest_data(*f0, rep.linear_density);
        if (first > 0) cur = simulate(first);
      }
    }
    if (r.error.empty()) {
      r.strands = cur->num_strands();
      r.points = cur->num_points();
      record(first, *cur);
      picture(first);
      tick();
      for (int f = first + 1; f <= last; ++f) {
        const auto t0 = std::chrono::steady_clock::now();
        auto next = simulate(f);
        wall += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        if (next && next->offsets != cur->offsets)
          r.error = fmt::format("frame {} has other strands than frame {}", f, f - 1);
        if (!r.error.empty()) break;
        // Central difference inside the range, forward at its first frame.
        const auto& a = prev ? *prev : *cur;
        const double dt = session.frame_time(f) - session.frame_time(prev ? f - 2 : f - 1);
        r.kinetic_j.back() = kinetic(ctx, a, *next, rest, dt);
        record(f, *next);
        picture(f);
        tick();
        prev = cur;
        cur = next;
      }
    }
    r.wall_seconds = wall;
    r.ms_per_simulated_second =
        r.error.empty() ? wall * 1e3 / (double(last - first) / anim.fps) : kNaN;
    if (!r.error.empty()) {
      ctx.log().info("harness: model {} stopped: {}", name, r.error);
      if (progress) progress->tick(std::size_t(last - first + 1) - ticks);
    }
    // Backward difference at the last frame measured.
    if (prev && cur && r.frames >= 2)
      r.kinetic_j.back() =
          kinetic(ctx, *prev, *cur, rest,
                  r.time_s[std::size_t(r.frames) - 1] - r.time_s[std::size_t(r.frames) - 2]);
    for (int i = 0; i < r.frames; ++i)
      r.total_j.push_back(r.kinetic_j[std::size_t(i)] + r.potential_j[std::size_t(i)]);
    const auto max_of = [&](const std::vector<double>& v) {
      return v.empty() ? kNaN : *std::max_element(v.begin(), v.end());
    };
    r.max_stretch_percent = max_of(r.stretch_percent);
    r.max_penetration_mm = max_of(r.penetration_mm);
    r.root_drift_mm = max_of(r.drift_mm);
    rep.models.push_back(std::move(r));
  }
  return rep;
}

Json harness_json(const HarnessReport& rep) {
  Json j = Json::object();
  j["follicle_harness"] = 1;
  j["scene"] = rep.scene;
  j["group"] = rep.group;
  j["group_name"] = rep.group_name;
  j["first_frame"] = rep.first_frame;
  j["last_frame"] = rep.last_frame;
  j["fps"] = rep.fps;
  j["gravity_m_s2"] = {rep.gravity.x(), rep.gravity.y(), rep.gravity.z()};
  j["hair_density_kg_m3"] = rep.hair_density;
  j["hair_radius_m"] = rep.hair_radius;
  j["linear_density_kg_m"] = rep.linear_density;
  j["groom_strands"] = rep.groom_strands;
  j["groom_points"] = rep.groom_points;
  j["sheet_frames"] = rep.sheet_frames;
  Json models = Json::array();
  const auto num = [](double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); };
  const auto arr = [&](const std::vector<double>& v) {
    Json a = Json::array();
    for (double x : v) a.push_back(num(x));
    return a;
  };
  for (const auto& r : rep.models) {
    Json m = Json::object();
    m["model"] = r.model;
    m["ok"] = r.error.empty();
    m["error"] = r.error;
    m["strands"] = r.strands;
    m["points"] = r.points;
    m["frames"] = r.frames;
    m["stretch_rest"] = r.rest_from_groom ? "groom" : "model frame 0";
    m["max_stretch_percent"] = num(r.max_stretch_percent);
    m["max_penetration_mm"] = num(r.max_penetration_mm);
    m["root_drift_mm"] = num(r.root_drift_mm);
    m["ms_per_simulated_second"] = num(r.ms_per_simulated_second);
    m["wall_s"] = num(r.wall_seconds);
    m["time_s"] = arr(r.time_s);
    m["kinetic_j"] = arr(r.kinetic_j);
    m["potential_j"] = arr(r.potential_j);
    m["total_j"] = arr(r.total_j);
    m["stretch_percent"] = arr(r.stretch_percent);
    m["penetration_mm"] = arr(r.penetration_mm);
    m["drift_mm"] = arr(r.drift_mm);
    models.push_back(std::move(m));
  }
  j["models"] = std::move(models);
  return j;
}

namespace {

// An SI prefix that makes the largest |value| a readable number: {factor, unit}.
std::pair<double, std::string> energy_unit(double max_abs) {
  static constexpr std::pair<double, const char*> kUnits[] = {
      {1.0, "J"}, {1e3, "mJ"}, {1e6, "uJ"}, {1e9, "nJ"}, {1e12, "pJ"}};
  for (const auto& [f, u] : kUnits)
    if (max_abs * f >= 1.0) return {f, u};
  return {1e12, "pJ"};
}

// Finite points of (x, y), scaled.
image::PlotSeries series(const HarnessModelResult& r, std::size_t i, const std::vector<double>& y,
                         double scale, double offset = 0.0) {
  image::PlotSeries s{r.model, {}, {}, image::palette_color(i)};
  for (std::size_t k = 0; k < y.size() && k < r.time_s.size(); ++k)
    if (std::isfinite(y[k]) && std::isfinite(r.time_s[k])) {
      s.x.push_back(r.time_s[k]);
      s.y.push_back((y[k] - offset) * scale);
    }
  return s;
}

std::string fixed(double v, int decimals) {
  return std::isfinite(v) ? fmt::format("{:.{}f}", v, decimals) : std::string("-");
}

}  // namespace

image::ImageRGB8 harness_sheet(const HarnessReport& rep) {
  const image::Rgb8 white{255, 255, 255}, ink{20, 20, 20}, grey{150, 150, 150};
  const int scale = 2, gap = 12;
  std::vector<image::ImageRGB8> parts;

  // Title.
  const std::string title = fmt::format(
      "follicle harness: {}  hair[{}] \"{}\"  frames {}-{} ({:.2f}-{:.2f} s)  {} strands",
      rep.scene, rep.group, rep.group_name, rep.first_frame, rep.last_frame,
      rep.first_frame / rep.fps, rep.last_frame / rep.fps, rep.groom_strands);

  // Pictures: one row per model, one column per sheet frame.
  if (!rep.sheet_frames.empty()) {
    std::vector<image::LabelledImage> cells;
    int w = 0, h = 0;
    for (const auto& r : rep.models)
      for (const auto& p : r.pictures) {
        w = std::max(w, p.width());
        h = std::max(h, p.height());
      }
    if (w == 0) w = h = 160;
    for (const auto& r : rep.models)
      for (std::size_t k = 0; k < rep.sheet_frames.size(); ++k) {
        const int f = rep.sheet_frames[k];
        image::LabelledImage c;
        c.label = fmt::format("{}\nframe {} ({:.2f} s)", r.model, f, f / rep.fps);
        if (k < r.pictures.size()) {
          c.image = r.pictures[k];
        } else {  // the model stopped before this frame
          c.image = image::ImageRGB8(w, h);
          image::fill_rect(c.image, 0, 0, w, h, image::Rgb8{235, 235, 235});
          image::draw_text(c.image, 8, h / 2 - 12, "model stopped", grey, scale);
        }
        cells.push_back(std::move(c));
      }
    image::GridOptions go;
    go.columns = int(rep.sheet_frames.size());
    go.gap = gap;
    go.text_scale = scale;
    parts.push_back(image::image_grid(cells, go));
  }

  // Plots: stretch, kinetic energy, total-energy change (one line per model).
  double kmax = 0.0, emax = 0.0;
  for (const auto& r : rep.models)
    for (std::size_t k = 0; k < r.total_j.size(); ++k) {
      if (std::isfinite(r.kinetic_j[k])) kmax = std::max(kmax, std::abs(r.kinetic_j[k]));
      if (std::isfinite(r.total_j[k]) && std::isfinite(r.total_j[0]))
        emax = std::max(emax, std::abs(r.total_j[k] - r.total_j[0]));
    }
  const auto [kf, ku] = energy_unit(kmax);
  const auto [ef, eu] = energy_unit(emax);
  std::vector<image::PlotSeries> stretch, kin, tot;
  for (std::size_t i = 0; i < rep.models.size(); ++i) {
    const auto& r = rep.models[i];
    stretch.push_back(series(r, i, r.stretch_percent, 1.0));
    kin.push_back(series(r, i, r.kinetic_j, kf));
    const double e0 = r.total_j.empty() ? 0.0 : r.total_j[0];
    tot.push_back(series(r, i, r.total_j, ef, std::isfinite(e0) ? e0 : 0.0));
  }
  const int grid_w = parts.empty() ? 0 : parts[0].width();
  const int plot_w = std::max(480, (grid_w - 2 * gap) / 3);
  image::PlotOptions po;
  po.width = plot_w;
  po.height = 380;
  po.text_scale = scale;
  po.x_label = "time [s]";
  std::vector<image::ImageRGB8> plots;
  po.title = "stretch";
  po.y_label = "max |l/l0 - 1| [%]";
  plots.push_back(image::line_plot(stretch, po).image);
  po.title = "kinetic energy";
  po.y_label = fmt::format("E_k [{}]", ku);
  plots.push_back(image::line_plot(kin, po).image);
  po.title = "total energy change";
  po.y_label = fmt::format("E - E(t0) [{}]", eu);
  plots.push_back(image::line_plot(tot, po).image);
  parts.push_back(image::stack(plots, false, gap, white));

  // Numbers, one line per model.
  std::vector<std::string> lines;
  for (const auto& r : rep.models) {
    std::string l = fmt::format(
        "{:<14} max stretch {} %   max penetration {} mm   root drift {} mm   {} ms per "
        "simulated s   {} points",
        r.model, fixed(r.max_stretch_percent, 4), fixed(r.max_penetration_mm, 2),
        fixed(r.root_drift_mm, 4), fixed(r.ms_per_simulated_second, 0), r.points);
    lines.push_back(std::move(l));
    if (!r.error.empty()) {  // on its own line, shortened to the width of the numbers
      std::string e = fmt::format("stopped after {} frames: {}", r.frames, r.error);
      if (e.size() > 110) e = e.substr(0, 107) + "...";
      lines.push_back("  " + e);
    }
  }
  int text_w = image::text_size(title, scale).width;
  for (const auto& l : lines) text_w = std::max(text_w, image::text_size(l, scale).width);

  int width = text_w + 2 * gap;
  for (const auto& p : parts) width = std::max(width, p.width() + 2 * gap);
  const int line = 12 * scale;
  int height = gap + line + gap;
  for (const auto& p : parts) height += p.height() + gap;
  height += int(lines.size()) * (line + 4) + gap;
  image::ImageRGB8 sheet(width, height);
  image::fill_rect(sheet, 0, 0, width, height, white);
  int y = gap;
  image::draw_text(sheet, gap, y, title, ink, scale);
  y += line + gap;
  for (const auto& p : parts) {
    image::blit(sheet, p, gap, y);
    y += p.height() + gap;
  }
  std::size_t model = 0;
  for (const auto& l : lines) {
    const bool detail = l.rfind("  ", 0) == 0;
    if (!detail)
      image::fill_rect(sheet, gap, y + 4 * scale, 10 * scale, 2 * scale,
                       image::palette_color(model++));
    image::draw_text(sheet, gap + 14 * scale, y, l, detail ? image::Rgb8{180, 30, 30} : ink, scale);
    y += line + 4;
  }
  return sheet;
}

}  // namespace follicle::scene
