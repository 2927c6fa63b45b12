#include "core/stereo/stereo_marker_options.h"

#include <cmath>
#include <limits>
#include <set>

#include "core/io/storage_reader.h"
#include "core/stereo/rigid_fit.h"

namespace hpose {

Status ValidateStereoMarkerOptions(const StereoMarkerOptions& o) {
  auto bad = [](const std::string& what) {
    return Status(MakeError(ErrorCode::kInvalidArgument, "stereo options: " + what));
  };
  for (const Eigen::Vector3d& p : o.landmarks_world_m) {
    if (!p.allFinite()) return bad("landmarks_world_m holds a non-finite value");
  }
  if (TriangleMinSine(o.landmarks_world_m[0], o.landmarks_world_m[1], o.landmarks_world_m[2]) <
      o.min_triangle_sine) {
    return bad("the three landmarks are (nearly) collinear");
  }
  Status s = ValidateHsvRange(o.landmark_color, "stereo options: landmark_color");
  if (!s.ok()) return s;
  s = ValidateHsvRange(o.object_color, "stereo options: object_color");
  if (!s.ok()) return s;
  if (o.segmentation.min_blob_area_px < 1) return bad("min_blob_area_px must be >= 1");
  if (o.segmentation.connectivity != 4 && o.segmentation.connectivity != 8) {
    return bad("connectivity must be 4 or 8");
  }
  if (!(o.max_epipolar_error_px > 0)) return bad("max_epipolar_error_px must be > 0");
  if (!(o.max_fit_rms_m > 0)) return bad("max_fit_rms_m must be > 0");
  if (!(o.fit_rms_sigmas >= 0)) return bad("fit_rms_sigmas must be >= 0");
  if (!(o.ambiguity_ratio >= 1)) return bad("ambiguity_ratio must be >= 1");
  if (!(o.min_triangle_sine >= 0 && o.min_triangle_sine < 0.87)) {
    return bad("min_triangle_sine must be in [0, 0.87)");
  }
  if (!std::isfinite(o.min_camera_height_m)) return bad("min_camera_height_m is not finite");
  if (!(o.max_object_area_ratio >= 1)) return bad("max_object_area_ratio must be >= 1");
  if (!(o.landmark_radius_m > 0) || !(o.ball_radius_m > 0)) {
    return bad("landmark_radius_m and ball_radius_m must be > 0");
  }
  if (!(o.max_landmark_range_m > 0)) return bad("max_landmark_range_m must be > 0");
  if (!(o.centroid_sigma_px > 0)) return bad("centroid_sigma_px must be > 0");
  if (!(o.layout_tolerance_m >= 0)) return bad("layout_tolerance_m must be >= 0");
  if (!(o.occluded_weight > 0 && o.occluded_weight <= 1)) {
    return bad("occluded_weight must be in (0, 1]");
  }
  if (!(o.min_visible_fraction >= 0 && o.min_visible_fraction <= o.occlusion_area_ratio)) {
    return bad("min_visible_fraction must be in [0, occlusion_area_ratio]");
  }
  if (!(o.max_landmark_area_ratio >= 1)) return bad("max_landmark_area_ratio must be >= 1");
  if (!(o.max_ball_area_factor >= 1)) return bad("max_ball_area_factor must be >= 1");
  if (!(o.min_ball_fill >= 0 && o.min_ball_fill < 1)) return bad("min_ball_fill must be in [0, 1)");
  if (!(o.max_ball_aspect >= 1)) return bad("max_ball_aspect must be >= 1");
  if (!(o.max_ball_height_error_m > 0)) return bad("max_ball_height_error_m must be > 0");
  if (!(o.robot_region_x_min_m < o.robot_region_x_max_m) ||
      !(o.robot_region_y_min_m < o.robot_region_y_max_m)) {
    return bad("robot region must have min < max");
  }
  return Status::Ok();
}

namespace {

Result<StereoMarkerOptions> ValidatedOrError(const StereoMarkerOptions& o,
                                             const std::string& path) {
  Status s = ValidateStereoMarkerOptions(o);
  if (!s.ok()) return MakeError(s.error().code, path + ": " + s.error().message);
  return o;
}

}  // namespace

Result<StereoMarkerOptions> LoadStereoMarkerOptions(const std::string& path) {
  Result<StorageNode> file = ReadStorageFile(path);
  if (!file.ok()) return file.error();
  if (file->kind == StorageNode::Kind::kNone) return ValidatedOrError(StereoMarkerOptions{}, path);
  if (!file->IsMap()) {
    return MakeError(ErrorCode::kDataLoss, path + ": holds no named options (key: value)");
  }
  StereoMarkerOptions o;
  auto fail = [&](const std::string& key, const std::string& what) {
    return MakeError(ErrorCode::kInvalidArgument, path + ": " + key + ": " + what);
  };
  auto number = [](const StorageNode& n, double* out) {
    return n.AsNumber(out) && std::isfinite(*out);
  };
  auto integer = [](const StorageNode& n, int* out) {
    long long v = 0;
    if (!n.AsInt(&v) || v < std::numeric_limits<int>::min() ||
        v > std::numeric_limits<int>::max()) {
      return false;
    }
    *out = static_cast<int>(v);
    return true;
  };
  auto color = [&](const StorageNode& n, HsvRange* out) {
    if (!n.IsSeq() || n.items.size() != 6) return false;
    double v[6];
    for (int i = 0; i < 6; ++i) {
      if (!number(n.items[i], &v[i])) return false;
    }
    *out = HsvRange{v[0], v[1], v[2], v[3], v[4], v[5]};
    return true;
  };
  for (const auto& [key, node] : file->members) {
    double v = 0;
    if (key == "landmarks_world_m") {
      Result<Eigen::MatrixXd> m = StorageMatrix(node, path, key, 9);
      if (!m.ok() || m->rows() != 3 || m->cols() != 3 || !m->allFinite()) {
        return fail(key, "must be a 3x3 matrix of finite numbers, one row per landmark");
      }
      for (int r = 0; r < 3; ++r) o.landmarks_world_m[r] = m->row(r).transpose();
    } else if (key == "landmark_color") {
      if (!color(node, &o.landmark_color)) return fail(key, "must be a list of 6 numbers");
    } else if (key == "object_color") {
      if (!color(node, &o.object_color)) return fail(key, "must be a list of 6 numbers");
    } else if (key == "method") {
      auto m = ParseRigidFitMethod(node.IsString() ? node.text : "");
      if (!m.ok()) return fail(key, m.error().message);
      o.method = *m;
    } else if (key == "depth_weighted_fit") {
      int flag = 0;
      if (!integer(node, &flag) || (flag != 0 && flag != 1)) return fail(key, "must be 0 or 1");
      o.depth_weighted_fit = flag != 0;
    } else if (key == "robot_region_m") {
      if (!node.IsSeq() || node.items.size() != 4)
        return fail(key, "must be [x_min, x_max, y_min, y_max]");
      double v4[4];
      for (int i = 0; i < 4; ++i) {
        if (!number(node.items[i], &v4[i])) return fail(key, "must hold 4 finite numbers");
      }
      o.robot_region_x_min_m = v4[0];
      o.robot_region_x_max_m = v4[1];
      o.robot_region_y_min_m = v4[2];
      o.robot_region_y_max_m = v4[3];
    } else if (key == "head_to_reference_m") {
      if (!node.IsSeq() || node.items.size() != 2 ||
          !number(node.items[0], &o.head_to_reference_m.x()) ||
          !number(node.items[1], &o.head_to_reference_m.y())) {
        return fail(key, "must be [x, y] in metres");
      }
    } else if (key == "min_blob_area_px") {
      if (!integer(node, &o.segmentation.min_blob_area_px)) {
        return fail(key, "must be an integer");
      }
    } else {
      double* target = key == "max_epipolar_error_px"     ? &o.max_epipolar_error_px
                       : key == "max_fit_rms_m"           ? &o.max_fit_rms_m
                       : key == "fit_rms_sigmas"          ? &o.fit_rms_sigmas
                       : key == "ambiguity_ratio"         ? &o.ambiguity_ratio
                       : key == "min_triangle_sine"       ? &o.min_triangle_sine
                       : key == "min_camera_height_m"     ? &o.min_camera_height_m
                       : key == "max_object_area_ratio"   ? &o.max_object_area_ratio
                       : key == "landmark_radius_m"       ? &o.landmark_radius_m
                       : key == "ball_radius_m"           ? &o.ball_radius_m
                       : key == "max_landmark_range_m"    ? &o.max_landmark_range_m
                       : key == "centroid_sigma_px"       ? &o.centroid_sigma_px
                       : key == "layout_tolerance_m"      ? &o.layout_tolerance_m
                       : key == "occlusion_area_ratio"    ? &o.occlusion_area_ratio
                       : key == "occluded_weight"         ? &o.occluded_weight
                       : key == "min_visible_fraction"    ? &o.min_visible_fraction
                       : key == "max_landmark_area_ratio" ? &o.max_landmark_area_ratio
                       : key == "max_ball_area_factor"    ? &o.max_ball_area_factor
                       : key == "min_ball_fill"           ? &o.min_ball_fill
                       : key == "max_ball_aspect"         ? &o.max_ball_aspect
                       : key == "max_ball_height_error_m" ? &o.max_ball_height_error_m
                                                          : nullptr;
      if (target == nullptr) return fail(key, "unknown key");
      if (!number(node, &v)) return fail(key, "must be a finite number");
      *target = v;
    }
  }
  return ValidatedOrError(o, path);
}

}  // namespace hpose
