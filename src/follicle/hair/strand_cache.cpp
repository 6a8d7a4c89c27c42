#include "follicle/hair/strand_cache.hpp"

#include <fmt/format.h>

#include <cstring>

#include "follicle/core/atomic_file.hpp"
#include "follicle/core/error.hpp"

namespace follicle::hair {

namespace {
constexpr char kMagic[8] = {'F', 'L', 'C', 'S', 'T', 'R', 'N', 'D'};
template <class T>
void put(std::string& o, const T& v) {
  o.append(reinterpret_cast<const char*>(&v), sizeof(T));
}
template <class T>
void put_vec(std::string& o, const std::vector<T>& v) {
  if (!v.empty()) o.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
}
}  // namespace

std::string serialize_strand_frame(const StrandFrame& f) {
  const auto& s = f.strands;
  const bool has_r = !s.radius.empty() && s.radius.size() == s.points.size();
  const bool has_c = !s.color.empty() && s.color.size() == s.points.size();
  std::string o(kMagic, 8);
  put(o, kStrandCacheVersion);
  put(o, uint32_t((has_r ? 1u : 0u) | (has_c ? 2u : 0u)));
  put(o, f.frame);
  put(o, f.time);
  put(o, uint64_t(s.num_strands()));
  put(o, uint64_t(s.num_points()));
  put_vec(o, s.offsets);
  put_vec(o, s.points);  // Vec3f is 3 packed floats
  if (has_r) put_vec(o, s.radius);
  if (has_c) put_vec(o, s.color);
  return o;
}

StrandFrame parse_strand_frame(const std::string& b, const std::string& where) {
  std::size_t pos = 0;
  auto need = [&](std::size_t n, const char* what) {
    if (n > b.size() || pos > b.size() - n)
      fail_at(where, "strand cache is truncated: expected {} bytes of {} at offset {}", n, what,
              pos);
  };
  auto get = [&](auto& v, const char* what) {
    need(sizeof(v), what);
    std::memcpy(&v, b.data() + pos, sizeof(v));
    pos += sizeof(v);
  };
  need(8, "magic");
  if (std::memcmp(b.data(), kMagic, 8) != 0)
    fail_at(where, "not a Follicle strand cache (bad magic)");
  pos = 8;
  uint32_t version = 0, flags = 0;
  get(version, "version");
  if (version != kStrandCacheVersion)
    fail_at(where, "strand cache version {} is not supported (expected {})", version,
            kStrandCacheVersion);
  get(flags, "flags");
  StrandFrame f;
  get(f.frame, "frame");
  get(f.time, "time");
  uint64_t ns = 0, np = 0;
  get(ns, "strand count");
  get(np, "point count");
  if (ns > b.size() || np > b.size()) fail_at(where, "strand cache counts exceed the file size");
  auto& s = f.strands;
  s.offsets.resize(ns + 1);
  need((ns + 1) * 4, "offsets");
  std::memcpy(s.offsets.data(), b.data() + pos, (ns + 1) * 4);
  pos += (ns + 1) * 4;
  s.points.resize(np);
  need(np * 12, "points");
  if (np) std::memcpy(static_cast<void*>(s.points.data()), b.data() + pos, np * 12);
  pos += np * 12;
  if (flags & 1) {
    s.radius.resize(np);
    need(np * 4, "radius");
    if (np) std::memcpy(s.radius.data(), b.data() + pos, np * 4);
    pos += np * 4;
  }
  if (flags & 2) {
    s.color.resize(np);
    need(np * 12, "colours");
    if (np) std::memcpy(static_cast<void*>(s.color.data()), b.data() + pos, np * 12);
    pos += np * 12;
  }
  if (s.offsets.front() != 0 || s.offsets.back() != np)
    fail_at(where, "strand cache offsets do not cover the {} points", np);
  for (std::size_t i = 1; i < s.offsets.size(); ++i)
    if (s.offsets[i] < s.offsets[i - 1])
      fail_at(where, "strand cache offsets decrease at strand {}", i - 1);
  // A NaN or infinite coordinate would surface later, far from the file that holds it.
  s.check(where);
  return f;
}

std::filesystem::path strand_frame_path(const std::filesystem::path& dir, int64_t frame) {
  return dir / fmt::format("strands_{:06d}.fsc", frame);
}

void write_strand_frame(const std::filesystem::path& dir, const StrandFrame& f) {
  write_file_atomically(strand_frame_path(dir, f.frame), serialize_strand_frame(f));
}

StrandFrame read_strand_frame(const std::filesystem::path& dir, int64_t frame) {
  const auto p = strand_frame_path(dir, frame);
  return parse_strand_frame(read_file(p), p.string());
}

bool has_strand_frame(const std::filesystem::path& dir, int64_t frame) {
  return std::filesystem::exists(strand_frame_path(dir, frame));
}

}  // namespace follicle::hair
