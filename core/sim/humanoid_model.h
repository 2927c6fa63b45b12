#ifndef HPOSE_CORE_SIM_HUMANOID_MODEL_H_
#define HPOSE_CORE_SIM_HUMANOID_MODEL_H_

#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/common/status.h"
#include "core/sim/primitive.h"

namespace hpose {

// Body dimensions of the parametric humanoid, metres. The defaults follow the published link
// lengths of an Aldebaran Nao (about 0.58 m tall standing).
struct HumanoidDimensions {
  // Feet: a box below each ankle.
  double foot_length_m = 0.160;
  double foot_width_m = 0.088;
  double foot_thickness_m = 0.030;
  double ankle_height_m = 0.045;         // ankle joint above the sole.
  double foot_forward_offset_m = 0.015;  // foot centre ahead of the ankle.
  // Legs: capsules hip-knee (thigh) and knee-ankle (shank).
  double thigh_length_m = 0.100;
  double tibia_length_m = 0.103;
  double leg_radius_m = 0.035;
  double hip_offset_y_m = 0.050;  // each hip joint from the body's mid-plane.
  double hip_offset_z_m = 0.085;  // hip joints below the torso origin.
  // Torso: a box around the torso origin (the template origin is on the floor below it).
  double torso_width_m = 0.140;    // along y.
  double torso_depth_m = 0.100;    // along x.
  double torso_bottom_m = -0.065;  // box bottom relative to the torso origin.
  double torso_top_m = 0.120;      // box top relative to the torso origin.
  // Battery pack: a box on the torso's back (a Nao carries its battery there), which gives the
  // body a back distinct from its front.
  double pack_depth_m = 0.035;     // how far it stands out behind the torso, along -x.
  double pack_width_m = 0.100;     // along y.
  double pack_height_m = 0.110;    // along z.
  double pack_centre_z_m = 0.020;  // its centre relative to the torso origin.
  bool battery_pack = true;        // false: no pack (front and back then differ less).
  // Arms: capsules shoulder-elbow and elbow-fingertip.
  double shoulder_offset_y_m = 0.098;
  double shoulder_offset_z_m = 0.100;
  double upper_arm_length_m = 0.105;
  double upper_arm_radius_m = 0.030;
  double forearm_length_m = 0.114;  // elbow to fingertips (forearm and hand).
  double forearm_radius_m = 0.025;
  // Neck and head: a short cylinder, a sphere above the neck joint and a cylinder across it
  // for the ears (so the head yaw shows).
  double neck_offset_z_m = 0.1265;  // head yaw joint above the torso origin.
  double neck_radius_m = 0.025;
  double head_radius_m = 0.060;
  double head_centre_above_neck_m = 0.060;
  double head_width_m = 0.134;  // ear to ear, along the head's y axis.
  double ear_radius_m = 0.035;  // the ears are a cylinder across the head.

  // Checks every value is finite and positive where it must be; names the offending field.
  Status Validate() const;

  // Named bodies, so accuracy is not only measured on one set of proportions: "nao" (the
  // defaults above), "long_legs" (about 0.73 m tall: thighs and shanks 60% longer, wider
  // torso and shoulders, no battery pack) and "tall" (every length of the Nao's 2.1 times:
  // 1.23 m, taller than 64 voxels of 16 mm). kInvalidArgument for another name, listing the
  // known ones.
  static Result<HumanoidDimensions> Variant(const std::string& name);
  static std::vector<std::string> VariantNames();
};

// Joint angles in radians. Zero everywhere is the robot standing straight with the arms
// hanging. Left and right use mirrored conventions, so equal values give a symmetric pose.
struct HumanoidJoints {
  double head_yaw_rad = 0.0;  // + turns the head to the robot's left.
  // Shoulder pitch: + raises the arm forward (pi/2 horizontal forward, pi straight up).
  double left_shoulder_pitch_rad = 0.0;
  double right_shoulder_pitch_rad = 0.0;
  // Shoulder roll: + moves the arm sideways away from the body.
  double left_shoulder_roll_rad = 0.0;
  double right_shoulder_roll_rad = 0.0;
  // Elbow: + bends the forearm forward/up relative to the upper arm.
  double left_elbow_rad = 0.0;
  double right_elbow_rad = 0.0;
  // Hip pitch: + swings the thigh forward. Hip roll: + spreads the leg sideways.
  double left_hip_pitch_rad = 0.0;
  double right_hip_pitch_rad = 0.0;
  double left_hip_roll_rad = 0.0;
  double right_hip_roll_rad = 0.0;
  // Knee: + bends the shank backwards.
  double left_knee_rad = 0.0;
  double right_knee_rad = 0.0;
  // Ankle pitch: + lifts the toes.
  double left_ankle_pitch_rad = 0.0;
  double right_ankle_pitch_rad = 0.0;

  // Named presets: "standing" (arms hanging slightly away from the body, symmetric),
  // "right_arm_raised" (the right arm raised forward and up, so the robot is not left/right
  // symmetric) and "arms_swung" (as standing, the arms swung 0.4 rad forward and back against
  // each other, as when walking). kInvalidArgument for another name, listing the known ones.
  static Result<HumanoidJoints> Preset(const std::string& name);
  static std::vector<std::string> PresetNames();

  // Checks every angle is finite and within [-2 pi, 2 pi]; names the offending joint.
  Status Validate() const;
};

// A parametric humanoid made of primitives, posed by forward kinematics in the template frame
// (origin on the floor below the torso centre, +x forward, +y left, +z up, metres). The body is
// lifted so that its lowest point (normally a sole) touches z = 0.
class HumanoidModel final {
 public:
  // Fails (kInvalidArgument) on invalid dimensions or joint angles.
  static Result<HumanoidModel> Create(const HumanoidDimensions& dimensions,
                                      const HumanoidJoints& joints);
  // Create() with the joints of a named preset (see HumanoidJoints::Preset).
  static Result<HumanoidModel> FromPreset(const std::string& preset,
                                          const HumanoidDimensions& dimensions = {});

  const HumanoidDimensions& dimensions() const { return dimensions_; }
  const HumanoidJoints& joints() const { return joints_; }
  // The posed primitives in the template frame: torso, neck, head, upper arms, forearms,
  // thighs, shanks, feet (names "torso", "left_upper_arm", ...).
  const std::vector<Primitive>& primitives() const { return primitives_; }
  // Axis-aligned bounds of the posed body in the template frame (min z is 0).
  const Eigen::AlignedBox3d& bounds() const { return bounds_; }
  // Top of the body above the floor, metres.
  double Height() const { return bounds_.max().z(); }

  // Points on the body's outer surface, roughly `spacing_m` apart, in the template frame.
  // Points hidden inside another primitive (where limbs join the torso) are left out.
  // Fails (kInvalidArgument) unless 0.5 mm <= spacing_m <= 0.1 m.
  Result<std::vector<Eigen::Vector3f>> SampleSurface(double spacing_m) const;
  // The points of SampleSurface that lie on free limbs (IsFreeLimb). Fails as SampleSurface.
  Result<std::vector<Eigen::Vector3f>> SampleFreeLimbSurface(double spacing_m) const;

  // Whether the primitive named `name` is on a free limb: a limb that does not reach the floor
  // and that a standing robot may hold otherwise than its template (the arms, the neck and the
  // head with its ears; not the torso, its pack or the legs). VoxelTemplate::free_limb.
  static bool IsFreeLimb(const std::string& name);

 private:
  HumanoidModel(const HumanoidDimensions& dimensions, const HumanoidJoints& joints);
  // SampleSurface's points, of the free limbs only when `free_limbs_only`.
  Result<std::vector<Eigen::Vector3f>> Sample(double spacing_m, bool free_limbs_only) const;

  HumanoidDimensions dimensions_;
  HumanoidJoints joints_;
  std::vector<Primitive> primitives_;
  Eigen::AlignedBox3d bounds_;
};

}  // namespace hpose

#endif  // HPOSE_CORE_SIM_HUMANOID_MODEL_H_
