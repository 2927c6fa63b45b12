// End-to-end tests of `hpose simulate stereo` (and `simulate-stereo`) and `hpose
// estimate-stereo`: a good run checked against the simulator's truth, and bad input (missing
// landmark, wrong calibration file, images of different sizes) giving a clear message and a
// non-zero exit status.
#include <gtest/gtest.h>

#include "tests/sanitizer_build.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/common/pose2d.h"
#include "core/stereo/rgb_image_io.h"
#include "tests/tools/cli_test_util.h"

namespace hpose {
namespace {

using testing::CliRun;
using testing::RunHpose;
using testing::Slurp;
using testing::TempDir;
namespace fs = std::filesystem;

constexpr double kTolM = 0.05;
constexpr double kTolRad = 5.0 * kPi / 180.0;

std::string Q(const std::string& s) { return "'" + s + "'"; }

// head_x_m, head_y_m, head_theta_rad of every row of ground_truth.csv.
std::vector<Pose2D> ReadHeadTruth(const std::string& path) {
  std::vector<Pose2D> heads;
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    std::vector<double> v;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) v.push_back(std::stod(cell));
    if (v.size() >= 8) heads.push_back(Pose2D{v[5], v[6], v[7]});
  }
  return heads;
}

// Paints every landmark-blue pixel of an image in the floor's green.
void PaintOutLandmarks(const std::string& path) {
  Result<RgbImage> image = ReadRgbImage(path);
  ASSERT_TRUE(image.ok());
  int painted = 0;
  for (int y = 0; y < image->height; ++y) {
    for (int x = 0; x < image->width; ++x) {
      std::uint8_t* p = image->at(x, y);
      if (p[2] > p[0] + 40 && p[2] > p[1] + 30) {
        p[0] = 60;
        p[1] = 110;
        p[2] = 65;
        ++painted;
      }
    }
  }
  EXPECT_GT(painted, 50) << "no landmark pixels found in " << path;
  ASSERT_TRUE(WriteRgbPng(*image, path).ok());
}

class StereoCliTest : public ::testing::Test {
 protected:
  // Simulating the sequence alone takes minutes under the sanitizers; the stereo programs are
  // checked there by the stereo daemon tests.
  static void SetUpTestSuite() {
    dir_ = new TempDir("stereo_cli");
    if (testing::kSanitizerBuild) return;
    const CliRun run = RunHpose("simulate stereo --out " + Q(*dir_ / "seq") + " --frames 6", *dir_);
    ASSERT_EQ(run.exit_code, 0) << run.err;
    ASSERT_NE(run.out.find("wrote 6 stereo pairs"), std::string::npos) << run.out;
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  void SetUp() override { HPOSE_SKIP_IF_SANITIZED(); }
  std::string Seq(const std::string& rel = "") const {
    return rel.empty() ? *dir_ / "seq" : *dir_ / ("seq/" + rel);
  }

  static TempDir* dir_;
};

TempDir* StereoCliTest::dir_ = nullptr;

TEST_F(StereoCliTest, SimulateStereoWritesTheSequenceLayout) {
  for (const char* f : {"calibration.yaml", "frames.csv", "ground_truth.csv", "left/000000.png",
                        "right/000005.png"}) {
    EXPECT_TRUE(fs::exists(Seq(f))) << f;
  }
  EXPECT_FALSE(fs::exists(Seq("left/000006.png")));
  // `hpose simulate-stereo` is the same command: the same files for the same arguments.
  const std::string other = *dir_ / "seq_dash";
  const CliRun run = RunHpose("simulate-stereo --out " + Q(other) + " --frames 6", *dir_);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(Slurp(other + "/ground_truth.csv"), Slurp(Seq("ground_truth.csv")));
  EXPECT_EQ(Slurp(other + "/frames.csv"), Slurp(Seq("frames.csv")));
  // Its flags and help are reachable through `simulate stereo`.
  const CliRun help = RunHpose("simulate stereo --help", *dir_);
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.out.find("--scenario"), std::string::npos) << help.out;
  const CliRun bad =
      RunHpose("simulate stereo --out " + Q(*dir_ / "x") + " --scenario dance", *dir_);
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("dance"), std::string::npos) << bad.err;
}

TEST_F(StereoCliTest, EstimateStereoSequenceJsonMatchesTheTruth) {
  const CliRun run = RunHpose("estimate-stereo --sequence " + Q(Seq()) + " --json", *dir_);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const std::vector<Pose2D> truth = ReadHeadTruth(Seq("ground_truth.csv"));
  ASSERT_EQ(truth.size(), 6u);
  std::stringstream lines(run.out);
  std::string line;
  size_t n = 0;
  while (std::getline(lines, line)) {
    const nlohmann::json j = nlohmann::json::parse(line);
    const size_t i = j.at("index").get<size_t>();
    ASSERT_LT(i, truth.size());
    EXPECT_EQ(j.at("estimator"), "stereo_marker");
    EXPECT_EQ(j.at("frame"), "world");
    ASSERT_EQ(j.at("status"), "ok") << line;
    const nlohmann::json& r = j.at("robot");
    EXPECT_NEAR(r.at("x_m").get<double>(), truth[i].x, kTolM) << i;
    EXPECT_NEAR(r.at("y_m").get<double>(), truth[i].y, kTolM) << i;
    EXPECT_LT(std::abs(AngleDiff(r.at("theta_rad").get<double>(), truth[i].theta)), kTolRad) << i;
    EXPECT_EQ(j.at("robot_mean").at("frames").get<int>(), static_cast<int>(std::min(i + 1, 8ul)));
    ++n;
  }
  EXPECT_EQ(n, 6u);
}

TEST_F(StereoCliTest, EstimateStereoOnePairInText) {
  const CliRun run =
      RunHpose("estimate-stereo --left " + Q(Seq("left/000002.png")) + " --right " +
                   Q(Seq("right/000002.png")) + " --calibration " + Q(Seq("calibration.yaml")),
               *dir_);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const std::vector<Pose2D> truth = ReadHeadTruth(Seq("ground_truth.csv"));
  double x_mm = 0.0, y_mm = 0.0;
  const size_t at = run.out.find("robot x=");
  ASSERT_NE(at, std::string::npos) << run.out;
  ASSERT_EQ(std::sscanf(run.out.c_str() + at, "robot x=%lf mm y=%lf mm", &x_mm, &y_mm), 2)
      << run.out;
  EXPECT_NEAR(x_mm * 1e-3, truth[2].x, kTolM);
  EXPECT_NEAR(y_mm * 1e-3, truth[2].y, kTolM);
}

TEST_F(StereoCliTest, MissingLandmarkIsReportedWithExitThree) {
  const std::string left = *dir_ / "no_landmarks.png";
  fs::copy_file(Seq("left/000001.png"), left, fs::copy_options::overwrite_existing);
  PaintOutLandmarks(left);
  const std::string args = "estimate-stereo --left " + Q(left) + " --right " +
                           Q(Seq("right/000001.png")) + " --calibration " +
                           Q(Seq("calibration.yaml"));
  CliRun run = RunHpose(args, *dir_);
  EXPECT_EQ(run.exit_code, 3);
  EXPECT_NE(run.err.find("no robot pose"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("missing_landmark"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("left image shows 0 landmark"), std::string::npos) << run.err;
  run = RunHpose(args + " --json", *dir_);
  EXPECT_EQ(run.exit_code, 3);
  const nlohmann::json j = nlohmann::json::parse(run.out);
  EXPECT_EQ(j.at("status"), "missing_landmark");
  EXPECT_FALSE(j.contains("robot"));
}

TEST_F(StereoCliTest, WrongCalibrationFileIsAClearError) {
  const std::string pair =
      " --left " + Q(Seq("left/000000.png")) + " --right " + Q(Seq("right/000000.png"));
  // Missing file.
  CliRun run = RunHpose("estimate-stereo --calibration " + Q(*dir_ / "nope.yaml") + pair, *dir_);
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("nope.yaml: no such file"), std::string::npos) << run.err;
  // A file that is not a stereo calibration: names the file and the missing entry.
  const std::string not_cal = *dir_ / "camera.yaml";
  std::ofstream(not_cal) << "%YAML:1.0\n---\nfx: 500\nfy: 500\n";
  run = RunHpose("estimate-stereo --calibration " + Q(not_cal) + pair, *dir_);
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("camera.yaml: missing entry M1"), std::string::npos) << run.err;
  // Garbage.
  const std::string garbage = *dir_ / "garbage.yaml";
  std::ofstream(garbage) << "\x01\x02 not { yaml [";
  run = RunHpose("estimate-stereo --calibration " + Q(garbage) + pair, *dir_);
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("garbage.yaml"), std::string::npos) << run.err;
  // The calibration of another camera (256x120) for these 512x240 images.
  const std::string small = *dir_ / "small";
  ASSERT_EQ(RunHpose("simulate stereo --out " + Q(small) +
                         " --frames 1 --width 256 --height 120 --no-distractors",
                     *dir_)
                .exit_code,
            0);
  run = RunHpose("estimate-stereo --calibration " + Q(small + "/calibration.yaml") + pair, *dir_);
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("calibration is for 256x120"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("small/calibration.yaml"), std::string::npos) << run.err;
  // A unit mix-up: a file without its own translation unit, read as millimetres, gives an
  // implausible baseline.
  const std::string no_unit = *dir_ / "no_unit.yaml";
  {
    std::stringstream in(Slurp(Seq("calibration.yaml")));
    std::ofstream out(no_unit);
    std::string l;
    while (std::getline(in, l)) {
      if (l.find("translation_unit") == std::string::npos) out << l << "\n";
    }
  }
  run = RunHpose("estimate-stereo --calibration " + Q(no_unit) + " --calib-unit m" + pair, *dir_);
  EXPECT_EQ(run.exit_code, 0) << run.err;  // metres: right.
  run = RunHpose("estimate-stereo --calibration " + Q(no_unit) + " --calib-unit mm" + pair, *dir_);
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("baseline"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("no_unit.yaml"), std::string::npos) << run.err;
}

TEST_F(StereoCliTest, ImagesOfDifferentSizesAreAClearError) {
  const std::string small = *dir_ / "small_right.png";
  ASSERT_TRUE(WriteRgbPng(RgbImage(256, 120), small).ok());
  CliRun run = RunHpose("estimate-stereo --left " + Q(Seq("left/000000.png")) + " --right " +
                            Q(small) + " --calibration " + Q(Seq("calibration.yaml")),
                        *dir_);
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("left image is 512x240 but right image is 256x120"), std::string::npos)
      << run.err;
  EXPECT_NE(run.err.find("small_right.png"), std::string::npos) << run.err;

  // In a sequence: the pair is named.
  const std::string seq = *dir_ / "seq_sizes";
  fs::copy(Seq(), seq, fs::copy_options::recursive);
  ASSERT_TRUE(WriteRgbPng(RgbImage(256, 120), seq + "/right/000003.png").ok());
  run = RunHpose("estimate-stereo --sequence " + Q(seq), *dir_);
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("000003.png"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("512x240"), std::string::npos) << run.err;
}

TEST_F(StereoCliTest, UsageErrors) {
  CliRun run = RunHpose("estimate-stereo --left " + Q(Seq("left/000000.png")), *dir_);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("--left and --right"), std::string::npos) << run.err;
  run = RunHpose("estimate-stereo --left a.png --right b.png", *dir_);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("--calibration is required"), std::string::npos) << run.err;
  run = RunHpose("estimate-stereo --sequence " + Q(*dir_ / "no_such_dir"), *dir_);
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("no_such_dir"), std::string::npos) << run.err;
  // A frame rate no clock can step (1e300 frames a second) is refused, nothing written.
  run = RunHpose("simulate stereo --out " + Q(*dir_ / "fast") + " --frames 2 --fps 1e300", *dir_);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("--fps must be within [0.01, 10000], got 1e300"), std::string::npos)
      << run.err;
  EXPECT_FALSE(std::filesystem::exists(*dir_ / "fast/frames.csv"));
  // A rig or a field no room holds is a usage error naming the flag, nothing written.
  for (const std::string flag : {"--head-height 1e9", "--robot-x -1e9", "--tilt 95",
                                 "--ball-vx 1e9", "--kick-time -1", "--seed -1"}) {
    run = RunHpose("simulate stereo --out " + Q(*dir_ / "far") + " --frames 2 " + flag, *dir_);
    EXPECT_EQ(run.exit_code, 2) << flag << "\n" << run.err;
    EXPECT_NE(run.err.find(flag.substr(0, flag.find(' ')) + " must be within ["), std::string::npos)
        << flag << "\n"
        << run.err;
    EXPECT_FALSE(std::filesystem::exists(*dir_ / "far")) << flag;
  }
}

TEST_F(StereoCliTest, HardVgaSimulationRecordsOcclusionAndDistractorTruth) {
  const std::string out = *dir_ / "hard";
  const CliRun run =
      RunHpose("simulate stereo --out " + Q(out) + " --rig vga --hard --frames 2", *dir_);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("640x480"), std::string::npos) << run.out;
  const std::string truth = Slurp(out + "/ground_truth.csv");
  EXPECT_NE(truth.find("occluded_p0,occluded_p1,occluded_p2,landmark_color_distractors"),
            std::string::npos);
  const CliRun est = RunHpose("estimate-stereo --sequence " + Q(out) + " --json", *dir_);
  EXPECT_EQ(est.exit_code, 0) << est.err;
  std::istringstream lines(est.out);
  std::string line;
  int frames = 0;
  while (std::getline(lines, line)) {
    const auto j = nlohmann::json::parse(line);
    ++frames;
    if (j["status"] != "ok") EXPECT_FALSE(j["reason"].get<std::string>().empty());
    EXPECT_TRUE(j.contains("landmark_candidates"));
  }
  EXPECT_EQ(frames, 2);
  const CliRun bad = RunHpose("simulate stereo --out " + Q(out) + " --rig nope", *dir_);
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("--rig"), std::string::npos) << bad.err;
}

TEST_F(StereoCliTest, CalibrateWorldFromGroundFromACsv) {
  // A square walk; the ground frame sits at (1, 2) turned by 90 degrees in the world.
  const std::string csv = *dir_ / "pairs.csv";
  {
    std::ofstream f(csv);
    f << "timestamp_s,ground_x_m,ground_y_m,ground_theta_rad,world_x_m,world_y_m,"
         "world_theta_rad\n";
    for (int i = 0; i < 20; ++i) {
      const double gx = 0.5 + 0.05 * (i % 5), gy = 0.1 * (i / 5);
      // world = R(90 deg) * ground + (1, 2).
      f << i * 0.1 << "," << gx << "," << gy << ",0.1," << 1.0 - gy << "," << 2.0 + gx << ","
        << 0.1 + kPi / 2 << "\n";
    }
    f << "2.0,0.7,0.2,0.1,9,9,0.1\n";  // an outlier.
  }
  CliRun run = RunHpose("calibrate world-from-ground --pairs " + Q(csv), *dir_);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("x 1.0000 m, y 2.0000 m, yaw 1.5708 rad"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("pairs used 20 of 21"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("observable:"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("dropped pair at t=2.000 s"), std::string::npos) << run.out;
  {
    std::ofstream f(*dir_ / "bad.csv");
    f << "0,1,2\n";
  }
  run = RunHpose("calibrate world-from-ground --pairs " + Q(*dir_ / "bad.csv"), *dir_);
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("bad.csv:1"), std::string::npos) << run.err;
  run = RunHpose("calibrate nothing", *dir_);
  EXPECT_EQ(run.exit_code, 2);
}

TEST_F(StereoCliTest, CalibrateWorldFromGroundFromARecording) {
  // A short recording both sensors see: 6 stereo pairs, a depth frame with each.
  const std::string rec = *dir_ / "rec";
  CliRun run = RunHpose("simulate stereo --out " + Q(rec) +
                            " --scenario walking --frames 6 --speed 0.3 --depth-sensor "
                            "-1.1,-2.1,45 --depth-every 1",
                        *dir_);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_TRUE(fs::exists(rec + "/stereo/frames.csv"));
  EXPECT_TRUE(fs::exists(rec + "/depth/intrinsics.json"));
  EXPECT_TRUE(
      fs::exists(rec + "/depth/0000.333333.png"));  // named by its time on the stereo clock.
  const std::string truth = Slurp(rec + "/depth/truth.csv");
  EXPECT_EQ(std::count(truth.begin(), truth.end(), '\n'), 7) << truth;

  const std::string pairs = *dir_ / "rec_pairs.csv";
  run = RunHpose("calibrate world-from-ground --recording " + Q(rec) + " --pairs-out " + Q(pairs),
                 *dir_);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("depth: robot found in 6 of 6 frames"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("6 pairs within 50 ms"), std::string::npos) << run.out;
  const size_t at = run.out.find("world_from_ground: x ");
  ASSERT_NE(at, std::string::npos) << run.out;
  // 0.1 m of walking: the yaw comes from the headings, the placement to a few centimetres.
  EXPECT_NEAR(std::stod(run.out.substr(at + 21)), -1.1, 0.06) << run.out;
  // The pairs it wrote give the same fit through --pairs.
  const std::string first = run.out.substr(run.out.find("world_from_ground:"));
  run = RunHpose("calibrate world-from-ground --pairs " + Q(pairs), *dir_);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(run.out.substr(run.out.find("world_from_ground:")), first);

  // Clocks that do not agree: no pair within the tolerance, and the hint.
  run = RunHpose("calibrate world-from-ground --recording " + Q(rec) + " --stereo-time-offset 100",
                 *dir_);
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("fewer than 3 pose pairs within --max-dt"), std::string::npos) << run.err;
  // Usage errors and a missing half.
  EXPECT_EQ(
      RunHpose("calibrate world-from-ground --recording " + Q(rec) + " --depth x", *dir_).exit_code,
      2);
  EXPECT_EQ(RunHpose("calibrate world-from-ground --depth " + Q(rec + "/depth"), *dir_).exit_code,
            2);
  EXPECT_EQ(RunHpose("calibrate world-from-ground --recording " + Q(rec) + " --max-dt 0", *dir_)
                .exit_code,
            2);
  run = RunHpose("calibrate world-from-ground --depth " + Q(rec + "/depth") + " --stereo " +
                     Q(*dir_ / "nowhere"),
                 *dir_);
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("nowhere"), std::string::npos) << run.err;
  run = RunHpose("simulate stereo --out " + Q(*dir_ / "x") + " --depth-every 2", *dir_);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("--depth-sensor"), std::string::npos) << run.err;
  run = RunHpose("simulate stereo --out " + Q(*dir_ / "x") + " --depth-sensor 1,2", *dir_);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("X,Y,YAW_DEG"), std::string::npos) << run.err;
}

TEST_F(StereoCliTest, CalibrateStereoOnOpenCvSamplesWritesAFileTheEstimatorReads) {
  const std::string samples = "/usr/share/doc/opencv-doc/examples/data";
  if (!fs::exists(samples + "/left01.jpg")) {
    GTEST_SKIP() << "OpenCV's sample chessboard pairs not in " << samples
                 << " (install opencv-doc)";
  }
  const std::string cal = *dir_ / "ocv.yaml";
  CliRun run = RunHpose("calibrate stereo --dir " + Q(samples) + " --out " + Q(cal), *dir_);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("stereo RMS reprojection error"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("| left01.jpg right01.jpg | yes |"), std::string::npos) << run.out;
  run = RunHpose("estimate-stereo --calibration " + Q(cal) + " --left " +
                     Q(samples + "/left01.jpg") + " --right " + Q(samples + "/right01.jpg"),
                 *dir_);
  EXPECT_EQ(run.exit_code, 3) << run.err;  // read fine; no landmarks on a chessboard.
  EXPECT_NE(run.err.find("landmark"), std::string::npos) << run.err;
  run = RunHpose("calibrate stereo --dir " + Q(*dir_ / "seq") + " --out " + Q(cal), *dir_);
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("no left<N>/right<N>"), std::string::npos) << run.err;
}

}  // namespace
}  // namespace hpose
