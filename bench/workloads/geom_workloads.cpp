#include "workloads/workload.hpp"

namespace follicle::workloads {

void add_geom_workloads(std::vector<Workload>& out) { (void)out; }

}  // namespace follicle::workloads
