#ifndef HPOSE_CORE_SEARCH_FIT_SUMMARY_H_
#define HPOSE_CORE_SEARCH_FIT_SUMMARY_H_

#include "core/search/estimate.h"
#include "core/search/pose_refiner.h"

namespace hpose {

// A pose's evidence as its fit, the fit's parts and its standard error (from the counts behind
// them: the cluster points considered and the template points judged).
FitSummary Summarise(const PoseEvidence& e);

// Two fits differ by no more than noise explains (two standard errors of the difference).
bool WithinNoise(const FitSummary& a, const FitSummary& b);

// `a` fits better than `b` by more than `sigmas` standard errors of their difference.
bool FarAhead(const FitSummary& a, const FitSummary& b, double sigmas);

}  // namespace hpose

#endif  // HPOSE_CORE_SEARCH_FIT_SUMMARY_H_
