// End-to-end tests of the URDF robot paths of the CLI: `hpose template from-urdf` and
// `hpose simulate --robot`, and the estimator finding a robot in its own simulated frames.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/io/atomic_file.h"
#include "core/sim/sim_truth.h"
#include "core/templates/template_io.h"
#include "tests/tools/cli_test_util.h"

namespace hpose {
namespace {

using testing::CliRun;
using testing::RunHpose;
using testing::TempDir;

const std::string kDarwinUrdf =
    std::string(HPOSE_SHARED_DATA_DIR) + "/darwin_op/robots/robotis_op.urdf";

#define SKIP_WITHOUT_DARWIN()                                             \
  if (!std::filesystem::exists(kDarwinUrdf)) {                            \
    GTEST_SKIP() << "shared Darwin-OP data not found at " << kDarwinUrdf; \
  }

TEST(RobotCliTest, FromUrdfMissingMeshIsAnErrorUnlessAllowed) {
  SKIP_WITHOUT_DARWIN();
  TempDir dir("robot_cli_missing");
  const CliRun fail =
      RunHpose("template from-urdf '" + kDarwinUrdf + "' --out '" + (dir / "d.bt") + "'", dir);
  EXPECT_EQ(fail.exit_code, 1);
  EXPECT_NE(fail.err.find("MP_HEAD"), std::string::npos) << fail.err;
  EXPECT_NE(fail.err.find("head.STL"), std::string::npos) << fail.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "d.bt"));

  const CliRun ok = RunHpose(
      "template from-urdf '" + kDarwinUrdf + "' --allow-missing --out '" + (dir / "d.bt") + "'",
      dir);
  ASSERT_EQ(ok.exit_code, 0) << ok.err;
  EXPECT_NE(ok.err.find("warning: link 'MP_HEAD'"), std::string::npos) << ok.err;
  Result<VoxelTemplate> tpl = LoadTemplate(dir / "d.bt");
  ASSERT_TRUE(tpl.ok()) << tpl.error().message;
  EXPECT_GT(tpl->voxels.size(), 500u);
  float min_z = 1e9f;
  for (const Eigen::Vector3f& v : tpl->voxels) min_z = std::min(min_z, v.z());
  EXPECT_NEAR(min_z, 0.008, 1e-4);  // feet on the floor: the lowest voxels are the first layer
  EXPECT_GT(tpl->Height(), 0.35);
  EXPECT_LT(tpl->Height(), 0.45);
}

TEST(RobotCliTest, FromUrdfMakesOneTemplatePerJointSet) {
  SKIP_WITHOUT_DARWIN();
  TempDir dir("robot_cli_sets");
  {
    std::ofstream yaml(dir / "poses.yaml");
    yaml << "standing: {}\n"
            "right_arm_raised: {j_shoulder_r: -2.5}\n"
            "mid_step: {j_thigh1_l: 0.0, j_thigh2_l: 0.5, j_tibia_l: -1.0, j_ankle1_l: 0.5}\n";
  }
  const CliRun run =
      RunHpose("template from-urdf '" + kDarwinUrdf + "' --geometry collision --joints '" +
                   (dir / "poses.yaml") + "' --out '" + (dir / "out") + "'",
               dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  // The arms and the head are free limbs, the legs (a foot lifted or not) are not.
  EXPECT_NE(run.out.find("free limbs (fitted without them where they moved): j_pan, j_shoulder_l, "
                         "j_shoulder_r;"),
            std::string::npos)
      << run.out;
  size_t sizes[3] = {0, 0, 0};
  int i = 0;
  for (const char* name : {"standing", "right_arm_raised", "mid_step"}) {
    Result<VoxelTemplate> tpl = LoadTemplate(dir / ("out/" + std::string(name) + ".bt"));
    ASSERT_TRUE(tpl.ok()) << name << ": " << tpl.error().message;
    EXPECT_EQ(tpl->name, name);
    sizes[i++] = tpl->voxels.size();
    ASSERT_EQ(tpl->free_limb.size(), tpl->surface.size());
    const long marked = std::count(tpl->free_limb.begin(), tpl->free_limb.end(), 1);
    EXPECT_GT(marked, static_cast<long>(tpl->surface.size()) / 10) << name;
    EXPECT_LT(marked, static_cast<long>(tpl->surface.size()) / 2) << name;
  }
  const CliRun info = RunHpose("template info '" + (dir / "out/standing.bt") + "'", dir);
  ASSERT_EQ(info.exit_code, 0) << info.err;
  EXPECT_NE(info.out.find("on free limbs (arms, head"), std::string::npos) << info.out;
  EXPECT_NE(sizes[0], sizes[1]);
  EXPECT_NE(sizes[0], sizes[2]);

  // Unknown joints are an error naming them; so is a --joint-set the file does not have.
  const CliRun bad =
      RunHpose("template from-urdf '" + kDarwinUrdf +
                   "' --geometry collision --joint j_elbow_x=0.2 --out '" + (dir / "x.bt") + "'",
               dir);
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.err.find("'j_elbow_x'"), std::string::npos) << bad.err;
  const CliRun no_set =
      RunHpose("template from-urdf '" + kDarwinUrdf + "' --geometry collision --joints '" +
                   (dir / "poses.yaml") + "' --joint-set sitting --out '" + (dir / "y") + "'",
               dir);
  EXPECT_NE(no_set.exit_code, 0);
  EXPECT_NE(no_set.err.find("sitting"), std::string::npos) << no_set.err;
}

TEST(RobotCliTest, FromUrdfRejectsBadFiles) {
  TempDir dir("robot_cli_bad");
  {
    std::ofstream garbage(dir / "garbage.urdf");
    garbage << "<robot><link name=";
  }
  const CliRun garbage = RunHpose(
      "template from-urdf '" + (dir / "garbage.urdf") + "' --out '" + (dir / "g.bt") + "'", dir);
  EXPECT_EQ(garbage.exit_code, 1);
  EXPECT_NE(garbage.err.find("garbage.urdf"), std::string::npos) << garbage.err;
  const CliRun missing = RunHpose(
      "template from-urdf '" + (dir / "none.urdf") + "' --out '" + (dir / "g.bt") + "'", dir);
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.err.find("none.urdf"), std::string::npos) << missing.err;

  // A body in millimetres: a clear error (it once aborted on memory), and no file written.
  {
    std::ofstream mm(dir / "mm.urdf");
    mm << "<robot name=\"mm\"><link name=\"base\"><visual><origin xyz=\"0 0 300\"/>"
          "<geometry><box size=\"200 200 600\"/></geometry></visual></link></robot>";
  }
  const CliRun huge = RunHpose(
      "template from-urdf '" + (dir / "mm.urdf") + "' --out '" + (dir / "mm.bt") + "'", dir);
  EXPECT_EQ(huge.exit_code, 1);
  EXPECT_NE(huge.err.find("millimetres"), std::string::npos) << huge.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "mm.bt"));
}

TEST(RobotCliTest, SimulateRobotFramesAreFoundWithTheRobotsTemplate) {
  SKIP_WITHOUT_DARWIN();
  TempDir dir("robot_cli_sim");
  const CliRun tpl = RunHpose("template from-urdf '" + kDarwinUrdf + "' --allow-missing --out '" +
                                  (dir / "darwin.bt") + "'",
                              dir);
  ASSERT_EQ(tpl.exit_code, 0) << tpl.err;
  const CliRun sim =
      RunHpose("simulate --robot '" + kDarwinUrdf + "' --allow-missing --out '" + (dir / "sim") +
                   "' --x 1.4 --y -0.1 --theta-deg 60 --clutter 3 --seed 4 --no-cloud",
               dir);
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  const Result<std::string> truth_text = ReadFile(dir / "sim/truth.json");
  ASSERT_TRUE(truth_text.ok());
  const Result<SimTruth> truth = ParseSimTruthJson(*truth_text, "truth.json");
  ASSERT_TRUE(truth.ok());
  EXPECT_EQ(truth->humanoid_preset, "robotis_op2/default");
  EXPECT_GT(truth->humanoid_height_m, 0.35);

  const CliRun est = RunHpose("estimate --depth '" + (dir / "sim/depth.png") + "' --template '" +
                                  (dir / "darwin.bt") + "' --json",
                              dir);
  ASSERT_EQ(est.exit_code, 0) << est.err;
  const nlohmann::json j = nlohmann::json::parse(est.out);
  const nlohmann::json& detections = j.at("depth_template").at("detections");
  ASSERT_FALSE(detections.empty()) << est.out;
  const nlohmann::json& d = detections[0].at("best").at("pose");
  EXPECT_NEAR(d.at("x").get<double>(), 1.4, 0.03);
  EXPECT_NEAR(d.at("y").get<double>(), -0.1, 0.03);
  EXPECT_NEAR(d.at("theta").get<double>(), 60.0 * M_PI / 180.0, 5.0 * M_PI / 180.0);

  // The parametric humanoid's flags do not mix with --robot.
  const CliRun mixed = RunHpose(
      "simulate --robot '" + kDarwinUrdf + "' --pose standing --out '" + (dir / "m") + "'", dir);
  EXPECT_EQ(mixed.exit_code, 2);
}

// Seen side-on with its far arm raised, the Darwin-OP shows the arm above its shoulder while the
// arm's joint is hidden behind the body: one humanoid, identified by the arm it raises (not a
// standing robot plus a second "humanoid" made of the arm alone).
TEST(RobotCliTest, AFarArmRaisedBehindTheBodyStaysWithIt) {
  SKIP_WITHOUT_DARWIN();
  TempDir dir("robot_cli_far_arm");
  const std::string joints = std::string(HPOSE_SOURCE_DIR) + "/docs/examples/darwin_op_joints.yaml";
  const CliRun tpl = RunHpose(
      "template from-urdf '" + kDarwinUrdf + "' --allow-missing --joints '" + joints +
          "' --joint-set standing --joint-set right_arm_raised --out '" + (dir / "tpl") + "'",
      dir);
  ASSERT_EQ(tpl.exit_code, 0) << tpl.err;
  const CliRun sim =
      RunHpose("simulate --robot '" + kDarwinUrdf + "' --allow-missing --joints '" + joints +
                   "' --joint-set right_arm_raised --out '" + (dir / "sim") +
                   "' --x 1.0 --theta-deg 90 --clutter 3 --seed 1 --no-cloud",
               dir);
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  const CliRun est = RunHpose("estimate --depth '" + (dir / "sim/depth.png") + "' --template '" +
                                  (dir / "tpl/standing.bt") + "' --template '" +
                                  (dir / "tpl/right_arm_raised.bt") + "' --json",
                              dir);
  ASSERT_EQ(est.exit_code, 0) << est.err;
  const nlohmann::json j = nlohmann::json::parse(est.out);
  int near_truth = 0;
  for (const nlohmann::json& d : j.at("depth_template").at("detections")) {
    if (!d.at("is_humanoid").get<bool>()) continue;
    const nlohmann::json& p = d.at("best").at("pose");
    if (std::hypot(p.at("x").get<double>() - 1.0, p.at("y").get<double>()) > 0.3) continue;
    ++near_truth;
    EXPECT_EQ(d.at("best").at("template_name"), "right_arm_raised") << est.out;
    EXPECT_FALSE(d.at("template_ambiguous").get<bool>()) << est.out;
    EXPECT_NEAR(p.at("theta").get<double>(), M_PI / 2.0, 3.0 * M_PI / 180.0);
  }
  EXPECT_EQ(near_truth, 1) << est.out;
}

TEST(RobotCliTest, SimulateRobotWithAJointSet) {
  SKIP_WITHOUT_DARWIN();
  TempDir dir("robot_cli_sim_set");
  {
    std::ofstream yaml(dir / "poses.yaml");
    yaml << "standing: {}\nright_arm_raised: {j_shoulder_r: 1.3}\n";
  }
  const std::string common =
      "simulate --robot '" + kDarwinUrdf +
      "' --geometry collision --no-cloud --width 160 --height 120 --joints '" +
      (dir / "poses.yaml") + "'";
  const CliRun run =
      RunHpose(common + " --joint-set right_arm_raised --out '" + (dir / "s") + "'", dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const Result<SimTruth> truth = ParseSimTruthJson(*ReadFile(dir / "s/truth.json"), "truth");
  ASSERT_TRUE(truth.ok());
  EXPECT_EQ(truth->humanoid_preset, "robotis_op2/right_arm_raised");
  const CliRun unknown = RunHpose(common + " --joint-set sitting --out '" + (dir / "t") + "'", dir);
  EXPECT_EQ(unknown.exit_code, 1);
  EXPECT_NE(unknown.err.find("sitting"), std::string::npos) << unknown.err;
}

TEST(RobotCliTest, SimulateBodyVariant) {
  TempDir dir("robot_cli_body");
  const CliRun run = RunHpose(
      "simulate --body long_legs --no-cloud --width 160 --height 120 --out '" + (dir / "s") + "'",
      dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const Result<SimTruth> truth = ParseSimTruthJson(*ReadFile(dir / "s/truth.json"), "truth");
  ASSERT_TRUE(truth.ok());
  EXPECT_EQ(truth->humanoid_preset, "standing/long_legs");
  EXPECT_GT(truth->humanoid_height_m, 0.7);
  const CliRun bad = RunHpose("simulate --body giraffe --out '" + (dir / "t") + "'", dir);
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("giraffe"), std::string::npos);
}

// `--robot ""` (an unset shell variable) is a usage error, not a quiet run of the default
// humanoid; nothing is drawn or written.
TEST(RobotCliTest, AnEmptyRobotPathIsRefused) {
  TempDir dir("robot_cli_empty");
  const CliRun demo = RunHpose("demo --robot '' --picture '" + (dir / "demo.png") + "'", dir);
  EXPECT_EQ(demo.exit_code, 2);
  EXPECT_NE(demo.err.find("--robot needs a URDF file"), std::string::npos) << demo.err;
  EXPECT_EQ(demo.out, "");
  EXPECT_FALSE(std::filesystem::exists(dir / "demo.png"));
  const CliRun sim = RunHpose("simulate --robot '' --out '" + (dir / "s") + "'", dir);
  EXPECT_EQ(sim.exit_code, 2);
  EXPECT_NE(sim.err.find("--robot needs a URDF file"), std::string::npos) << sim.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "s"));
}

}  // namespace
}  // namespace hpose
