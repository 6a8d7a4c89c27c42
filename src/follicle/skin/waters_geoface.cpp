#include "follicle/skin/waters_geoface.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "follicle/core/error.hpp"

namespace follicle::skin {

namespace {

// Whitespace-token reader that knows the line of each token (for error messages).
class Tokens {
 public:
  explicit Tokens(const std::filesystem::path& p) : m_file(p.string()) {
    std::ifstream in(p);
    if (!in) fail_at(m_file, "cannot open the file");
    std::string line;
    int ln = 0;
    while (std::getline(in, line)) {
      ++ln;
      std::istringstream ss(line);
      std::string t;
      while (ss >> t) m_tok.emplace_back(t, ln);
    }
  }
  bool done() const { return m_i >= m_tok.size(); }
  std::string word(const char* what) {
    if (done()) fail_at(m_file, "unexpected end of file, expected {}", what);
    return m_tok[m_i++].first;
  }
  double number(const char* what) {
    const int ln = done() ? 0 : m_tok[m_i].second;
    const std::string t = word(what);
    try {
      std::size_t pos = 0;
      const double v = std::stod(t, &pos);
      if (pos != t.size() || !std::isfinite(v)) throw std::invalid_argument(t);
      return v;
    } catch (const std::exception&) {
      fail_at(m_file + ":" + std::to_string(ln), "expected {} (a number), got '{}'", what, t);
    }
  }
  int integer(const char* what) {
    const double v = number(what);
    if (v != std::floor(v)) fail_at(m_file, "expected {} (an integer), got {}", what, v);
    return int(v);
  }
  const std::string& file() const { return m_file; }

 private:
  std::string m_file;
  std::vector<std::pair<std::string, int>> m_tok;
  std::size_t m_i = 0;
};

}  // namespace

WatersFace load_waters_geoface(const std::filesystem::path& dir, double s) {
  if (!(s > 0)) fail("load_waters_geoface: metres_per_unit must be positive, got {}", s);
  WatersFace out;
  // Vertices of the left half.
  Tokens fl(dir / "faceline.dat");
  const int nv = fl.integer("the vertex count");
  if (nv <= 0 || nv > 1000000) fail_at(fl.file(), "vertex count {} out of range", nv);
  std::vector<Vec3> half(static_cast<std::size_t>(nv));
  for (auto& p : half) {
    p.x() = fl.number("x");
    p.y() = fl.number("y");
    p.z() = fl.number("z");
  }
  // Mirror: vertex i -> i (left) and mirror index (right); x = 0 vertices are shared (welded).
  std::vector<int> mirror(static_cast<std::size_t>(nv));
  out.mesh.positions = half;
  for (int i = 0; i < nv; ++i) {
    if (std::abs(half[std::size_t(i)].x()) < 1e-9) {
      mirror[std::size_t(i)] = i;
    } else {
      mirror[std::size_t(i)] = int(out.mesh.positions.size());
      out.mesh.positions.push_back(
          Vec3(-half[std::size_t(i)].x(), half[std::size_t(i)].y(), half[std::size_t(i)].z()));
    }
  }
  Tokens ix(dir / "index.dat");
  const int np = ix.integer("the polygon count");
  if (np <= 0 || np > 1000000) fail_at(ix.file(), "polygon count {} out of range", np);
  std::set<std::array<int, 3>> seen;
  auto add = [&](int a, int b, int c) {
    std::array<int, 3> k{a, b, c};
    std::sort(k.begin(), k.end());
    if (a == b || b == c || a == c || !seen.insert(k).second) return;
    out.mesh.faces.emplace_back(a, c, b);  // data are clockwise from the front; make CCW
  };
  for (int p = 0; p < np; ++p) {
    std::array<int, 4> q{};
    for (auto& v : q) {
      v = ix.integer("a vertex index");
      if (v != 1000 && (v < 1 || v > nv))
        fail_at(ix.file(), "polygon {}: vertex index {} out of range [1, {}]", p + 1, v, nv);
    }
    std::vector<std::array<int, 3>> tris;
    if (q[0] == 1000) {
      tris.push_back({q[1] - 1, q[2] - 1, q[3] - 1});
    } else {
      tris.push_back({q[0] - 1, q[1] - 1, q[2] - 1});
      tris.push_back({q[0] - 1, q[2] - 1, q[3] - 1});
    }
    for (const auto& t : tris) {
      add(t[0], t[1], t[2]);
      // Mirrored polygon: x -> -x with the first two vertices swapped (keeps orientation).
      add(mirror[std::size_t(t[1])], mirror[std::size_t(t[0])], mirror[std::size_t(t[2])]);
    }
  }
  for (auto& p : out.mesh.positions) p *= s;
  out.mesh.name = "waters-geoface";
  // Muscles.
  Tokens mu(dir / "muscle.dat");
  const int nm = mu.integer("the muscle count");
  if (nm <= 0 || nm > 1000) fail_at(mu.file(), "muscle count {} out of range", nm);
  for (int m = 0; m < nm; ++m) {
    LinearMuscle lm;
    lm.name = mu.word("a muscle name");
    Vec3 head, tail;
    for (int k = 0; k < 3; ++k) head[k] = mu.number("head coordinate");
    for (int k = 0; k < 3; ++k) tail[k] = mu.number("tail coordinate");
    lm.falloff_start = mu.number("fall-off start") * s;
    lm.falloff_end = mu.number("fall-off end") * s;
    lm.zone = mu.number("zone (degrees)") * kPi / 180.0;
    (void)mu.number("clamp value");  // read but unused in Waters' code
    lm.insertion = head * s;  // Muscle.cpp: activate_muscle(face, head, tail, ...) with vt = head
    lm.origin = tail * s;     // vertices move toward vh = tail (the bony origin)
    out.muscles.linear.push_back(lm);
  }
  const auto ex = dir / "expression-macros.dat";
  if (std::filesystem::exists(ex)) {
    Tokens et(ex);
    const int ne = et.integer("the expression count");
    if (ne < 0 || ne > 1000) fail_at(et.file(), "expression count {} out of range", ne);
    for (int e = 0; e < ne; ++e) {
      Expression xp;
      xp.name = et.word("an expression name");
      // Values are assigned by position to muscles 0..nm-1 (Waters' reader ignores the names).
      for (int m = 0; m < nm; ++m) {
        (void)et.word("a muscle name");
        xp.contractions[out.muscles.linear[std::size_t(m)].name] = et.number("a contraction");
      }
      out.muscles.expressions.push_back(std::move(xp));
    }
  }
  out.mesh.check(dir.string());
  out.muscles.validate();
  return out;
}

}  // namespace follicle::skin
