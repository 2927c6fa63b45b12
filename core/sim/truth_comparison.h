#ifndef HPOSE_CORE_SIM_TRUTH_COMPARISON_H_
#define HPOSE_CORE_SIM_TRUTH_COMPARISON_H_

#include <string>
#include <vector>

#include "core/common/pose2d.h"
#include "core/sim/sim_truth.h"

namespace hpose {

// The frame of `truth` whose depth or cloud file is `file_name` (a path: only its last part is
// compared), or nullptr.
const SimFrameTruth* FindFrameTruth(const SimTruth& truth, const std::string& file_name);

// How a recording's estimates compare with where the humanoid truly stood.
struct TruthComparison {
  int frames = 0;  // frames that have a truth.
  int found = 0;   // ... of which a humanoid was found in.
  // Of the frames found: the heading within 5 degrees and the position within 0.1 m, and the
  // heading more than 150 degrees off (the robot taken facing the other way).
  int within_5deg_10cm = 0;
  int turned_about = 0;
  // Over the frames found: position error (metres) and absolute heading error (radians).
  double position_median_m = 0.0;
  double position_p95_m = 0.0;
  double position_max_m = 0.0;
  double heading_median_rad = 0.0;
  double heading_p95_rad = 0.0;
  double heading_max_rad = 0.0;
};

// For people, one line: "humanoid found in 30 of 30 frame(s), 30 within 5 deg and 0.1 m, 0
// turned about (over 150 deg off); position error median 0.8 mm, p95 ..., heading error ...".
std::string DescribeTruthComparison(const TruthComparison& c);

// Accumulates estimates against truth, frame by frame.
class TruthComparer {
 public:
  // A frame with a truth: the humanoids found in it (none: not found). With more than one (a
  // second robot, clutter taken for one) the one nearest the truth is compared.
  void Add(const Pose2D& truth, const std::vector<Pose2D>& humanoids);
  TruthComparison Summary() const;

 private:
  int frames_ = 0;
  std::vector<double> position_m_;
  std::vector<double> heading_rad_;
};

}  // namespace hpose

#endif  // HPOSE_CORE_SIM_TRUTH_COMPARISON_H_
