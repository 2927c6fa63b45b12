#ifndef HPOSE_TOOLS_ESTIMATE_REPORT_H_
#define HPOSE_TOOLS_ESTIMATE_REPORT_H_

#include <string>

#include "core/search/estimate.h"

namespace hpose::tools {

// A few lines for people: the floor, the humanoid(s) with pose in m and degrees, the runner-up,
// the other candidates and the stage timings.
std::string EstimateToText(const Estimate& estimate);

}  // namespace hpose::tools

#endif  // HPOSE_TOOLS_ESTIMATE_REPORT_H_
