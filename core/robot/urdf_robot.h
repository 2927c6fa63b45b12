#ifndef HPOSE_CORE_ROBOT_URDF_ROBOT_H_
#define HPOSE_CORE_ROBOT_URDF_ROBOT_H_

#include <map>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "core/common/status.h"
#include "core/robot/joint_sets.h"
#include "core/sim/triangle_mesh.h"

namespace hpose {

enum class UrdfGeometryKind { kVisual, kCollision };

struct UrdfLoadOptions {
  UrdfGeometryKind geometry = UrdfGeometryKind::kVisual;  // which shapes of each link.
  // Directories searched for package://NAME (see ResolveUrdfResource), in order.
  std::vector<std::string> package_paths;
  // Skip meshes that are missing or unreadable (each listed in UrdfRobot::skipped()) instead of
  // failing.
  bool allow_missing = false;
  double primitive_max_edge_m = 0.005;  // tessellation of URDF cylinders and spheres, metres.
};

// A mesh left out by UrdfLoadOptions::allow_missing.
struct SkippedMesh {
  std::string link;
  std::string uri;     // as written in the URDF, e.g. package://pkg/meshes/head.STL.
  std::string path;    // what it resolved to ("" when the package was not found).
  std::string reason;  // e.g. "file does not exist".
};

// One joint of the URDF, as loaded.
struct UrdfJointInfo {
  std::string name;
  std::string type;  // revolute, continuous, prismatic, fixed, floating or planar.
  std::string parent_link;
  std::string child_link;
  bool has_limits = false;  // revolute and prismatic joints.
  double lower = 0.0;       // radians or metres.
  double upper = 0.0;
  std::string mimic_of;  // non-empty: position = multiplier * mimic_of + offset.
  double mimic_multiplier = 1.0;
  double mimic_offset = 0.0;

  // Revolute, continuous and prismatic joints that are not mimics: the ones users set.
  bool Settable() const;
};

// A robot posed by forward kinematics, in the template frame: origin on the floor below the
// reference link's origin, +x that link's x axis projected on the floor, +z up; the floor is
// the plane through the posed robot's lowest point (its feet), parallel to the root link's
// x-y plane (URDF robots stand with their root z axis up).
struct PosedRobot {
  TriangleMesh mesh;  // every loaded shape, template frame, metres.
  // The part of `mesh` on free limbs: the links beyond a moving joint of the trunk (the root link
  // and what is fixed to it) whose lowest point stays more than kFreeLimbClearance of the robot's
  // height above the floor (arms, head; not the legs it stands on). A standing robot may hold
  // them otherwise than the template does (VoxelTemplate::free_limb).
  TriangleMesh free_limbs;
  // The joints those limbs hang from, in the URDF's order.
  std::vector<std::string> free_limb_joints;
  Eigen::Isometry3d template_from_root = Eigen::Isometry3d::Identity();
  std::map<std::string, Eigen::Isometry3d> template_from_link;
  std::string reference_link;
  // Facts the user should know, e.g. a mimic joint driven outside its limits.
  std::vector<std::string> notes;

  // Top of the posed robot above the floor, metres.
  double Height() const { return mesh.empty() ? 0.0 : mesh.Bounds().max().z(); }
};

// How far above the floor, as a share of the robot's height, a limb's lowest point must stay to
// count as a free limb (PosedRobot::free_limbs): a humanoid's hands hang at a third of its height
// or higher, its feet stand on the floor (a foot lifted for a step stays below a tenth).
inline constexpr double kFreeLimbClearance = 0.15;

// A robot read from a URDF file (urdfdom) with its visual or collision shapes loaded: meshes
// (STL, COLLADA, OBJ and the other formats assimp reads, with the URDF scale) and primitives
// (box, cylinder, sphere; tessellated). Load once, pose many times.
class UrdfRobot final {
 public:
  // Fails with kNotFound (no such URDF file), kInvalidArgument (not a valid URDF: the
  // parser's message is given), or, unless options.allow_missing, kNotFound/kDataLoss naming
  // the link and the path of a mesh that is missing or cannot be read.
  static Result<UrdfRobot> Load(const std::string& urdf_path, const UrdfLoadOptions& options = {});

  const std::string& name() const { return name_; }
  const std::string& root_link() const { return root_link_; }
  std::vector<std::string> LinkNames() const;
  const std::vector<UrdfJointInfo>& joints() const { return joint_infos_; }
  const std::vector<SkippedMesh>& skipped() const { return skipped_; }
  // Number of triangles of all loaded shapes (unposed).
  size_t TriangleCount() const;

  // Poses the robot: joints not in `positions` stay at 0, mimic joints follow their leader.
  // `reference_link` defines the template frame (empty: the root link). Fails
  // (kInvalidArgument) naming every unknown joint, a joint that cannot be set (fixed, mimic,
  // floating, planar), a position outside the joint's limits, an unknown reference link or
  // one whose x axis is vertical, a link whose shapes lie farther than kMaxTemplateOffsetM from
  // the root, or a robot with no shape at all. Mimic joints driven outside
  // their own limits are noted in PosedRobot::notes.
  Result<PosedRobot> Pose(const JointValues& positions,
                          const std::string& reference_link = "") const;

 private:
  struct Link {
    std::string name;
    int parent_joint = -1;
    TriangleMesh shapes;  // link frame.
  };
  struct Joint {
    UrdfJointInfo info;
    int parent_link = -1;
    int child_link = -1;
    Eigen::Isometry3d parent_from_origin = Eigen::Isometry3d::Identity();
    Eigen::Vector3d axis = Eigen::Vector3d::UnitX();
  };

  UrdfRobot() = default;

  std::string name_;
  std::string root_link_;
  std::vector<Link> links_;  // parents before children (the root first).
  std::vector<Joint> joints_;
  std::vector<UrdfJointInfo> joint_infos_;
  std::vector<SkippedMesh> skipped_;
};

}  // namespace hpose

#endif  // HPOSE_CORE_ROBOT_URDF_ROBOT_H_
