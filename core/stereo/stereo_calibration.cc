#include "core/stereo/stereo_calibration.h"

#include <sys/stat.h>

#include <cmath>
#include <cstdio>
#include <exception>
#include <initializer_list>
#include <sstream>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include "core/io/input_file.h"

namespace hpose {
namespace {

constexpr std::uint64_t kMaxCalibrationFileBytes = std::uint64_t{1} << 20;

bool FileExists(const std::string& path) {
  struct stat st {};
  return stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

// Finds the first of `names` present in any of the open files.
cv::FileNode FindNode(const std::vector<cv::FileStorage>& files,
                      std::initializer_list<const char*> names, std::string* found_name) {
  for (const char* name : names) {
    for (const cv::FileStorage& fs : files) {
      cv::FileNode node = fs[name];
      if (!node.empty() && !node.isNone()) {
        *found_name = name;
        return node;
      }
    }
  }
  return cv::FileNode();
}

std::string JoinNames(std::initializer_list<const char*> names) {
  std::string out;
  for (const char* n : names) out += (out.empty() ? "" : "|") + std::string(n);
  return out;
}

// Reads a matrix node into a double matrix, or explains why not.
Result<cv::Mat> ReadMatrix(const std::vector<cv::FileStorage>& files,
                           std::initializer_list<const char*> names, const std::string& where,
                           bool required) {
  std::string name;
  cv::FileNode node = FindNode(files, names, &name);
  if (node.empty()) {
    if (!required) return cv::Mat();
    return MakeError(ErrorCode::kInvalidArgument, where + ": missing entry " + JoinNames(names));
  }
  cv::Mat m;
  try {
    if (node.isSeq()) {
      std::vector<double> values;
      node >> values;
      m = cv::Mat(values, true).reshape(1, 1);
    } else {
      // OpenCV allocates rows x cols before reading the data: bound them first (calibration
      // matrices are 3x3, 3x1 or 1x14 at most).
      const cv::FileNode rows = node["rows"], cols = node["cols"], data = node["data"];
      const int nr = rows.isInt() ? static_cast<int>(rows) : 0;
      const int nc = cols.isInt() ? static_cast<int>(cols) : 0;
      if (!node.isMap() || nr < 1 || nc < 1 || nr > 64 || nc > 64 || nr * nc > 64 ||
          !data.isSeq() || data.size() != static_cast<size_t>(nr * nc)) {
        return MakeError(
            ErrorCode::kInvalidArgument,
            where + ": entry " + name + " is not a matrix of at most 64 values (rows, cols, data)");
      }
      node >> m;
    }
  } catch (const std::exception& e) {
    return MakeError(ErrorCode::kInvalidArgument, where + ": entry " + name + " is not a matrix");
  }
  if (m.empty()) {
    return MakeError(ErrorCode::kInvalidArgument, where + ": entry " + name + " is empty");
  }
  cv::Mat d;
  m.convertTo(d, CV_64F);
  for (int r = 0; r < d.rows; ++r) {
    for (int c = 0; c < d.cols; ++c) {
      if (!std::isfinite(d.at<double>(r, c))) {
        return MakeError(ErrorCode::kInvalidArgument,
                         where + ": entry " + name + " holds a non-finite value");
      }
    }
  }
  return d;
}

Result<Eigen::Matrix3d> ToMatrix3(const cv::Mat& m, const std::string& what,
                                  const std::string& where) {
  if (m.rows != 3 || m.cols != 3) {
    return MakeError(ErrorCode::kInvalidArgument, where + ": " + what + " must be 3x3, got " +
                                                      std::to_string(m.rows) + "x" +
                                                      std::to_string(m.cols));
  }
  Eigen::Matrix3d out;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out(r, c) = m.at<double>(r, c);
  return out;
}

Result<std::vector<double>> ToVector(const cv::Mat& m, const std::string& what,
                                     const std::string& where) {
  std::vector<double> out;
  if (m.empty()) return out;
  if (m.rows != 1 && m.cols != 1) {
    return MakeError(ErrorCode::kInvalidArgument, where + ": " + what + " must be a vector");
  }
  const int n = static_cast<int>(m.total());
  if (n != 4 && n != 5 && n != 8 && n != 12 && n != 14) {
    return MakeError(ErrorCode::kInvalidArgument,
                     where + ": " + what + " has " + std::to_string(n) +
                         " coefficients (OpenCV uses 4, 5, 8, 12 or 14)");
  }
  const cv::Mat flat = m.reshape(1, 1);
  for (int i = 0; i < n; ++i) out.push_back(flat.at<double>(0, i));
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

// Reads the entries of the opened files. OpenCV's FileNode accessors throw on some malformed
// trees (found by fuzzing), so the caller runs this inside a handler.
Result<StereoCalibration> ParseOpenedCalibration(const std::vector<cv::FileStorage>& files,
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
  if (r->total() == 3) {  // A rotation vector (Rodrigues), as some tools write.
    const Eigen::Vector3d rv(r->at<double>(0), r->at<double>(1), r->at<double>(2));
    const double angle = rv.norm();
    rm = angle < 1e-15 ? Eigen::Matrix3d::Identity()
                       : Eigen::AngleAxisd(angle, rv / angle).toRotationMatrix();
  } else {
    rm = ToMatrix3(*r, "R", where);
  }
  if (!rm.ok()) return rm.error();
  if (t->total() != 3) {
    return MakeError(ErrorCode::kInvalidArgument,
                     where + ": T must have 3 elements, got " + std::to_string(t->total()));
  }

  double unit_m = options.translation_unit_m;
  std::string unit_name;
  cv::FileNode unit_node = FindNode(files, {"translation_unit"}, &unit_name);
  if (!unit_node.empty()) {
    const std::string unit = unit_node.isString() ? static_cast<std::string>(unit_node) : "";
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
  cal.right_t_left = Eigen::Vector3d(t->at<double>(0), t->at<double>(1), t->at<double>(2)) * unit_m;

  std::string size_name;
  cv::FileNode w = FindNode(files, {"image_width"}, &size_name);
  cv::FileNode h = FindNode(files, {"image_height"}, &size_name);
  if (!w.empty() && !h.empty() && w.isInt() && h.isInt()) {
    cal.image_width = static_cast<int>(w);
    cal.image_height = static_cast<int>(h);
  } else {
    cv::FileNode sz = FindNode(files, {"imageSize", "image_size"}, &size_name);
    if (!sz.empty() && sz.isSeq() && sz.size() == 2) {
      cal.image_width = static_cast<int>(sz[0]);
      cal.image_height = static_cast<int>(sz[1]);
    }
  }
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
  std::vector<cv::FileStorage> files;
  for (const std::string& path : paths) {
    where += (where.empty() ? "" : "+") + path;
    if (!FileExists(path)) return MakeError(ErrorCode::kNotFound, path + ": no such file");
    // Calibration files are a few kilobytes. OpenCV's YAML parser never returns on some
    // malformed files (found by fuzzing: a "%" directive line after the first line, then a
    // line starting with "--"); a directive may only open the file, so such files are refused.
    Result<std::uint64_t> size = CheckInputFile(path, kMaxCalibrationFileBytes);
    if (!size.ok()) return size.error();
    Result<std::string> text = ReadFileHead(path, kMaxCalibrationFileBytes);
    if (!text.ok()) return text.error();
    if (text->find("\n%") != std::string::npos) {
      return MakeError(ErrorCode::kDataLoss,
                       path +
                           ": a \"%\" directive after the first line; not an OpenCV "
                           "calibration file (YAML/XML FileStorage)");
    }
    cv::FileStorage fs;
    try {
      fs.open(path, cv::FileStorage::READ);
    } catch (const std::exception& e) {  // cv::Exception, and std::length_error on some input.
      return MakeError(ErrorCode::kDataLoss,
                       path + ": not an OpenCV calibration file (YAML/XML FileStorage)");
    }
    if (!fs.isOpened()) {
      return MakeError(ErrorCode::kDataLoss,
                       path + ": not an OpenCV calibration file (YAML/XML FileStorage)");
    }
    files.push_back(std::move(fs));
  }

  try {
    return ParseOpenedCalibration(files, where, options);
  } catch (const std::exception& e) {  // cv::Exception from FileNode access on a malformed tree.
    return MakeError(ErrorCode::kDataLoss, where + ": malformed calibration file (" +
                                               std::string(e.what()).substr(0, 200) + ")");
  }
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
