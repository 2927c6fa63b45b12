#ifndef HPOSE_CORE_ROBOT_JOINT_SETS_H_
#define HPOSE_CORE_ROBOT_JOINT_SETS_H_

#include <map>
#include <string>
#include <vector>

#include "core/common/status.h"

namespace hpose {

// Joint positions by joint name: radians for revolute and continuous joints, metres for
// prismatic ones. Joints not named keep 0.
using JointValues = std::map<std::string, double>;

// One named posture of a robot, e.g. "standing" or "right_arm_raised".
struct NamedJointSet {
  std::string name;
  JointValues joints;
};

// Parses a YAML document mapping set names to maps of joint name -> position, e.g.
//   standing: {}
//   right_arm_raised: {j_shoulder_r: -2.8, j_high_arm_r: 0.3}
// Sets keep the order of the document. Fails (kInvalidArgument) on malformed YAML, a top level
// that is not a map, an empty or repeated set name, a set name with characters other than
// [A-Za-z0-9_.-], or a position that is not a finite number, naming `origin`, the set and the
// joint.
Result<std::vector<NamedJointSet>> ParseJointSetsYaml(const std::string& text,
                                                      const std::string& origin);
// Reads and parses a joint-set file. kNotFound when it cannot be read.
Result<std::vector<NamedJointSet>> LoadJointSetsFile(const std::string& path);

// Parses "NAME=VALUE" (a joint position given on a command line) into `values`. Fails
// (kInvalidArgument) on a missing '=', an empty name or a value that is not a finite number.
Status ParseJointAssignment(const std::string& text, JointValues* values);

}  // namespace hpose

#endif  // HPOSE_CORE_ROBOT_JOINT_SETS_H_
