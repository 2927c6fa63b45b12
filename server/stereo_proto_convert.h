#ifndef HPOSE_SERVER_STEREO_PROTO_CONVERT_H_
#define HPOSE_SERVER_STEREO_PROTO_CONVERT_H_

#include <chrono>
#include <cstdint>
#include <string>

#include "core/common/status.h"
#include "core/stereo/rgb_image.h"
#include "core/stereo/stereo_frame_result.h"
#include "core/stereo/stereo_tracker.h"
#include "hpose/v1/pose_service.pb.h"

namespace hpose::server {

// The stereo-marker estimator's result for one pair (world frame, SI units) and, when `track`
// is not null, the tracker's state after it (averaged robot pose, motion, predicted path).
void StereoResultToProto(const StereoFrameResult& frame, const StereoTrackState* track,
                         v1::StereoMarkerResult* out);

// Fills a PoseEstimate of the stereo-marker estimator: `frame` (with `track` when known) when
// the pair was processed, or `error` when it could not be. robot_pose_world is set when the
// pair gave a robot pose. timings.total is `process_s`.
void FillStereoPoseEstimate(std::uint64_t sequence, double source_time_s,
                            std::chrono::system_clock::time_point received,
                            const std::string& source, const StereoFrameResult* frame,
                            const StereoTrackState* track, const Error* error, double process_s,
                            v1::PoseEstimate* out);

// API image -> core image. Fails with kInvalidArgument naming `field` when the size is zero or
// above 8192 pixels a side, or data does not hold width * height * 3 bytes.
Result<RgbImage> ColorImageFromProto(const v1::ColorImage& image, const std::string& field);
// The inverse, for clients and tests.
void ColorImageToProto(const RgbImage& image, v1::ColorImage* out);

}  // namespace hpose::server

#endif  // HPOSE_SERVER_STEREO_PROTO_CONVERT_H_
