#include "core/sim/humanoid_model.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "core/common/pose2d.h"

namespace hpose {
namespace {

Eigen::Matrix3d RotX(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitX()).matrix(); }
Eigen::Matrix3d RotY(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()).matrix(); }
Eigen::Matrix3d RotZ(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).matrix(); }

Eigen::Isometry3d MakeIsometry(const Eigen::Matrix3d& r, const Eigen::Vector3d& t) {
  Eigen::Isometry3d iso = Eigen::Isometry3d::Identity();
  iso.linear() = r;
  iso.translation() = t;
  return iso;
}

const std::pair<const char*, double HumanoidDimensions::*> kDimensionFields[] = {
    {"foot_length_m", &HumanoidDimensions::foot_length_m},
    {"foot_width_m", &HumanoidDimensions::foot_width_m},
    {"foot_thickness_m", &HumanoidDimensions::foot_thickness_m},
    {"ankle_height_m", &HumanoidDimensions::ankle_height_m},
    {"thigh_length_m", &HumanoidDimensions::thigh_length_m},
    {"tibia_length_m", &HumanoidDimensions::tibia_length_m},
    {"leg_radius_m", &HumanoidDimensions::leg_radius_m},
    {"hip_offset_y_m", &HumanoidDimensions::hip_offset_y_m},
    {"hip_offset_z_m", &HumanoidDimensions::hip_offset_z_m},
    {"torso_width_m", &HumanoidDimensions::torso_width_m},
    {"torso_depth_m", &HumanoidDimensions::torso_depth_m},
    {"torso_top_m", &HumanoidDimensions::torso_top_m},
    {"pack_depth_m", &HumanoidDimensions::pack_depth_m},
    {"pack_width_m", &HumanoidDimensions::pack_width_m},
    {"pack_height_m", &HumanoidDimensions::pack_height_m},
    {"shoulder_offset_y_m", &HumanoidDimensions::shoulder_offset_y_m},
    {"upper_arm_length_m", &HumanoidDimensions::upper_arm_length_m},
    {"upper_arm_radius_m", &HumanoidDimensions::upper_arm_radius_m},
    {"forearm_length_m", &HumanoidDimensions::forearm_length_m},
    {"forearm_radius_m", &HumanoidDimensions::forearm_radius_m},
    {"neck_offset_z_m", &HumanoidDimensions::neck_offset_z_m},
    {"neck_radius_m", &HumanoidDimensions::neck_radius_m},
    {"head_radius_m", &HumanoidDimensions::head_radius_m},
    {"head_width_m", &HumanoidDimensions::head_width_m},
    {"ear_radius_m", &HumanoidDimensions::ear_radius_m},
};

const std::pair<const char*, double HumanoidJoints::*> kJointFields[] = {
    {"head_yaw", &HumanoidJoints::head_yaw_rad},
    {"left_shoulder_pitch", &HumanoidJoints::left_shoulder_pitch_rad},
    {"right_shoulder_pitch", &HumanoidJoints::right_shoulder_pitch_rad},
    {"left_shoulder_roll", &HumanoidJoints::left_shoulder_roll_rad},
    {"right_shoulder_roll", &HumanoidJoints::right_shoulder_roll_rad},
    {"left_elbow", &HumanoidJoints::left_elbow_rad},
    {"right_elbow", &HumanoidJoints::right_elbow_rad},
    {"left_hip_pitch", &HumanoidJoints::left_hip_pitch_rad},
    {"right_hip_pitch", &HumanoidJoints::right_hip_pitch_rad},
    {"left_hip_roll", &HumanoidJoints::left_hip_roll_rad},
    {"right_hip_roll", &HumanoidJoints::right_hip_roll_rad},
    {"left_knee", &HumanoidJoints::left_knee_rad},
    {"right_knee", &HumanoidJoints::right_knee_rad},
    {"left_ankle_pitch", &HumanoidJoints::left_ankle_pitch_rad},
    {"right_ankle_pitch", &HumanoidJoints::right_ankle_pitch_rad},
};

}  // namespace

std::vector<std::string> HumanoidDimensions::VariantNames() { return {"nao", "long_legs", "tall"}; }

Result<HumanoidDimensions> HumanoidDimensions::Variant(const std::string& name) {
  HumanoidDimensions d;
  if (name == "nao") return d;
  if (name == "long_legs") {
    d.thigh_length_m = 0.160;
    d.tibia_length_m = 0.165;
    d.hip_offset_y_m = 0.060;
    d.torso_width_m = 0.190;
    d.shoulder_offset_y_m = 0.128;
    d.battery_pack = false;
    return d;
  }
  if (name == "tall") {
    constexpr double kScale = 2.1;  // 0.58 m -> 1.23 m.
    for (const auto& [field_name, field] : kDimensionFields) d.*field *= kScale;
    for (double* v : {&d.foot_forward_offset_m, &d.torso_bottom_m, &d.pack_centre_z_m,
                      &d.shoulder_offset_z_m, &d.head_centre_above_neck_m}) {
      *v *= kScale;
    }
    return d;
  }
  std::string known;
  for (const std::string& n : VariantNames()) known += (known.empty() ? "" : ", ") + n;
  return MakeError(ErrorCode::kInvalidArgument,
                   "unknown body '" + name + "' (known: " + known + ")");
}

Status HumanoidDimensions::Validate() const {
  for (const auto& [name, field] : kDimensionFields) {
    const double v = this->*field;
    if (!std::isfinite(v) || v <= 0.0 || v > 2.0) {
      return MakeError(ErrorCode::kInvalidArgument, std::string("humanoid dimension ") + name +
                                                        " must be in (0, 2] m, got " +
                                                        std::to_string(v));
    }
  }
  for (const auto& [name, v] :
       {std::pair<const char*, double>{"foot_forward_offset_m", foot_forward_offset_m},
        {"torso_bottom_m", torso_bottom_m},
        {"shoulder_offset_z_m", shoulder_offset_z_m},
        {"head_centre_above_neck_m", head_centre_above_neck_m}}) {
    if (!std::isfinite(v) || std::abs(v) > 2.0) {
      return MakeError(ErrorCode::kInvalidArgument, std::string("humanoid dimension ") + name +
                                                        " must be in [-2, 2] m, got " +
                                                        std::to_string(v));
    }
  }
  if (torso_bottom_m >= torso_top_m) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "humanoid dimension torso_bottom_m must be below torso_top_m");
  }
  if (foot_thickness_m > ankle_height_m + leg_radius_m) {
    return MakeError(ErrorCode::kInvalidArgument,
                     "humanoid dimension foot_thickness_m exceeds ankle_height_m + leg_radius_m");
  }
  return Status::Ok();
}

Status HumanoidJoints::Validate() const {
  for (const auto& [name, field] : kJointFields) {
    const double v = this->*field;
    if (!std::isfinite(v) || std::abs(v) > 2.0 * kPi) {
      return MakeError(ErrorCode::kInvalidArgument, std::string("joint angle ") + name +
                                                        " must be finite and within +-2 pi rad");
    }
  }
  return Status::Ok();
}

std::vector<std::string> HumanoidJoints::PresetNames() {
  return {"standing", "right_arm_raised", "arms_swung"};
}

Result<HumanoidJoints> HumanoidJoints::Preset(const std::string& name) {
  HumanoidJoints j;
  // Arms hang slightly away from the body, as a Nao stands.
  j.left_shoulder_roll_rad = DegToRad(6.0);
  j.right_shoulder_roll_rad = DegToRad(6.0);
  if (name == "standing") return j;
  if (name == "right_arm_raised") {
    // Forward and up, 30 degrees short of vertical.
    j.right_shoulder_pitch_rad = DegToRad(150.0);
    return j;
  }
  if (name == "arms_swung") {
    // A walking robot's arms, the left forward and the right back.
    j.left_shoulder_pitch_rad = 0.4;
    j.right_shoulder_pitch_rad = -0.4;
    return j;
  }
  std::string known;
  for (const std::string& n : PresetNames()) known += (known.empty() ? "" : ", ") + n;
  return MakeError(ErrorCode::kInvalidArgument,
                   "unknown humanoid pose '" + name + "' (known: " + known + ")");
}

Result<HumanoidModel> HumanoidModel::Create(const HumanoidDimensions& dimensions,
                                            const HumanoidJoints& joints) {
  if (Status s = dimensions.Validate(); !s.ok()) return s.error();
  if (Status s = joints.Validate(); !s.ok()) return s.error();
  return HumanoidModel(dimensions, joints);
}

Result<HumanoidModel> HumanoidModel::FromPreset(const std::string& preset,
                                                const HumanoidDimensions& dimensions) {
  Result<HumanoidJoints> joints = HumanoidJoints::Preset(preset);
  if (!joints.ok()) return joints.error();
  return Create(dimensions, *joints);
}

HumanoidModel::HumanoidModel(const HumanoidDimensions& dimensions, const HumanoidJoints& joints)
    : dimensions_(dimensions), joints_(joints) {
  const HumanoidDimensions& d = dimensions_;
  const HumanoidJoints& j = joints_;
  std::vector<Primitive> body;  // in the torso frame (origin at the torso origin).

  body.push_back(Primitive::Box(
      "torso", Eigen::Vector3d(d.torso_depth_m, d.torso_width_m, d.torso_top_m - d.torso_bottom_m),
      MakeIsometry(Eigen::Matrix3d::Identity(),
                   Eigen::Vector3d(0.0, 0.0, 0.5 * (d.torso_top_m + d.torso_bottom_m)))));
  // The battery pack, overlapping the torso's back face by 5 mm so the two are one solid.
  if (d.battery_pack) {
    body.push_back(Primitive::Box(
        "battery_pack", Eigen::Vector3d(d.pack_depth_m + 0.005, d.pack_width_m, d.pack_height_m),
        MakeIsometry(Eigen::Matrix3d::Identity(),
                     Eigen::Vector3d(-0.5 * d.torso_depth_m - 0.5 * d.pack_depth_m + 0.0025, 0.0,
                                     d.pack_centre_z_m))));
  }

  // Neck and head; the head turns with the head yaw.
  const Eigen::Vector3d head_centre(0.0, 0.0, d.neck_offset_z_m + d.head_centre_above_neck_m);
  const double neck_bottom = d.torso_top_m - 0.01;
  const double neck_top = head_centre.z();
  if (neck_top > neck_bottom) {
    body.push_back(Primitive::Cylinder(
        "neck", d.neck_radius_m, neck_top - neck_bottom,
        MakeIsometry(Eigen::Matrix3d::Identity(),
                     Eigen::Vector3d(0.0, 0.0, 0.5 * (neck_top + neck_bottom)))));
  }
  body.push_back(Primitive::Sphere("head", d.head_radius_m, head_centre));
  // The ears: a short cylinder across the head (along the head's y axis), so head yaw shows.
  body.push_back(
      Primitive::Cylinder("ears", d.ear_radius_m, d.head_width_m,
                          MakeIsometry(RotZ(j.head_yaw_rad) * RotX(kPi / 2.0), head_centre)));

  for (const int side : {+1, -1}) {
    const bool left = side > 0;
    const std::string prefix = left ? "left_" : "right_";
    // Arm: shoulder pitch about y, then roll about x (mirrored), then the elbow about y.
    const double sh_pitch = left ? j.left_shoulder_pitch_rad : j.right_shoulder_pitch_rad;
    const double sh_roll = left ? j.left_shoulder_roll_rad : j.right_shoulder_roll_rad;
    const double elbow = left ? j.left_elbow_rad : j.right_elbow_rad;
    const Eigen::Vector3d shoulder(0.0, side * d.shoulder_offset_y_m, d.shoulder_offset_z_m);
    const Eigen::Matrix3d r_shoulder = RotY(-sh_pitch) * RotX(side * sh_roll);
    const Eigen::Vector3d elbow_pos =
        shoulder + r_shoulder * Eigen::Vector3d(0.0, 0.0, -d.upper_arm_length_m);
    const Eigen::Matrix3d r_elbow = r_shoulder * RotY(-elbow);
    const Eigen::Vector3d forearm_dir = r_elbow * Eigen::Vector3d(0.0, 0.0, -1.0);
    const double forearm_axis = std::max(0.0, d.forearm_length_m - d.forearm_radius_m);
    body.push_back(
        Primitive::Capsule(prefix + "upper_arm", d.upper_arm_radius_m, shoulder, elbow_pos));
    body.push_back(Primitive::Capsule(prefix + "forearm", d.forearm_radius_m, elbow_pos,
                                      elbow_pos + forearm_axis * forearm_dir));

    // Leg: hip pitch about y, hip roll about x (mirrored), knee about y, ankle about y.
    const double hip_pitch = left ? j.left_hip_pitch_rad : j.right_hip_pitch_rad;
    const double hip_roll = left ? j.left_hip_roll_rad : j.right_hip_roll_rad;
    const double knee = left ? j.left_knee_rad : j.right_knee_rad;
    const double ankle = left ? j.left_ankle_pitch_rad : j.right_ankle_pitch_rad;
    const Eigen::Vector3d hip(0.0, side * d.hip_offset_y_m, -d.hip_offset_z_m);
    const Eigen::Matrix3d r_hip = RotY(-hip_pitch) * RotX(side * hip_roll);
    const Eigen::Vector3d knee_pos = hip + r_hip * Eigen::Vector3d(0.0, 0.0, -d.thigh_length_m);
    const Eigen::Matrix3d r_knee = r_hip * RotY(knee);
    const Eigen::Vector3d ankle_pos =
        knee_pos + r_knee * Eigen::Vector3d(0.0, 0.0, -d.tibia_length_m);
    const Eigen::Matrix3d r_ankle = r_knee * RotY(-ankle);
    body.push_back(Primitive::Capsule(prefix + "thigh", d.leg_radius_m, hip, knee_pos));
    body.push_back(Primitive::Capsule(prefix + "shank", d.leg_radius_m, knee_pos, ankle_pos));
    const Eigen::Vector3d foot_centre =
        ankle_pos + r_ankle * Eigen::Vector3d(d.foot_forward_offset_m, 0.0,
                                              -(d.ankle_height_m - 0.5 * d.foot_thickness_m));
    body.push_back(Primitive::Box(
        prefix + "foot", Eigen::Vector3d(d.foot_length_m, d.foot_width_m, d.foot_thickness_m),
        MakeIsometry(r_ankle, foot_centre)));
  }

  // Lift the body so its lowest point touches the floor; the origin stays below the torso.
  double min_z = std::numeric_limits<double>::infinity();
  for (const Primitive& p : body) min_z = std::min(min_z, p.Bounds().min().z());
  const Eigen::Isometry3d template_from_torso(Eigen::Translation3d(0.0, 0.0, -min_z));
  bounds_.setEmpty();
  for (const Primitive& p : body) {
    primitives_.push_back(p.Transformed(template_from_torso));
    bounds_.extend(primitives_.back().Bounds());
  }
}

bool HumanoidModel::IsFreeLimb(const std::string& name) {
  const auto ends_with = [&](const std::string& suffix) {
    return name.size() >= suffix.size() &&
           name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0;
  };
  return ends_with("upper_arm") || ends_with("forearm") || name == "neck" || name == "head" ||
         name == "ears";
}

Result<std::vector<Eigen::Vector3f>> HumanoidModel::SampleSurface(double spacing_m) const {
  return Sample(spacing_m, false);
}

Result<std::vector<Eigen::Vector3f>> HumanoidModel::SampleFreeLimbSurface(double spacing_m) const {
  return Sample(spacing_m, true);
}

Result<std::vector<Eigen::Vector3f>> HumanoidModel::Sample(double spacing_m,
                                                           bool free_limbs_only) const {
  if (!std::isfinite(spacing_m) || spacing_m < 0.0005 || spacing_m > 0.1) {
    return MakeError(
        ErrorCode::kInvalidArgument,
        "surface spacing must be in [0.0005, 0.1] m, got " + std::to_string(spacing_m));
  }
  // Points this far inside another primitive are hidden; points on a shared surface stay.
  const double margin = std::min(0.001, 0.25 * spacing_m);
  std::vector<Eigen::Vector3f> out;
  for (size_t i = 0; i < primitives_.size(); ++i) {
    if (free_limbs_only && !IsFreeLimb(primitives_[i].name)) continue;
    for (const Eigen::Vector3d& p : primitives_[i].SampleSurface(spacing_m)) {
      bool hidden = false;
      for (size_t k = 0; k < primitives_.size() && !hidden; ++k) {
        hidden = k != i && primitives_[k].Contains(p, margin);
      }
      if (!hidden) out.push_back(p.cast<float>());
    }
  }
  return out;
}

}  // namespace hpose
