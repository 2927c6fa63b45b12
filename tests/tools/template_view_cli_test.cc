// End-to-end tests of `hpose template show` and `hpose template info --json`.
#include <filesystem>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/tools/cli_test_util.h"

namespace hpose {
namespace {

using testing::CliRun;
using testing::RunHpose;
using testing::Slurp;
using testing::TempDir;

const std::string kTemplates = std::string(HPOSE_SOURCE_DIR) + "/templates/";

TEST(TemplateViewCliTest, InfoJsonGivesSizesAndAsymmetry) {
  TempDir dir("template_view_info");
  const CliRun standing = RunHpose("template info --json '" + kTemplates + "standing.bt'", dir);
  ASSERT_EQ(standing.exit_code, 0) << standing.err;
  const nlohmann::json s = nlohmann::json::parse(standing.out);
  EXPECT_EQ(s.at("name"), "standing");
  EXPECT_GT(s.at("voxels").get<int>(), 1000);
  EXPECT_NEAR(s.at("height_m").get<double>(), 0.59, 0.03);
  EXPECT_GT(s.at("width_y_m").get<double>(), s.at("width_x_m").get<double>());
  // The standing humanoid is left/right symmetric; its battery pack tells back from front.
  EXPECT_LT(s.at("mirror_difference").get<double>(), 0.02);
  EXPECT_GT(s.at("front_back_difference").get<double>(), 0.05);
  const CliRun arm = RunHpose("template info --json '" + kTemplates + "right_arm_raised.bt'", dir);
  ASSERT_EQ(arm.exit_code, 0) << arm.err;
  const nlohmann::json a = nlohmann::json::parse(arm.out);
  EXPECT_GT(a.at("mirror_difference").get<double>(), 0.1);
  const CliRun text = RunHpose("template info '" + kTemplates + "standing.bt'", dir);
  EXPECT_NE(text.out.find("asymmetry:"), std::string::npos);
  EXPECT_NE(text.out.find("widths:"), std::string::npos);
  // A shipped template by its name is the same file; a name that is none says which are.
  const CliRun named = RunHpose("template info --json standing", dir);
  ASSERT_EQ(named.exit_code, 0) << named.err;
  const nlohmann::json n = nlohmann::json::parse(named.out);
  EXPECT_EQ(n.at("voxels"), s.at("voxels"));
  EXPECT_EQ(n.at("height_m"), s.at("height_m"));
  const CliRun unknown = RunHpose("template info standng", dir);
  EXPECT_EQ(unknown.exit_code, 1);
  EXPECT_NE(
      unknown.err.find("'standng' is no shipped template (those are arms_swung, right_arm_raised, "
                       "standing, in "),
      std::string::npos)
      << unknown.err;
  EXPECT_NE(unknown.err.find("); did you mean 'standing'? Or give a template file by its path"),
            std::string::npos)
      << unknown.err;
  // A name like none of them gets no suggestion.
  const CliRun other = RunHpose("template info sitting_down", dir);
  EXPECT_EQ(other.exit_code, 1);
  EXPECT_NE(other.err.find("); give a template file by its path, FILE.bt"), std::string::npos)
      << other.err;
}

TEST(TemplateViewCliTest, ShowWritesAPicture) {
  TempDir dir("template_view_show");
  const std::string png = dir / "standing.png";
  const CliRun run =
      RunHpose("template show '" + kTemplates + "standing.bt' --picture '" + png + "'", dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const std::string bytes = Slurp(png);
  ASSERT_GT(bytes.size(), 8000u);
  EXPECT_EQ(bytes.substr(1, 3), "PNG");
  const CliRun missing = RunHpose("template show '" + kTemplates + "standing.bt'", dir);
  EXPECT_EQ(missing.exit_code, 2);
  const CliRun absent =
      RunHpose("template show '" + (dir / "none.bt") + "' --picture '" + png + "'", dir);
  EXPECT_EQ(absent.exit_code, 1);
}

}  // namespace
}  // namespace hpose
