#ifndef HPOSE_TOOLS_ESTIMATE_REPORT_H_
#define HPOSE_TOOLS_ESTIMATE_REPORT_H_

#include <string>

#include "core/search/estimate.h"

namespace hpose {
class Estimator;
struct EstimatorOptions;
}  // namespace hpose

namespace hpose::tools {

// A few lines for people: the floor, the humanoid(s) with pose in m and degrees, the runner-up,
// the other candidates and the stage timings. A frame without a humanoid says which rule refused
// the nearest miss (NearestMissReason; the thresholds' values given with the estimator's options).
std::string EstimateToText(const Estimate& estimate, const EstimatorOptions* options = nullptr);

// Why a detection that is not a humanoid was refused (Detection::refused_by) in words: its score
// against the threshold, or which rule after the refinement (fit, evidence, the far clusters'
// evidence, the coverage off the floor) with the option that sets it, e.g. "score 52.0 but a
// refined fit of 41.5, below the fit threshold 60: --min-fit". Without the options the
// thresholds' values are left out.
std::string NearestMissReason(const Detection& detection,
                              const EstimatorOptions* options = nullptr);

// Under this share of its template in view (FitSummary::in_view) a refined pose is said to be
// partly in view: a robot the image holds whole shows nearly all of its template.
constexpr double kPartlyInViewBelow = 0.9;

// "partly in view: N% of the template's surface facing the sensor lies within the view" for a
// refined candidate under kPartlyInViewBelow; empty otherwise.
std::string PartlyInViewNote(const Candidate& candidate);

// A sentence for a note when templates are searched on coarser voxels than they were made
// with (a tall body, EstimatorOptions::max_height_voxels, or the search's edge set coarser);
// empty otherwise.
std::string SearchVoxelsNote(const Estimator& estimator);

}  // namespace hpose::tools

#endif  // HPOSE_TOOLS_ESTIMATE_REPORT_H_
