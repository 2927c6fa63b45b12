// The `hpose` front end: help and flag errors without the command programs, and every command
// handed to its own program `hpose-COMMAND` with the same flags.
#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "tests/tools/cli_test_util.h"

namespace hpose::testing {
namespace {

const std::string kToolsDir = std::string(HPOSE_BINARY_DIR) + "/tools";

// The command names listed by `hpose --help` (the lines under "commands:").
std::vector<std::string> ListedCommands(const std::string& help) {
  std::vector<std::string> names;
  std::istringstream lines(help);
  std::string line;
  bool in_list = false;
  while (std::getline(lines, line)) {
    if (line == "commands:") {
      in_list = true;
    } else if (in_list && line.empty()) {
      break;
    } else if (in_list) {
      std::istringstream words(line);
      std::string name;
      words >> name;
      names.push_back(name);
    }
  }
  return names;
}

TEST(FrontEndCliTest, HelpAndFlagErrorsNeedNoCommandProgram) {
  TempDir dir("front_end_alone");
  const std::string alone = dir / "hpose";
  std::filesystem::copy_file(kToolsDir + "/hpose", alone);

  CliRun help = RunProgram(alone, "estimate --help", dir);
  EXPECT_EQ(help.exit_code, 0) << help.err;
  EXPECT_NE(help.out.find("usage: hpose estimate"), std::string::npos) << help.out;
  EXPECT_NE(help.out.find("--floor-height"), std::string::npos) << help.out;

  CliRun sub_help = RunProgram(alone, "template from-urdf --help", dir);
  EXPECT_EQ(sub_help.exit_code, 0) << sub_help.err;
  EXPECT_NE(sub_help.out.find("--joint-set"), std::string::npos) << sub_help.out;

  CliRun bad = RunProgram(alone, "estimate --no-such-flag", dir);
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("unknown flag --no-such-flag"), std::string::npos) << bad.err;
  EXPECT_EQ(bad.err.find("did you mean"), std::string::npos) << bad.err;

  // A slip of the keyboard gets the name meant, for commands and flags alike.
  CliRun slip = RunProgram(alone, "estmate", dir);
  EXPECT_EQ(slip.exit_code, 2);
  EXPECT_NE(slip.err.find("unknown command 'estmate' (did you mean 'estimate'?)"),
            std::string::npos)
      << slip.err;
  slip = RunProgram(alone, "template from-urfd robot.urdf", dir);
  EXPECT_EQ(slip.exit_code, 2);
  EXPECT_NE(slip.err.find("unknown subcommand 'from-urfd' (did you mean 'from-urdf'?)"),
            std::string::npos)
      << slip.err;
  slip = RunProgram(alone, "estimate --tempalte standing", dir);
  EXPECT_EQ(slip.exit_code, 2);
  EXPECT_NE(slip.err.find("unknown flag --tempalte (did you mean '--template'?)"),
            std::string::npos)
      << slip.err;

  // Accepted flags need the command's program: without it, a clear error naming it.
  CliRun missing = RunProgram(alone, "estimate --depth frame.png", dir);
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.err.find("hpose-estimate"), std::string::npos) << missing.err;
  EXPECT_NE(missing.err.find("cannot start"), std::string::npos) << missing.err;
}

// What makes the help instant: the front end records no heavy library. It holds the commands'
// flags (tools/cmd_*_flags.h) and none of their work, whatever the build's optimisation.
TEST(FrontEndCliTest, FrontEndLinksNoHeavyLibrary) {
  TempDir dir("front_end_needed");
  const CliRun needed = RunProgram("readelf", "-d '" + kToolsDir + "/hpose'", dir);
  if (needed.exit_code == 127) GTEST_SKIP() << "readelf (binutils) not installed";
  ASSERT_EQ(needed.exit_code, 0) << needed.err;
  ASSERT_NE(needed.out.find("(NEEDED)"), std::string::npos) << needed.out;
  for (const char* heavy :
       {"pcl", "opencv", "vtk", "grpc", "protobuf", "OpenNI", "octo", "assimp", "urdf", "yaml"}) {
    EXPECT_EQ(needed.out.find(heavy), std::string::npos) << heavy << " in\n" << needed.out;
  }
}

// What keeps every program quick to start: depth frames, colour images, pictures and clouds
// are read and written with libpng, libjpeg, libtiff and hpose's own readers, so neither a
// command's program nor the daemon loads OpenCV's image codecs (GDAL and ~100 more) or PCL's io
// (VTK), not even through another library (ldd lists every library loaded). Nor does a program
// load PCL's segmentation or features for the k-d tree they also export (core/CMakeLists.txt):
// with them `hpose template` took about 0.1 s to start.
TEST(FrontEndCliTest, ProgramsLoadNoImageCodecsNorPclIo) {
  TempDir dir("front_end_programs_loaded");
  std::vector<std::string> programs;
  for (const char* command : {"estimate", "replay", "record", "demo", "simulate", "template",
                              "estimate-stereo", "simulate-stereo", "calibrate", "query", "plot"}) {
    programs.push_back(kToolsDir + "/hpose-" + command);
  }
  programs.push_back(std::string(HPOSE_BINARY_DIR) + "/server/hposed");
  for (const std::string& program : programs) {
    const CliRun loaded = RunProgram("ldd", "'" + program + "'", dir);
    if (loaded.exit_code == 127) GTEST_SKIP() << "ldd not installed";
    ASSERT_EQ(loaded.exit_code, 0) << program << ": " << loaded.err;
    ASSERT_NE(loaded.out.find("libc.so"), std::string::npos) << loaded.out;
    for (const char* heavy : {"libopencv_imgcodecs", "libpcl_io", "libvtk", "libgdal",
                              "libpcl_segmentation", "libpcl_features"}) {
      EXPECT_EQ(loaded.out.find(heavy), std::string::npos) << program << " loads " << heavy << ":\n"
                                                           << loaded.out;
    }
  }
}

// Programs whose work touches no image load no OpenCV at all: `hpose query` prints the stereo
// estimator's results by the names of its enums, not with the estimator (core/stereo/
// stereo_names.cc), and recording and replay move depth frames as they are. Programs that draw
// pictures load it only when they draw one: the drawing is in the module hpose-drawing.so
// (tools/canvas.h), which alone records OpenCV's core and imgproc.
TEST(FrontEndCliTest, ProgramsWithoutImageWorkLoadNoOpenCv) {
  TempDir dir("front_end_no_opencv");
  for (const char* command :
       {"query", "record", "replay", "estimate", "demo", "template", "plot"}) {
    const std::string program = kToolsDir + "/hpose-" + command;
    const CliRun loaded = RunProgram("ldd", "'" + program + "'", dir);
    if (loaded.exit_code == 127) GTEST_SKIP() << "ldd not installed";
    ASSERT_EQ(loaded.exit_code, 0) << program << ": " << loaded.err;
    ASSERT_NE(loaded.out.find("libc.so"), std::string::npos) << loaded.out;
    EXPECT_EQ(loaded.out.find("libopencv"), std::string::npos) << program << " loads OpenCV:\n"
                                                               << loaded.out;
  }
}

TEST(FrontEndCliTest, TheDrawingModuleAloneLoadsOpenCvsDrawing) {
  TempDir dir("front_end_drawing_module");
  const std::string module = kToolsDir + "/hpose-drawing.so";
  const CliRun loaded = RunProgram("ldd", "'" + module + "'", dir);
  if (loaded.exit_code == 127) GTEST_SKIP() << "ldd not installed";
  ASSERT_EQ(loaded.exit_code, 0) << module << ": " << loaded.err;
  EXPECT_NE(loaded.out.find("libopencv_imgproc"), std::string::npos) << loaded.out;
  EXPECT_EQ(loaded.out.find("libopencv_imgcodecs"), std::string::npos) << loaded.out;
  EXPECT_EQ(loaded.out.find("libhpose"), std::string::npos) << loaded.out;
}

TEST(FrontEndCliTest, EveryCommandHasAProgramWithTheSameFlags) {
  TempDir dir("front_end_programs");
  const CliRun top = RunHpose("--help", dir);
  ASSERT_EQ(top.exit_code, 0);
  const std::vector<std::string> commands = ListedCommands(top.out);
  ASSERT_GE(commands.size(), 10u) << top.out;
  // The environment variables the commands read are listed after them.
  for (const char* variable :
       {"HPOSE_TEMPLATE_DIR", "HPOSE_DRAWING_MODULE", "HPOSE_VECTOR_LEVEL"}) {
    EXPECT_NE(top.out.find(std::string("\n  ") + variable + " "), std::string::npos) << variable;
  }
  for (const std::string& c : commands) {
    SCOPED_TRACE(c);
    const CliRun front = RunHpose(c + " --help", dir);
    EXPECT_EQ(front.exit_code, 0) << front.err;
    // The command's program prints the same help from the same flag declarations.
    const CliRun program = RunProgram(kToolsDir + "/hpose-" + c, c + " --help", dir);
    EXPECT_EQ(program.exit_code, 0) << program.err;
    EXPECT_EQ(program.out, front.out);
    // Run alone, it says how to run it.
    const CliRun direct = RunProgram(kToolsDir + "/hpose-" + c, "--help", dir);
    EXPECT_EQ(direct.exit_code, 2);
    EXPECT_NE(direct.err.find("hpose " + c), std::string::npos) << direct.err;
  }
}

// hpose query names the command it did not know before trying to reach a daemon (none runs at
// this address).
TEST(FrontEndCliTest, QueryNamesTheCommandMeant) {
  TempDir dir("front_end_query");
  const CliRun run =
      RunProgram(kToolsDir + "/hpose", "query sttus --server 127.0.0.1:1 --timeout 30", dir);
  EXPECT_EQ(run.exit_code, 2) << run.err;
  EXPECT_NE(run.err.find("hpose query: unknown command 'sttus' (did you mean 'status'?)"),
            std::string::npos)
      << run.err;
  EXPECT_EQ(run.err.find("unavailable"), std::string::npos) << run.err;
}

}  // namespace
}  // namespace hpose::testing
