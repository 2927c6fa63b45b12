#ifndef HPOSE_TESTS_SEARCH_FAR_NAO_SCENE_H_
#define HPOSE_TESTS_SEARCH_FAR_NAO_SCENE_H_

#include <cmath>
#include <vector>

#include "core/search/estimator.h"
#include "core/sim/frame_simulator.h"
#include "tests/search/model_templates.h"

namespace hpose::testing {

// A Nao 3.3 m from a sensor 0.9 m high looking 20 degrees down, among 3 clutter objects: the
// depth noise spreads its surfaces over more voxels than the template covers, and it scores
// below 50.
inline FrameSpec FarNaoSpec() {
  FrameSpec spec;
  spec.preset = "standing";
  spec.humanoid_pose = Pose2D{3.3, 0.2, DegToRad(120.0)};
  spec.sensor_height_m = 0.9;
  spec.sensor_pitch_rad = DegToRad(20.0);
  spec.clutter = 3;
  spec.seed = 3;
  return spec;
}

// That frame (or another of `spec`, Simulate()) with the Nao's two templates, estimated on the
// sensor's true mount so that runs differ only in what a test changes.
struct FarNaoFrame {
  FrameSpec spec = FarNaoSpec();
  SimulatedFrame frame = *SimulateFrame(spec);
  std::vector<VoxelTemplate> templates = {ModelTemplate("standing"),
                                          ModelTemplate("right_arm_raised")};

  void Simulate() { frame = *SimulateFrame(spec); }
  // The default options with the true mount as a fixed floor.
  EstimatorOptions Options() const {
    EstimatorOptions o = DefaultEstimatorOptions();
    o.use_fixed_floor = true;
    o.fixed_floor = frame.sensor_mount;
    return o;
  }
  Estimate Run(const EstimatorOptions& o, const FramePrior* prior = nullptr) const {
    return *Estimator::Create(o, templates)
                .value()
                ->EstimateDepth(frame.depth, spec.intrinsics, prior);
  }
  // Within 5 cm and 10 degrees of the humanoid's true pose.
  bool NearTruth(const Detection& d) const {
    return std::hypot(d.best.pose.x - spec.humanoid_pose.x, d.best.pose.y - spec.humanoid_pose.y) <
               0.05 &&
           std::abs(RadToDeg(AngleDiff(d.best.pose.theta, spec.humanoid_pose.theta))) < 10.0;
  }
};

}  // namespace hpose::testing

#endif  // HPOSE_TESTS_SEARCH_FAR_NAO_SCENE_H_
