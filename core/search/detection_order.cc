#include "core/search/detection_order.h"

namespace hpose {

double HumanoidEvidence(const Candidate& c) {
  if (!c.refined) return 0.0;
  const double f2 = (c.fit.fit / 100.0) * (c.fit.fit / 100.0);
  const double f4 = f2 * f2;
  return c.hits * (f4 * f4);
}

double HumanoidEvidenceShare(const Candidate& c) {
  return c.template_voxels > 0 ? HumanoidEvidence(c) / c.template_voxels : 0.0;
}

bool DetectionBefore(const Detection& a, const Detection& b) {
  if (a.is_humanoid != b.is_humanoid) return a.is_humanoid;
  if (a.is_humanoid) {
    if (a.best.refined != b.best.refined) return a.best.refined;
    const double ea = HumanoidEvidence(a.best), eb = HumanoidEvidence(b.best);
    if (ea != eb) return ea > eb;
  }
  return a.best.score > b.best.score;
}

}  // namespace hpose
