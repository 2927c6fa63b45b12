#include "server/stereo_proto_convert.h"

#include <Eigen/Geometry>
#include <Eigen/SVD>

#include "core/stereo/stereo_marker_options.h"
#include "server/proto_convert.h"

namespace hpose::server {

namespace {

// The closed-form fit's matrix need not be orthonormal: report the nearest rotation.
Eigen::Matrix3d NearestRotation(const Eigen::Matrix3d& m) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(m, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  d(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
  return svd.matrixU() * d * svd.matrixV().transpose();
}

}  // namespace

void StereoResultToProto(const StereoFrameResult& f, const StereoTrackState* track,
                         v1::StereoMarkerResult* out) {
  out->set_status(StereoFrameStatusName(f.status));
  out->set_status_reason(f.reason);
  out->set_robot_found(f.ok());
  out->set_landmark_blobs_left(f.landmark_blobs_left);
  out->set_landmark_blobs_right(f.landmark_blobs_right);
  if (f.ok()) {
    SetPose2D(f.robot, out->mutable_robot_pose_world());
    const RigidFit& fit = f.fit();
    const Eigen::Quaterniond q(NearestRotation(fit.rotation));
    v1::Pose3D* cam = out->mutable_camera_in_world();
    SetVector(fit.translation, cam->mutable_position());
    cam->mutable_orientation()->set_w(q.w());
    cam->mutable_orientation()->set_x(q.x());
    cam->mutable_orientation()->set_y(q.y());
    cam->mutable_orientation()->set_z(q.z());
    out->set_camera_height(f.camera_height_m);
    out->set_fit_method(RigidFitMethodName(f.method));
    out->set_fit_rms_residual(fit.rms_residual_m);
    out->set_max_epipolar_error(f.max_epipolar_error_px);
  }
  out->set_object_found(f.object_in_world);
  if (f.object_in_world) SetVector(f.object_world_m, out->mutable_object_position_world());
  out->set_object_in_camera(f.object_in_camera);
  if (f.object_in_camera) SetVector(f.object_camera_m, out->mutable_object_position_camera());
  if (!f.object_in_world) out->set_object_reason(f.object_reason);
  if (track == nullptr) return;
  if (track->robot_valid) {
    SetPose2D(track->robot_mean, out->mutable_robot_pose_world_mean());
    out->set_robot_mean_frames(track->robot_frames);
  }
  out->set_object_moving(track->object_moving);
  if (track->object_moving) out->set_motion_start_time(track->motion_start_s);
  if (track->path_valid) {
    v1::ObjectPath* path = out->mutable_path();
    path->set_t0(track->path.t0_s);
    SetVector(Eigen::Vector3d(track->path.origin_m.x(), track->path.origin_m.y(), 0.0),
              path->mutable_origin());
    SetVector(Eigen::Vector3d(track->path.velocity_mps.x(), track->path.velocity_mps.y(), 0.0),
              path->mutable_velocity());
    path->set_rms_residual(track->path.rms_residual_m);
    if (track->robot_valid) {
      const PathPrediction::Approach a =
          track->path.ClosestApproach(Eigen::Vector2d(track->robot_mean.x, track->robot_mean.y));
      path->set_has_closest_approach(true);
      path->set_closest_approach_time(a.t_s);
      path->set_closest_approach_distance(a.distance_m);
    }
  }
}

void FillStereoPoseEstimate(std::uint64_t sequence, double source_time_s,
                            std::chrono::system_clock::time_point received,
                            const std::string& source, const StereoFrameResult* frame,
                            const StereoTrackState* track, const Error* error, double process_s,
                            v1::PoseEstimate* out) {
  out->set_estimator(v1::ESTIMATOR_KIND_STEREO_MARKER);
  out->set_sequence(sequence);
  out->set_source_time(source_time_s);
  SetTimestamp(received, out->mutable_received_time());
  out->set_source(source);
  out->mutable_timings()->set_total(process_s);
  if (frame != nullptr) {
    StereoResultToProto(*frame, track, out->mutable_stereo_marker());
    if (frame->ok()) SetPose2D(frame->robot, out->mutable_robot_pose_world());
  }
  if (error != nullptr) {
    out->mutable_error()->set_code(ErrorCodeName(error->code));
    out->mutable_error()->set_message(error->message);
  }
}

Result<RgbImage> ColorImageFromProto(const v1::ColorImage& image, const std::string& field) {
  if (image.width() == 0 || image.height() == 0 || image.width() > 8192 || image.height() > 8192) {
    return MakeError(ErrorCode::kInvalidArgument,
                     field + ": width and height must be in [1, 8192], got " +
                         std::to_string(image.width()) + "x" + std::to_string(image.height()));
  }
  const size_t expected = static_cast<size_t>(image.width()) * image.height() * 3;
  if (image.data().size() != expected) {
    return MakeError(ErrorCode::kInvalidArgument,
                     field + ".data: expected width * height * 3 = " + std::to_string(expected) +
                         " bytes, got " + std::to_string(image.data().size()));
  }
  RgbImage out(static_cast<int>(image.width()), static_cast<int>(image.height()));
  std::copy(image.data().begin(), image.data().end(), out.pixels.begin());
  return out;
}

void ColorImageToProto(const RgbImage& image, v1::ColorImage* out) {
  out->set_width(static_cast<std::uint32_t>(image.width));
  out->set_height(static_cast<std::uint32_t>(image.height));
  out->set_data(std::string(image.pixels.begin(), image.pixels.end()));
}

}  // namespace hpose::server
