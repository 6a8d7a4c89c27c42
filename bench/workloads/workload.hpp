#pragma once
// A benchmark workload: the same code runs under `follicle bench NAME` and under Google
// Benchmark (bench/bench_*.cpp). Default sizes are the ones the issues name as targets.
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "follicle/core/context.hpp"

namespace follicle::workloads {

using Sizes = std::map<std::string, double>;

class WorkloadInstance {
 public:
  virtual ~WorkloadInstance() = default;
  /// One iteration of the timed work (setup happens in the factory, untimed).
  virtual void run_once() = 0;
  /// Units of work one iteration does, in the workload's throughput unit (e.g. strands).
  virtual double items_per_iter() const = 0;
};

struct Workload {
  std::string name;             // e.g. "mesh-load"
  std::string description;      // one line
  Sizes default_sizes;          // every accepted --size key with its default
  std::string throughput_unit;  // e.g. "queries/s"
  std::function<std::unique_ptr<WorkloadInstance>(const Context&, const Sizes&)> make;
};

/// Every workload Follicle knows, in a fixed order.
std::vector<Workload> all_workloads();
/// Looks up a workload by name; throws follicle::Error with a did-you-mean otherwise.
const Workload& find_workload(const std::vector<Workload>& all, const std::string& name);
/// Merges user sizes into the defaults; an unknown key is an error naming the accepted keys.
Sizes resolve_sizes(const Workload& w, const Sizes& user);

}  // namespace follicle::workloads
