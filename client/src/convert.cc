#include "convert.h"

#include <string>

namespace hpose::client::internal {

namespace {

constexpr int kInvalidArgument = 3;

Pose2D FromProto(const v1::Pose2D& p) { return Pose2D{p.x(), p.y(), p.theta()}; }

Estimator FromProto(v1::EstimatorKind kind) {
  switch (kind) {
    case v1::ESTIMATOR_KIND_DEPTH_TEMPLATE:
      return Estimator::kDepthTemplate;
    case v1::ESTIMATOR_KIND_STEREO_MARKER:
      return Estimator::kStereoMarker;
    default:
      return Estimator::kAny;
  }
}

MarginKind FromProto(v1::TemplateMarginKind kind) {
  switch (kind) {
    case v1::TEMPLATE_MARGIN_FIT:
      return MarginKind::kFit;
    case v1::TEMPLATE_MARGIN_SCORE_AT_LEAST:
      return MarginKind::kScoreAtLeast;
    default:
      return MarginKind::kScore;
  }
}

void FillDepth(const v1::DepthTemplateResult& r, PoseEstimate* out) {
  out->humanoid_found = r.humanoid_found();
  out->clusters = r.clusters_size();
  out->floor_height_m = r.floor().height();
  out->floor_pitch_rad = r.floor().pitch();
  if (r.detections_size() == 0) return;
  const v1::Detection& d = r.best();
  const v1::Candidate& c = d.best();
  out->has_match = true;
  out->template_name = c.template_name();
  out->pose = FromProto(c.pose());
  out->score = c.score();
  out->template_margin = d.template_margin();
  out->template_margin_kind = FromProto(d.template_margin_kind());
  out->has_runner_up = c.has_runner_up();
  out->runner_up_pose = FromProto(c.runner_up_pose());
  out->runner_up_margin = c.runner_up_margin();
}

void FillStereo(const v1::StereoMarkerResult& r, PoseEstimate* out) {
  out->object_found = r.object_found();
  out->object_x_m = r.object_position_world().x();
  out->object_y_m = r.object_position_world().y();
  out->object_moving = r.object_moving();
}

std::string StateName(v1::SourceState state) {
  switch (state) {
    case v1::SOURCE_STATE_NONE:
      return "none";
    case v1::SOURCE_STATE_STARTING:
      return "starting";
    case v1::SOURCE_STATE_RUNNING:
      return "running";
    case v1::SOURCE_STATE_RECONNECTING:
      return "reconnecting";
    case v1::SOURCE_STATE_FINISHED:
      return "finished";
    default:
      return "unspecified";
  }
}

}  // namespace

PoseEstimate FromProto(const v1::PoseEstimate& e) {
  PoseEstimate out;
  out.estimator = FromProto(e.estimator());
  out.sequence = e.sequence();
  out.source_time_s = e.source_time();
  out.source = e.source();
  out.stale = e.stale();
  out.stale_reason = e.stale_reason();
  out.error_code = e.error().code();
  out.error_message = e.error().message();
  out.estimate_time_s = e.timings().total();
  out.latency_s = e.timings().latency();
  out.age_s = e.age();
  out.skipped = e.skipped();
  if (e.has_depth_template()) FillDepth(e.depth_template(), &out);
  if (e.has_stereo_marker()) FillStereo(e.stereo_marker(), &out);
  out.has_world_pose = e.has_robot_pose_world();
  out.world_pose = FromProto(e.robot_pose_world());
  return out;
}

DaemonStatus FromProto(const v1::GetStatusResponse& s) {
  DaemonStatus out;
  out.version = s.version();
  out.uptime_s = s.uptime();
  out.source = s.source().description();
  out.source_state = StateName(s.source().state());
  out.frames_in = s.source().frames_in();
  out.frames_estimated = s.source().frames_estimated();
  out.frames_dropped = s.source().frames_dropped();
  out.templates = s.templates();
  const v1::Intrinsics& k = s.source().camera();  // all zero when unset.
  out.frame_width = k.width();
  out.frame_height = k.height();
  out.fx = k.fx();
  out.fy = k.fy();
  out.cx = k.cx();
  out.cy = k.cy();
  out.point_clouds = s.source().point_clouds();
  return out;
}

v1::EstimatorKind ToProto(Estimator estimator) {
  switch (estimator) {
    case Estimator::kDepthTemplate:
      return v1::ESTIMATOR_KIND_DEPTH_TEMPLATE;
    case Estimator::kStereoMarker:
      return v1::ESTIMATOR_KIND_STEREO_MARKER;
    default:
      return v1::ESTIMATOR_KIND_UNSPECIFIED;
  }
}

Status ToProto(const DepthImage& depth, v1::DepthImage* out) {
  const std::size_t pixels = std::size_t{depth.width} * depth.height;
  if (pixels == 0 || depth.depth_mm.size() != pixels) {
    return Status{kInvalidArgument, "depth image: " + std::to_string(depth.depth_mm.size()) +
                                        " values for " + std::to_string(depth.width) + "x" +
                                        std::to_string(depth.height) + " pixels"};
  }
  out->set_width(depth.width);
  out->set_height(depth.height);
  // The API's depth bytes: 16-bit millimetres, little-endian whatever this machine's order.
  std::string* data = out->mutable_data();
  data->resize(pixels * 2);
  for (std::size_t i = 0; i < pixels; ++i) {
    (*data)[2 * i] = static_cast<char>(depth.depth_mm[i] & 0xff);
    (*data)[2 * i + 1] = static_cast<char>(depth.depth_mm[i] >> 8);
  }
  v1::Intrinsics* k = out->mutable_intrinsics();
  k->set_width(depth.width);
  k->set_height(depth.height);
  k->set_fx(depth.fx);
  k->set_fy(depth.fy);
  k->set_cx(depth.cx);
  k->set_cy(depth.cy);
  return Status{};
}

Status ToProto(const PointCloud& cloud, v1::PointCloud* out) {
  if (cloud.xyz.empty() || cloud.xyz.size() % 3 != 0) {
    return Status{kInvalidArgument, "point cloud: " + std::to_string(cloud.xyz.size()) +
                                        " values, expected a non-zero multiple of 3"};
  }
  out->mutable_xyz()->Assign(cloud.xyz.begin(), cloud.xyz.end());
  return Status{};
}

}  // namespace hpose::client::internal
