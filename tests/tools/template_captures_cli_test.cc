// End-to-end tests of `hpose simulate turntable` and `hpose template from-captures`.
#include <cmath>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/templates/template_io.h"
#include "tests/sanitizer_build.h"
#include "tests/tools/cli_test_util.h"

namespace hpose {
namespace {

using testing::CliRun;
using testing::RunHpose;
using testing::Slurp;
using testing::TempDir;

Eigen::Vector3d Vec(const nlohmann::json& a) {
  return Eigen::Vector3d(a[0].get<double>(), a[1].get<double>(), a[2].get<double>());
}

TEST(TemplateCapturesCliTest, TurntableCapturesGiveATemplateAndAReport) {
  HPOSE_SKIP_IF_SANITIZED();  // the same registration and template work as CaptureTemplateTest.
  TempDir dir("captures_cli_turntable");
  const std::string captures = dir / "tt";
  const CliRun sim = RunHpose("simulate turntable --out '" + captures +
                                  "' --views 12 --step-deg 30 --axis-x 1.32 --axis-y 0.07 "
                                  "--robot-offset 0.04,0.02 --clutter 2 --seed 4",
                              dir);
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  const nlohmann::json truth = nlohmann::json::parse(Slurp(captures + "/truth.json"));
  ASSERT_EQ(truth["views"].size(), 12u);
  EXPECT_DOUBLE_EQ(truth["axis_ground"]["x"].get<double>(), 1.32);

  const std::string bt = dir / "robot.bt";
  const std::string report_path = dir / "report.json";
  const CliRun run = RunHpose("template from-captures '" + captures +
                                  "' --turntable --step-deg 30 --table-height 0.02 --name robot "
                                  "--out '" +
                                  bt + "' --report '" + report_path + "'",
                              dir);
  ASSERT_EQ(run.exit_code, 0) << run.err << run.out;
  EXPECT_NE(run.out.find("depth_011.png"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("not observable"), std::string::npos) << run.out;
  const Result<VoxelTemplate> tpl = LoadTemplate(bt);
  ASSERT_TRUE(tpl.ok()) << tpl.error().ToString();
  EXPECT_EQ(tpl->name, "robot");
  EXPECT_NEAR(tpl->Height(), truth["humanoid_height_m"].get<double>(), 0.02);

  const nlohmann::json report = nlohmann::json::parse(Slurp(report_path));
  EXPECT_EQ(report["motion"], "turntable");
  ASSERT_EQ(report["views"].size(), 12u);
  for (const nlohmann::json& v : report["views"]) {
    EXPECT_TRUE(v["fits"].get<bool>()) << v.dump();
    EXPECT_LT(v["rms_m"].get<double>(), 0.006);
  }
  EXPECT_GE(report["unobservable"].size(), 1u);
  EXPECT_NE(report["unobservable"][0].get<std::string>().find("along the turntable axis"),
            std::string::npos);
  // The axis in the sensor frame against the truth: where each meets the floor, and direction.
  const Eigen::Vector3d p = Vec(report["axis"]["sensor"]["point_on_floor"]);
  const Eigen::Vector3d p_true = Vec(truth["axis_sensor"]["point_on_floor"]);
  const Eigen::Vector3d d = Vec(report["axis"]["sensor"]["direction"]);
  const Eigen::Vector3d d_true = Vec(truth["axis_sensor"]["direction"]);
  const Eigen::Vector3d gap = p - p_true;
  EXPECT_LT((gap - gap.dot(d_true) * d_true).norm(), 0.005);  // across the axis.
  EXPECT_LT(std::acos(std::min(1.0, d.dot(d_true))), 0.5 * M_PI / 180.0);
}

TEST(TemplateCapturesCliTest, EmptyDirectoryIsAClearError) {
  TempDir dir("captures_cli_empty");
  std::filesystem::create_directories(dir / "nothing");
  const CliRun run = RunHpose("template from-captures '" + (dir / "nothing") +
                                  "' --turntable --name r --out '" + (dir / "r.bt") + "'",
                              dir);
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("holds no captures"), std::string::npos) << run.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "r.bt"));
}

TEST(TemplateCapturesCliTest, BadInputsAreNamed) {
  TempDir dir("captures_cli_bad");
  std::ofstream(dir / "notes.txt") << "hello";
  CliRun run = RunHpose("template from-captures '" + (dir / "notes.txt") +
                            "' --turntable --name r --out '" + (dir / "r.bt") + "'",
                        dir);
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("notes.txt"), std::string::npos) << run.err;

  // A depth PNG without intrinsics beside it.
  const CliRun sim = RunHpose("simulate turntable --out '" + (dir / "tt") +
                                  "' --views 2 --step-deg 90 --width 160 --height 120",
                              dir);
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  std::filesystem::remove(dir / "tt/intrinsics.json");
  run = RunHpose("template from-captures '" + (dir / "tt") + "' --turntable --name r --out '" +
                     (dir / "r.bt") + "'",
                 dir);
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("intrinsics"), std::string::npos) << run.err;

  // Usage: the motion must be said, and angles must match the captures.
  run = RunHpose(
      "template from-captures '" + (dir / "tt") + "' --name r --out '" + (dir / "r.bt") + "'", dir);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("--turntable or --headings-deg"), std::string::npos) << run.err;
  run = RunHpose("template from-captures '" + (dir / "tt") +
                     "' --headings-deg 0,90,180 --name r --out '" + (dir / "r.bt") + "'",
                 dir);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("3 angles for 2 captures"), std::string::npos) << run.err;
  // Angles no turn can have: a table that never turned, a heading of 1e300 degrees.
  run = RunHpose("template from-captures '" + (dir / "tt") +
                     "' --turntable --step-deg 0 --name r --out '" + (dir / "r.bt") + "'",
                 dir);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("--step-deg must be a turn"), std::string::npos) << run.err;
  run = RunHpose("template from-captures '" + (dir / "tt") +
                     "' --headings-deg 0,1e300 --name r --out '" + (dir / "r.bt") + "'",
                 dir);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("within +-3600"), std::string::npos) << run.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "r.bt"));
  // Turntable captures from a sensor no room holds are refused by the flag, as simulate's.
  for (const std::string flag : {"--sensor-height -1e9", "--pitch-deg 1e9", "--roll-deg 60"}) {
    run = RunHpose("simulate turntable --out '" + (dir / "odd") + "' --views 2 " + flag, dir);
    EXPECT_EQ(run.exit_code, 2) << flag << "\n" << run.err;
    EXPECT_NE(run.err.find(flag.substr(0, flag.find(' ')) + " must be within ["), std::string::npos)
        << flag << "\n"
        << run.err;
    EXPECT_FALSE(std::filesystem::exists(dir / "odd")) << flag;
  }
}

TEST(TemplateCapturesCliTest, HelpExplainsTheFrameAndWhatIsNotObservable) {
  TempDir dir("captures_cli_help");
  const CliRun run = RunHpose("template from-captures --help", dir);
  EXPECT_EQ(run.exit_code, 0);
  EXPECT_NE(run.out.find("translation along it"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("--front-view"), std::string::npos);
  EXPECT_NE(run.out.find("--drop-bad-views"), std::string::npos);
  const CliRun sim = RunHpose("simulate turntable --help", dir);
  EXPECT_EQ(sim.exit_code, 0);
  EXPECT_NE(sim.out.find("--axis-x"), std::string::npos);
}

}  // namespace
}  // namespace hpose
