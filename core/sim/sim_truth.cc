#include "core/sim/sim_truth.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

#include "core/io/atomic_file.h"

namespace hpose {
namespace {

using Json = nlohmann::ordered_json;

constexpr double kMaxSceneM = 1e4;
constexpr double kMaxHeadingRad = 4 * kPi;

Json PoseToJson(const Pose2D& p) { return Json{{"x", p.x}, {"y", p.y}, {"theta", p.theta}}; }

// A number of the file that must be finite and within `limit` of zero: a simulated scene lies
// within 10 km, as a ground frame is given; a heading within two turns. `where` names the
// object in the file ("frames[3]") for the message.
double BoundedNumber(const Json& j, const std::string& where, const char* key, double limit,
                     const char* unit) {
  const double v = j.at(key).get<double>();
  if (!(std::abs(v) <= limit)) {
    char text[96];
    std::snprintf(text, sizeof text, " = %g is not within %g %s", v, limit, unit);
    throw std::runtime_error(where + "." + key + text);
  }
  return v;
}

Pose2D PoseFromJson(const Json& j, const std::string& where) {
  Pose2D p;
  p.x = BoundedNumber(j, where, "x", kMaxSceneM, "m");
  p.y = BoundedNumber(j, where, "y", kMaxSceneM, "m");
  p.theta = BoundedNumber(j, where, "theta", kMaxHeadingRad, "rad");
  return p;
}

Json PrimitiveToJson(const Primitive& p) {
  const Eigen::Vector3d t = p.parent_from_local.translation();
  const Eigen::Quaterniond q(p.parent_from_local.linear());
  const Eigen::Matrix3d r = p.parent_from_local.linear();
  return Json{{"name", p.name},
              {"shape", PrimitiveShapeName(p.shape)},
              {"position_m", {t.x(), t.y(), t.z()}},
              {"orientation_wxyz", {q.w(), q.x(), q.y(), q.z()}},
              {"yaw_rad", std::atan2(r(1, 0), r(0, 0))},
              {"half_size_m", {p.half_size.x(), p.half_size.y(), p.half_size.z()}}};
}

Eigen::Vector3d Vector3FromJson(const Json& j, const std::string& where, const char* field) {
  const Json& a = j.at(field);
  if (!a.is_array() || a.size() != 3) {
    throw std::runtime_error(where + "." + field + " needs 3 numbers");
  }
  const Eigen::Vector3d v(a[0].get<double>(), a[1].get<double>(), a[2].get<double>());
  if (!(v.cwiseAbs().maxCoeff() <= kMaxSceneM)) {
    char text[160];
    std::snprintf(text, sizeof text, " = [%g, %g, %g] is not within %g m", v.x(), v.y(), v.z(),
                  kMaxSceneM);
    throw std::runtime_error(where + "." + field + text);
  }
  return v;
}

Primitive PrimitiveFromJson(const Json& j, const std::string& where) {
  Primitive p;
  p.name = j.at("name").get<std::string>();
  const std::optional<PrimitiveShape> shape =
      PrimitiveShapeFromName(j.at("shape").get<std::string>());
  if (!shape) throw std::runtime_error(where + ": unknown clutter shape");
  p.shape = *shape;
  const Json& q = j.at("orientation_wxyz");
  if (!q.is_array() || q.size() != 4) {
    throw std::runtime_error(where + ".orientation_wxyz needs 4 numbers");
  }
  const Eigen::Quaterniond quat(q[0].get<double>(), q[1].get<double>(), q[2].get<double>(),
                                q[3].get<double>());
  if (!(quat.norm() > 0.5)) throw std::runtime_error(where + ".orientation_wxyz is not a rotation");
  p.parent_from_local = Eigen::Isometry3d::Identity();
  p.parent_from_local.linear() = quat.normalized().toRotationMatrix();
  p.parent_from_local.translation() = Vector3FromJson(j, where, "position_m");
  p.half_size = Vector3FromJson(j, where, "half_size_m");
  return p;
}

}  // namespace

std::string SimTruthToJson(const SimTruth& truth) {
  Json j;
  j["format"] = "hpose-sim-truth";
  j["version"] = 1;
  Json humanoid = PoseToJson(truth.humanoid_pose);
  humanoid["preset"] = truth.humanoid_preset;
  humanoid["height_m"] = truth.humanoid_height_m;
  j["humanoid"] = humanoid;
  j["other_humanoids"] = Json::array();
  for (const SimHumanoidTruth& h : truth.other_humanoids) {
    Json o = PoseToJson(h.pose);
    o["preset"] = h.preset;
    j["other_humanoids"].push_back(o);
  }
  j["sensor"] = {{"height_m", truth.sensor_height_m},
                 {"pitch_rad", truth.sensor_pitch_rad},
                 {"roll_rad", truth.sensor_roll_rad}};
  const Intrinsics& k = truth.intrinsics;
  j["intrinsics"] = {{"width", k.width}, {"height", k.height}, {"fx", k.fx},
                     {"fy", k.fy},       {"cx", k.cx},         {"cy", k.cy}};
  j["noise"] = {{"enabled", truth.noise_enabled}, {"seed", truth.seed}};
  if (truth.noise_correlated_share > 0.0) {
    j["noise"]["correlated_share"] = truth.noise_correlated_share;
    j["noise"]["correlation_radius_px"] = truth.noise_correlation_radius_px;
  }
  j["clutter_count"] = truth.clutter_count;
  j["clutter"] = Json::array();
  for (const Primitive& p : truth.clutter) j["clutter"].push_back(PrimitiveToJson(p));
  j["frames"] = Json::array();
  for (const SimFrameTruth& f : truth.frames) {
    Json o = PoseToJson(f.humanoid_pose);
    o["index"] = f.index;
    o["depth"] = f.depth_file;
    o["cloud"] = f.cloud_file;
    o["noise_seed"] = f.noise_seed;
    j["frames"].push_back(o);
  }
  j["command"] = truth.command;
  return j.dump(2) + "\n";
}

Result<SimTruth> ParseSimTruthJson(const std::string& text, const std::string& origin) {
  try {
    const Json j = Json::parse(text);
    if (j.at("format").get<std::string>() != "hpose-sim-truth") {
      return MakeError(ErrorCode::kDataLoss, origin + ": not an hpose-sim-truth file");
    }
    if (j.at("version").get<int>() != 1) {
      return MakeError(ErrorCode::kDataLoss, origin + ": unsupported version");
    }
    SimTruth t;
    const Json& h = j.at("humanoid");
    t.humanoid_pose = PoseFromJson(h, "humanoid");
    t.humanoid_preset = h.at("preset").get<std::string>();
    t.humanoid_height_m = h.at("height_m").get<double>();
    for (const Json& o : j.at("other_humanoids")) {
      const std::string where = "other_humanoids[" + std::to_string(t.other_humanoids.size()) + "]";
      t.other_humanoids.push_back({PoseFromJson(o, where), o.at("preset").get<std::string>()});
    }
    const Json& s = j.at("sensor");
    t.sensor_height_m = s.at("height_m").get<double>();
    t.sensor_pitch_rad = s.at("pitch_rad").get<double>();
    t.sensor_roll_rad = s.at("roll_rad").get<double>();
    const Json& k = j.at("intrinsics");
    t.intrinsics.width = k.at("width").get<int>();
    t.intrinsics.height = k.at("height").get<int>();
    t.intrinsics.fx = k.at("fx").get<double>();
    t.intrinsics.fy = k.at("fy").get<double>();
    t.intrinsics.cx = k.at("cx").get<double>();
    t.intrinsics.cy = k.at("cy").get<double>();
    t.noise_enabled = j.at("noise").at("enabled").get<bool>();
    t.seed = j.at("noise").at("seed").get<std::uint64_t>();
    t.noise_correlated_share = j.at("noise").value("correlated_share", 0.0);
    t.noise_correlation_radius_px = j.at("noise").value("correlation_radius_px", 4);
    t.clutter_count = j.at("clutter_count").get<int>();
    for (const Json& c : j.at("clutter")) {
      t.clutter.push_back(
          PrimitiveFromJson(c, "clutter[" + std::to_string(t.clutter.size()) + "]"));
    }
    for (const Json& f : j.at("frames")) {
      SimFrameTruth frame;
      frame.humanoid_pose = PoseFromJson(f, "frames[" + std::to_string(t.frames.size()) + "]");
      frame.index = f.at("index").get<int>();
      frame.depth_file = f.at("depth").get<std::string>();
      frame.cloud_file = f.at("cloud").get<std::string>();
      frame.noise_seed = f.at("noise_seed").get<std::uint64_t>();
      t.frames.push_back(frame);
    }
    t.command = j.at("command").get<std::string>();
    return t;
  } catch (const std::exception& e) {
    return MakeError(ErrorCode::kDataLoss, origin + ": bad simulation truth: " + e.what());
  }
}

Result<SimTruth> LoadSimTruth(const std::string& path) {
  Result<std::string> text = ReadFile(path);
  if (!text.ok()) return text.error();
  return ParseSimTruthJson(*text, path);
}

}  // namespace hpose
