#pragma once
// StepReport: what a solver step returns instead of throwing from deep inside. Shared by every
// solver (hair dynamics, particles, skin). `ok` is false when a state value became NaN/Inf or a
// speed exceeded the solver's blow-up limit; `first_bad` names the offending item (strand,
// particle, vertex) and `message` says what happened, so the caller can stop, log or retry with a
// smaller step.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <string>

namespace follicle::sim {

struct StepReport {
  static constexpr std::size_t npos = std::numeric_limits<std::size_t>::max();

  bool ok = true;
  bool non_finite = false;       // a NaN or Inf appeared in the state
  bool blow_up = false;          // max_speed exceeded the solver's limit
  double max_speed = 0.0;        // [m/s] largest speed of any point this step
  std::size_t first_bad = npos;  // smallest index of an offending item, npos when ok
  std::string message;           // empty when ok

  /// Records a non-finite value at `item` (keeps the smallest index, so the report does not
  /// depend on the order in which parallel chunks are merged).
  void mark_non_finite(std::size_t item) {
    ok = false;
    non_finite = true;
    first_bad = std::min(first_bad, item);
  }
  void mark_blow_up(std::size_t item) {
    ok = false;
    blow_up = true;
    first_bad = std::min(first_bad, item);
  }
  /// Order-independent merge (max of speeds, min of indices): deterministic for any split.
  void merge(const StepReport& o) {
    ok = ok && o.ok;
    non_finite = non_finite || o.non_finite;
    blow_up = blow_up || o.blow_up;
    max_speed = std::max(max_speed, o.max_speed);
    first_bad = std::min(first_bad, o.first_bad);
    if (message.empty()) message = o.message;
  }
  /// Fills `message` from the flags (call once after merging).
  void finish(const char* solver, double speed_limit) {
    if (ok) return;
    message = std::string(solver) + ": " +
              (non_finite ? "state became NaN/Inf" : "blow-up: speed above limit") + " at item " +
              std::to_string(first_bad) + " (max speed " + std::to_string(max_speed) +
              " m/s, limit " + std::to_string(speed_limit) + " m/s)";
  }
};

}  // namespace follicle::sim
