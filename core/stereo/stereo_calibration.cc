#include "core/stereo/stereo_calibration.h"

#include <cmath>
#include <initializer_list>
#include <sstream>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include "core/io/storage_reader.h"

namespace hpose {
namespace {

// Finds the first of `names` present in any of the files.
const StorageNode* FindNode(const std::vector<StorageNode>& files,
                            std::initializer_list<const char*> names, std::string* found_name) {
  for (const char* name : names) {
    for (const StorageNode& file : files) {
      const StorageNode* node = file.Find(name);
      if (node != nullptr && node->kind != StorageNode::Kind::kNone) {
        *found_name = name;
        return node;
      }
    }
  }
  return nullptr;
}

std::string JoinNames(std::initializer_list<const char*> names) {
  std::string out;
  for (const char* n : names) out += (out.empty() ? "" : "|") + std::string(n);
  return out;
}

// Reads a matrix entry (calibration matrices are 3x3, 3x1 or 1x14 at most), or explains why
// not; an empty matrix when an optional entry is absent.
Result<Eigen::MatrixXd> ReadMatrix(const std::vector<StorageNode>& files,
                                   std::initializer_list<const char*> names,
                                   const std::string& where, bool required) {
  std::string name;
  const StorageNode* node = FindNode(files, names, &name);
  if (node == nullptr) {
    if (!required) return Eigen::MatrixXd();
    return MakeError(ErrorCode::kInvalidArgument, where + ": missing entry " + JoinNames(names));
  }
  Result<Eigen::MatrixXd> m = StorageMatrix(*node, where, name, 64);
  if (!m.ok()) return m.error();
  if (!m->allFinite()) {
    return MakeError(ErrorCode::kInvalidArgument,
                     where + ": entry " + name + " holds a non-finite value");
  }
  return m;
}

Result<Eigen::Matrix3d> ToMatrix3(const Eigen::MatrixXd& m, const std::string& what,
                                  const std::string& where) {
  if (m.rows() != 3 || m.cols() != 3) {
    return MakeError(ErrorCode::kInvalidArgument, where + ": " + what + " must be 3x3, got " +
                                                      std::to_string(m.rows()) + "x" +
                                                      std::to_string(m.cols()));
  }
  return Eigen::Matrix3d(m);
}

Result<std::vector<double>> ToVector(const Eigen::MatrixXd& m, const std::string& what,
                                     const std::string& where) {
  std::vector<double> out;
  if (m.size() == 0) return out;
  if (m.rows() != 1 && m.cols() != 1) {
    return MakeError(ErrorCode::kInvalidArgument, where + ": " + what + " must be a vector");
  }
  const int n = static_cast<int>(m.size());
  if (n != 4 && n != 5 && n != 8 && n != 12 && n != 14) {
    return MakeError(ErrorCode::kInvalidArgument,
                     where + ": " + what + " has " + std::to_string(n) +
                         " coefficients (OpenCV uses 4, 5, 8, 12 or 14)");
  }
  for (int i = 0; i < n; ++i) out.push_back(m(i));
  return out;
}

}  // namespace

Status ValidateStereoCalibration(const StereoCalibration& calibration, const std::string& where,
                                 const StereoCalibrationReadOptions& options) {
  for (const CameraModel* cam : {&calibration.left, &calibration.right}) {
    const char* side = cam == &calibration.left ? "left" : "right";
    const Eigen::Matrix3d& k = cam->camera_matrix;
    if (!k.allFinite() || !(k(0, 0) > 0) || !(k(1, 1) > 0) || k(2, 0) != 0 || k(2, 1) != 0 ||
        std::abs(k(2, 2) - 1.0) > 1e-9) {
      return MakeError(
          ErrorCode::kInvalidArgument,
          where + ": " + side + " camera matrix is not [fx 0 cx; 0 fy cy; 0 0 1] with fx, fy > 0");
    }
    for (double d : cam->distortion) {
      if (!std::isfinite(d)) {
        return MakeError(ErrorCode::kInvalidArgument,
                         where + ": " + side + " distortion holds a non-finite value");
      }
    }
  }
  const Eigen::Matrix3d& r = calibration.right_R_left;
  if (!r.allFinite() || (r.transpose() * r - Eigen::Matrix3d::Identity()).norm() > 1e-3 ||
      std::abs(r.determinant() - 1.0) > 1e-3) {
    return MakeError(ErrorCode::kInvalidArgument,
                     where + ": R is not a rotation matrix (orthonormal, determinant 1)");
  }
  const double baseline = calibration.BaselineM();
  if (!calibration.right_t_left.allFinite() || baseline < options.min_baseline_m ||
      baseline > options.max_baseline_m) {
    std::ostringstream msg;
    msg << where << ": baseline |T| = " << baseline << " m is outside the plausible range ["
        << options.min_baseline_m << ", " << options.max_baseline_m
        << "] m; is T in millimetres (set the translation unit to mm)?";
    return MakeError(ErrorCode::kInvalidArgument, msg.str());
  }
  if (calibration.image_width < 0 || calibration.image_height < 0) {
    return MakeError(ErrorCode::kInvalidArgument, where + ": negative image size");
  }
  return Status::Ok();
}

namespace {

// Reads the entries of the parsed files.
Result<StereoCalibration> ParseCalibration(const std::vector<StorageNode>& files,
                                           const std::string& where,
                                           const StereoCalibrationReadOptions& options) {
  StereoCalibration cal;
  auto k1 = ReadMatrix(files, {"M1", "K1", "cameraMatrix1", "camera_matrix_left", "cameraMatrixL"},
                       where, true);
  if (!k1.ok()) return k1.error();
  auto d1 =
      ReadMatrix(files, {"D1", "distCoeffs1", "dist_coeffs_left", "distCoeffsL"}, where, false);
  if (!d1.ok()) return d1.error();
  auto k2 = ReadMatrix(files, {"M2", "K2", "cameraMatrix2", "camera_matrix_right", "cameraMatrixR"},
                       where, true);
  if (!k2.ok()) return k2.error();
  auto d2 =
      ReadMatrix(files, {"D2", "distCoeffs2", "dist_coeffs_right", "distCoeffsR"}, where, false);
  if (!d2.ok()) return d2.error();
  auto r = ReadMatrix(files, {"R"}, where, true);
  if (!r.ok()) return r.error();
  auto t = ReadMatrix(files, {"T"}, where, true);
  if (!t.ok()) return t.error();

  auto km1 = ToMatrix3(*k1, "left camera matrix", where);
  if (!km1.ok()) return km1.error();
  auto km2 = ToMatrix3(*k2, "right camera matrix", where);
  if (!km2.ok()) return km2.error();
  auto dv1 = ToVector(*d1, "left distortion", where);
  if (!dv1.ok()) return dv1.error();
  auto dv2 = ToVector(*d2, "right distortion", where);
  if (!dv2.ok()) return dv2.error();
  Result<Eigen::Matrix3d> rm = MakeError(ErrorCode::kInvalidArgument, "");
  if (r->size() == 3) {  // A rotation vector (Rodrigues), as some tools write.
    const Eigen::Vector3d rv((*r)(0), (*r)(1), (*r)(2));
    const double angle = rv.norm();
    rm = angle < 1e-15 ? Eigen::Matrix3d::Identity()
                       : Eigen::AngleAxisd(angle, rv / angle).toRotationMatrix();
  } else {
    rm = ToMatrix3(*r, "R", where);
  }
  if (!rm.ok()) return rm.error();
  if (t->size() != 3) {
    return MakeError(ErrorCode::kInvalidArgument,
                     where + ": T must have 3 elements, got " + std::to_string(t->size()));
  }

  double unit_m = options.translation_unit_m;
  std::string unit_name;
  const StorageNode* unit_node = FindNode(files, {"translation_unit"}, &unit_name);
  if (unit_node != nullptr) {
    const std::string unit = unit_node->IsString() ? unit_node->text : "";
    if (unit == "m") {
      unit_m = 1.0;
    } else if (unit == "mm") {
      unit_m = 0.001;
    } else {
      return MakeError(ErrorCode::kInvalidArgument,
                       where + ": translation_unit must be \"m\" or \"mm\"");
    }
  }

  cal.left.camera_matrix = *km1;
  cal.right.camera_matrix = *km2;
  cal.left.distortion = *dv1;
  cal.right.distortion = *dv2;
  cal.right_R_left = *rm;
  cal.right_t_left = Eigen::Vector3d((*t)(0), (*t)(1), (*t)(2)) * unit_m;

  std::string size_name;
  const StorageNode* w = FindNode(files, {"image_width"}, &size_name);
  const StorageNode* h = FindNode(files, {"image_height"}, &size_name);
  long long width = 0, height = 0;
  auto in_range = [](long long v) { return v >= 0 && v <= 1000000; };
  if (w != nullptr && h != nullptr && w->AsInt(&width) && h->AsInt(&height)) {
    if (!in_range(width) || !in_range(height)) {
      return MakeError(ErrorCode::kInvalidArgument,
                       where + ": image_width and image_height must be in [0, 1000000]");
    }
  } else {
    const StorageNode* sz = FindNode(files, {"imageSize", "image_size"}, &size_name);
    if (sz != nullptr && sz->IsSeq() && sz->items.size() == 2) {
      if (!sz->items[0].AsInt(&width) || !sz->items[1].AsInt(&height) || !in_range(width) ||
          !in_range(height)) {
        return MakeError(ErrorCode::kInvalidArgument,
                         where + ": " + size_name + " must be [width, height] in [0, 1000000]");
      }
    }
  }
  cal.image_width = static_cast<int>(width);
  cal.image_height = static_cast<int>(height);
  Status valid = ValidateStereoCalibration(cal, where, options);
  if (!valid.ok()) return valid.error();
  return cal;
}

}  // namespace

Result<StereoCalibration> ReadStereoCalibration(const std::vector<std::string>& paths,
                                                const StereoCalibrationReadOptions& options) {
  if (paths.empty()) {
    return MakeError(ErrorCode::kInvalidArgument, "no stereo calibration file given");
  }
  std::string where;
  std::vector<StorageNode> files;
  for (const std::string& path : paths) {
    where += (where.empty() ? "" : "+") + path;
    // Calibration files are a few kilobytes. They are parsed by hpose's own reader: OpenCV's
    // parsers hang or allocate without bound on some malformed files (found by fuzzing).
    Result<StorageNode> file = ReadStorageFile(path);
    if (!file.ok()) return file.error();
    if (!file->IsMap()) {
      return MakeError(ErrorCode::kDataLoss,
                       path + ": malformed calibration file: it holds no named entries");
    }
    files.push_back(std::move(*file));
  }
  return ParseCalibration(files, where, options);
}

Status WriteStereoCalibration(const StereoCalibration& calibration, const std::string& path,
                              const std::vector<NamedMatrix>& extra) {
  auto to_cv = [](const Eigen::MatrixXd& m) {
    cv::Mat out(static_cast<int>(m.rows()), static_cast<int>(m.cols()), CV_64F);
    for (int r = 0; r < m.rows(); ++r)
      for (int c = 0; c < m.cols(); ++c) out.at<double>(r, c) = m(r, c);
    return out;
  };
  auto dist = [](const std::vector<double>& d) {
    return d.empty() ? cv::Mat::zeros(1, 5, CV_64F) : cv::Mat(d, true).reshape(1, 1);
  };
  try {
    cv::FileStorage fs(path, cv::FileStorage::WRITE);
    if (!fs.isOpened()) return MakeError(ErrorCode::kInternal, path + ": cannot write");
    fs << "image_width" << calibration.image_width;
    fs << "image_height" << calibration.image_height;
    fs << "M1" << to_cv(calibration.left.camera_matrix);
    fs << "D1" << dist(calibration.left.distortion);
    fs << "M2" << to_cv(calibration.right.camera_matrix);
    fs << "D2" << dist(calibration.right.distortion);
    fs << "R" << to_cv(calibration.right_R_left);
    fs << "T" << to_cv(calibration.right_t_left);
    fs << "translation_unit"
       << "m";
    for (const NamedMatrix& m : extra) fs << m.name << to_cv(m.value);
    fs.release();
  } catch (const cv::Exception& e) {
    return MakeError(ErrorCode::kInternal, path + ": cannot write (" + e.what() + ")");
  }
  return Status::Ok();
}

}  // namespace hpose
