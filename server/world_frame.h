#ifndef HPOSE_SERVER_WORLD_FRAME_H_
#define HPOSE_SERVER_WORLD_FRAME_H_

#include "core/common/pose2d.h"
#include "hpose/v1/pose_service.pb.h"
#include "server/daemon_config.h"

namespace hpose::server {

// world_from_ground of a configuration as a planar pose (x, y in metres, theta = yaw in
// (-pi, pi]).
Pose2D WorldFromGround(const WorldFrameConfig& config);

// A pose in the ground frame (robot frame in the ground frame) expressed in the world frame:
// world_from_robot = world_from_ground * ground_from_robot; theta in (-pi, pi].
Pose2D GroundPoseToWorld(const Pose2D& world_from_ground, const Pose2D& pose_ground);

// Adds the world-frame fields to a depth-template estimate already filled in the ground frame:
// every candidate's (and detection's) pose_world / runner_up_pose_world, the result's
// world_from_ground, and the estimate's robot_pose_world when the humanoid was found. Leaves
// estimates of other estimators, and estimates without a result, unchanged.
void AddDepthWorldFrame(const Pose2D& world_from_ground, v1::PoseEstimate* estimate);

}  // namespace hpose::server

#endif  // HPOSE_SERVER_WORLD_FRAME_H_
