// `hpose plot` on what `hpose replay` writes, and on input it cannot draw.
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/tools/cli_test_util.h"

namespace hpose {
namespace {

using testing::CliRun;
using testing::RunHpose;
using testing::Slurp;
using testing::TempDir;

// Width and height of a PNG from its IHDR chunk (big-endian, from byte 16); 0, 0 if not a PNG.
std::pair<int, int> PngSize(const std::string& path) {
  const std::string head = Slurp(path).substr(0, 24);
  if (head.size() < 24 || head.substr(1, 3) != "PNG") return {0, 0};
  const auto be32 = [&](int at) {
    int v = 0;
    for (int i = 0; i < 4; ++i) v = (v << 8) | static_cast<unsigned char>(head[at + i]);
    return v;
  };
  return {be32(16), be32(20)};
}

// Four frames of a robot turning and stepping 1.4 m away, in DIR/walk (with its truth.json).
CliRun SimulateWalk(const TempDir& dir) {
  return RunHpose("simulate --out '" + (dir / "walk") +
                      "' --frames 4 --x 1.4 --turn-deg 20 --step-m 0.05 --width 320 --height "
                      "240 --no-cloud",
                  dir);
}

TEST(PlotCliTest, DrawsWhatReplayWrote) {
  TempDir dir("plot_cli");
  const CliRun sim = SimulateWalk(dir);
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  const std::string poses = dir / "walk.jsonl";
  const CliRun replay =
      RunHpose("replay '" + (dir / "walk") + "' --no-progress --out '" + poses + "'", dir);
  ASSERT_EQ(replay.exit_code, 0) << replay.err;
  int humanoids = 0;
  std::istringstream lines(Slurp(poses));
  for (std::string line; std::getline(lines, line);) {
    const nlohmann::json e = nlohmann::json::parse(line);
    humanoids += e["depth_template"]["best"]["is_humanoid"].get<bool>() ? 1 : 0;
  }
  ASSERT_GT(humanoids, 0);

  const CliRun plot = RunHpose("plot '" + poses + "' --out '" + (dir / "t.png") + "'", dir);
  ASSERT_EQ(plot.exit_code, 0) << plot.err;
  EXPECT_NE(plot.out.find("drew 4 estimates (humanoid in " + std::to_string(humanoids) + ")"),
            std::string::npos)
      << plot.out;
  EXPECT_EQ(PngSize(dir / "t.png"), std::make_pair(1280, 720));
  // From standard input, as a stream's lines would come.
  const CliRun piped =
      RunHpose("plot - --title 'a walk' --out '" + (dir / "s.png") + "' < '" + poses + "'", dir);
  ASSERT_EQ(piped.exit_code, 0) << piped.err;
  EXPECT_EQ(PngSize(dir / "s.png"), std::make_pair(1280, 720));
}

TEST(PlotCliTest, DrawsASimulationsTruthAndSaysTheErrors) {
  TempDir dir("plot_cli_truth");
  const CliRun sim = SimulateWalk(dir);
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  const std::string poses = dir / "walk.jsonl";
  const std::string truth = dir / "walk/truth.json";
  const CliRun replay = RunHpose(
      "replay '" + (dir / "walk") + "' --no-progress --truth '" + truth + "' --out '" + poses + "'",
      dir);
  ASSERT_EQ(replay.exit_code, 0) << replay.err;
  // The replay's summary of the errors and the plot's are one and the same.
  const std::string against = "against " + truth + ": ";
  const std::size_t line = replay.err.find(against);
  ASSERT_NE(line, std::string::npos) << replay.err;
  const std::size_t from = line + against.size();
  const std::string summary = replay.err.substr(from, replay.err.find('\n', from) - from);
  EXPECT_NE(summary.find("humanoid found in 4 of 4 frame(s)"), std::string::npos) << summary;

  const CliRun plot =
      RunHpose("plot '" + poses + "' --truth '" + truth + "' --out '" + (dir / "t.png") + "'", dir);
  ASSERT_EQ(plot.exit_code, 0) << plot.err;
  EXPECT_NE(plot.out.find(against + summary + "\n"), std::string::npos)
      << plot.out << "\nreplay said: " << summary;
  EXPECT_EQ(PngSize(dir / "t.png"), std::make_pair(1280, 720));

  // A line whose frame the truth does not name is drawn, and counted apart.
  std::string lines = Slurp(poses);
  const std::size_t at = lines.find("depth_000.png");
  ASSERT_NE(at, std::string::npos);
  std::string renamed = lines;
  renamed.replace(at, 13, "other_000.png");
  std::ofstream(dir / "renamed.jsonl") << renamed;
  const CliRun partly = RunHpose("plot '" + (dir / "renamed.jsonl") + "' --truth '" + truth +
                                     "' --out '" + (dir / "r.png") + "'",
                                 dir);
  ASSERT_EQ(partly.exit_code, 0) << partly.err;
  EXPECT_NE(partly.out.find("of 3 frame(s)"), std::string::npos) << partly.out;
  EXPECT_NE(partly.out.find("; 1 estimate(s) not in it"), std::string::npos) << partly.out;

  // A truth of other frames, and no truth at all, are errors that name the file; nothing drawn.
  std::string others = Slurp(truth);
  for (std::size_t p = 0; (p = others.find("depth_", p)) != std::string::npos;) {
    others.replace(p, 6, "frame_");
  }
  std::ofstream(dir / "others.json") << others;
  const CliRun unmatched = RunHpose("plot '" + poses + "' --truth '" + (dir / "others.json") +
                                        "' --out '" + (dir / "u.png") + "'",
                                    dir);
  EXPECT_EQ(unmatched.exit_code, 1);
  EXPECT_NE(unmatched.err.find("others.json: names none of walk.jsonl's frames"), std::string::npos)
      << unmatched.err;
  const CliRun missing = RunHpose(
      "plot '" + poses + "' --truth '" + (dir / "none.json") + "' --out '" + (dir / "m.png") + "'",
      dir);
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.err.find("none.json"), std::string::npos) << missing.err;
  std::ofstream(dir / "broken.json") << "{\"format\": \"hpose-sim-truth\"";
  const CliRun broken = RunHpose("plot '" + poses + "' --truth '" + (dir / "broken.json") +
                                     "' --out '" + (dir / "b.png") + "'",
                                 dir);
  EXPECT_EQ(broken.exit_code, 1);
  EXPECT_NE(broken.err.find("broken.json"), std::string::npos) << broken.err;
  for (const char* png : {"u.png", "m.png", "b.png"}) {
    EXPECT_FALSE(std::ifstream(dir / png).good()) << png;
  }
}

TEST(PlotCliTest, InputItCannotDrawIsNamed) {
  TempDir dir("plot_cli_bad");
  const auto plot = [&](const std::string& content) {
    std::ofstream(dir / "in.jsonl") << content;
    return RunHpose("plot '" + (dir / "in.jsonl") + "' --out '" + (dir / "x.png") + "'", dir);
  };
  const CliRun broken = plot("{\"estimator\": \"ESTIMATOR_KIND_DEPTH_TEMPLATE\"}\n{\"a\": 1\n");
  EXPECT_EQ(broken.exit_code, 1);
  EXPECT_NE(broken.err.find("in.jsonl: line 2 is not a PoseEstimate"), std::string::npos)
      << broken.err;
  const CliRun stereo = plot("{\"estimator\": \"ESTIMATOR_KIND_STEREO_MARKER\"}\n");
  EXPECT_EQ(stereo.exit_code, 1);
  EXPECT_NE(stereo.err.find("no depth estimates (1 lines, 1 of another estimator)"),
            std::string::npos)
      << stereo.err;
  const CliRun wrong_type =
      plot("{\"estimator\": \"ESTIMATOR_KIND_DEPTH_TEMPLATE\", \"source_time\": \"soon\"}\n");
  EXPECT_EQ(wrong_type.exit_code, 1);
  EXPECT_NE(wrong_type.err.find("line 1"), std::string::npos) << wrong_type.err;
  const CliRun far = plot(
      "{\"estimator\": \"ESTIMATOR_KIND_DEPTH_TEMPLATE\", \"source_time\": 1.0, "
      "\"depth_template\": {\"best\": {\"is_humanoid\": true, \"best\": "
      "{\"pose\": {\"x\": 1e300, \"y\": 0, \"theta\": 0}}}}}\n");
  EXPECT_EQ(far.exit_code, 1);
  EXPECT_NE(far.err.find("line 1 has a time beyond 1e11 s or a pose beyond 10 km"),
            std::string::npos)
      << far.err;
  EXPECT_FALSE(std::ifstream(dir / "x.png").good());  // nothing written by a failed plot.
  // Frames without a humanoid (or that failed) are drawn as such.
  const CliRun none = plot(
      "{\"estimator\": \"ESTIMATOR_KIND_DEPTH_TEMPLATE\", \"source_time\": 1.0, "
      "\"depth_template\": null}\n");
  EXPECT_EQ(none.exit_code, 0) << none.err;
  EXPECT_NE(none.out.find("drew 1 estimates (humanoid in 0)"), std::string::npos) << none.out;
  EXPECT_EQ(RunHpose("plot '" + (dir / "in.jsonl") + "'", dir).exit_code, 2);  // no --out.
  EXPECT_EQ(RunHpose("plot '" + (dir / "none.jsonl") + "' --out '" + (dir / "y.png") + "'", dir)
                .exit_code,
            1);
}

}  // namespace
}  // namespace hpose
