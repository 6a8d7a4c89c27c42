#include "follicle/skin/hand_rig.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "follicle/core/error.hpp"
#include "follicle/core/parallel.hpp"
#include "follicle/skin/face_rig.hpp"

namespace follicle::skin {

namespace {

std::string suffix(bool left) {
  return left ? ".L" : ".R";
}

bool is_hand_bone(const std::string& name, bool left) {
  const std::string s = suffix(left);
  if (name.size() < 2 || name.compare(name.size() - 2, 2, s) != 0) return false;
  return name.rfind("finger", 0) == 0 || name.rfind("metacarpal", 0) == 0 ||
         name.rfind("wrist", 0) == 0;
}

/// Moeller-Trumbore ray/triangle test: distance along the (unit) ray and barycentrics, or false.
/// Hand-written: a few hundred rays against ~3k triangles once at construction; building an
/// Embree scene would cost more than the brute-force loop.
bool ray_triangle(const Vec3& o, const Vec3& d, const Vec3& a, const Vec3& b, const Vec3& c,
                  double& t, double& b1, double& b2) {
  const Vec3 e1 = b - a, e2 = c - a;
  const Vec3 p = d.cross(e2);
  const double det = e1.dot(p);
  if (std::abs(det) < 1e-18) return false;
  const double inv = 1.0 / det;
  const Vec3 s = o - a;
  b1 = s.dot(p) * inv;
  if (b1 < 0 || b1 > 1) return false;
  const Vec3 q = s.cross(e1);
  b2 = d.dot(q) * inv;
  if (b2 < 0 || b1 + b2 > 1) return false;
  t = e2.dot(q) * inv;
  return t > 0;
}

struct Hit {
  Vec3 x;
  Vec2 uv;
};

bool first_hit(const geom::TriMesh& m, const Vec3& o, const Vec3& d, Hit& hit) {
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t f = 0; f < m.faces.size(); ++f) {
    const Vec3i& F = m.faces[f];
    double t, b1, b2;
    if (!ray_triangle(o, d, m.positions[F[0]], m.positions[F[1]], m.positions[F[2]], t, b1, b2))
      continue;
    if (t >= best) continue;
    best = t;
    const Vec3i& T = m.uv_faces[f];
    hit.x = o + t * d;
    hit.uv = (1 - b1 - b2) * m.uvs[T[0]] + b1 * m.uvs[T[1]] + b2 * m.uvs[T[2]];
  }
  return std::isfinite(best);
}

/// Distance from p to segment ab.
double segment_distance(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double l2 = ab.squaredNorm();
  const double t = l2 > 0 ? std::clamp((p - a).dot(ab) / l2, 0.0, 1.0) : 0.0;
  return (p - (a + t * ab)).norm();
}

/// Refined-mesh skinning weights: new vertices average their two parents' weights (the same
/// rule as RefinedMesh::propagate for positions, so the rest pose stays exact).
anim::SkinWeights propagate_weights(const anim::SkinWeights& w, const RefinedMesh& r) {
  std::vector<std::vector<std::pair<int, float>>> lists(w.num_vertices());
  for (std::size_t v = 0; v < lists.size(); ++v)
    for (uint32_t k = w.offsets[v]; k < w.offsets[v + 1]; ++k)
      lists[v].emplace_back(w.bone[k], w.weight[k]);
  lists.reserve(r.mesh.positions.size());
  for (const auto& p : r.parents) {
    std::vector<std::pair<int, float>> m;
    for (int c = 0; c < 2; ++c)
      for (const auto& [b, x] : lists[std::size_t(p[c])]) {
        const int bone = b;  // (a structured binding in a lambda capture needs clang 16)
        auto it = std::find_if(m.begin(), m.end(), [&](const auto& e) { return e.first == bone; });
        if (it == m.end())
          m.emplace_back(b, 0.5f * x);
        else
          it->second += 0.5f * x;
      }
    std::sort(m.begin(), m.end());
    lists.push_back(std::move(m));
  }
  anim::SkinWeights out = anim::SkinWeights::from_lists(lists);
  out.normalize();
  return out;
}

}  // namespace

double texel_coverage(const TexelMap& t) {
  return t.size > 0 ? double(t.covered.size()) / (double(t.size) * t.size) : 0.0;
}

std::unique_ptr<HandRig> HandRig::load(const Context& ctx,
                                       const std::filesystem::path& makehuman_dir,
                                       const HandRigParams& params) {
  const auto base = anim::load_makehuman_obj(makehuman_dir / "base.obj");
  anim::Skeleton skel = anim::load_mhskel(makehuman_dir / "default.mhskel", base.positions);
  const auto w = anim::load_mhw(makehuman_dir / "default_weights.mhw", skel, base.positions.size());
  return std::make_unique<HandRig>(ctx, base, std::move(skel), w, params);
}

HandRig::HandRig(const Context& ctx, const anim::MakeHumanBase& base, anim::Skeleton skel,
                 const anim::SkinWeights& weights, const HandRigParams& params)
    : m_params(params), m_skel(std::move(skel)) {
  m_params.validate();
  m_hand =
      anim::extract_hand(base, m_skel, weights, params.left ? anim::Side::left : anim::Side::right,
                         params.weight_threshold);
  if (params.joint_wrinkles) build_joint_wrinkles();
  // Adaptive refinement around the joint furrows (paper §8: 4,000 -> 34,000 triangles).
  m_refined = refine_around_wrinkles(m_hand.mesh, m_wrinkles, params.refine);
  m_rest = m_refined.mesh;
  m_rest.name = m_hand.mesh.name;
  m_weights = propagate_weights(m_hand.weights, m_refined);
  m_layer = std::make_unique<WrinkleLayer>(m_rest, m_wrinkles, 10.0, ShrinkageMethod::deformation);
  {
    std::vector<Vec3> face_n;
    std::vector<double> face_area;
    compute_vertex_normals(ctx, m_rest, m_layer->texture_mesh(), m_rest.positions, face_n,
                           face_area, m_rest_normals);
  }
  m_fine = generate_fine_wrinkles(ctx, m_rest, fine_keys(), params.fine);
  m_fine_anim = std::make_unique<FineWrinkleAnimator>(m_rest, m_fine);
  m_track = anim::finger_flexion_track(2.0);
}

HandRig::~HandRig() = default;

anim::Pose HandRig::pose(double flexion) const {
  return anim::finger_flexion_pose(m_skel, m_params.left ? anim::Side::left : anim::Side::right,
                                   flexion, m_params.max_flexion);
}

void HandRig::build_joint_wrinkles() {
  const geom::TriMesh& m = m_hand.mesh;
  const auto& bones = m_skel.bones();
  // Palm-ward motion of each bone's tail under a small flexion, relative to its parent: the
  // dorsal side of a joint is the opposite direction.
  const auto xf = anim::skinning_transforms(m_skel, pose(0.05));
  // Global texture scale [m per uv unit] for the seam check below.
  double a3 = 0, at = 0;
  for (std::size_t f = 0; f < m.faces.size(); ++f) {
    const Vec3i& F = m.faces[f];
    const Vec3i& T = m.uv_faces[f];
    a3 +=
        0.5 *
        (m.positions[F[1]] - m.positions[F[0]]).cross(m.positions[F[2]] - m.positions[F[0]]).norm();
    const Vec2 e1 = m.uvs[T[1]] - m.uvs[T[0]], e2 = m.uvs[T[2]] - m.uvs[T[0]];
    at += 0.5 * std::abs(e1.x() * e2.y() - e1.y() * e2.x());
  }
  const double scale = at > 0 ? std::sqrt(a3 / at) : 1.0;
  const int n = m_params.creases_per_joint;
  for (int finger = 1; finger <= 5; ++finger)
    for (int seg = 2; seg <= 3; ++seg) {
      const std::string name = fmt::format("finger{}-{}{}", finger, seg, suffix(m_params.left));
      const int b = m_skel.find(name);
      if (b < 0 || bones[b].parent < 0) continue;
      const anim::Bone& bone = bones[b];
      const Vec3 y = (bone.tail - bone.head).normalized();
      Vec3 palm = xf.apply(b, bone.tail) - xf.apply(bone.parent, bone.tail);
      palm -= y * y.dot(palm);
      if (palm.norm() < 1e-12) continue;
      for (int palmar = 0; palmar < (m_params.palmar_creases ? 2 : 1); ++palmar) {
        const Vec3 dorsal = palmar ? Vec3(palm.normalized()) : Vec3(-palm.normalized());
        const Vec3 side = y.cross(dorsal);
        for (int k = 0; k < n; ++k) {
          const Vec3 o = bone.head + (k - 0.5 * (n - 1)) * m_params.crease_spacing * y;
          // Four hits across the back of the joint, at t = 0, 1/3, 2/3, 1 of the Bezier curve;
          // the arc shrinks if the hits straddle a UV seam.
          double arc = m_params.crease_half_arc;
          for (int attempt = 0; attempt < 5; ++attempt, arc *= 0.75) {
            std::array<Hit, 4> h;
            bool ok = true;
            for (int i = 0; i < 4 && ok; ++i) {
              const double phi = arc * (-1.0 + 2.0 * i / 3.0);
              const Vec3 d = std::cos(phi) * dorsal + std::sin(phi) * side;
              ok = first_hit(m, o, d, h[i]);
            }
            for (int i = 0; i < 3 && ok; ++i) {
              const double d3 = (h[i + 1].x - h[i].x).norm();
              const double duv = (h[i + 1].uv - h[i].uv).norm() * scale;
              if (duv > 3.0 * d3 + 1e-4) ok = false;  // a UV seam between the hits
            }
            if (!ok) continue;
            // Interpolating Bezier: B(0) = s0, B(1/3) = s1, B(2/3) = s2, B(1) = s3.
            const Vec2 p0 = h[0].uv, p3 = h[3].uv;
            const Vec2 A = 27.0 * h[1].uv - 8.0 * p0 - p3;
            const Vec2 B = 27.0 * h[2].uv - p0 - 8.0 * p3;
            LargeWrinkle w;
            w.name = fmt::format("{}{}#{}", name, palmar ? "/palm" : "", k);
            w.control = {p0, (2.0 * A - B) / 18.0, (2.0 * B - A) / 18.0, p3};
            w.depth = m_params.joint_depth;
            w.width = m_params.joint_width;
            w.r = m_params.joint_r;
            w.end_taper = m_params.joint_end_taper;
            m_wrinkles.push_back(w);
            m_info.push_back({name, k, palmar != 0});
            break;
          }
        }
      }
    }
}

std::array<std::vector<DirectionKey>, 2> HandRig::fine_keys() const {
  const geom::TriMesh& m = m_rest;
  const auto& bones = m_skel.bones();
  std::vector<int> hand_bones;
  for (std::size_t b = 0; b < bones.size(); ++b)
    if (is_hand_bone(bones[b].name, m_params.left)) hand_bones.push_back(int(b));
  // Rest normals and one incident face per uv vertex.
  std::vector<Vec3> normals(m.positions.size(), Vec3::Zero());
  std::vector<int> face_of_uv(m.uvs.size(), -1), pos_of_uv(m.uvs.size(), -1);
  for (std::size_t f = 0; f < m.faces.size(); ++f) {
    const Vec3i& F = m.faces[f];
    const Vec3 nf =
        (m.positions[F[1]] - m.positions[F[0]]).cross(m.positions[F[2]] - m.positions[F[0]]);
    for (int c = 0; c < 3; ++c) {
      normals[F[c]] += nf;
      const int t = m.uv_faces[f][c];
      if (face_of_uv[t] < 0) {
        face_of_uv[t] = int(f);
        pos_of_uv[t] = F[c];
      }
    }
  }
  std::array<std::vector<DirectionKey>, 2> keys;
  const int stride = m_params.fine_key_stride;
  for (std::size_t t = 0; t < m.uvs.size(); t += std::size_t(stride)) {
    const int f = face_of_uv[t];
    if (f < 0) continue;
    const Vec3& p = m.positions[pos_of_uv[t]];
    const Vec3 nrm = normals[pos_of_uv[t]].normalized();
    int nb = -1;
    double best = std::numeric_limits<double>::infinity();
    for (int b : hand_bones) {
      const double d = segment_distance(p, bones[b].head, bones[b].tail);
      if (d < best) {
        best = d;
        nb = b;
      }
    }
    if (nb < 0) continue;
    Vec3 y = (bones[nb].tail - bones[nb].head).normalized();
    y -= nrm * nrm.dot(y);
    if (y.norm() < 0.3) continue;  // finger tips: the bone runs into the skin
    y.normalize();
    const Vec3 c = nrm.cross(y);  // around the finger / across the back of the hand
    // 3D tangent -> texture direction through the face's [Pu Pv] (least squares).
    const Vec3i& F = m.faces[f];
    const Vec3i& T = m.uv_faces[f];
    const Vec3 e1 = m.positions[F[1]] - m.positions[F[0]];
    const Vec3 e2 = m.positions[F[2]] - m.positions[F[0]];
    const Vec2 d1 = m.uvs[T[1]] - m.uvs[T[0]], d2 = m.uvs[T[2]] - m.uvs[T[0]];
    const double det = d1.x() * d2.y() - d2.x() * d1.y();
    if (std::abs(det) < 1e-14) continue;
    Eigen::Matrix<double, 3, 2> J;
    J.col(0) = (e1 * d2.y() - e2 * d1.y()) / det;  // Pu
    J.col(1) = (e2 * d1.x() - e1 * d2.x()) / det;  // Pv
    const Eigen::Matrix2d JtJ = J.transpose() * J;
    if (std::abs(JtJ.determinant()) < 1e-30) continue;
    auto to_uv = [&](const Vec3& d3) -> Vec2 {
      const Vec2 x = JtJ.inverse() * (J.transpose() * d3);
      return x.norm() > 0 ? Vec2(x.normalized()) : Vec2::Zero();
    };
    const double a = m_params.fine_angle;
    keys[0].push_back({int(t), to_uv(c) * m_params.fine_m0});
    keys[1].push_back({int(t), to_uv(std::cos(a) * c + std::sin(a) * y) * m_params.fine_m1});
  }
  return keys;
}

void HandRig::update(const Context& ctx, double flexion, HandState& s,
                     const HandUpdateOptions& opt) const {
  s.flexion = flexion;
  const anim::SkinningTransforms xf = anim::skinning_transforms(m_skel, pose(flexion));
  anim::skin_lbs(ctx, m_rest.positions, m_weights, xf, s.animated);
  const TextureSpaceMesh& tex = m_layer->texture_mesh();
  const std::size_t nv = s.animated.size();
  if (opt.joint_wrinkles && !m_wrinkles.empty()) {
    // Normals of the skinned surface by blending the rest normals with the bones' rotations
    // (n' ~ sum w_i R_i n): the wrinkle displacement only needs a smooth normal field, and this
    // saves one full face-normal pass per frame.
    s.normals.resize(nv);
    parallel_for(
        ctx, 0, nv,
        [&](std::size_t v) {
          const Vec3& n = m_rest_normals[v];
          Vec3 b = Vec3::Zero();
          for (uint32_t k = m_weights.offsets[v]; k < m_weights.offsets[v + 1]; ++k)
            b += double(m_weights.weight[k]) * (n + xf.A[m_weights.bone[k]] * n);
          const double l = b.norm();
          s.normals[v] = l > 0 ? Vec3(b / l) : n;
        },
        2048);
    m_layer->heights(ctx, s.animated, s.joint_height);  // (2.3)(2.4)(2.1) M(s) S(l)
    s.positions.resize(nv);
    parallel_for(
        ctx, 0, nv,
        [&](std::size_t i) { s.positions[i] = s.animated[i] + s.joint_height[i] * s.normals[i]; },
        2048);
  } else {
    s.joint_height.assign(nv, 0.0);
    s.positions = s.animated;
  }
  compute_vertex_normals(ctx, m_rest, tex, s.positions, s.face_n, s.face_area, s.normals);
  if (opt.fine_shrinkage || opt.fine_relief) {
    m_fine_anim->shrinkage(ctx, s.animated, s.fine_shrinkage);                    // (2.3) per field
    if (opt.fine_relief) m_fine_anim->modulate(ctx, s.fine_shrinkage, s.relief);  // (2.4)
  }
}

geom::TriMesh HandRig::deformed_mesh(const HandState& s) const {
  geom::TriMesh m;
  m.positions = s.positions;
  m.faces = m_rest.faces;
  m.uvs = m_rest.uvs;
  m.uv_faces = m_rest.uv_faces;
  m.normals = s.normals;
  m.name = m_rest.name;
  return m;
}

HandFrame HandRig::frame_at_flexion(const Context& ctx, double flexion, bool wrinkles) const {
  HandState s;
  HandUpdateOptions opt;
  opt.joint_wrinkles = opt.fine_shrinkage = opt.fine_relief = wrinkles;
  update(ctx, flexion, s, opt);
  HandFrame out;
  out.flexion = flexion;
  out.bump_strength = m_params.bump_strength;
  out.mesh = std::make_shared<const geom::TriMesh>(deformed_mesh(s));
  if (wrinkles) {
    auto h = std::make_shared<image::ImageF>(std::move(s.relief));
    const float depth = float(m_fine.depth_m);
    for (float& x : h->storage()) x *= depth;  // relief units -> metres
    out.height_m = std::move(h);
  }
  return out;
}

HandFrame HandRig::frame(const Context& ctx, double t, bool wrinkles) const {
  return frame_at_flexion(ctx, std::clamp(m_track.value(t), 0.0, 1.0), wrinkles);
}

}  // namespace follicle::skin
