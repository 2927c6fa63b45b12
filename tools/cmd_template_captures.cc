// `hpose template from-captures`: a 360 degree template from depth captures of the robot on a
// turntable (or turned by hand), taken by the fixed sensor that will watch it.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/common/file_names.h"
#include "core/common/pose2d.h"
#include "core/depth/depth_to_cloud.h"
#include "core/io/atomic_file.h"
#include "core/io/cloud_io.h"
#include "core/io/depth_png.h"
#include "core/io/intrinsics_json.h"
#include "core/templates/capture_registration.h"
#include "core/templates/capture_template.h"
#include "core/templates/capture_views.h"
#include "core/templates/template_io.h"
#include "tools/canvas.h"
#include "tools/cmd_template_captures_flags.h"
#include "tools/command.h"
#include "tools/exit_codes.h"
#include "tools/fixed_text.h"
#include "tools/flag_parser.h"
#include "tools/picture_png.h"

namespace hpose::tools {
namespace {

namespace fs = std::filesystem;

const char kCapturesCmd[] = "template from-captures";

int Fail(const Error& error) {
  std::cerr << "hpose " << kCapturesCmd << ": " << error.message << "\n";
  return kExitError;
}

bool ParseList(const std::string& text, std::vector<double>* out) {
  out->clear();
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    char* end = nullptr;
    const double v = std::strtod(item.c_str(), &end);
    if (item.empty() || end == item.c_str() || *end != '\0' || !(std::abs(v) <= 3600.0)) {
      return false;
    }
    out->push_back(v);
  }
  return !out->empty();
}

bool IsDepth(const fs::path& p) { return LowerCase(p.extension().string()) == ".png"; }
bool IsCloud(const fs::path& p) {
  const std::string e = LowerCase(p.extension().string());
  return e == ".pcd" || e == ".ply";
}

// The capture files: directories give their depth PNGs (or, without any, their clouds) sorted
// by name; files are taken in the order given.
Result<std::vector<fs::path>> CollectCaptureFiles(const std::vector<std::string>& args) {
  std::vector<fs::path> files;
  for (const std::string& arg : args) {
    const fs::path p(arg);
    std::error_code ec;
    if (fs::is_directory(p, ec)) {
      std::vector<fs::path> depth, clouds;
      for (const fs::directory_entry& e : fs::directory_iterator(p, ec)) {
        if (!e.is_regular_file()) continue;
        if (IsDepth(e.path())) depth.push_back(e.path());
        if (IsCloud(e.path())) clouds.push_back(e.path());
      }
      std::vector<fs::path>& chosen = depth.empty() ? clouds : depth;
      if (chosen.empty()) {
        return MakeError(ErrorCode::kInvalidArgument,
                         "directory " + arg + " holds no captures (.png depth images, .pcd or " +
                             ".ply clouds)");
      }
      std::sort(chosen.begin(), chosen.end());
      files.insert(files.end(), chosen.begin(), chosen.end());
    } else if (fs::exists(p, ec)) {
      if (!IsDepth(p) && !IsCloud(p)) {
        return MakeError(ErrorCode::kInvalidArgument,
                         arg + ": not a capture (expected .png depth, .pcd or .ply)");
      }
      files.push_back(p);
    } else {
      return MakeError(ErrorCode::kNotFound, arg + ": no such file or directory");
    }
  }
  return files;
}

Result<CaptureView> LoadCapture(const fs::path& file, const std::string& intrinsics_flag) {
  CaptureView view;
  view.name = file.filename().string();
  if (IsCloud(file)) {
    Result<PointCloud> cloud = ReadCloud(file.string());
    if (!cloud.ok()) return cloud.error();
    view.cloud_sensor = std::move(*cloud);
    return view;
  }
  const std::string k_path =
      intrinsics_flag.empty() ? (file.parent_path() / "intrinsics.json").string() : intrinsics_flag;
  Result<Intrinsics> k = ReadIntrinsicsJson(k_path);
  if (!k.ok()) {
    return MakeError(k.error().code, view.name + ": intrinsics: " + k.error().message +
                                         " (pass --intrinsics FILE.json)");
  }
  Result<DepthImage> depth = ReadDepthPng(file.string());
  if (!depth.ok()) return depth.error();
  DepthToCloudOptions options;
  options.keep_organised = true;
  Result<PointCloud> cloud = DepthToCloud(*depth, *k, options);
  if (!cloud.ok()) return MakeError(cloud.error().code, view.name + ": " + cloud.error().message);
  view.cloud_sensor = std::move(*cloud);
  return view;
}

nlohmann::json Vec3(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

// The registered captures in the template frame, one colour per capture: from above (x up,
// y left) and from the robot's right side (x right, z up), with the origin, the +x axis and,
// for a turntable, the axis. Metres to pixels at 1 px = 1.5 mm.
Status WriteRegistrationPicture(const CaptureRegistration& reg, const CaptureTemplate& tpl,
                                const std::string& path) {
  constexpr int kPanel = 480;
  constexpr double kScale = 1.0 / 0.0015;
  Result<Canvas> made = Canvas::Create(2 * kPanel, kPanel, Bgr(255, 255, 255));
  if (!made.ok()) return made.error();
  Canvas& img = *made;
  const Pose2D& t = tpl.table_from_template;
  const double c = std::cos(t.theta), s = std::sin(t.theta);
  auto to_template = [&](double x, double y) {
    return Eigen::Vector2d(c * (x - t.x) + s * (y - t.y), -s * (x - t.x) + c * (y - t.y));
  };
  auto top = [&](const Eigen::Vector2d& p) {
    return Px(kPanel / 2 - static_cast<int>(p.y() * kScale),
              kPanel / 2 - static_cast<int>(p.x() * kScale));
  };
  auto side = [&](double x, double z) {
    return Px(kPanel + kPanel / 2 + static_cast<int>(x * kScale),
              kPanel - 30 - static_cast<int>(z * kScale));
  };
  const int n = static_cast<int>(reg.views.size());
  for (int i = 0; i < n; ++i) {
    // Hues from red through green to violet (OpenCV's 8-bit hue steps of 2 degrees).
    const Bgr hsv = BgrFromHsv(2.0 * static_cast<int>(170.0 * i / n), 230.0 / 255, 200.0 / 255);
    const Bgr colour(std::round(hsv.b), std::round(hsv.g), std::round(hsv.r));
    const Pose2D& g = reg.table_from_ground[i];
    const double gc = std::cos(g.theta), gs = std::sin(g.theta);
    for (const Eigen::Vector3f& p : reg.views[i].points) {
      const Eigen::Vector2d q =
          to_template(gc * p.x() - gs * p.y() + g.x, gs * p.x() + gc * p.y() + g.y);
      for (const Px& px : {top(q), side(q.x(), p.z())}) {
        img.SetPixel(px, colour);
      }
    }
    img.Text(reg.views[i].name, Px(8, 16 + 14 * i), 0.4, colour, 1, LineKind::kSmooth);
  }
  const Bgr black(0, 0, 0), red(0, 0, 220);
  img.Line(Px(kPanel, 0), Px(kPanel, kPanel), Bgr(180, 180, 180));
  img.Line(side(-0.2, 0.0), side(0.2, 0.0), Bgr(150, 150, 150));
  for (const auto& [from, to] :
       {std::pair(top({0, 0}), top({0.1, 0})), std::pair(side(0, 0), side(0.1, 0))}) {
    img.ArrowedLine(from, to, red, 2, LineKind::kSmooth, 0.2);
    img.Circle(from, 4, red, 2, LineKind::kSmooth);
  }
  if (reg.motion == CaptureMotion::kTurntable) {
    img.Marker(top(to_template(0.0, 0.0)), black, MarkerShape::kCross, 16, 2);
    img.Text("axis", top(to_template(0.0, 0.0)) + Px(8, 14), 0.45, black, 1, LineKind::kSmooth);
  }
  img.Text("from above (template frame, +x up)", Px(8, kPanel - 10), 0.45, black, 1,
           LineKind::kSmooth);
  img.Text("from the robot's right (+x right, z up)", Px(kPanel + 8, kPanel - 10), 0.45, black, 1,
           LineKind::kSmooth);
  return WritePicturePng(img, path);
}

}  // namespace

int RunTemplateFromCaptures(int argc, char** argv) {
  TemplateFromCapturesFlags f;
  FlagParser flags = f.Parser();
  if (const int code = flags.ParseOrExitCode(argc, argv, 2); code >= 0) return code;

  if (flags.positional().empty())
    return UsageError(kCapturesCmd, "give the capture files or a directory");
  if (f.name.empty()) return UsageError(kCapturesCmd, "--name N is required");
  if (f.out.empty()) return UsageError(kCapturesCmd, "--out FILE.bt is required");
  const bool hand = !f.headings_text.empty();
  if (f.turntable == hand) {
    return UsageError(kCapturesCmd, "say how the robot was turned: --turntable or --headings-deg");
  }
  if (hand && (flags.Seen("step-deg") || !f.angles_text.empty())) {
    return UsageError(kCapturesCmd, "--step-deg and --angles-deg are for --turntable");
  }
  if (!(std::abs(f.step_deg) > 0.0 && std::abs(f.step_deg) <= 360.0)) {
    // Captures all at one table angle cannot be told apart, nor place the table's axis.
    return UsageError(kCapturesCmd, "--step-deg must be a turn within +-360 degrees, not 0");
  }
  if (!(f.resolution >= 0.001 && f.resolution <= 0.5)) {
    return UsageError(kCapturesCmd, "--resolution must be in [0.001, 0.5] m");
  }
  if (!(f.table_height >= 0.0 && f.table_height <= 1.5)) {
    return UsageError(kCapturesCmd, "--table-height must be in [0, 1.5] m");
  }
  if (f.origin_name != "centroid" && f.origin_name != "axis") {
    return UsageError(kCapturesCmd,
                      "--origin must be centroid or axis, got '" + f.origin_name + "'");
  }
  if (f.origin_name == "axis" && hand)
    return UsageError(kCapturesCmd, "--origin axis needs --turntable");
  if (!(f.max_rms_mm > 0.0) || !(f.min_inliers >= 0.0 && f.min_inliers <= 1.0)) {
    return UsageError(kCapturesCmd, "--max-rms-mm must be > 0 and --min-inliers in [0, 1]");
  }
  if (!(f.axis_search >= 0.0 && f.axis_search <= 2.0) ||
      !(f.heading_search_deg >= 0.0 && f.heading_search_deg <= 90.0)) {
    return UsageError(kCapturesCmd,
                      "--axis-search-m must be in [0, 2] and --heading-search-deg in [0, 90]");
  }

  Result<std::vector<fs::path>> files = CollectCaptureFiles(flags.positional());
  if (!files.ok()) return Fail(files.error());
  const int n = static_cast<int>(files->size());
  std::vector<double> angles_deg;
  if (hand) {
    if (!ParseList(f.headings_text, &angles_deg)) {
      return UsageError(kCapturesCmd,
                        "--headings-deg needs comma-separated degrees (within +-3600), got '" +
                            f.headings_text + "'");
    }
  } else if (!f.angles_text.empty()) {
    if (!ParseList(f.angles_text, &angles_deg)) {
      return UsageError(kCapturesCmd,
                        "--angles-deg needs comma-separated degrees (within +-3600), got '" +
                            f.angles_text + "'");
    }
  } else {
    for (int i = 0; i < n; ++i) angles_deg.push_back(i * f.step_deg);
  }
  if (static_cast<int>(angles_deg.size()) != n) {
    return UsageError(kCapturesCmd, std::to_string(angles_deg.size()) + " angles for " +
                                        std::to_string(n) + " captures");
  }
  if (f.front_view < 0 || f.front_view >= n) {
    return UsageError(kCapturesCmd, "--front-view must be in [0, " + std::to_string(n - 1) + "]");
  }

  const auto start = std::chrono::steady_clock::now();
  auto progress = [](const std::string& line) { std::cout << "  " << line << "\n" << std::flush; };
  std::cout << "reading " << n << " captures\n";
  std::vector<CaptureView> captures;
  for (const fs::path& file : *files) {
    Result<CaptureView> v = LoadCapture(file, f.intrinsics);
    if (!v.ok()) return Fail(v.error());
    captures.push_back(std::move(*v));
  }

  std::cout << "cutting the robot out of every capture\n";
  CaptureViewOptions view_options;
  view_options.table_height_m = f.table_height;
  view_options.drop_bad_views = f.drop_bad;
  Result<CaptureViews> views = ExtractRobotViews(captures, view_options, progress);
  if (!views.ok()) return Fail(views.error());
  std::cout << "  common floor: sensor " << Fixed(views->floor.height_m * 1000.0, 0)
            << " mm above it, pitch " << Fixed(RadToDeg(views->floor.pitch_rad), 2) << " deg, roll "
            << Fixed(RadToDeg(views->floor.roll_rad), 2) << " deg\n";

  std::cout << "registering the views\n";
  CaptureRegistrationOptions reg_options;
  reg_options.motion = hand ? CaptureMotion::kHandTurned : CaptureMotion::kTurntable;
  for (const double d : angles_deg) reg_options.angles_rad.push_back(DegToRad(d));
  reg_options.axis_search_radius_m = f.axis_search;
  reg_options.heading_search_rad = DegToRad(f.heading_search_deg);
  reg_options.max_rms_m = f.max_rms_mm / 1000.0;
  reg_options.min_inlier_fraction = f.min_inliers;
  reg_options.drop_bad_views = f.drop_bad;
  Result<CaptureRegistration> reg = RegisterCaptureViews(*views, reg_options, progress);
  if (!reg.ok()) return Fail(reg.error());

  std::cout << "view residuals (point-to-plane against the neighbouring views):\n";
  for (const ViewResidual& r : reg->residuals) {
    char line[256];
    std::snprintf(line, sizeof(line), "  %-24s %s %7.1f deg  RMS %4.1f mm  %5.1f%% inliers  %s\n",
                  r.name.c_str(), hand ? "heading" : "table", RadToDeg(r.angle_rad),
                  r.rms_m * 1000.0, r.inlier_fraction * 100.0,
                  r.dropped ? "DROPPED" : (r.fits ? "ok" : "does not fit"));
    std::cout << line;
  }
  for (const DroppedView& d : views->dropped) {
    std::cout << "  " << d.name << ": DROPPED (" << d.reason << ")\n";
  }

  CaptureTemplateOptions tpl_options;
  tpl_options.name = f.name;
  tpl_options.variant = f.variant;
  tpl_options.resolution_m = f.resolution;
  tpl_options.origin =
      f.origin_name == "axis" ? TemplateOrigin::kAxis : TemplateOrigin::kVoxelCentroid;
  tpl_options.front_view = f.front_view;
  tpl_options.front_yaw_rad = DegToRad(f.front_yaw_deg);
  tpl_options.source = "hpose template from-captures (" + std::to_string(reg->views.size()) + " " +
                       (hand ? "hand-turned" : "turntable") + " captures, origin " + f.origin_name +
                       ", front view " + std::to_string(f.front_view) + ")";
  Result<CaptureTemplate> tpl = MakeCaptureTemplate(*reg, tpl_options);
  if (!tpl.ok()) return Fail(tpl.error());
  if (Status s = SaveTemplate(tpl->tpl, f.out); !s.ok()) return Fail(s.error());

  if (!f.report_path.empty()) {
    nlohmann::json report = {{"format", "hpose-capture-report"},
                             {"version", 1},
                             {"motion", hand ? "hand_turned" : "turntable"},
                             {"template", f.out},
                             {"captures", n}};
    report["floor"] = {{"plane_sensor",
                        {views->floor.plane_sensor[0], views->floor.plane_sensor[1],
                         views->floor.plane_sensor[2], views->floor.plane_sensor[3]}},
                       {"height_m", views->floor.height_m},
                       {"pitch_rad", views->floor.pitch_rad},
                       {"roll_rad", views->floor.roll_rad}};
    if (!hand) {
      const Eigen::Isometry3d sensor_from_ground = views->floor.ground_from_sensor.inverse();
      report["axis"] = {
          {"ground", {{"x", reg->axis_ground.x()}, {"y", reg->axis_ground.y()}}},
          {"sensor",
           {{"point_on_floor",
             Vec3(sensor_from_ground *
                  Eigen::Vector3d(reg->axis_ground.x(), reg->axis_ground.y(), 0.0))},
            {"direction", Vec3(reg->axis_direction_sensor)}}},
          {"conditioning", reg->axis_conditioning},
          {"estimated", "position on the floor (x, y); direction = the floor normal"}};
    }
    report["unobservable"] = reg->unobservable;
    report["views"] = nlohmann::json::array();
    for (const ViewResidual& r : reg->residuals) {
      report["views"].push_back({{"file", r.name},
                                 {"angle_rad", r.angle_rad},
                                 {"rms_m", r.rms_m},
                                 {"inlier_fraction", r.inlier_fraction},
                                 {"points", r.points},
                                 {"fits", r.fits},
                                 {"dropped", r.dropped}});
    }
    for (const DroppedView& d : views->dropped) {
      report["views"].push_back({{"file", d.name}, {"dropped", true}, {"reason", d.reason}});
    }
    report["template_frame"] = {{"origin", f.origin_name},
                                {"front_view", f.front_view},
                                {"front_yaw_rad", DegToRad(f.front_yaw_deg)},
                                {"table_from_template",
                                 {{"x", tpl->table_from_template.x},
                                  {"y", tpl->table_from_template.y},
                                  {"theta", tpl->table_from_template.theta}}},
                                {"z", "0 on the table top (the floor when --table-height is 0)"},
                                {"voxels", tpl->tpl.voxels.size()},
                                {"noise_voxels_dropped", tpl->noise_voxels_dropped},
                                {"merged_points", tpl->merged_points}};
    if (Status s = WriteFileAtomically(f.report_path, report.dump(2) + "\n"); !s.ok()) {
      return Fail(s.error());
    }
  }
  if (!f.picture_path.empty()) {
    if (Status s = WriteRegistrationPicture(*reg, *tpl, f.picture_path); !s.ok()) {
      return Fail(s.error());
    }
    std::cout << "drew " << f.picture_path << "\n";
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!hand) {
    std::cout << "turntable axis: x " << Fixed(reg->axis_ground.x() * 1000.0, 1) << " mm, y "
              << Fixed(reg->axis_ground.y() * 1000.0, 1)
              << " mm on the floor (ground frame), along the floor normal; not observable: "
                 "translation along the axis and the table's zero angle\n";
  }
  std::cout << "wrote " << f.out << " and " << TemplateSidecarPath(f.out) << ": '" << f.name
            << "', " << tpl->tpl.voxels.size() << " voxels of " << Fixed(f.resolution * 1000.0, 1)
            << " mm, height " << Fixed(tpl->tpl.Height() * 1000.0, 0) << " mm from "
            << reg->views.size() << " captures";
  if (!f.report_path.empty()) std::cout << "; report " << f.report_path;
  std::cout << " (" << Fixed(seconds, 1) << " s)\n";
  return kExitOk;
}

}  // namespace hpose::tools
