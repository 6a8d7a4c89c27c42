#include "follicle/skin/muscles_waters1987.hpp"

#include <algorithm>
#include <cmath>
#include <set>

#include "follicle/core/error.hpp"
#include "follicle/core/parallel.hpp"

namespace follicle::skin {

void LinearMuscle::validate() const {
  const std::string where = "muscle '" + name + "'";
  validate_params(*this, where);
  if ((insertion - origin).norm() < 1e-9) fail_at(where, "origin and insertion coincide");
  if (profile != "waters" && profile != "smooth")
    fail_at(where, "profile '{}' is not one of: waters, smooth", profile);
  if (falloff_start >= falloff_end)
    fail_at(where, "falloff_start {} must be smaller than falloff_end {}", falloff_start,
            falloff_end);
}

void SphincterMuscle::validate() const {
  const std::string where = "sphincter '" + name + "'";
  validate_params(*this, where);
  if (semi_axis_a.norm() < 1e-9 || semi_axis_b.norm() < 1e-9 ||
      semi_axis_a.cross(semi_axis_b).norm() < 1e-12)
    fail_at(where, "semi-axes must be non-zero and not parallel");
}

void JawParams::validate() const {
  validate_params(*this, "jaw");
  if (enabled && (axis.norm() < 1e-9 || plane_normal.norm() < 1e-9))
    fail_at("jaw", "axis and plane_normal must be non-zero");
}

void MuscleSet::validate() const {
  std::set<std::string> names;
  for (std::size_t i = 0; i < linear.size(); ++i) {
    if (linear[i].name.empty()) fail_at(fmt::format("linear[{}]", i), "a muscle needs a name");
    linear[i].validate();
    if (!names.insert(linear[i].name).second)
      fail_at(fmt::format("linear[{}]", i), "duplicate muscle name '{}'", linear[i].name);
  }
  for (std::size_t i = 0; i < sphincter.size(); ++i) {
    if (sphincter[i].name.empty())
      fail_at(fmt::format("sphincter[{}]", i), "a muscle needs a name");
    sphincter[i].validate();
    if (!names.insert(sphincter[i].name).second)
      fail_at(fmt::format("sphincter[{}]", i), "duplicate muscle name '{}'", sphincter[i].name);
  }
  jaw.validate();
  for (const auto& e : expressions) {
    e.validate();
    for (const auto& [m, k] : e.contractions) {
      (void)k;
      muscle_index(m);  // throws with did-you-mean
    }
    if (std::abs(e.jaw_angle) > jaw.max_angle + 1e-12)
      fail_at("expression '" + e.name + "'", "jaw_angle {} exceeds jaw.max_angle {}", e.jaw_angle,
              jaw.max_angle);
  }
}

std::vector<std::string> MuscleSet::muscle_names() const {
  std::vector<std::string> out;
  for (const auto& m : linear) out.push_back(m.name);
  for (const auto& m : sphincter) out.push_back(m.name);
  return out;
}

int MuscleSet::muscle_index(const std::string& name) const {
  const auto names = muscle_names();
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return int(i);
  const std::string dym = did_you_mean(name, names);
  fail("unknown muscle '{}'{}", name,
       dym.empty() ? std::string() : " (did you mean '" + dym + "'?)");
}

const Expression& MuscleSet::expression(const std::string& name) const {
  std::vector<std::string> names;
  for (const auto& e : expressions) {
    if (e.name == name) return e;
    names.push_back(e.name);
  }
  const std::string dym = did_you_mean(name, names);
  fail("unknown expression '{}'{}", name,
       dym.empty() ? std::string() : " (did you mean '" + dym + "'?)");
}

MusclePose pose_from_expression(const MuscleSet& set, const Expression& e, double weight) {
  MusclePose p;
  p.contractions.assign(set.num_muscles(), 0.0);
  for (const auto& [name, k] : e.contractions)
    p.contractions[std::size_t(set.muscle_index(name))] = weight * k;
  p.jaw_angle = weight * e.jaw_angle;
  return p;
}

MusclePose blend_poses(const MusclePose& a, const MusclePose& b, double t) {
  if (a.contractions.size() != b.contractions.size())
    fail("blend_poses: poses have {} and {} muscles", a.contractions.size(), b.contractions.size());
  MusclePose p;
  p.contractions.resize(a.contractions.size());
  for (std::size_t i = 0; i < p.contractions.size(); ++i)
    p.contractions[i] = (1 - t) * a.contractions[i] + t * b.contractions[i];
  p.jaw_angle = (1 - t) * a.jaw_angle + t * b.jaw_angle;
  const std::size_t ns = std::max(a.shape_weights.size(), b.shape_weights.size());
  if ((!a.shape_weights.empty() && a.shape_weights.size() != ns) ||
      (!b.shape_weights.empty() && b.shape_weights.size() != ns))
    fail("blend_poses: poses have {} and {} shape weights", a.shape_weights.size(),
         b.shape_weights.size());
  p.shape_weights.resize(ns);
  for (std::size_t i = 0; i < ns; ++i) {
    const double wa = a.shape_weights.empty() ? 0.0 : a.shape_weights[i];
    const double wb = b.shape_weights.empty() ? 0.0 : b.shape_weights[i];
    p.shape_weights[i] = (1 - t) * wa + t * wb;
  }
  return p;
}

double linear_muscle_factor(const LinearMuscle& m, const Vec3& p) {
  const Vec3 va = m.insertion - m.origin;  // muscle vector (tail - head in Waters' code)
  const Vec3 vb = p - m.origin;
  const double valen = va.norm(), vblen = vb.norm();
  if (valen <= 0 || vblen <= 0) return 0.0;
  const double cos_zone = std::cos(m.zone);
  const double cosa = va.dot(vb) / (valen * vblen);
  if (cosa < cos_zone || vblen > m.falloff_end) return 0.0;
  if (m.profile == "smooth") {
    // C1 variant (see LinearMuscle): smoothstep in the angular coordinate, raised cosine radially.
    const double t = std::clamp((cosa - cos_zone) / (1.0 - cos_zone), 0.0, 1.0);
    const double angular = t * t * (3.0 - 2.0 * t);
    double radial = 1.0;
    if (vblen >= m.falloff_start) {
      const double x = (vblen - m.falloff_start) / (m.falloff_end - m.falloff_start);
      radial = 0.5 * (1.0 + std::cos(x * kPi));
    }
    return -angular * radial;
  }
  const double angular = 1.0 - cosa / cos_zone;  // <= 0 inside the zone: pulls toward origin
  double radial = 1.0;                           // cosine radial fall-off
  if (vblen >= m.falloff_start) {
    const double percent = (vblen - m.falloff_start) / (m.falloff_end - m.falloff_start);
    radial = std::cos(percent * 0.5 * kPi);
  }
  return angular * radial;
}

namespace {

double sphincter_factor(const SphincterMuscle& m, const Vec3& p, Vec3* pull) {
  const double a = m.semi_axis_a.norm(), b = m.semi_axis_b.norm();
  const Vec3 ea = m.semi_axis_a / a;
  const Vec3 eb = (m.semi_axis_b - m.semi_axis_b.dot(ea) * ea).normalized();
  const Vec3 n = ea.cross(eb);
  const Vec3 d = p - m.center;
  const double z = std::abs(d.dot(n));
  if (z >= m.depth) return 0.0;
  const double x = d.dot(ea), y = d.dot(eb);
  const double rho = std::sqrt((x / a) * (x / a) + (y / b) * (y / b));
  if (rho >= 1.0) return 0.0;
  double f = 1.0;
  if (rho > m.falloff_start)  // raised cosine: 0 with zero slope at the outline
    f = 0.5 * (1.0 + std::cos((rho - m.falloff_start) / (1.0 - m.falloff_start) * kPi));
  const double zt = std::clamp((z - 0.5 * m.depth) / (0.5 * m.depth), 0.0, 1.0);
  f *= 1.0 - zt * zt * (3.0 - 2.0 * zt);  // smooth fade across the depth limit
  *pull = -(x * ea + y * eb);             // toward the centre within the ellipse plane
  return f;
}

double smoothstep01(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * (3 - 2 * x);
}

}  // namespace

MuscleField::MuscleField(const MuscleSet& set, const std::vector<Vec3>& rest) : m_jaw(set.jaw) {
  set.validate();
  m_num_muscles = set.num_muscles();
  m_offsets.assign(rest.size() + 1, 0);
  std::vector<std::vector<Entry>> per(rest.size());
  for (std::size_t i = 0; i < rest.size(); ++i) {
    for (std::size_t m = 0; m < set.linear.size(); ++m) {
      const double c = linear_muscle_factor(set.linear[m], rest[i]);
      if (c != 0.0) per[i].push_back({int(m), c * (rest[i] - set.linear[m].origin)});
    }
    for (std::size_t s = 0; s < set.sphincter.size(); ++s) {
      Vec3 pull;
      const double f = sphincter_factor(set.sphincter[s], rest[i], &pull);
      if (f > 0.0) per[i].push_back({int(set.linear.size() + s), f * pull});
    }
    m_offsets[i + 1] = m_offsets[i] + per[i].size();
  }
  m_entries.reserve(m_offsets.back());
  for (auto& v : per) m_entries.insert(m_entries.end(), v.begin(), v.end());
  if (m_jaw.enabled) {
    const Vec3 n = m_jaw.plane_normal.normalized();
    for (std::size_t i = 0; i < rest.size(); ++i) {
      const double w =
          smoothstep01(((rest[i] - m_jaw.pivot).dot(n) - m_jaw.offset) / m_jaw.blend_width);
      if (w > 0) m_jaw_weights.emplace_back(int(i), w);
    }
  }
}

void MuscleField::apply(const Context& ctx, const MusclePose& pose, const std::vector<Vec3>& rest,
                        std::vector<Vec3>& out) const {
  if (rest.size() != num_vertices())
    fail("MuscleField: {} rest vertices, built for {}", rest.size(), num_vertices());
  if (pose.contractions.size() != m_num_muscles)
    fail("MuscleField: pose has {} contractions for {} muscles", pose.contractions.size(),
         m_num_muscles);
  out.resize(rest.size());
  const double* k = pose.contractions.data();
  parallel_for(
      ctx, 0, rest.size(),
      [&](std::size_t i) {
        Vec3 p = rest[i];
        for (std::size_t e = m_offsets[i]; e < m_offsets[i + 1]; ++e)
          p += k[m_entries[e].muscle] * m_entries[e].d;
        out[i] = p;
      },
      1024);
  if (m_jaw.enabled && pose.jaw_angle != 0.0) {
    const Eigen::AngleAxisd rot(pose.jaw_angle, m_jaw.axis.normalized());
    const Mat3 R = rot.toRotationMatrix();
    parallel_for(
        ctx, 0, m_jaw_weights.size(),
        [&](std::size_t j) {
          const auto [i, w] = m_jaw_weights[j];
          const Vec3 p = out[std::size_t(i)];
          const Vec3 q = R * (p - m_jaw.pivot) + m_jaw.pivot;
          out[std::size_t(i)] = p + w * (q - p);
        },
        1024);
  }
}

std::vector<int> MuscleField::influenced_vertices(int muscle) const {
  std::vector<int> out;
  for (std::size_t i = 0; i + 1 < m_offsets.size(); ++i)
    for (std::size_t e = m_offsets[i]; e < m_offsets[i + 1]; ++e)
      if (m_entries[e].muscle == muscle) out.push_back(int(i));
  return out;
}

}  // namespace follicle::skin
