#ifndef HPOSE_CORE_IO_INTRINSICS_FILE_H_
#define HPOSE_CORE_IO_INTRINSICS_FILE_H_

#include <string>

#include "core/common/status.h"
#include "core/depth/intrinsics.h"

namespace hpose {

// Reads a depth camera's pinhole intrinsics from either
//   hpose's intrinsics.json ({"width","height","fx","fy","cx","cy"}; ReadIntrinsicsJson), or
//   a ROS camera_info YAML: the calibration file ROS's camera_calibration writes
//   (image_width, image_height, camera_matrix: {rows: 3, cols: 3, data: [fx 0 cx 0 fy cy 0 0 1]})
//   or a sensor_msgs/CameraInfo message as YAML (width, height, K or k: [9 numbers]).
// The format is chosen by the extension (.json; .yaml / .yml). Distortion is ignored (depth
// images from OpenNI2-class sensors come rectified). kNotFound, kDataLoss (malformed) or
// kInvalidArgument (values out of range), naming the file and the field.
Result<Intrinsics> ReadIntrinsicsFile(const std::string& path);

}  // namespace hpose

#endif  // HPOSE_CORE_IO_INTRINSICS_FILE_H_
