#ifndef HPOSE_CORE_TEMPLATES_CAPTURE_REGISTRATION_H_
#define HPOSE_CORE_TEMPLATES_CAPTURE_REGISTRATION_H_

#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/common/pose2d.h"
#include "core/common/status.h"
#include "core/templates/capture_views.h"

namespace hpose {

// How the robot was turned between the captures.
enum class CaptureMotion {
  // On a turntable: view i is at a known table angle. Only the axis position on the floor is
  // estimated (2 unknowns for all views together); the axis direction is the floor normal.
  kTurntable,
  // Turned by hand to roughly known headings: every view but the first gets its own rigid
  // motion on the floor (x, y, theta), seeded by its heading.
  kHandTurned,
};

struct CaptureRegistrationOptions {
  CaptureMotion motion = CaptureMotion::kTurntable;
  // Per capture given to ExtractRobotViews (RobotView::capture_index): the table angle (turntable)
  // or the rough heading (hand-turned) of the robot, radians, counter-clockwise seen from above.
  // Only differences matter.
  std::vector<double> angles_rad;
  // Turntable: the axis is searched within this distance of the mean of the robot's centroids,
  // metres, on a grid of 2 x `coarse_step_m`, then of coarse_step_m / 2 around the best, before
  // the joint least squares refinement.
  double axis_search_radius_m = 0.3;
  double coarse_step_m = 0.01;
  // Hand-turned: each heading is searched within +- this of the given one first, radians,
  // and the position within +- heading_search_translation_m.
  double heading_search_rad = 0.3;  // 17 degrees.
  double heading_search_translation_m = 0.12;
  // Each view is compared with up to two views on each side by angle, within this of its own
  // angle (radians).
  double max_pair_angle_rad = 1.6;  // ~90 degrees.
  // Correspondences: nearest neighbours closer than this (metres) at the end of the
  // refinement; the first iterations use 3x.
  double max_correspondence_m = 0.015;
  int iterations = 40;
  double normal_radius_m = 0.025;  // neighbourhood of the surface normals.
  // A registered view fits when its inlier fraction (points with a neighbour of another view
  // within max_correspondence_m) reaches this and its point-to-plane RMS stays below
  // max_rms_m. Views that do not fit fail the registration, naming them, unless
  // drop_bad_views (then they are left out and registration runs again without them).
  double min_inlier_fraction = 0.6;
  double max_rms_m = 0.006;
  bool drop_bad_views = false;
};

// How well one view agrees with the others after registration.
struct ViewResidual {
  std::string name;
  double angle_rad = 0.0;        // table angle / heading used (hand-turned: the refined one).
  double rms_m = 0.0;            // point-to-plane RMS over the inliers.
  double inlier_fraction = 0.0;  // of the view's points.
  int points = 0;
  bool fits = false;
  bool dropped = false;
};

// The views in one common frame (the table frame) and what was estimated.
struct CaptureRegistration {
  CaptureMotion motion = CaptureMotion::kTurntable;
  // Table frame: z up from the table top. Turntable: origin on the axis, x = the ground frame's
  // x axis turned by the first kept view's table angle (so an angle-0 view maps unchanged).
  // Hand-turned: the first kept view's ground frame turned by minus its heading.
  // table_from_ground[i] maps view i's ground-frame points (RobotView::points) into it.
  std::vector<Pose2D> table_from_ground;  // per kept view (same order as `views`).
  std::vector<RobotView> views;           // the kept views.
  std::vector<ViewResidual> residuals;    // every view given, dropped ones flagged.
  // Turntable only: where the axis meets the floor in the common ground frame (metres), and its
  // direction in the sensor frame (the floor normal, unit).
  Eigen::Vector2d axis_ground = Eigen::Vector2d::Zero();
  Eigen::Vector3d axis_direction_sensor = Eigen::Vector3d::UnitZ();
  // The two smallest singular values' ratio of the final axis least squares (well posed when
  // far from 0).
  double axis_conditioning = 0.0;
  int iterations_run = 0;
  // Directions the motion cannot identify, in words (for reports).
  std::vector<std::string> unobservable;
};

// Registers the robot views into one 360 degree cloud. Turntable: a coarse grid search of the
// axis position maximising the overlap of views at neighbouring angles, then point-to-plane
// least squares over all view pairs jointly (the residual is linear in the axis position).
// Hand-turned: each view is placed by a coarse search around its heading against the views
// already placed, then all (x, y, theta) are refined jointly (Gauss-Newton, point-to-plane),
// the first view fixed. Fails (kInvalidArgument) when the angles' count differs from the views'
// or options are invalid; (kFailedPrecondition) when views do not fit, naming each with its
// residual and inlier fraction. `progress` (may be empty) receives progress lines.
Result<CaptureRegistration> RegisterCaptureViews(const CaptureViews& views,
                                                 const CaptureRegistrationOptions& options,
                                                 const ProgressFn& progress = {});

// The merged cloud of the registered views in the table frame.
std::vector<Eigen::Vector3f> MergedTablePoints(const CaptureRegistration& registration);

}  // namespace hpose

#endif  // HPOSE_CORE_TEMPLATES_CAPTURE_REGISTRATION_H_
