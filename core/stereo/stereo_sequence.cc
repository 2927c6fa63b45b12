#include "core/stereo/stereo_sequence.h"

#include <dirent.h>
#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include "core/stereo/rgb_image_io.h"

namespace hpose {
namespace {

bool IsDir(const std::string& p) {
  struct stat st {};
  return stat(p.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
}
bool IsFile(const std::string& p) {
  struct stat st {};
  return stat(p.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

bool IsImageName(const std::string& name) {
  static const char* kExt[] = {".png", ".jpg", ".jpeg", ".ppm", ".bmp", ".tif", ".tiff"};
  std::string lower = name;
  std::transform(lower.begin(), lower.end(), lower.begin(), ::tolower);
  for (const char* e : kExt) {
    const std::string ext = e;
    if (lower.size() > ext.size() &&
        lower.compare(lower.size() - ext.size(), ext.size(), ext) == 0) {
      return true;
    }
  }
  return false;
}

std::vector<std::string> ListImages(const std::string& dir) {
  std::vector<std::string> names;
  DIR* d = opendir(dir.c_str());
  if (d == nullptr) return names;
  while (dirent* e = readdir(d)) {
    const std::string name = e->d_name;
    if (name[0] != '.' && IsImageName(name)) names.push_back(name);
  }
  closedir(d);
  std::sort(names.begin(), names.end());
  return names;
}

std::string Trim(const std::string& s) {
  const size_t b = s.find_first_not_of(" \t\r");
  const size_t e = s.find_last_not_of(" \t\r");
  return b == std::string::npos ? "" : s.substr(b, e - b + 1);
}

}  // namespace

Result<StereoSequence> StereoSequence::Open(const std::string& dir, double fps) {
  if (!IsDir(dir)) return MakeError(ErrorCode::kNotFound, dir + ": no such directory");
  if (!(fps > 0) || !std::isfinite(fps)) {
    return MakeError(ErrorCode::kInvalidArgument, "frame rate must be > 0");
  }
  StereoSequence seq;
  seq.dir_ = dir;
  for (const char* name : {"calibration.yaml", "calibration.yml", "calibration.xml"}) {
    if (IsFile(dir + "/" + name)) {
      seq.calibration_path_ = dir + "/" + name;
      break;
    }
  }
  const std::string csv = dir + "/frames.csv";
  if (IsFile(csv)) {
    std::ifstream in(csv);
    std::string line;
    int number = 0;
    while (std::getline(in, line)) {
      ++number;
      const std::string t = Trim(line);
      if (t.empty() || t[0] == '#' || (number == 1 && t.rfind("timestamp", 0) == 0)) continue;
      std::stringstream ss(t);
      std::string ts, l, r, extra;
      if (!std::getline(ss, ts, ',') || !std::getline(ss, l, ',') || !std::getline(ss, r, ',') ||
          std::getline(ss, extra, ',')) {
        return MakeError(ErrorCode::kDataLoss, csv + ": line " + std::to_string(number) +
                                                   ": expected \"timestamp_s,left,right\"");
      }
      StereoFrameEntry e;
      char* end = nullptr;
      const std::string tt = Trim(ts);
      e.timestamp_s = std::strtod(tt.c_str(), &end);
      if (tt.empty() || end == nullptr || *end != '\0' || !std::isfinite(e.timestamp_s)) {
        return MakeError(ErrorCode::kDataLoss,
                         csv + ": line " + std::to_string(number) + ": bad timestamp '" + tt + "'");
      }
      e.left_path = dir + "/" + Trim(l);
      e.right_path = dir + "/" + Trim(r);
      if (!seq.frames_.empty() && e.timestamp_s <= seq.frames_.back().timestamp_s) {
        return MakeError(ErrorCode::kInvalidArgument,
                         csv + ": line " + std::to_string(number) + ": timestamps must increase");
      }
      seq.frames_.push_back(e);
    }
    return seq;
  }
  const std::string ldir = dir + "/left", rdir = dir + "/right";
  if (!IsDir(ldir) || !IsDir(rdir)) {
    return MakeError(ErrorCode::kNotFound,
                     dir + ": neither frames.csv nor the left/ and right/ directories exist");
  }
  const std::vector<std::string> left = ListImages(ldir);
  const std::vector<std::string> right = ListImages(rdir);
  const std::set<std::string> right_set(right.begin(), right.end());
  for (const std::string& name : left) {
    if (right_set.count(name) == 0) {
      return MakeError(ErrorCode::kInvalidArgument,
                       ldir + "/" + name + " has no partner " + rdir + "/" + name);
    }
  }
  if (left.size() != right.size()) {
    return MakeError(ErrorCode::kInvalidArgument,
                     rdir + " holds images without a partner in " + ldir);
  }
  for (size_t i = 0; i < left.size(); ++i) {
    seq.frames_.push_back(
        {static_cast<double>(i) / fps, ldir + "/" + left[i], rdir + "/" + left[i]});
  }
  return seq;
}

Result<std::pair<RgbImage, RgbImage>> StereoSequence::Load(size_t i) const {
  const StereoFrameEntry& e = frames_.at(i);
  auto l = ReadRgbImage(e.left_path);
  if (!l.ok()) return l.error();
  auto r = ReadRgbImage(e.right_path);
  if (!r.ok()) return r.error();
  if (l->width != r->width || l->height != r->height) {
    return MakeError(ErrorCode::kInvalidArgument,
                     e.left_path + " is " + std::to_string(l->width) + "x" +
                         std::to_string(l->height) + " but " + e.right_path + " is " +
                         std::to_string(r->width) + "x" + std::to_string(r->height));
  }
  return std::make_pair(std::move(l).value(), std::move(r).value());
}

}  // namespace hpose
