#include "workloads/workload.hpp"

namespace follicle::workloads {

void add_render_workloads(std::vector<Workload>& out) { (void)out; }

}  // namespace follicle::workloads
