#ifndef HPOSE_CORE_SEARCH_DETECTION_ORDER_H_
#define HPOSE_CORE_SEARCH_DETECTION_ORDER_H_

#include "core/search/estimate.h"

namespace hpose {

// How much a refined candidate says its cluster is the humanoid: the cluster voxels its pose
// covers (hits) times the eighth power of its refined fit (0-1). Both matter across clusters. A
// small object inside the template's outline, or the sliver of one that the image's edge cuts,
// covers most of its own few voxels (a high score) and, all of it in view, fits well; the robot
// covers many more. A larger object that is not the robot covers about as many voxels, but the
// sensor sees through much of the template around it (a lower fit). The power weighs a fit 10%
// lower as much as 57% fewer voxels: on the random scenes of bench/cluster_choice_bench.cc, powers
// 6 to 12 named the robot first most often, the fit alone or the score less often (figures in
// docs/BENCHMARKS.md). 0 when not refined.
double HumanoidEvidence(const Candidate& c);

// HumanoidEvidence over the template's voxels (Candidate::template_voxels): the share of the
// template its pose covers, weighed by the fit, comparable between bodies and voxel edges. What a
// far cluster that passes only by EstimatorOptions::far_score_ratio must reach. 0 when not
// refined or the template's size is unknown.
double HumanoidEvidenceShare(const Candidate& c);

// Whether `a` goes before `b` in Estimate::detections: humanoids (is_humanoid) first; among
// them the refined ones, by HumanoidEvidence, then by search score (unrefined); the others by
// search score. A strict weak order (for std::stable_sort).
bool DetectionBefore(const Detection& a, const Detection& b);

}  // namespace hpose

#endif  // HPOSE_CORE_SEARCH_DETECTION_ORDER_H_
