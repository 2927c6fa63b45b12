#include "server/proto_convert.h"

#include <cmath>
#include <cstring>

#include <Eigen/Geometry>

namespace hpose::server {

void SetVector(const Eigen::Vector3d& v, v1::Vector3* out) {
  out->set_x(v.x());
  out->set_y(v.y());
  out->set_z(v.z());
}

void SetPose2D(const Pose2D& p, v1::Pose2D* out) {
  out->set_x(p.x);
  out->set_y(p.y);
  out->set_theta(p.theta);
}

namespace {

void SetPose3D(const Eigen::Isometry3d& t, v1::Pose3D* out) {
  SetVector(t.translation(), out->mutable_position());
  Eigen::Quaterniond q(t.rotation());
  q.normalize();
  out->mutable_orientation()->set_w(q.w());
  out->mutable_orientation()->set_x(q.x());
  out->mutable_orientation()->set_y(q.y());
  out->mutable_orientation()->set_z(q.z());
}

// `refined` false: the candidate kept its lattice pose, nothing was measured, and in_view stays
// unset (the other fields are zeros).
void SetFit(const FitSummary& f, bool refined, v1::Fit* out) {
  out->set_fit(f.fit);
  out->set_explained(f.explained);
  out->set_contradicted(f.contradicted);
  out->set_fit_sigma(f.fit_sigma);
  out->set_cost(f.cost);
  if (refined) out->set_in_view(f.in_view);
}

void CandidateToProto(const Candidate& c, v1::Candidate* out) {
  out->set_template_name(c.template_name);
  out->set_cluster_index(c.cluster_index);
  SetPose2D(c.pose, out->mutable_pose());
  Eigen::Isometry3d ground_from_robot = Eigen::Isometry3d::Identity();
  ground_from_robot.translation() = Eigen::Vector3d(c.pose.x, c.pose.y, 0.0);
  ground_from_robot.linear() =
      Eigen::AngleAxisd(c.pose.theta, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  SetPose3D(ground_from_robot, out->mutable_pose_3d());
  out->set_score(c.score);
  out->set_hits(c.hits);
  out->set_cluster_voxels(c.cluster_voxels);
  out->set_has_runner_up(c.has_runner_up);
  if (c.has_runner_up) {
    SetPose2D(c.runner_up_pose, out->mutable_runner_up_pose());
    out->set_runner_up_score(c.runner_up_score);
    out->set_runner_up_margin(c.score - c.runner_up_score);
  }
  out->set_poses_evaluated(c.poses_evaluated);
  SetPose2D(c.lattice_pose, out->mutable_lattice_pose());
  out->set_refined(c.refined);
  if (c.refined) {
    for (int r = 0; r < 3; ++r) {
      for (int k = 0; k < 3; ++k) out->add_pose_covariance(c.covariance(r, k));
    }
  }
  SetFit(c.fit, c.refined, out->mutable_fit());
  if (c.has_runner_up) SetFit(c.runner_up_fit, c.refined, out->mutable_runner_up_fit());
  out->set_heading_ambiguous(c.heading_ambiguous);
  out->set_heading_from_prior(c.heading_from_prior);
  out->set_heading_confirmed(c.heading_confirmed);
  out->set_height_offset(c.height_offset_m);
  out->set_free_limbs_moved(c.free_limbs_moved);
  out->set_free_limbs_left_out(c.free_limbs_left_out);
  out->set_stopped_below_threshold(c.stopped_below_threshold);
  out->set_score_upper_bound(c.score_upper_bound);
}

v1::Refusal RefusalToProto(Refusal r) {
  switch (r) {
    case Refusal::kNone:
      return v1::REFUSAL_NONE;
    case Refusal::kScore:
      return v1::REFUSAL_SCORE;
    case Refusal::kFit:
      return v1::REFUSAL_FIT;
    case Refusal::kEvidence:
      return v1::REFUSAL_EVIDENCE;
    case Refusal::kFarEvidence:
      return v1::REFUSAL_FAR_EVIDENCE;
    case Refusal::kOffFloorCoverage:
      return v1::REFUSAL_OFF_FLOOR_COVERAGE;
  }
  return v1::REFUSAL_NONE;
}

v1::TemplateMarginKind MarginKindToProto(MarginKind k) {
  switch (k) {
    case MarginKind::kScore:
      return v1::TEMPLATE_MARGIN_SCORE;
    case MarginKind::kFit:
      return v1::TEMPLATE_MARGIN_FIT;
    case MarginKind::kScoreAtLeast:
      return v1::TEMPLATE_MARGIN_SCORE_AT_LEAST;
  }
  return v1::TEMPLATE_MARGIN_SCORE;
}

void DetectionToProto(const Detection& d, v1::Detection* out) {
  CandidateToProto(d.best, out->mutable_best());
  out->set_second_template(d.second_template);
  out->set_template_margin(d.template_margin);
  out->set_template_margin_kind(MarginKindToProto(d.template_margin_kind));
  out->set_is_humanoid(d.is_humanoid);
  out->set_template_ambiguous(d.template_ambiguous);
  out->set_score_threshold(d.score_threshold);
  out->set_refused_by(RefusalToProto(d.refused_by));
}

Error Invalid(const std::string& message) {
  return MakeError(ErrorCode::kInvalidArgument, message);
}

}  // namespace

void FloorToProto(const FloorEstimate& f, v1::FloorFrame* out) {
  out->set_plane_a(f.plane_sensor[0]);
  out->set_plane_b(f.plane_sensor[1]);
  out->set_plane_c(f.plane_sensor[2]);
  out->set_plane_d(f.plane_sensor[3]);
  SetPose3D(f.ground_from_sensor, out->mutable_ground_from_sensor());
  out->set_height(f.height_m);
  out->set_pitch(f.pitch_rad);
  out->set_roll(f.roll_rad);
  out->set_fitted(f.fitted);
  out->set_inliers(f.inliers);
}

void TimingsToProto(const StageTimings& t, v1::Timings* out) {
  out->set_cloud(t.cloud_ms * 1e-3);
  out->set_floor(t.floor_ms * 1e-3);
  out->set_cluster(t.cluster_ms * 1e-3);
  out->set_search(t.search_ms * 1e-3);
  out->set_total(t.total_ms * 1e-3);
  out->set_refine(t.refine_ms * 1e-3);
}

void EstimateToProto(const Estimate& e, v1::DepthTemplateResult* out) {
  out->Clear();
  FloorToProto(e.floor, out->mutable_floor());
  out->set_cloud_points(e.cloud_points);
  for (const ClusterSummary& c : e.clusters) {
    v1::ClusterSummary* p = out->add_clusters();
    p->set_index(c.index);
    p->set_points(c.points);
    SetVector(c.centroid.cast<double>(), p->mutable_centroid());
    SetVector(c.min.cast<double>(), p->mutable_min());
    SetVector(c.max.cast<double>(), p->mutable_max());
    p->set_searched(c.searched);
  }
  for (const Candidate& c : e.candidates) CandidateToProto(c, out->add_candidates());
  v1::Tracking* tracking = out->mutable_tracking();
  tracking->set_tracked(e.tracking.tracked);
  tracking->set_prior_given(e.tracking.prior_given);
  tracking->set_floor_reused(e.tracking.floor_reused);
  tracking->set_height_searches(e.height_passes);
  if (e.tracking.prior_given) {
    tracking->set_prior_template(e.tracking.prior_template);
    SetPose2D(e.tracking.prior_pose, tracking->mutable_prior_pose());
  }
  for (const Detection& d : e.detections) DetectionToProto(d, out->add_detections());
  if (!e.detections.empty()) {
    DetectionToProto(e.detections.front(), out->mutable_best());
    out->set_humanoid_found(e.detections.front().is_humanoid);
  }
}

void SetTimestamp(std::chrono::system_clock::time_point t, google::protobuf::Timestamp* out) {
  const auto ns =
      std::chrono::duration_cast<std::chrono::nanoseconds>(t.time_since_epoch()).count();
  out->set_seconds(ns / 1000000000);
  out->set_nanos(static_cast<int>(ns % 1000000000));
}

void FillPoseEstimate(std::uint64_t sequence, double source_time_s,
                      std::chrono::system_clock::time_point received, const std::string& source,
                      const Estimate* result, const Error* error, v1::PoseEstimate* out) {
  out->set_estimator(v1::ESTIMATOR_KIND_DEPTH_TEMPLATE);
  out->set_sequence(sequence);
  out->set_source_time(source_time_s);
  SetTimestamp(received, out->mutable_received_time());
  out->set_source(source);
  if (result != nullptr) {
    EstimateToProto(*result, out->mutable_depth_template());
    TimingsToProto(result->timings, out->mutable_timings());
  }
  if (error != nullptr) {
    out->mutable_error()->set_code(ErrorCodeName(error->code));
    out->mutable_error()->set_message(error->message);
  }
}

Result<DepthImage> DepthFromProto(const v1::DepthImage& depth, Intrinsics* intrinsics) {
  if (depth.width() == 0 || depth.height() == 0 || depth.width() > 8192 || depth.height() > 8192) {
    return Invalid("depth: width and height must be in [1, 8192], got " +
                   std::to_string(depth.width()) + "x" + std::to_string(depth.height()));
  }
  const size_t expected = static_cast<size_t>(depth.width()) * depth.height() * 2;
  if (depth.data().size() != expected) {
    return Invalid("depth.data: expected width * height * 2 = " + std::to_string(expected) +
                   " bytes, got " + std::to_string(depth.data().size()));
  }
  if (!depth.has_intrinsics()) return Invalid("depth.intrinsics: missing");
  const v1::Intrinsics& k = depth.intrinsics();
  const double values[] = {k.fx(), k.fy(), k.cx(), k.cy()};
  const char* names[] = {"fx", "fy", "cx", "cy"};
  for (int i = 0; i < 4; ++i) {
    if (!std::isfinite(values[i])) {
      return Invalid(std::string("depth.intrinsics.") + names[i] + ": not a finite number");
    }
  }
  if (k.width() != depth.width() || k.height() != depth.height()) {
    return Invalid("depth.intrinsics: " + std::to_string(k.width()) + "x" +
                   std::to_string(k.height()) + " does not match the image " +
                   std::to_string(depth.width()) + "x" + std::to_string(depth.height()));
  }
  intrinsics->width = static_cast<int>(k.width());
  intrinsics->height = static_cast<int>(k.height());
  intrinsics->fx = k.fx();
  intrinsics->fy = k.fy();
  intrinsics->cx = k.cx();
  intrinsics->cy = k.cy();
  Status valid = intrinsics->Validate();
  if (!valid.ok()) return Invalid("depth.intrinsics: " + valid.error().message);
  DepthImage image(static_cast<int>(depth.width()), static_cast<int>(depth.height()));
  const auto* bytes = reinterpret_cast<const unsigned char*>(depth.data().data());
  for (size_t i = 0; i < image.mm.size(); ++i) {
    image.mm[i] = static_cast<std::uint16_t>(bytes[2 * i] | (bytes[2 * i + 1] << 8));
  }
  return image;
}

Result<PointCloud> CloudFromProto(const v1::PointCloud& cloud) {
  const int n = cloud.xyz_size();
  if (n == 0) return Invalid("cloud.xyz: empty");
  if (n % 3 != 0) {
    return Invalid("cloud.xyz: length " + std::to_string(n) + " is not a multiple of 3");
  }
  if (static_cast<size_t>(n / 3) > kMaxRequestCloudPoints) {
    return MakeError(ErrorCode::kOutOfRange,
                     "cloud.xyz: more than " + std::to_string(kMaxRequestCloudPoints) + " points");
  }
  PointCloud out;
  out.points.reserve(n / 3);
  for (int i = 0; i < n; i += 3) {
    out.points.emplace_back(cloud.xyz(i), cloud.xyz(i + 1), cloud.xyz(i + 2));
  }
  return out;
}

void DepthToProto(const DepthImage& depth, const Intrinsics& k, v1::DepthImage* out) {
  out->set_width(depth.width);
  out->set_height(depth.height);
  std::string data(depth.mm.size() * 2, '\0');
  for (size_t i = 0; i < depth.mm.size(); ++i) {
    data[2 * i] = static_cast<char>(depth.mm[i] & 0xff);
    data[2 * i + 1] = static_cast<char>(depth.mm[i] >> 8);
  }
  out->set_data(std::move(data));
  IntrinsicsToProto(k, out->mutable_intrinsics());
}

void IntrinsicsToProto(const Intrinsics& k, v1::Intrinsics* out) {
  out->set_width(static_cast<std::uint32_t>(k.width));
  out->set_height(static_cast<std::uint32_t>(k.height));
  out->set_fx(k.fx);
  out->set_fy(k.fy);
  out->set_cx(k.cx);
  out->set_cy(k.cy);
}

void CloudToProto(const PointCloud& cloud, v1::PointCloud* out) {
  out->mutable_xyz()->Reserve(static_cast<int>(cloud.size() * 3));
  for (const Eigen::Vector3f& p : cloud.points) {
    out->add_xyz(p.x());
    out->add_xyz(p.y());
    out->add_xyz(p.z());
  }
}

}  // namespace hpose::server
