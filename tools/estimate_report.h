#ifndef HPOSE_TOOLS_ESTIMATE_REPORT_H_
#define HPOSE_TOOLS_ESTIMATE_REPORT_H_

#include <string>

#include "core/search/estimate.h"

namespace hpose::tools {

// One JSON object (one line when indent < 0): {"humanoid_found", "detections": [...best first,
// each {"template","x","y","theta","score","cluster","runner_up":{...},"template_margin",...}],
// "candidates": [...], "floor": {...}, "clusters": [...], "timings_ms": {...}}. SI units.
std::string EstimateToJson(const Estimate& estimate, const std::string& search_name,
                           const std::string& score_name, int indent = -1);

// A few lines for people: the floor, the humanoid(s) with pose in m and degrees, the runner-up,
// the other candidates and the stage timings.
std::string EstimateToText(const Estimate& estimate);

}  // namespace hpose::tools

#endif  // HPOSE_TOOLS_ESTIMATE_REPORT_H_
