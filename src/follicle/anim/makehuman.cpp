#include "follicle/anim/makehuman.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>

#include "follicle/core/atomic_file.hpp"
#include "follicle/core/error.hpp"

namespace follicle::anim {

namespace {

constexpr double kDecimetre = 0.1;  // base.obj units -> metres

std::string where_line(const std::filesystem::path& p, std::size_t line) {
  return fmt::format("{}:{}", p.string(), line);
}

double parse_double(std::string_view tok, const std::string& where) {
  double v = 0;
  const auto r = std::from_chars(tok.data(), tok.data() + tok.size(), v);
  if (r.ec != std::errc() || r.ptr != tok.data() + tok.size() || !std::isfinite(v))
    fail_at(where, "expected a finite number, got '{}'", tok);
  return v;
}

long parse_int(std::string_view tok, const std::string& where) {
  long v = 0;
  const auto r = std::from_chars(tok.data(), tok.data() + tok.size(), v);
  if (r.ec != std::errc() || r.ptr != tok.data() + tok.size())
    fail_at(where, "expected an integer index, got '{}'", tok);
  return v;
}

std::vector<std::string_view> split_ws(std::string_view s) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\t' || s[i] == '\r')) ++i;
    std::size_t j = i;
    while (j < s.size() && s[j] != ' ' && s[j] != '\t' && s[j] != '\r') ++j;
    if (j > i) out.push_back(s.substr(i, j - i));
    i = j;
  }
  return out;
}

nlohmann::json read_json(const std::filesystem::path& path) {
  const std::string text = read_file(path);
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    fail_at(path.string(), "invalid JSON: {}", e.what());
  }
}

bool is_hand_bone(const std::string& name, Side side) {
  const std::string suffix = side == Side::left ? ".L" : ".R";
  if (name.size() < 2 || name.compare(name.size() - 2, 2, suffix) != 0) return false;
  return name.rfind("finger", 0) == 0 || name.rfind("metacarpal", 0) == 0 ||
         name.rfind("wrist", 0) == 0;
}

}  // namespace

MakeHumanBase load_makehuman_obj(const std::filesystem::path& path) {
  // Hand-written: we need the raw vertex numbering and the "body" group, which the general OBJ
  // loader (geom::load_mesh) does not expose.
  const std::string text = read_file(path);
  MakeHumanBase out;
  std::string group;
  std::size_t line_no = 0, pos = 0;
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string::npos) end = text.size();
    const std::string_view line(text.data() + pos, end - pos);
    pos = end + 1;
    ++line_no;
    if (line.size() < 2 || line[0] == '#') continue;
    const auto tok = split_ws(line);
    if (tok.empty()) continue;
    if (tok[0] == "v") {
      if (tok.size() < 4) fail_at(where_line(path, line_no), "vertex needs 3 coordinates");
      const std::string w = where_line(path, line_no);
      out.positions.emplace_back(parse_double(tok[1], w) * kDecimetre,
                                 parse_double(tok[2], w) * kDecimetre,
                                 parse_double(tok[3], w) * kDecimetre);
    } else if (tok[0] == "vt") {
      if (tok.size() < 3) fail_at(where_line(path, line_no), "texture vertex needs 2 values");
      const std::string w = where_line(path, line_no);
      out.uvs.emplace_back(parse_double(tok[1], w), parse_double(tok[2], w));
    } else if (tok[0] == "g") {
      group = tok.size() > 1 ? std::string(tok[1]) : std::string();
    } else if (tok[0] == "f" && group == "body") {
      const std::string w = where_line(path, line_no);
      if (tok.size() < 4) fail_at(w, "face needs at least 3 corners");
      std::vector<int> pv, tv;
      for (std::size_t k = 1; k < tok.size(); ++k) {
        const std::string_view c = tok[k];
        const std::size_t slash = c.find('/');
        if (slash == std::string_view::npos) fail_at(w, "face corner '{}' needs v/vt", c);
        std::string_view vt = c.substr(slash + 1);
        const std::size_t slash2 = vt.find('/');
        if (slash2 != std::string_view::npos) vt = vt.substr(0, slash2);
        const long vi = parse_int(c.substr(0, slash), w);
        const long ti = parse_int(vt, w);
        if (vi < 1 || std::size_t(vi) > out.positions.size())
          fail_at(w, "vertex index {} out of range 1..{}", vi, out.positions.size());
        if (ti < 1 || std::size_t(ti) > out.uvs.size())
          fail_at(w, "texture index {} out of range 1..{}", ti, out.uvs.size());
        pv.push_back(int(vi - 1));
        tv.push_back(int(ti - 1));
      }
      for (std::size_t k = 1; k + 1 < pv.size(); ++k) {
        out.faces.emplace_back(pv[0], pv[k], pv[k + 1]);
        out.uv_faces.emplace_back(tv[0], tv[k], tv[k + 1]);
      }
    }
  }
  if (out.faces.empty()) fail_at(path.string(), "no faces in group 'body'");
  return out;
}

Skeleton load_mhskel(const std::filesystem::path& path, const std::vector<Vec3>& base_positions) {
  const nlohmann::json j = read_json(path);
  const std::string file = path.string();
  if (!j.contains("bones") || !j["bones"].is_object()) fail_at(file, "expected object 'bones'");
  if (!j.contains("joints") || !j["joints"].is_object()) fail_at(file, "expected object 'joints'");
  const auto& joints = j["joints"];
  auto joint_pos = [&](const std::string& name, const std::string& where) -> Vec3 {
    if (!joints.contains(name)) fail_at(where, "unknown joint '{}'", name);
    const auto& ids = joints[name];
    if (!ids.is_array() || ids.empty()) fail_at(where, "joint '{}' has no vertices", name);
    Vec3 s = Vec3::Zero();
    for (const auto& id : ids) {
      if (!id.is_number_integer()) fail_at(where, "joint '{}': expected vertex indices", name);
      const long v = id.get<long>();
      if (v < 0 || std::size_t(v) >= base_positions.size())
        fail_at(where, "joint '{}': vertex {} out of range (mesh has {})", name, v,
                base_positions.size());
      s += base_positions[v];
    }
    return s / double(ids.size());
  };
  const auto& planes = j.contains("planes") ? j["planes"] : nlohmann::json::object();
  // Bones in parent-first order (the file's object is sorted by name).
  std::vector<std::string> names;
  for (auto it = j["bones"].begin(); it != j["bones"].end(); ++it) names.push_back(it.key());
  Skeleton skel;
  std::size_t added = 0;
  std::vector<char> done(names.size(), 0);
  while (added < names.size()) {
    const std::size_t before = added;
    for (std::size_t i = 0; i < names.size(); ++i) {
      if (done[i]) continue;
      const auto& b = j["bones"][names[i]];
      const std::string where = fmt::format("{}: bones.{}", file, names[i]);
      std::string parent;
      if (b.contains("parent") && !b["parent"].is_null()) {
        if (!b["parent"].is_string()) fail_at(where, "parent must be a string or null");
        parent = b["parent"].get<std::string>();
        if (skel.find(parent) < 0) {
          if (!j["bones"].contains(parent)) fail_at(where, "unknown parent bone '{}'", parent);
          continue;  // parent not added yet
        }
      }
      if (!b.contains("head") || !b["head"].is_string() || !b.contains("tail") ||
          !b["tail"].is_string())
        fail_at(where, "expected string fields 'head' and 'tail'");
      const Vec3 head = joint_pos(b["head"].get<std::string>(), where);
      const Vec3 tail = joint_pos(b["tail"].get<std::string>(), where);
      Vec3 x_hint = Vec3::UnitX();
      if (b.contains("rotation_plane") && b["rotation_plane"].is_string()) {
        const std::string pn = b["rotation_plane"].get<std::string>();
        if (planes.contains(pn) && planes[pn].is_array() && planes[pn].size() == 3) {
          const Vec3 p0 = joint_pos(planes[pn][0].get<std::string>(), where);
          const Vec3 p1 = joint_pos(planes[pn][1].get<std::string>(), where);
          const Vec3 p2 = joint_pos(planes[pn][2].get<std::string>(), where);
          const Vec3 n = (p1 - p0).cross(p2 - p1);
          if (n.norm() > 1e-12) x_hint = n.normalized();
        }
      }
      skel.add_bone(names[i], parent, head, tail, Skeleton::frame_from(head, tail, x_hint));
      done[i] = 1;
      ++added;
    }
    if (added == before) fail_at(file, "bone hierarchy has a cycle");
  }
  return skel;
}

SkinWeights load_mhw(const std::filesystem::path& path, const Skeleton& skel,
                     std::size_t num_vertices) {
  const nlohmann::json j = read_json(path);
  const std::string file = path.string();
  if (!j.contains("weights") || !j["weights"].is_object())
    fail_at(file, "expected object 'weights'");
  std::vector<std::vector<std::pair<int, float>>> lists(num_vertices);
  for (auto it = j["weights"].begin(); it != j["weights"].end(); ++it) {
    const std::string where = fmt::format("{}: weights.{}", file, it.key());
    const int b = skel.find(it.key());
    if (b < 0) fail_at(where, "bone not in the skeleton");
    if (!it.value().is_array()) fail_at(where, "expected an array of [vertex, weight]");
    for (const auto& pair : it.value()) {
      if (!pair.is_array() || pair.size() != 2 || !pair[0].is_number_integer() ||
          !pair[1].is_number())
        fail_at(where, "expected [vertex, weight] pairs");
      const long v = pair[0].get<long>();
      const double x = pair[1].get<double>();
      if (v < 0 || std::size_t(v) >= num_vertices)
        fail_at(where, "vertex {} out of range (mesh has {})", v, num_vertices);
      if (!std::isfinite(x) || x < 0) fail_at(where, "weight {} must be finite and >= 0", x);
      lists[v].emplace_back(b, float(x));
    }
  }
  // Deterministic order within a vertex: by bone index.
  for (auto& l : lists) std::sort(l.begin(), l.end());
  SkinWeights w = SkinWeights::from_lists(lists);
  w.normalize();
  return w;
}

SubMesh extract_hand(const MakeHumanBase& base, const Skeleton& skel, const SkinWeights& w,
                     Side side, double threshold) {
  if (w.num_vertices() != base.positions.size())
    fail("extract_hand: {} weight rows for {} vertices", w.num_vertices(), base.positions.size());
  std::vector<char> mask(skel.size(), 0);
  for (std::size_t b = 0; b < skel.size(); ++b)
    mask[b] = is_hand_bone(skel.bones()[b].name, side) ? 1 : 0;
  std::vector<char> in(base.positions.size(), 0);
  for (std::size_t v = 0; v < base.positions.size(); ++v)
    in[v] = w.weight_on(v, mask) >= threshold ? 1 : 0;
  // Keep only the largest connected piece (normalized weights let a few stray vertices elsewhere
  // pass the threshold): union-find over the vertices of fully selected faces.
  {
    std::vector<int> parent(base.positions.size());
    for (std::size_t v = 0; v < parent.size(); ++v) parent[v] = int(v);
    auto find = [&](int a) {
      while (parent[a] != a) a = parent[a] = parent[parent[a]];
      return a;
    };
    for (const Vec3i& F : base.faces)
      if (in[F[0]] && in[F[1]] && in[F[2]])
        for (int c = 1; c < 3; ++c) parent[find(F[c])] = find(F[0]);
    std::vector<int> count(parent.size(), 0);
    for (const Vec3i& F : base.faces)
      if (in[F[0]] && in[F[1]] && in[F[2]]) ++count[find(F[0])];
    const int best = int(std::max_element(count.begin(), count.end()) - count.begin());
    for (std::size_t v = 0; v < in.size(); ++v)
      if (in[v] && find(int(v)) != best) in[v] = 0;
  }
  // Keep only the faces of the largest UV island: a face selected by its weights may belong to
  // another chart of the atlas (hm08 has one wrist face whose UVs lie at v = 0.83, far from the
  // hand island at v < 0.2); its UVs would stretch the bounding box used for the rescale below
  // and shrink the hand to a small part of the texture.
  std::vector<char> face_in(base.faces.size(), 0);
  // A face whose corners lie in two charts (its texture edge is many times longer, relative to
  // its 3D edge, than is typical) joins the charts in the connectivity below: drop it first.
  {
    std::vector<double> ratio;
    std::vector<double> face_ratio(base.faces.size(), 0.0);
    for (std::size_t f = 0; f < base.faces.size(); ++f) {
      const Vec3i& F = base.faces[f];
      if (!in[F[0]] || !in[F[1]] || !in[F[2]]) continue;
      const Vec3i& T = base.uv_faces[f];
      double worst = 0;
      for (int c = 0; c < 3; ++c) {
        const double l3 = (base.positions[F[(c + 1) % 3]] - base.positions[F[c]]).norm();
        const double lt = (base.uvs[T[(c + 1) % 3]] - base.uvs[T[c]]).norm();
        const double q = l3 > 0 ? lt / l3 : std::numeric_limits<double>::infinity();
        ratio.push_back(q);
        worst = std::max(worst, q);
      }
      face_ratio[f] = worst;
      face_in[f] = 1;
    }
    if (!ratio.empty()) {
      std::nth_element(ratio.begin(), ratio.begin() + ratio.size() / 2, ratio.end());
      const double median = ratio[ratio.size() / 2];
      for (std::size_t f = 0; f < base.faces.size(); ++f)
        if (face_in[f] && !(face_ratio[f] <= 8.0 * median)) face_in[f] = 0;
    }
  }
  {
    std::vector<int> parent(base.uvs.size());
    for (std::size_t t = 0; t < parent.size(); ++t) parent[t] = int(t);
    auto find = [&](int a) {
      while (parent[a] != a) a = parent[a] = parent[parent[a]];
      return a;
    };
    for (std::size_t f = 0; f < base.faces.size(); ++f) {
      if (!face_in[f]) continue;
      const Vec3i& T = base.uv_faces[f];
      for (int c = 1; c < 3; ++c) parent[find(T[c])] = find(T[0]);
    }
    std::vector<int> count(parent.size(), 0);
    for (std::size_t f = 0; f < base.faces.size(); ++f)
      if (face_in[f]) ++count[find(base.uv_faces[f][0])];
    const int best = int(std::max_element(count.begin(), count.end()) - count.begin());
    for (std::size_t f = 0; f < base.faces.size(); ++f)
      if (face_in[f] && find(base.uv_faces[f][0]) != best) face_in[f] = 0;
  }
  SubMesh out;
  std::vector<int> pos_new(base.positions.size(), -1), uv_new(base.uvs.size(), -1);
  for (std::size_t f = 0; f < base.faces.size(); ++f) {
    const Vec3i& F = base.faces[f];
    if (!face_in[f]) continue;
    Vec3i nf, nt;
    for (int c = 0; c < 3; ++c) {
      int& p = pos_new[F[c]];
      if (p < 0) {
        p = int(out.vertex_map.size());
        out.vertex_map.push_back(F[c]);
        out.mesh.positions.push_back(base.positions[F[c]]);
      }
      nf[c] = p;
      int& t = uv_new[base.uv_faces[f][c]];
      if (t < 0) {
        t = int(out.mesh.uvs.size());
        out.mesh.uvs.push_back(base.uvs[base.uv_faces[f][c]]);
      }
      nt[c] = t;
    }
    out.mesh.faces.push_back(nf);
    out.mesh.uv_faces.push_back(nt);
  }
  if (out.mesh.faces.empty()) fail("extract_hand: no faces above weight threshold {}", threshold);
  // Rescale the hand's UV island to fill the unit square (as the paper scales the hand mesh to
  // fit the texture space, Fig. 2.2b), keeping the aspect ratio, with a 2% margin.
  Eigen::AlignedBox2d box;
  for (const Vec2& t : out.mesh.uvs) box.extend(t);
  const double ext = std::max(box.sizes().x(), box.sizes().y());
  const double s = 0.96 / ext;
  const Vec2 off = Vec2(0.5, 0.5) - s * box.center();
  for (Vec2& t : out.mesh.uvs) t = s * t + off;
  out.mesh.name = side == Side::left ? "makehuman_hand_left" : "makehuman_hand_right";
  out.weights = w.remap(out.vertex_map);
  out.weights.normalize();
  return out;
}

Pose finger_flexion_pose(const Skeleton& skel, Side side, double flexion, double max_angle) {
  Pose p = Pose::rest(skel);
  const std::string suffix = side == Side::left ? ".L" : ".R";
  const auto& bones = skel.bones();
  // Palm normal from the skeleton: F = wrist -> middle finger base, T = little -> index finger
  // base (toward the thumb); for a left hand the palm faces F x T, for a right hand T x F.
  // (The rest fingers of hm08 are not reliably curled toward the palm: the joint centres of the
  // middle finger lie slightly on the back side of the line from its base to its tip, so the
  // rest curl cannot fix the sign.)
  const int wrist = skel.find("wrist" + suffix);
  const int mid = skel.find("finger3-1" + suffix);
  const int index = skel.find("finger2-1" + suffix);
  const int little = skel.find("finger5-1" + suffix);
  if (wrist < 0 || mid < 0 || index < 0 || little < 0)
    fail("finger_flexion_pose: the skeleton has no wrist{0}/finger2-1{0}/finger3-1{0}/finger5-1{0}",
         suffix);
  const Vec3 F = bones[mid].head - bones[wrist].head;
  const Vec3 T = bones[index].head - bones[little].head;
  const Vec3 palm = side == Side::left ? F.cross(T) : T.cross(F);
  for (int f = 1; f <= 5; ++f) {
    for (int k = 1; k <= 3; ++k) {
      const int b = skel.find(fmt::format("finger{}-{}{}", f, k, suffix));
      if (b < 0) continue;
      // Fingers curl toward the palm: the tail moves along +palm.
      const Vec3 x = bones[b].frame.col(0);
      const Vec3 motion = x.cross(bones[b].tail - bones[b].head);
      const double sign = motion.dot(palm) >= 0 ? 1.0 : -1.0;
      const double angle = flexion * max_angle * (f == 1 ? 0.5 : 1.0);
      p.rotate(b, 0, sign * angle);
    }
  }
  return p;
}

ScalarTrack finger_flexion_track(double duration) {
  if (!(duration > 0)) fail("finger_flexion_track: duration must be > 0, got {}", duration);
  return ScalarTrack({{0.0, 0.0}, {0.5 * duration, 1.0}, {duration, 0.0}}, Interp::smooth,
                     "finger_flexion");
}

}  // namespace follicle::anim
