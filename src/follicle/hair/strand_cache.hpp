#pragma once
// Per-frame strand cache: one small binary file per frame so a frame range can be re-rendered
// without re-simulating. Layout (little-endian): "FLCSTRND" magic, uint32 version (1), uint32
// flags (1 = radius, 2 = colour), int64 frame, double time [s], uint64 strands, uint64 points,
// uint32 offsets[strands+1], float3 points [m], then float radius[points] and float3
// colour[points] when flagged.
#include <cstdint>
#include <filesystem>
#include <string>

#include "follicle/geom/strands.hpp"

namespace follicle::hair {

inline constexpr uint32_t kStrandCacheVersion = 1;

struct StrandFrame {
  int64_t frame = 0;
  double time = 0.0;  // [s]
  geom::StrandSet strands;
};

std::string serialize_strand_frame(const StrandFrame& f);
/// Throws follicle::Error naming `where` on a bad magic, unknown version, truncation or
/// inconsistent offsets.
StrandFrame parse_strand_frame(const std::string& bytes, const std::string& where);

/// dir / "strands_000042.fsc".
std::filesystem::path strand_frame_path(const std::filesystem::path& dir, int64_t frame);
void write_strand_frame(const std::filesystem::path& dir, const StrandFrame& f);  // atomic
StrandFrame read_strand_frame(const std::filesystem::path& dir, int64_t frame);
bool has_strand_frame(const std::filesystem::path& dir, int64_t frame);

}  // namespace follicle::hair
