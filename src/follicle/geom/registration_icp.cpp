#include "follicle/geom/registration_icp.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

#include "follicle/core/error.hpp"
#include "follicle/core/parallel.hpp"
#include "follicle/geom/adjacency.hpp"
#include "follicle/geom/sampling.hpp"
#include "follicle/geom/spatial_embree.hpp"

namespace follicle::geom {

double mesh_size(const TriMesh& mesh) {
  if (mesh.positions.empty()) return 0.0;
  return mesh.bounds().diagonal().norm();
}

namespace {

struct Samples {
  std::vector<Vec3> p, n;
};

Samples surface_samples(const Context& ctx, const TriMesh& mesh, std::size_t n, uint64_t seed) {
  Samples s;
  for (const auto& x : sample_uniform(ctx, mesh, n, seed)) {
    s.p.push_back(x.point);
    s.n.push_back(mesh.face_normal(static_cast<std::size_t>(x.face)));
  }
  return s;
}

struct Frame {
  Vec3 centre = Vec3::Zero();
  Mat3 axes = Mat3::Identity();  // columns: principal axes, largest variance first
  double rms = 0;                // RMS distance to the centre
};

Frame principal_frame(const std::vector<Vec3>& pts) {
  Frame f;
  for (const auto& p : pts) f.centre += p;
  f.centre /= double(pts.size());
  Mat3 c = Mat3::Zero();
  for (const auto& p : pts) {
    const Vec3 d = p - f.centre;
    c += d * d.transpose();
    f.rms += d.squaredNorm();
  }
  f.rms = std::sqrt(f.rms / double(pts.size()));
  Eigen::SelfAdjointEigenSolver<Mat3> es(c);
  for (int k = 0; k < 3; ++k) f.axes.col(k) = es.eigenvectors().col(2 - k);
  // Signs: each axis towards the side with the longer tail (third moment), so the frame turns
  // with the surface; then proper (det +1).
  for (int k = 0; k < 2; ++k) {
    double m3 = 0;
    for (const auto& p : pts) m3 += std::pow((p - f.centre).dot(f.axes.col(k)), 3);
    if (m3 < 0) f.axes.col(k) *= -1.0;
  }
  if (f.axes.determinant() < 0) f.axes.col(2) *= -1.0;
  return f;
}

/// `n` rotations spread evenly over SO(3): the super-Fibonacci spiral of unit quaternions
/// (Alexa 2022, "Super-Fibonacci spirals: fast, low-discrepancy sampling of SO(3)").
std::vector<Mat3> even_rotations(int n) {
  const double phi = std::sqrt(2.0), psi = 1.533751168755204288118041;
  std::vector<Mat3> out;
  for (int i = 0; i < n; ++i) {
    const double s = i + 0.5, r = std::sqrt(s / n), R = std::sqrt(1.0 - s / n);
    const double alpha = 2 * kPi * s / phi, beta = 2 * kPi * s / psi;
    out.push_back(
        Quat(R * std::cos(beta), r * std::sin(alpha), r * std::cos(alpha), R * std::sin(beta))
            .normalized()
            .toRotationMatrix());
  }
  return out;
}

/// Fractional ICP (Phillips et al. 2007): the number of the smallest distances to keep,
/// minimising RMS(k) / (k/n)^lambda over k >= min_overlap n. `d` holds +inf for dropped pairs.
struct Trim {
  std::size_t keep = 0;
  double rms = 0, score = std::numeric_limits<double>::infinity();
};

Trim ficp_trim(const std::vector<double>& d_sorted, double min_overlap, double lambda) {
  Trim t;
  const std::size_t n = d_sorted.size();
  std::size_t valid = 0;
  while (valid < n && std::isfinite(d_sorted[valid])) ++valid;
  if (valid == 0) return t;
  const std::size_t k0 =
      std::min(valid, std::max<std::size_t>(1, std::size_t(std::ceil(min_overlap * double(n)))));
  double sum = 0;
  for (std::size_t k = 1; k <= valid; ++k) {
    sum += d_sorted[k - 1] * d_sorted[k - 1];
    if (k < k0) continue;
    const double rms = std::sqrt(sum / double(k));
    const double score = rms / std::pow(double(k) / double(n), lambda);
    if (score < t.score) t = {k, rms, score};
  }
  return t;
}

struct Pairs {
  std::vector<Vec3> src, dst;  // source frame, target frame
  std::vector<Vec3> n;         // the target's unit normal at the pair (target frame)
  std::vector<double> d;       // [m] in the target frame, +inf when dropped
};

class RigidSolver {
 public:
  RigidSolver(const Context& ctx, const TriMesh& source, const TriMesh& target, const MeshQuery& sq,
              const MeshQuery& tq, const RigidRegistrationParams& p)
      : m_ctx(ctx), m_source(source), m_target(target), m_sq(sq), m_tq(tq), m_p(p) {}

  struct Result {
    Similarity xf;
    double score = std::numeric_limits<double>::infinity(), residual = 0;
    double overlap_source = 0, overlap_target = 0;
  };

  Result run(Similarity xf, const Samples& a, const Samples& b, int iterations,
             bool lock_rotation = false, bool lock_scale = false) const {
    Result r;
    for (int it = 0; it <= iterations; ++it) {
      Pairs pa = pair_source(xf, a), pb = pair_target(xf, b);
      // The target (the new head) should be covered by the source nearly everywhere but for
      // extra parts (shoulders); the source may cover much more than the target (a whole head
      // against a face mask), so its side keeps a small share cheaply.
      const auto ka = keep(pa, m_p.min_overlap_source, m_p.lambda_source);
      const auto kb = keep(pb, m_p.min_overlap, m_p.lambda);
      r.xf = xf;
      // Score: the share of samples with a partner within the inlier distance, the target's
      // twice (the new head must be covered; the template may reach past a mask's rim).
      // Lower is better.
      const auto share = [&](const Pairs& p) {
        std::size_t in = 0;
        for (double d : p.d) in += d < m_inlier ? 1 : 0;
        return double(in) / double(std::max<std::size_t>(1, p.d.size()));
      };
      r.score = 3.0 - (2.0 * share(pb) + share(pa));
      const double na = double(ka.trim.keep), nb = double(kb.trim.keep);
      r.residual =
          na + nb > 0
              ? std::sqrt((ka.trim.rms * ka.trim.rms * na + kb.trim.rms * kb.trim.rms * nb) /
                          (na + nb))
              : 0.0;
      r.overlap_source = share(pa);
      r.overlap_target = share(pb);
      if (it == iterations || ka.trim.keep + kb.trim.keep < 4) break;
      // Point-to-plane step (Chen & Medioni 1992) for a similarity, linearised about the kept
      // pairs' centroid m: x' = m + dt + (1 + delta) Rot(w) (x - m); residual (x' - c) . n.
      Vec3 m = Vec3::Zero();
      std::size_t cnt = 0;
      for (auto i : ka.idx) m += xf.apply(pa.src[i]), ++cnt;
      for (auto i : kb.idx) m += xf.apply(pb.src[i]), ++cnt;
      m /= double(cnt);
      Eigen::Matrix<double, 7, 7> JtJ = Eigen::Matrix<double, 7, 7>::Zero();
      Eigen::Matrix<double, 7, 1> Jtr = Eigen::Matrix<double, 7, 1>::Zero();
      const auto add = [&](const Vec3& src, const Vec3& dst, const Vec3& n) {
        const Vec3 x = xf.apply(src), q = x - m;
        Eigen::Matrix<double, 7, 1> j;
        j << q.cross(n), q.dot(n), n;
        const double res = (x - dst).dot(n);
        JtJ += j * j.transpose();
        Jtr += j * res;
      };
      for (auto i : ka.idx) add(pa.src[i], pa.dst[i], pa.n[i]);
      for (auto i : kb.idx) add(pb.src[i], pb.dst[i], pb.n[i]);
      JtJ.diagonal().array() += 1e-9 * JtJ.diagonal().mean() + 1e-30;
      if (lock_rotation) {  // scale and translation only
        JtJ.topRows<3>().setZero();
        JtJ.leftCols<3>().setZero();
        JtJ.topLeftCorner<3, 3>().setIdentity();
        Jtr.head<3>().setZero();
      }
      if (lock_scale) {
        JtJ.row(3).setZero();
        JtJ.col(3).setZero();
        JtJ(3, 3) = 1;
        Jtr[3] = 0;
      }
      const Eigen::Matrix<double, 7, 1> dx = JtJ.ldlt().solve(-Jtr);
      if (!dx.allFinite()) break;
      const Vec3 w = dx.head<3>();
      const double delta = std::clamp(dx[3], -0.2, 0.2);
      const Mat3 Rw =
          w.norm() > 0 ? Mat3(Eigen::AngleAxisd(w.norm(), w.normalized())) : Mat3::Identity();
      Similarity next;
      next.R = Rw * xf.R;
      next.s = (1 + delta) * xf.s;
      next.t = m + dx.tail<3>() + (1 + delta) * (Rw * (xf.t - m));
      const double change = (next.R - xf.R).norm() + std::abs(next.s / xf.s - 1.0) +
                            (next.t - xf.t).norm() / (xf.s * m_source_size);
      xf = next;
      if (change < 1e-7) {
        iterations = it + 1;  // one more round for the final pairs and score
      }
    }
    return r;
  }

  void set_source_size(double s) { m_source_size = s; }
  void set_inlier_distance(double d) { m_inlier = d; }

 private:
  struct Kept {
    Trim trim;
    std::vector<std::size_t> idx;
  };

  Kept keep(const Pairs& p, double min_overlap, double lambda) const {
    std::vector<std::size_t> order(p.d.size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t x, std::size_t y) { return p.d[x] < p.d[y]; });
    std::vector<double> sorted(order.size());
    for (std::size_t i = 0; i < order.size(); ++i) sorted[i] = p.d[order[i]];
    Kept k;
    k.trim = ficp_trim(sorted, min_overlap, lambda);
    k.idx.assign(order.begin(), order.begin() + std::ptrdiff_t(k.trim.keep));
    return k;
  }

  Pairs pair_source(const Similarity& xf, const Samples& a) const {
    Pairs p;
    const std::size_t n = a.p.size();
    p.src.resize(n), p.dst.resize(n), p.n.resize(n),
        p.d.assign(n, std::numeric_limits<double>::infinity());
    parallel_for(m_ctx, 0, n, [&](std::size_t i) {
      const auto cp = m_tq.closest_point(xf.apply(a.p[i]));
      p.src[i] = a.p[i];
      if (cp.face < 0) return;
      const Vec3 nt = m_target.face_normal(std::size_t(cp.face));
      if (std::abs(nt.dot(xf.R * a.n[i])) < m_p.normal_agreement) return;
      p.dst[i] = cp.point;
      p.n[i] = nt;
      p.d[i] = cp.distance;
    });
    return p;
  }

  Pairs pair_target(const Similarity& xf, const Samples& b) const {
    Pairs p;
    const std::size_t n = b.p.size();
    p.src.resize(n), p.dst.resize(n), p.n.resize(n),
        p.d.assign(n, std::numeric_limits<double>::infinity());
    parallel_for(m_ctx, 0, n, [&](std::size_t i) {
      const auto cp = m_sq.closest_point(xf.inverse(b.p[i]));
      p.dst[i] = b.p[i];
      if (cp.face < 0) return;
      const Vec3 ns = m_source.face_normal(std::size_t(cp.face));
      if (std::abs((xf.R * ns).dot(b.n[i])) < m_p.normal_agreement) return;
      p.src[i] = cp.point;
      p.n[i] = b.n[i];
      p.d[i] = xf.s * cp.distance;
    });
    return p;
  }

  const Context& m_ctx;
  const TriMesh& m_source;
  const TriMesh& m_target;
  const MeshQuery& m_sq;
  const MeshQuery& m_tq;
  const RigidRegistrationParams& m_p;
  double m_source_size = 1.0;
  double m_inlier = 0.0;
};

void check_mesh(const TriMesh& m, const char* what) {
  if (m.positions.empty() || m.faces.empty()) fail("registration: the {} mesh is empty", what);
  double area = 0;
  for (std::size_t f = 0; f < m.num_faces(); ++f) area += m.face_area(f);
  if (!(area > 0)) fail("registration: the {} mesh has no surface area", what);
}

}  // namespace

RigidRegistration register_rigid(const Context& ctx, const TriMesh& source, const TriMesh& target,
                                 const RigidRegistrationParams& params, const Mat3* initial_R) {
  params.validate();
  check_mesh(source, "source");
  check_mesh(target, "target");
  const MeshQuery sq(source), tq(target);
  RigidSolver solver(ctx, source, target, sq, tq, params);
  solver.set_source_size(mesh_size(source));
  // A coarse mesh's facets stand off a smooth surface by a fraction of an edge: the inlier
  // distance is at least half the target's mean edge length.
  double edges = 0;
  for (const auto& f : target.faces)
    for (int k = 0; k < 3; ++k)
      edges += (target.positions[std::size_t(f[k])] - target.positions[std::size_t(f[(k + 1) % 3])])
                   .norm();
  const double mean_edge = edges / (3.0 * double(target.num_faces()));
  solver.set_inlier_distance(std::max(params.inlier_distance * mesh_size(target), 0.5 * mean_edge));

  // Phase 1: every start (orientation x scale) a few coarse rounds; phase 2: the best dozen
  // further at more samples; phase 3: the best three refined. Each start puts the source's
  // centre on the target's; the scales bracket the RMS-radius ratio, which a mask against a
  // whole head or a bust against a bare head gets wrong by up to ~1.5x.
  const Samples a = surface_samples(ctx, source, params.samples, params.seed);
  const Samples b = surface_samples(ctx, target, params.samples, params.seed + 1);
  const Frame fa = principal_frame(a.p), fb = principal_frame(b.p);
  std::vector<Mat3> starts;
  const bool locked = initial_R != nullptr;  // rotation held through the search
  if (initial_R) {
    starts.push_back(*initial_R);
  } else {
    for (const auto& Q : even_rotations(params.rotations))
      starts.push_back(fb.axes * Q * fa.axes.transpose());
  }
  struct Start {
    Similarity xf;
    double score;
    int index;
  };
  std::vector<Start> tried;
  RigidRegistration out;
  const double s0 = fb.rms / fa.rms;
  const double scales[] = {1.0, 0.75, 1.0 / 0.75};
  const Samples a1 =
      surface_samples(ctx, source, std::max<uint64_t>(50, params.samples / 5), params.seed + 4);
  const Samples b1 =
      surface_samples(ctx, target, std::max<uint64_t>(50, params.samples / 5), params.seed + 5);
  for (std::size_t k = 0; k < starts.size(); ++k)
    for (double sc : scales) {
      Similarity xf;
      xf.R = starts[k];
      xf.s = s0 * sc;
      xf.t = fb.centre - xf.s * (xf.R * fa.centre);
      // Each start twice: scale free, and scale held (the three start scales then search it:
      // from a poor start a free scale can shrink the source onto a patch of the target, while
      // a held one can keep a good start from converging in the few coarse rounds).
      for (const bool hold : {false, true}) {
        const auto r = solver.run(xf, a1, b1, 6, locked, hold);
        out.start_scores.push_back(r.score);
        tried.push_back({r.xf, r.score, initial_R ? -1 : int(k)});
      }
    }
  const auto by_score = [](const Start& x, const Start& y) { return x.score < y.score; };
  std::stable_sort(tried.begin(), tried.end(), by_score);
  tried.resize(std::min<std::size_t>(16, tried.size()));
  for (auto& t : tried) {
    const auto r = solver.run(t.xf, a, b, params.iterations, locked, locked);
    t.xf = r.xf;
    t.score = r.score;
  }
  std::stable_sort(tried.begin(), tried.end(), by_score);

  const Samples fa_s = surface_samples(ctx, source, params.fine_samples, params.seed + 2);
  const Samples fb_s = surface_samples(ctx, target, params.fine_samples, params.seed + 3);
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < std::min<std::size_t>(3, tried.size()); ++k) {
    auto r = solver.run(tried[k].xf, fa_s, fb_s, params.fine_iterations);
    // A given orientation is refined, not abandoned: when the free refinement turns more than
    // 20 degrees away from it, the scale-and-translation fit stands.
    if (locked && Eigen::AngleAxisd(r.xf.R * initial_R->transpose()).angle() > 20.0 * kPi / 180.0)
      r = solver.run(tried[k].xf, fa_s, fb_s, params.fine_iterations, true);
    if (r.score < best) {
      best = r.score;
      out.xf = r.xf;
      out.residual = r.residual;
      out.score = r.score;
      out.overlap_source = r.overlap_source;
      out.overlap_target = r.overlap_target;
      out.start = tried[k].index;
    }
  }
  if (!std::isfinite(best))
    fail("registration: no start paired the two surfaces (do they overlap at all?)");
  return out;
}

NonrigidRegistration register_nonrigid(const Context& ctx, const TriMesh& source,
                                       const TriMesh& target, const Similarity& rigid,
                                       const std::vector<Landmark>& landmarks,
                                       const NonrigidRegistrationParams& params) {
  params.validate();
  check_mesh(source, "source");
  check_mesh(target, "target");
  const std::size_t n = source.num_vertices();
  for (const auto& l : landmarks)
    if (l.vertex < 0 || std::size_t(l.vertex) >= n || !l.target.allFinite())
      fail("registration: landmark vertex {} is not a source vertex", l.vertex);

  const MeshQuery tq(target);
  const auto tadj = build_adjacency(target);
  // A target edge on its open boundary: a closest point on it means the source runs past the
  // target's edge there (the back of a head past a mask's rim) and is not paired.
  std::vector<std::array<bool, 3>> boundary_edge(target.num_faces(), {false, false, false});
  for (std::size_t f = 0; f < target.num_faces(); ++f)
    for (int e = 0; e < 3; ++e) boundary_edge[f][std::size_t(e)] = tadj.face_neighbours[f][e] < 0;
  const auto sadj = build_adjacency(source);

  std::vector<Vec3> x0(n);
  for (std::size_t i = 0; i < n; ++i) x0[i] = rigid.apply(source.positions[i]);
  const double size = mesh_size(target);
  const double max_d = params.max_distance * size;

  // Graph Laplacian of the source (uniform weights): sum over edges |d_i - d_j|^2.
  using Sp = Eigen::SparseMatrix<double>;
  std::vector<Eigen::Triplet<double>> lap;
  for (std::size_t i = 0; i < n; ++i) {
    const auto nb = sadj.vertex_neighbours(i);
    lap.emplace_back(int(i), int(i), double(nb.size()));
    for (auto j : nb) lap.emplace_back(int(i), int(j), -1.0);
  }
  const auto N = Eigen::Index(n);
  Sp L(N, N);
  L.setFromTriplets(lap.begin(), lap.end());

  NonrigidRegistration out;
  out.positions = x0;
  out.matched.assign(n, 0);
  Eigen::MatrixX3d d = Eigen::MatrixX3d::Zero(Eigen::Index(n), 3);
  std::vector<Vec3> c(n);
  std::vector<double> dist(n, 0.0);
  TriMesh current = source;

  const int steps = params.steps;
  for (int step = 0; step < steps; ++step) {
    const double alpha = steps == 1 ? params.stiffness_end
                                    : params.stiffness_start *
                                          std::pow(params.stiffness_end / params.stiffness_start,
                                                   double(step) / double(steps - 1));
    for (int round = 0; round < params.rounds_per_step; ++round) {
      current.positions = out.positions;
      current.compute_normals();
      parallel_for(ctx, 0, n, [&](std::size_t i) {
        out.matched[i] = 0;
        const auto cp = tq.closest_point(out.positions[i], max_d);
        if (cp.face < 0) return;
        const auto f = std::size_t(cp.face);
        for (int e = 0; e < 3; ++e)  // edge e joins corners e and e+1: opposite weight e+2
          if (boundary_edge[f][std::size_t(e)] && cp.bary[(e + 2) % 3] < 1e-6) return;
        if (std::abs(target.face_normal(f).dot(current.normals[i])) < params.normal_agreement)
          return;
        out.matched[i] = 1;
        c[i] = cp.point;
        dist[i] = cp.distance;
      });
      std::vector<Eigen::Triplet<double>> w;
      Eigen::MatrixX3d rhs = Eigen::MatrixX3d::Zero(Eigen::Index(n), 3);
      for (std::size_t i = 0; i < n; ++i) {
        w.emplace_back(int(i), int(i), 1e-8);  // keeps parts with no pair solvable
        if (!out.matched[i]) continue;
        w.emplace_back(int(i), int(i), 1.0);
        rhs.row(Eigen::Index(i)) += (c[i] - x0[i]).transpose();
      }
      for (const auto& l : landmarks) {
        w.emplace_back(l.vertex, l.vertex, params.landmark_weight);
        rhs.row(l.vertex) +=
            params.landmark_weight * (l.target - x0[std::size_t(l.vertex)]).transpose();
      }
      Sp A(N, N);
      A.setFromTriplets(w.begin(), w.end());
      A += alpha * L;
      Eigen::SimplicialLDLT<Sp> solver(A);
      if (solver.info() != Eigen::Success) fail("registration: the deformation system is singular");
      d = solver.solve(rhs);
      if (!d.allFinite()) fail("registration: the deformation diverged (non-finite positions)");
      for (std::size_t i = 0; i < n; ++i)
        out.positions[i] = x0[i] + d.row(Eigen::Index(i)).transpose();
    }
  }

  // Final pairing for the report.
  std::vector<double> matched_d;
  parallel_for(ctx, 0, n, [&](std::size_t i) {
    const auto cp = tq.closest_point(out.positions[i], max_d);
    dist[i] = cp.face < 0 ? -1.0 : cp.distance;
  });
  for (std::size_t i = 0; i < n; ++i)
    if (out.matched[i] && dist[i] >= 0) matched_d.push_back(dist[i]);
  if (!matched_d.empty()) {
    double s2 = 0;
    for (double x : matched_d) s2 += x * x;
    out.rms = std::sqrt(s2 / double(matched_d.size()));
    std::sort(matched_d.begin(), matched_d.end());
    out.p95 = matched_d[std::min(matched_d.size() - 1,
                                 std::size_t(std::ceil(0.95 * double(matched_d.size()))) - 1)];
  }
  out.matched_fraction = double(matched_d.size()) / double(n);
  return out;
}

}  // namespace follicle::geom
