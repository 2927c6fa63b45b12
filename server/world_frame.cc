#include "server/world_frame.h"

#include <cmath>

namespace hpose::server {

namespace {

Pose2D FromProto(const v1::Pose2D& p) { return Pose2D{p.x(), p.y(), p.theta()}; }

void ToProto(const Pose2D& p, v1::Pose2D* out) {
  out->set_x(p.x);
  out->set_y(p.y);
  out->set_theta(p.theta);
}

void AddToCandidate(const Pose2D& world_from_ground, v1::Candidate* c) {
  ToProto(GroundPoseToWorld(world_from_ground, FromProto(c->pose())), c->mutable_pose_world());
  if (c->has_runner_up()) {
    ToProto(GroundPoseToWorld(world_from_ground, FromProto(c->runner_up_pose())),
            c->mutable_runner_up_pose_world());
  }
}

}  // namespace

Pose2D WorldFromGround(const WorldFrameConfig& config) {
  return Pose2D{config.x_m, config.y_m, NormalizeAngle(config.yaw_rad)};
}

Pose2D GroundPoseToWorld(const Pose2D& world_from_ground, const Pose2D& pose_ground) {
  const double c = std::cos(world_from_ground.theta);
  const double s = std::sin(world_from_ground.theta);
  return Pose2D{world_from_ground.x + c * pose_ground.x - s * pose_ground.y,
                world_from_ground.y + s * pose_ground.x + c * pose_ground.y,
                NormalizeAngle(world_from_ground.theta + pose_ground.theta)};
}

void AddDepthWorldFrame(const Pose2D& world_from_ground, v1::PoseEstimate* estimate) {
  if (estimate->estimator() != v1::ESTIMATOR_KIND_DEPTH_TEMPLATE ||
      !estimate->has_depth_template()) {
    return;
  }
  v1::DepthTemplateResult* r = estimate->mutable_depth_template();
  ToProto(world_from_ground, r->mutable_world_from_ground());
  for (v1::Candidate& c : *r->mutable_candidates()) AddToCandidate(world_from_ground, &c);
  for (v1::Detection& d : *r->mutable_detections()) {
    AddToCandidate(world_from_ground, d.mutable_best());
  }
  if (r->has_best()) {
    AddToCandidate(world_from_ground, r->mutable_best()->mutable_best());
    if (r->humanoid_found()) *estimate->mutable_robot_pose_world() = r->best().best().pose_world();
  }
}

}  // namespace hpose::server
