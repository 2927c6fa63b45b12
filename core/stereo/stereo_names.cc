// The stereo estimator's enum names, in a file of their own: programs that only print results
// (`hpose query`, the daemon's message conversion) link these without the estimator, and so
// without OpenCV.
#include "core/stereo/stereo_frame_result.h"
#include "core/stereo/stereo_marker_options.h"

namespace hpose {

const char* StereoFrameStatusName(StereoFrameStatus status) {
  switch (status) {
    case StereoFrameStatus::kOk:
      return "ok";
    case StereoFrameStatus::kMissingLandmark:
      return "missing_landmark";
    case StereoFrameStatus::kTooManyLandmarks:
      return "too_many_landmarks";
    case StereoFrameStatus::kNoConsistentMatch:
      return "no_consistent_match";
    case StereoFrameStatus::kAmbiguousMatch:
      return "ambiguous_match";
    case StereoFrameStatus::kCollinearLandmarks:
      return "collinear_landmarks";
    case StereoFrameStatus::kPoorFit:
      return "poor_fit";
    case StereoFrameStatus::kOccludedLandmark:
      return "occluded_landmark";
  }
  return "unknown";
}

const char* RigidFitMethodName(RigidFitMethod method) {
  switch (method) {
    case RigidFitMethod::kSvd:
      return "svd";
    case RigidFitMethod::kClosedForm:
      return "closed_form";
    case RigidFitMethod::kCovariance:
      return "covariance";
  }
  return "unknown";
}

Result<RigidFitMethod> ParseRigidFitMethod(const std::string& name) {
  for (RigidFitMethod m :
       {RigidFitMethod::kSvd, RigidFitMethod::kClosedForm, RigidFitMethod::kCovariance}) {
    if (name == RigidFitMethodName(m)) return m;
  }
  return MakeError(ErrorCode::kInvalidArgument,
                   "unknown fit method '" + name + "' (svd, closed_form or covariance)");
}

}  // namespace hpose
