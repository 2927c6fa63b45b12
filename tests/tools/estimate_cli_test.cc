// `hpose estimate` and `hpose demo` end to end: a simulated frame gives the humanoid back in the
// JSON, and every kind of bad input gives a message naming the problem and a non-zero exit.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/common/pose2d.h"
#include "core/io/cloud_io.h"
#include "tests/tools/cli_test_util.h"

namespace hpose {
namespace {

using testing::CliRun;
using testing::RunHpose;
using testing::TempDir;

class EstimateCliTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TempDir("estimate_cli");
    const CliRun sim = RunHpose("simulate --out '" + (*dir_ / "frame") +
                                    "' --x 1.2 --y -0.1 --theta-deg 40 --clutter 2 --seed 5",
                                *dir_);
    ASSERT_EQ(sim.exit_code, 0) << sim.err;
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  static std::string Frame(const std::string& name) { return *dir_ / ("frame/" + name); }
  static TempDir* dir_;
};
TempDir* EstimateCliTest::dir_ = nullptr;

TEST_F(EstimateCliTest, FindsTheSimulatedHumanoidInJson) {
  const CliRun run = RunHpose("estimate --depth '" + Frame("depth.png") + "' --intrinsics '" +
                                  Frame("intrinsics.json") + "' --json",
                              *dir_);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json j = nlohmann::json::parse(run.out);
  const nlohmann::json& r = j.at("depth_template");
  ASSERT_TRUE(r.at("humanoid_found").get<bool>());
  const nlohmann::json& c = r.at("detections").at(0).at("best");
  EXPECT_EQ(c.at("template_name"), "standing");
  EXPECT_NEAR(c.at("pose").at("x").get<double>(), 1.2, 0.03);
  EXPECT_NEAR(c.at("pose").at("y").get<double>(), -0.1, 0.03);
  EXPECT_LT(std::abs(AngleDiff(c.at("pose").at("theta").get<double>(), DegToRad(40))), DegToRad(6));
  EXPECT_GT(c.at("score").get<double>(), 50.0);
  EXPECT_LE(c.at("score").get<double>(), 100.0);
  for (const char* stage : {"cloud", "floor", "cluster", "search", "total"}) {
    EXPECT_GE(j.at("timings").at(stage).get<double>(), 0.0) << stage;
  }
  EXPECT_NEAR(r.at("floor").at("height").get<double>(), 0.34, 0.02);
}

TEST_F(EstimateCliTest, CloudInputAndPaperSearchAgree) {
  const CliRun run =
      RunHpose("estimate --cloud '" + Frame("cloud.pcd") + "' --search paper --json", *dir_);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json j = nlohmann::json::parse(run.out);
  EXPECT_NEAR(j.at("depth_template").at("best").at("best").at("pose").at("x").get<double>(), 1.2,
              0.04);
}

// The estimate without what changes from run to run (the timings, the time it was made).
nlohmann::json WithoutTimes(const nlohmann::json& j) {
  if (j.is_array()) {
    nlohmann::json out = nlohmann::json::array();
    for (const nlohmann::json& v : j) out.push_back(WithoutTimes(v));
    return out;
  }
  if (!j.is_object()) return j;
  nlohmann::json out = nlohmann::json::object();
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (it.key() == "timings" || it.key() == "received_time") continue;
    out[it.key()] = WithoutTimes(it.value());
  }
  return out;
}

// HPOSE_VECTOR_LEVEL caps core's vector paths: the scalar, AVX2 and AVX-512 forms (each where
// this CPU has it; a cap above the CPU's takes the CPU's best) give the same estimate to the bit,
// here on the near frame and on a far one among more clutter.
TEST_F(EstimateCliTest, EveryVectorLevelGivesTheSameEstimate) {
  const CliRun sim = RunHpose("simulate --out '" + (*dir_ / "far") +
                                  "' --x 2.9 --y 0.4 --theta-deg 130 --clutter 4 --seed 11",
                              *dir_);
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  const std::string hpose = std::string(HPOSE_BINARY_DIR) + "/tools/hpose";
  for (const std::string frame : {Frame(""), *dir_ / "far/"}) {
    const std::string args = "estimate --depth '" + frame + "depth.png' --intrinsics '" + frame +
                             "intrinsics.json' --json";
    const CliRun plain = RunHpose(args, *dir_);
    ASSERT_EQ(plain.exit_code, 0) << plain.err;
    const nlohmann::json want = WithoutTimes(nlohmann::json::parse(plain.out));
    ASSERT_TRUE(want.at("depth_template").at("humanoid_found").get<bool>()) << frame;
    for (const char* level : {"scalar", "avx2", "avx512"}) {
      const CliRun run = testing::RunProgram(
          "env", std::string("HPOSE_VECTOR_LEVEL=") + level + " '" + hpose + "' " + args, *dir_);
      ASSERT_EQ(run.exit_code, 0) << level << ": " << run.err;
      EXPECT_EQ(WithoutTimes(nlohmann::json::parse(run.out)), want) << level << " on " << frame;
    }
  }
  const CliRun bad = testing::RunProgram(
      "env",
      "HPOSE_VECTOR_LEVEL=avx3 '" + hpose + "' estimate --depth '" + Frame("depth.png") +
          "' --intrinsics '" + Frame("intrinsics.json") + "' --json",
      *dir_);
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_EQ(bad.out, "");
  EXPECT_NE(bad.err.find("HPOSE_VECTOR_LEVEL: unknown vector level \"avx3\""), std::string::npos)
      << bad.err;
}

TEST_F(EstimateCliTest, HumanReadableOutputAndPicture) {
  const std::string picture = *dir_ / "match.png";
  const CliRun run =
      RunHpose("estimate --depth '" + Frame("depth.png") + "' --picture '" + picture + "'", *dir_);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("humanoid  standing at x 1.2"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("deg"), std::string::npos);
  EXPECT_GT(std::filesystem::file_size(picture), 1000u);
}

TEST_F(EstimateCliTest, BadInputNamesTheProblem) {
  struct Case {
    std::string args;
    int exit_code;
    std::string says;
  };
  std::ofstream(*dir_ / "garbage.png") << "not a png at all";
  std::ofstream(*dir_ / "nan.json")
      << R"({"width":640,"height":480,"fx":NaN,"fy":525,"cx":320,"cy":240})";
  std::ofstream(*dir_ / "small.json")
      << R"({"width":320,"height":240,"fx":285,"fy":285,"cx":160,"cy":120})";
  std::ofstream(*dir_ / "extra.json")
      << R"({"width":640,"height":480,"fx":525,"fy":525,"cx":320,"cy":240,"k1":0.1})";
  std::ofstream(*dir_ / "garbage.pcd") << "VERSION .7\nFIELDS x y z\nnonsense\n";
  PointCloud nan_cloud;
  nan_cloud.points.assign(50, Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN()));
  ASSERT_TRUE(WritePcd(nan_cloud, *dir_ / "nan.pcd").ok());
  ASSERT_TRUE(WritePcd(PointCloud{}, *dir_ / "empty.pcd").ok());
  const std::vector<Case> cases = {
      {"estimate --depth '" + (*dir_ / "missing.png") + "'", 1, "missing.png"},
      {"estimate --depth '" + (*dir_ / "garbage.png") + "'", 1, "garbage.png"},
      {"estimate --depth '" + Frame("depth.png") + "' --intrinsics '" + (*dir_ / "nan.json") + "'",
       1, "nan.json"},
      {"estimate --depth '" + Frame("depth.png") + "' --intrinsics '" + (*dir_ / "small.json") +
           "'",
       1, "320x240"},
      {"estimate --depth '" + Frame("depth.png") + "' --intrinsics '" + (*dir_ / "extra.json") +
           "'",
       1, "k1"},
      {"estimate --cloud '" + (*dir_ / "garbage.pcd") + "'", 1, "garbage.pcd"},
      {"estimate --cloud '" + (*dir_ / "nan.pcd") + "'", 1, "NaN"},
      {"estimate --cloud '" + (*dir_ / "empty.pcd") + "'", 1, "empty"},
      {"estimate --depth '" + Frame("depth.png") + "' --template '" + (*dir_ / "nope.bt") + "'", 1,
       "nope.bt"},
      {"estimate --depth '" + Frame("depth.png") + "' --search fastest", 2, "--search: "},
      {"estimate --depth '" + Frame("depth.png") + "' --template no_such_body", 1,
       "'no_such_body' is no shipped template (those are arms_swung, right_arm_raised, standing, "
       "in "},
      {"estimate --depth '" + Frame("depth.png") + "' --cloud '" + Frame("cloud.pcd") + "'", 2,
       "either"},
      {"estimate --frobnicate", 2, "frobnicate"},
  };
  for (const Case& c : cases) {
    const CliRun run = RunHpose(c.args, *dir_);
    EXPECT_EQ(run.exit_code, c.exit_code) << c.args << "\n" << run.err;
    EXPECT_NE(run.err.find(c.says), std::string::npos) << c.args << "\n" << run.err;
  }
}

// Out-of-range values are usage errors (exit 2) that name the flag, its range and the value,
// before any work; a flag that only goes with another says so.
TEST_F(EstimateCliTest, FlagsOutOfRangeNameTheFlag) {
  const std::string frame = "estimate --depth '" + Frame("depth.png") + "'";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {" --threshold 101", "--threshold must be within [0, 100], got 101"},
      {" --min-fit -2", "--min-fit must be within [0, 100], got -2"},
      {" --min-evidence 1.5", "--min-evidence must be within [0, 1], got 1.5"},
      {" --far-ratio 5", "--far-ratio must be within [0, 1], got 5"},
      {" --height-offset-voxels 9", "--height-offset-voxels must be within [0, 8], got 9"},
      {" --max-height-voxels 3", "--max-height-voxels must be 0 (off) or within [8, 1024], got 3"},
      {" --max-height-voxels 2000", "--max-height-voxels must be 0 (off) or within [8, 1024]"},
      {" --stride 0", "--stride must be within [1, 16], got 0"},
      {" --threads 300", "--threads must be within [0, 256], got 300"},
      {" --floor-min-width -1", "--floor-min-width must be within [0, 100], got -1"},
      {" --floor-roll-deg 3", "--floor-roll-deg goes with --floor-height"},
      {" --score loudest", "--score: unknown score 'loudest'"},
  };
  for (const auto& [flags, says] : cases) {
    const CliRun run = RunHpose(frame + flags, *dir_);
    EXPECT_EQ(run.exit_code, 2) << flags << "\n" << run.err;
    EXPECT_NE(run.err.find(says), std::string::npos) << flags << "\n" << run.err;
    EXPECT_EQ(run.err.find("score_threshold"), std::string::npos) << run.err;  // no option keys.
  }
  // The ends of each range are accepted.
  const CliRun ends = RunHpose(frame +
                                   " --threshold 0 --min-fit 100 --height-offset-voxels 8 "
                                   "--far-ratio 1 --json",
                               *dir_);
  EXPECT_NE(ends.exit_code, 2) << ends.err;
}

// A shipped template is given by its name as well as by its path, as `hpose replay` and hposed
// take it: the same estimate.
TEST_F(EstimateCliTest, ShippedTemplatesByName) {
  const std::string frame = "estimate --depth '" + Frame("depth.png") + "' --json --template ";
  const CliRun by_name = RunHpose(frame + "standing", *dir_);
  const CliRun by_path =
      RunHpose(frame + "'" + std::string(HPOSE_SOURCE_DIR) + "/templates/standing.bt'", *dir_);
  ASSERT_EQ(by_name.exit_code, 0) << by_name.err;
  ASSERT_EQ(by_path.exit_code, 0) << by_path.err;
  const nlohmann::json a = nlohmann::json::parse(by_name.out).at("depth_template");
  const nlohmann::json b = nlohmann::json::parse(by_path.out).at("depth_template");
  ASSERT_TRUE(a.at("humanoid_found").get<bool>());
  EXPECT_EQ(a.at("detections").at(0).at("best").at("template_name"), "standing");
  EXPECT_EQ(a.at("detections").at(0).at("best").at("pose"),
            b.at("detections").at(0).at("best").at("pose"));
}

// `hpose estimate FRAME`: the kind of frame from its extension, and the intrinsics.json beside
// a depth frame used as `hpose replay` and hposed use it (a note names it), before Kinect v1's.
TEST_F(EstimateCliTest, AFrameAloneIsReadByItsExtensionWithTheIntrinsicsBesideIt) {
  namespace fs = std::filesystem;
  auto pose_y = [](const CliRun& run) {
    const nlohmann::json j = nlohmann::json::parse(run.out);
    return j.at("depth_template")
        .at("detections")
        .at(0)
        .at("best")
        .at("pose")
        .at("y")
        .get<double>();
  };
  const CliRun depth = RunHpose("estimate '" + Frame("depth.png") + "' --json", *dir_);
  ASSERT_EQ(depth.exit_code, 0) << depth.err;
  EXPECT_NE(depth.err.find("intrinsics beside the frame, " + Frame("intrinsics.json")),
            std::string::npos)
      << depth.err;
  EXPECT_EQ(depth.err.find("assuming Kinect v1"), std::string::npos) << depth.err;
  EXPECT_NEAR(pose_y(depth), -0.1, 0.03);
  const CliRun cloud = RunHpose("estimate '" + Frame("cloud.pcd") + "' --json", *dir_);
  ASSERT_EQ(cloud.exit_code, 0) << cloud.err;
  EXPECT_NEAR(pose_y(cloud), -0.1, 0.03);

  // The same frame alone in a directory: Kinect v1's intrinsics, said so. Beside it intrinsics
  // whose principal point is 25 px to the left: the whole scene, the humanoid too, is seen
  // about 5 cm further to the right. A broken intrinsics.json beside it is an error naming it.
  for (const char* sub : {"alone", "shifted", "broken"}) {
    fs::create_directories(*dir_ / sub);
    fs::copy_file(Frame("depth.png"), *dir_ / (std::string(sub) + "/depth.png"),
                  fs::copy_options::overwrite_existing);
  }
  std::ofstream(*dir_ / "shifted/intrinsics.json")
      << R"({"width":640,"height":480,"fx":594.2,"fy":591.0,"cx":314.3,"cy":242.7})";
  std::ofstream(*dir_ / "broken/intrinsics.json") << R"({"width":640,"height":480})";
  const CliRun alone = RunHpose("estimate '" + (*dir_ / "alone/depth.png") + "' --json", *dir_);
  ASSERT_EQ(alone.exit_code, 0) << alone.err;
  EXPECT_NE(alone.err.find("assuming Kinect v1 intrinsics for 640x480"), std::string::npos)
      << alone.err;
  EXPECT_NEAR(pose_y(alone), pose_y(depth), 0.005);
  const CliRun shifted = RunHpose("estimate '" + (*dir_ / "shifted/depth.png") + "' --json", *dir_);
  ASSERT_EQ(shifted.exit_code, 0) << shifted.err;
  EXPECT_NEAR(pose_y(shifted) - pose_y(depth), -0.05, 0.015);
  const CliRun broken = RunHpose("estimate '" + (*dir_ / "broken/depth.png") + "'", *dir_);
  EXPECT_EQ(broken.exit_code, 1);
  EXPECT_NE(broken.err.find(*dir_ / "broken/intrinsics.json"), std::string::npos) << broken.err;

  struct Case {
    std::string args;
    std::string says;
  };
  const std::vector<Case> usage = {
      {"estimate '" + Frame("depth.png") + "' '" + Frame("cloud.pcd") + "'", "one frame at a time"},
      {"estimate '" + Frame("depth.png") + "' --cloud '" + Frame("cloud.pcd") + "'",
       "give the frame once"},
      {"estimate '" + Frame("truth.json") + "'", "cannot tell what"},
      {"estimate '" + Frame("depth.png") + "' --floor-height 0.34 --floor-pitch-deg 1e300",
       "--floor-pitch-deg and --floor-roll-deg must be within"},
  };
  for (const Case& c : usage) {
    const CliRun run = RunHpose(c.args, *dir_);
    EXPECT_EQ(run.exit_code, 2) << c.args << "\n" << run.err;
    EXPECT_NE(run.err.find(c.says), std::string::npos) << c.args << "\n" << run.err;
  }
}

// A humanoid too far to reach the score threshold: exit 3, and the report says which cluster
// came nearest, that it was proved below the threshold, and what can find it.
TEST_F(EstimateCliTest, AFarHumanoidBelowTheThresholdIsExplained) {
  const CliRun sim = RunHpose("simulate --out '" + (*dir_ / "far") +
                                  "' --x 3.5 --theta-deg 60 --sensor-height 0.9 --pitch-deg 20 "
                                  "--clutter 3 --seed 4 --no-cloud",
                              *dir_);
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  // By default a far cluster passes from a lower score on strong evidence: found where it stands.
  const CliRun found = RunHpose("estimate --depth '" + (*dir_ / "far/depth.png") + "'", *dir_);
  EXPECT_EQ(found.exit_code, 0) << found.out << found.err;
  const size_t x_at = found.out.find(" at x ");
  ASSERT_NE(x_at, std::string::npos) << found.out;
  EXPECT_NEAR(std::stod(found.out.substr(x_at + 6)), 3.5, 0.05) << found.out;
  const size_t score_at = found.out.find(", score ");
  ASSERT_NE(score_at, std::string::npos) << found.out;
  EXPECT_LT(std::stod(found.out.substr(score_at + 8)), 50.0) << found.out;
  // With one threshold at every range it is not, and the report says why and what finds it.
  const CliRun run =
      RunHpose("estimate --depth '" + (*dir_ / "far/depth.png") + "' --far-ratio 1", *dir_);
  EXPECT_EQ(run.exit_code, 3) << run.out << run.err;
  EXPECT_NE(run.out.find("none found (best: "), std::string::npos) << run.out;
  EXPECT_NE(run.out.find(" m away, proved below score 50"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("far humanoids score less"), std::string::npos) << run.out;
  // Nothing passed on the floor, so the frame was searched again one and two voxels lower and
  // higher: five searches, which its JSON counts.
  const CliRun json_run =
      RunHpose("estimate --depth '" + (*dir_ / "far/depth.png") + "' --far-ratio 1 --json", *dir_);
  ASSERT_EQ(json_run.exit_code, 3) << json_run.err;
  EXPECT_EQ(nlohmann::json::parse(json_run.out)["depth_template"]["tracking"]["height_searches"]
                .get<int>(),
            5)
      << json_run.out;
  // With the bar lowered for this frame it is found where it stands.
  EXPECT_NE(run.out.find("(--far-ratio)"), std::string::npos) << run.out;
  const CliRun low = RunHpose(
      "estimate --depth '" + (*dir_ / "far/depth.png") + "' --far-ratio 1 --threshold 35", *dir_);
  EXPECT_EQ(low.exit_code, 0) << low.out << low.err;
  const size_t at = low.out.find(" at x ");
  ASSERT_NE(at, std::string::npos) << low.out;
  EXPECT_NEAR(std::stod(low.out.substr(at + 6)), 3.5, 0.05) << low.out;
  // Asked for more evidence than its pose has, it is refused, and the report says by what.
  const CliRun strict = RunHpose("estimate --depth '" + (*dir_ / "far/depth.png") +
                                     "' --far-ratio 1 --threshold 35 --min-evidence 0.9",
                                 *dir_);
  EXPECT_EQ(strict.exit_code, 3) << strict.out << strict.err;
  EXPECT_NE(strict.out.find("but evidence of 0."), std::string::npos) << strict.out;
  EXPECT_NE(strict.out.find("below 0.90: --min-evidence)"), std::string::npos) << strict.out;
}

// hpose replay --initial-pose: the far robot above, turning on the spot, is found in every frame
// of the recording; without it in none (with one score threshold at every range, from --config:
// the far clusters' lower one finds it cold). A malformed pose is a usage error. --truth sums up
// the errors against the simulation's truth.json, and refuses one that names none of the frames.
TEST_F(EstimateCliTest, ReplayFromAnInitialPoseFindsAFarRobot) {
  const CliRun sim = RunHpose("simulate --out '" + (*dir_ / "farseq") +
                                  "' --x 3.5 --theta-deg 60 --sensor-height 0.9 --pitch-deg 20 "
                                  "--clutter 3 --seed 4 --frames 3 --turn-deg 10 --width 320 "
                                  "--height 240 --no-cloud",
                              *dir_);
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  const std::string config = *dir_ / "one_threshold.yaml";
  std::ofstream(config) << "search: {far_score_ratio: 1}\n";
  const std::string replay = "replay '" + (*dir_ / "farseq") + "' --no-progress --format csv" +
                             " --config '" + config + "'";
  for (const bool given : {false, true}) {
    const CliRun run = RunHpose(replay + (given ? " --initial-pose 3.5,0,60" : "") + " --truth '" +
                                    (*dir_ / "farseq/truth.json") + "'",
                                *dir_);
    ASSERT_EQ(run.exit_code, 0) << run.err;
    EXPECT_NE(run.err.find(given ? "humanoid found in 3 of 3 frame(s)"
                                 : "humanoid found in 0 of 3 frame(s)"),
              std::string::npos)
        << run.err;
    EXPECT_EQ(run.err.find("position error median") != std::string::npos, given) << run.err;
    std::istringstream lines(run.out);
    std::string line;
    // The last two columns of a row.
    const auto last_two = [](const std::string& row) {
      const size_t last = row.rfind(',');
      const size_t before = row.rfind(',', last - 1);
      return std::pair{row.substr(before + 1, last - before - 1), row.substr(last + 1)};
    };
    std::getline(lines, line);  // the header.
    EXPECT_EQ(last_two(line),
              (std::pair<std::string, std::string>{"refused_by", "template_margin_kind"}));
    int rows = 0, humanoids = 0, refused_by_score = 0;
    while (std::getline(lines, line)) {
      ++rows;
      humanoids += line.find(",standing,1,") != std::string::npos ||
                   line.find(",right_arm_raised,1,") != std::string::npos;
      const auto [refused_by, margin_kind] = last_two(line);
      // Empty for a humanoid, else the rule (one score threshold: the score).
      refused_by_score += refused_by == "score";
      // The points of the margin over the other template.
      EXPECT_TRUE(margin_kind == "fit" || margin_kind == "score" || margin_kind == "score_at_least")
          << line;
    }
    EXPECT_EQ(rows, 3) << run.out;
    EXPECT_EQ(humanoids, given ? 3 : 0) << run.out;
    EXPECT_EQ(refused_by_score, given ? 0 : 3) << run.out;
  }
  const CliRun bad = RunHpose(replay + " --initial-pose 3.5,0", *dir_);
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("--initial-pose"), std::string::npos) << bad.err;
  const CliRun negative = RunHpose(replay + " --max-frames -1", *dir_);
  EXPECT_EQ(negative.exit_code, 2);
  EXPECT_NE(negative.err.find("--max-frames must be within [0, 2147483647], got -1"),
            std::string::npos)
      << negative.err;
  // Another simulation's truth (one frame, depth.png) names none of these frames.
  ASSERT_EQ(RunHpose("simulate --out '" + (*dir_ / "other") +
                         "' --x 15 --width 320 --height 240 --no-cloud",
                     *dir_)
                .exit_code,
            0);
  const CliRun other = RunHpose(replay + " --truth '" + (*dir_ / "other/truth.json") + "'", *dir_);
  EXPECT_EQ(other.exit_code, 1);
  EXPECT_NE(other.err.find("names none of the recording's frames"), std::string::npos) << other.err;
}

TEST_F(EstimateCliTest, NoFloorAndNoHumanoidHaveTheirOwnExitStatus) {
  // Only the floor: exit 3 (no humanoid).
  const CliRun sim = RunHpose("simulate --out '" + (*dir_ / "empty") + "' --x 15", *dir_);
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  CliRun run = RunHpose("estimate --depth '" + (*dir_ / "empty/depth.png") + "'", *dir_);
  EXPECT_EQ(run.exit_code, 3) << run.out << run.err;
  EXPECT_NE(run.out.find("none found"), std::string::npos) << run.out;
  // A wall straight ahead and no floor: exit 4.
  PointCloud wall;
  for (int i = 0; i < 4000; ++i) {
    wall.points.emplace_back(-0.5f + 0.001f * (i % 100), -0.5f + 0.025f * (i / 100), 1.5f);
  }
  ASSERT_TRUE(WritePcd(wall, *dir_ / "wall.pcd").ok());
  run = RunHpose("estimate --cloud '" + (*dir_ / "wall.pcd") + "'", *dir_);
  EXPECT_EQ(run.exit_code, 4) << run.out << run.err;
  EXPECT_NE(run.err.find("floor"), std::string::npos) << run.err;
  // A sensor pitched up sees no floor in range, only clutter: the planes through the clutter's
  // sides are strips, no floor (exit 4). Without the width check one was taken for a floor
  // (and no humanoid stood on it: exit 3).
  const CliRun up = RunHpose("simulate --out '" + (*dir_ / "up") +
                                 "' --sensor-height 0.9 --pitch-deg -10 --clutter 6 --seed 1",
                             *dir_);
  ASSERT_EQ(up.exit_code, 0) << up.err;
  const std::string frame = "estimate '" + (*dir_ / "up/depth.png") + "'";
  run = RunHpose(frame, *dir_);
  EXPECT_EQ(run.exit_code, 4) << run.out << run.err;
  EXPECT_NE(run.err.find("strips up to"), std::string::npos) << run.err;
  run = RunHpose(frame + " --floor-min-width 0", *dir_);
  EXPECT_EQ(run.exit_code, 3) << run.out << run.err;
  run = RunHpose(frame + " --floor-min-width -1", *dir_);
  EXPECT_EQ(run.exit_code, 2) << run.out << run.err;
  EXPECT_NE(run.err.find("--floor-min-width"), std::string::npos) << run.err;
}

// A sensor near the ceiling looking down 75 degrees: past the floor fit's default tilt limit
// (70), the error says how to go on (exit 4); with --floor-max-tilt-deg the humanoid is found.
TEST_F(EstimateCliTest, ASteepMountNeedsTheTiltFlagAndSaysSo) {
  const CliRun sim = RunHpose("simulate --out '" + (*dir_ / "steep") +
                                  "' --sensor-height 2.5 --pitch-deg 75 --x 1.0 --y 0.1 "
                                  "--theta-deg -30 --clutter 3 --seed 2 --no-cloud",
                              *dir_);
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  const std::string frame = "estimate '" + (*dir_ / "steep/depth.png") + "'";
  CliRun run = RunHpose(frame, *dir_);
  EXPECT_EQ(run.exit_code, 4) << run.out << run.err;
  EXPECT_NE(run.err.find("looking down that steeply"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("--floor-max-tilt-deg"), std::string::npos) << run.err;
  run = RunHpose(frame + " --floor-max-tilt-deg 85 --json", *dir_);
  ASSERT_EQ(run.exit_code, 0) << run.out << run.err;
  const nlohmann::json j = nlohmann::json::parse(run.out).at("depth_template");
  EXPECT_NEAR(j.at("floor").at("height").get<double>(), 2.5, 0.02);
  EXPECT_NEAR(j.at("floor").at("pitch").get<double>(), DegToRad(75), DegToRad(1));
  const nlohmann::json& pose = j.at("detections").at(0).at("best").at("pose");
  EXPECT_NEAR(pose.at("x").get<double>(), 1.0, 0.03);
  EXPECT_NEAR(pose.at("y").get<double>(), 0.1, 0.03);
  EXPECT_LT(std::abs(AngleDiff(pose.at("theta").get<double>(), DegToRad(-30))), DegToRad(6));
  // hpose replay (and hposed) take it from the config: floor.max_tilt_rad. Without it every
  // frame fails, and the summary says why.
  const std::string config = *dir_ / "steep.yaml";
  std::ofstream(config) << "floor: {max_tilt_rad: 1.45}\n";
  const std::string replay = "replay '" + (*dir_ / "steep") + "' --no-progress --format csv";
  run = RunHpose(replay, *dir_);
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("1 frame(s)"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("0 estimated, 1 failed"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("the first that failed, " + (*dir_ / "steep/depth.png") + ": no floor"),
            std::string::npos)
      << run.err;
  run = RunHpose(replay + " --config '" + config + "'", *dir_);
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("1 estimated, 0 failed"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("humanoid found in 1"), std::string::npos) << run.err;
  EXPECT_EQ(run.err.find("the first that failed"), std::string::npos) << run.err;
  for (const char* bad : {"0", "86", "nan"}) {
    run = RunHpose(frame + " --floor-max-tilt-deg " + bad, *dir_);
    EXPECT_EQ(run.exit_code, 2) << bad << "\n" << run.err;
    EXPECT_NE(run.err.find(std::string(bad) == "nan" ? "bad value 'nan' for --floor-max-tilt-deg"
                                                     : "--floor-max-tilt-deg must be within"),
              std::string::npos)
        << run.err;
  }
}

// hpose replay checks a config's search, floor and initial pose as hposed does, naming the file
// and the key; what only serving needs (an address off loopback without TLS) is not its
// business.
TEST_F(EstimateCliTest, ReplayChecksItsConfigAsHposedDoes) {
  const std::string replay = "replay '" + Frame("depth.png") + "' --no-progress --format csv";
  const struct {
    const char* yaml;
    const char* error;
  } bad[] = {
      {"search: {score_threshold: 500}\n", "search.score_threshold: must be in [0, 100]"},
      {"search: {stride: 0}\n", "search.stride: must be in [1, 16], got 0"},
      {"floor: {max_tilt_rad: 2}\n", "floor.max_tilt_rad: must be in (0, 1.5] rad"},
      {"source: {tracking: false, initial_pose: {x_m: 1, y_m: 0}}\n",
       "source.initial_pose: needs source.tracking: true"},
  };
  const std::string config = *dir_ / "replay_check.yaml";
  for (const auto& c : bad) {
    std::ofstream(config) << c.yaml;
    const CliRun run = RunHpose(replay + " --config '" + config + "'", *dir_);
    EXPECT_EQ(run.exit_code, 1) << c.yaml << run.err;
    EXPECT_NE(run.err.find("hpose replay: " + config + ": " + c.error), std::string::npos)
        << c.yaml << run.err;
    EXPECT_TRUE(run.out.empty()) << c.yaml << run.out;
  }
  std::ofstream(config) << "listen: 0.0.0.0:50051\nsearch: {score_threshold: 55}\n";
  const CliRun run = RunHpose(replay + " --config '" + config + "'", *dir_);
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("1 estimated, 0 failed"), std::string::npos) << run.err;
}

// The shipped templates mark their arms and head as free limbs: a robot walking with its arms
// swung (the parametric humanoid's `arms_swung`) is fitted without them, and its heading comes
// out right where the search's lattice optimum had turned it toward its arms.
TEST(EstimateShippedTemplatesTest, ArmsSwungAreLeftOutOfTheFit) {
  TempDir dir("estimate_cli_swung");
  const CliRun sim = RunHpose("simulate --out '" + (dir / "swung") +
                                  "' --pose arms_swung --x 1.8 --y 0.15 --theta-deg 60 "
                                  "--clutter 4 --seed 7",
                              dir);
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  const CliRun run = RunHpose("estimate '" + (dir / "swung/depth.png") + "' --json", dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json j = nlohmann::json::parse(run.out);
  ASSERT_TRUE(j.at("depth_template").at("humanoid_found").get<bool>());
  const nlohmann::json& c = j.at("depth_template").at("detections").at(0).at("best");
  EXPECT_TRUE(c.value("free_limbs_left_out", false));
  EXPECT_TRUE(c.value("free_limbs_moved", false));
  const double theta = c.at("pose").at("theta").get<double>();
  const double lattice = c.at("lattice_pose").at("theta").get<double>();
  EXPECT_LT(std::abs(AngleDiff(theta, DegToRad(60))), DegToRad(2));
  EXPECT_GT(std::abs(AngleDiff(lattice, DegToRad(60))), std::abs(AngleDiff(theta, DegToRad(60))));
  const CliRun text = RunHpose("estimate '" + (dir / "swung/depth.png") + "'", dir);
  ASSERT_EQ(text.exit_code, 0) << text.err;
  EXPECT_NE(text.out.find("fitted without the template's free limbs"), std::string::npos)
      << text.out;
  // Refused for its fit (a bar no swung-armed robot reaches), the report says why it may fit
  // so poorly and what would fit it.
  const CliRun strict = RunHpose("estimate '" + (dir / "swung/depth.png") + "' --min-fit 99", dir);
  ASSERT_EQ(strict.exit_code, 3) << strict.out << strict.err;  // no humanoid.
  EXPECT_NE(strict.out.find("humanoid  none found"), std::string::npos) << strict.out;
  EXPECT_NE(strict.out.find("contradicts the template's free limbs"), std::string::npos)
      << strict.out;
  EXPECT_NE(strict.out.find("that posture would fit it"), std::string::npos) << strict.out;
  EXPECT_NE(strict.out.find("arms_swung, given with them by --template"), std::string::npos)
      << strict.out;
  // The shipped template of that posture, given beside the two, is taken and fits it closer.
  const CliRun three = RunHpose("estimate '" + (dir / "swung/depth.png") +
                                    "' --json --template standing --template right_arm_raised "
                                    "--template arms_swung",
                                dir);
  ASSERT_EQ(three.exit_code, 0) << three.err;
  const nlohmann::json k = nlohmann::json::parse(three.out);
  const nlohmann::json& swung = k.at("depth_template").at("detections").at(0).at("best");
  EXPECT_EQ(swung.at("template_name"), "arms_swung");
  EXPECT_LT(std::abs(AngleDiff(swung.at("pose").at("theta").get<double>(), DegToRad(60))),
            DegToRad(1.5));
  EXPECT_GT(swung.at("fit").at("fit").get<double>(), c.at("fit").at("fit").get<double>());
}

TEST(DemoCliTest, RunsWithoutInput) {
  TempDir dir("demo_cli");
  const CliRun run = RunHpose("demo --picture '" + (dir / "demo.png") + "'", dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("truth"), std::string::npos);
  EXPECT_NE(run.out.find("error     x"), std::string::npos);
  EXPECT_TRUE(std::filesystem::exists(dir / "demo.png"));
  // A robot placed where no simulated room reaches, or too much clutter, is refused by the flag.
  for (const auto& [flags, says] : std::vector<std::pair<std::string, std::string>>{
           {"--x 1e9", "--x must be within [-20, 20], got 1e9"},
           {"--y -30", "--y must be within [-20, 20], got -30"},
           {"--clutter 51", "--clutter must be within [0, 50], got 51"},
           {"--seed -1", "--seed must be within [0, "}}) {
    const CliRun bad = RunHpose("demo " + flags + " --picture '" + (dir / "bad.png") + "'", dir);
    EXPECT_EQ(bad.exit_code, 2) << flags << "\n" << bad.err;
    EXPECT_NE(bad.err.find(says), std::string::npos) << flags << "\n" << bad.err;
    EXPECT_FALSE(std::filesystem::exists(dir / "bad.png")) << flags;
  }
}

}  // namespace
}  // namespace hpose

namespace hpose {
namespace {

// Below the threshold the reported candidates are real poses with their exact scores, never an
// invented pose at the origin carrying the search's bound (PCL's five-people Kinect frame: no
// humanoid in it).
TEST(EstimateBelowThresholdTest, CandidatesAreRealEvaluatedPoses) {
  const std::string cloud = std::string(HPOSE_SHARED_DATA_DIR) + "/kinect/five_people.pcd";
  if (!std::filesystem::exists(cloud)) GTEST_SKIP() << "shared data absent: " << cloud;
  const TempDir dir("below_threshold");
  const CliRun run = RunHpose("estimate --cloud '" + cloud + "' --json", dir);
  ASSERT_EQ(run.exit_code, 3) << run.err;  // no humanoid.
  const nlohmann::json j = nlohmann::json::parse(run.out);
  const nlohmann::json& cands = j["depth_template"]["candidates"];
  ASSERT_FALSE(cands.empty());
  for (const nlohmann::json& c : cands) {
    const double x = c["pose"]["x"], y = c["pose"]["y"], theta = c["pose"]["theta"];
    EXPECT_FALSE(x == 0.0 && y == 0.0 && theta == 0.0) << c.dump();
    EXPECT_GT(c["poses_evaluated"].get<long long>(), 0) << c.dump();
    // Stopped below the threshold, or (a far cluster searched on below it, as nothing passed)
    // its optimum, below the threshold too.
    if (!c["stopped_below_threshold"].get<bool>()) {
      EXPECT_EQ(c["score"].get<double>(), c["score_upper_bound"].get<double>()) << c.dump();
    }
    EXPECT_LE(c["score"].get<double>(), c["score_upper_bound"].get<double>() + 1e-9);
    EXPECT_LT(c["score_upper_bound"].get<double>(), 50.0);  // the default threshold.
    // The pose lies at the cluster it was searched on (within a template's reach).
    const nlohmann::json& cl = j["depth_template"]["clusters"][c["cluster_index"].get<int>()];
    EXPECT_LT(
        std::hypot(x - cl["centroid"]["x"].get<double>(), y - cl["centroid"]["y"].get<double>()),
        0.6)
        << c.dump();
  }
}

}  // namespace
}  // namespace hpose
