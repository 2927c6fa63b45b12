// Files that used to hang `hpose` or exhaust its memory (headers announcing far more than the
// file holds, a template that expands to trillions of voxels, a FIFO, a huge PNG) and output
// that used to be lost silently (/dev/full, a missing directory). Every case must end with
// exit status 1 and a message naming the problem; each runs under `timeout 5` (times
// kTimeScale in sanitizer builds), so a hang shows up as status 124 instead.
#include <sys/stat.h>

#include <cstdint>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "tests/robot/collada_box.h"
#include "tests/sanitizer_build.h"
#include "tests/tools/cli_test_util.h"

namespace hpose {
namespace {

using testing::CliRun;
using testing::Slurp;
using testing::TempDir;

class HostileFilesCliTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TempDir("hostile_files");
    const CliRun sim = Run("simulate --out '" + (*dir_ / "frame") +
                           "' --width 160 --height 120 --no-cloud > /dev/null");
    ASSERT_EQ(sim.exit_code, 0) << sim.err;
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }

  // Runs `hpose <args>` under `timeout 5` (scaled); `args` may redirect stdout itself (else it is
  // discarded). stderr is captured.
  static CliRun Run(const std::string& args) {
    const std::string err = *dir_ / "stderr.txt";
    const std::string redirect = args.find('>') == std::string::npos ? " > /dev/null" : "";
    const std::string cmd = "timeout " + std::to_string(5 * testing::kTimeScale) + " '" +
                            HPOSE_BINARY_DIR + "/tools/hpose' " + args + redirect + " 2>'" + err +
                            "'";
    const int status = std::system(cmd.c_str());
    CliRun run;
    run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    run.err = Slurp(err);
    return run;
  }

  static std::string Write(const std::string& name, const std::string& bytes) {
    const std::string path = *dir_ / name;
    std::ofstream(path, std::ios::binary) << bytes;
    return path;
  }

  static std::string Frame(const std::string& name) { return *dir_ / ("frame/" + name); }

  static void ExpectFailsNaming(const std::string& args, const std::string& text) {
    const CliRun run = Run(args);
    EXPECT_EQ(run.exit_code, 1) << args << "\n" << run.err;
    EXPECT_NE(run.err.find(text), std::string::npos) << args << "\n" << run.err;
  }

  static TempDir* dir_;
};
TempDir* HostileFilesCliTest::dir_ = nullptr;

std::string PcdHeader(const std::string& points, const std::string& data) {
  return "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH " +
         points + "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " + points + "\nDATA " + data + "\n";
}

std::string Le32(std::uint32_t v) {
  std::string s(4, '\0');
  for (int i = 0; i < 4; ++i) s[i] = static_cast<char>((v >> (8 * i)) & 0xff);
  return s;
}

TEST_F(HostileFilesCliTest, PcdAnnouncingHugePointCounts) {
  ExpectFailsNaming(
      "estimate --cloud '" + Write("huge.pcd", PcdHeader("2000000000", "ascii") + "1 2 3\n") + "'",
      "2000000000");
  // Within the point limit, but far more than the 120 bytes that follow.
  ExpectFailsNaming(
      "estimate --cloud '" +
          Write("short.pcd", PcdHeader("1000000", "binary") + std::string(120, '\0')) + "'",
      "announces 1000000 points");
}

TEST_F(HostileFilesCliTest, PcdWithBogusCompressedSizes) {
  const std::string header = PcdHeader("10", "binary_compressed");
  ExpectFailsNaming("estimate --cloud '" +
                        Write("bogus1.pcd", header + Le32(0xFFFFFF00u) + Le32(0xFFFFFFF0u) +
                                                std::string(64, '\0')) +
                        "'",
                    "compressed bytes");
  ExpectFailsNaming(
      "estimate --cloud '" +
          Write("bogus2.pcd", header + Le32(20) + Le32(4000000000u) + std::string(64, '\0')) + "'",
      "unpacks to 4000000000 bytes");
}

TEST_F(HostileFilesCliTest, PlyWithNegativeOrHugeCount) {
  const std::string tail = "property float x\nproperty float y\nproperty float z\nend_header\n";
  ExpectFailsNaming(
      "estimate --cloud '" +
          Write("negative.ply", "ply\nformat ascii 1.0\nelement vertex -5\n" + tail + "1 2 3\n") +
          "'",
      "count -5 is negative");
  ExpectFailsNaming(
      "estimate --cloud '" +
          Write("huge.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 3000000\n" +
                                tail + std::string(24, '\0')) +
          "'",
      "announces 3000000 points");
}

TEST_F(HostileFilesCliTest, TemplateThatExpandsToTrillionsOfVoxels) {
  // The root's first child is an occupied leaf one level below the root: expanded to the
  // tree's 16 levels it stands for 8^15 voxels.
  const std::string bt =
      Write("bomb.bt", "# Octomap OcTree binary file\nid OcTree\nsize 2\nres 0.016\ndata\n" +
                           std::string("\x02\x00", 2));
  ExpectFailsNaming("template info '" + bt + "'", "expands to 35184372088832");
  ExpectFailsNaming("estimate --depth '" + Frame("depth.png") + "' --template '" + bt + "'",
                    "expands to");
}

TEST_F(HostileFilesCliTest, RobotWhoseMeshCrashesAssimpOrWhoseSphereIsAHundredKilometres) {
  // A COLLADA mesh that crashes Debian's assimp (read in a child process, so an error), and a
  // sphere that would have taken all memory to tessellate.
  Write("crashing.dae", testing::BoxCollada(false));
  const std::string meshy =
      Write("meshy.urdf",
            "<robot name=\"r\"><link name=\"base\"><visual><geometry><mesh "
            "filename=\"crashing.dae\"/></geometry></visual></link></robot>\n");
  ExpectFailsNaming("template from-urdf '" + meshy + "' --out '" + (*dir_ / "meshy.bt") + "'",
                    "link 'base': mesh " + (*dir_ / "crashing.dae") + ": cannot read it: assimp ");
  const std::string huge = Write("huge.urdf",
                                 "<robot name=\"r\"><link name=\"base\"><visual><geometry><sphere "
                                 "radius=\"100000\"/></geometry></visual></link></robot>\n");
  ExpectFailsNaming("template from-urdf '" + huge + "' --out '" + (*dir_ / "huge.bt") + "'",
                    "link 'base': sphere radius makes a shape 200000 m across");
  EXPECT_FALSE(std::ifstream(*dir_ / "meshy.bt").good());
  EXPECT_FALSE(std::ifstream(*dir_ / "huge.bt").good());
}

TEST_F(HostileFilesCliTest, FifoGivenAsADepthFile) {
  const std::string fifo = *dir_ / "fifo.png";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  ExpectFailsNaming("estimate --depth '" + fifo + "'", "FIFO");
  ExpectFailsNaming("estimate --cloud '" + (*dir_ / "fifo.png") + "'", "FIFO");
}

TEST_F(HostileFilesCliTest, PngOfTwentyThousandPixelsPerSide) {
  // A valid signature and IHDR announcing 20000 x 20000 16-bit grey; the data never comes.
  std::string png("\x89PNG\r\n\x1a\n", 8);
  png += std::string("\0\0\0\x0d", 4) + "IHDR";
  png += std::string("\0\0\x4e\x20\0\0\x4e\x20\x10\0\0\0\0", 13) + std::string(4, '\0');
  png += std::string("\0\0\0\0", 4) + "IEND" + std::string(4, '\0');
  ExpectFailsNaming("estimate --depth '" + Write("huge.png", png) + "'", "20000x20000 px");
}

TEST_F(HostileFilesCliTest, PictureIntoAMissingDirectory) {
  ExpectFailsNaming("estimate --depth '" + Frame("depth.png") + "' --intrinsics '" +
                        Frame("intrinsics.json") + "' --picture '" + (*dir_ / "no/such/p.png") +
                        "'",
                    "does not exist");
  ExpectFailsNaming("demo --picture '" + (*dir_ / "no/such/p.png") + "'", "does not exist");
  ExpectFailsNaming("replay '" + (*dir_ / "frame") + "' --out '" + (*dir_ / "no/out.jsonl") + "'",
                    "does not exist");
}

// Without its drawing module a program still refuses a picture by name, writes no file and
// leaves the rest of its work to the runs that ask for no picture.
TEST_F(HostileFilesCliTest, PictureWithoutTheDrawingModule) {
  const std::string hpose = std::string(HPOSE_BINARY_DIR) + "/tools/hpose";
  const std::string frame =
      "--depth '" + Frame("depth.png") + "' --intrinsics '" + Frame("intrinsics.json") + "'";
  const std::string picture = *dir_ / "unmade.png";
  const std::string missing = *dir_ / "no-such-module.so";
  CliRun run = RunProgram("env",
                          "HPOSE_DRAWING_MODULE='" + missing + "' '" + hpose + "' estimate " +
                              frame + " --picture '" + picture + "'",
                          *dir_);
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_NE(run.err.find("drawing module"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find(missing), std::string::npos) << run.err;
  EXPECT_FALSE(std::filesystem::exists(picture));

  const std::string not_a_module = Write("not-a-module.so", "plain text, not a shared object");
  run = RunProgram("env",
                   "HPOSE_DRAWING_MODULE='" + not_a_module + "' '" + hpose + "' template show '" +
                       HPOSE_SOURCE_DIR + "/templates/standing.bt' --picture '" + picture + "'",
                   *dir_);
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_NE(run.err.find("cannot load the drawing module " + not_a_module), std::string::npos)
      << run.err;
  EXPECT_FALSE(std::filesystem::exists(picture));

  // The same runs without a picture need no module.
  run = RunProgram(
      "env", "HPOSE_DRAWING_MODULE='" + missing + "' '" + hpose + "' estimate " + frame + " --json",
      *dir_);
  EXPECT_EQ(run.exit_code, 0) << run.err;
}

// Output that cannot be written is an error, not a success with the results lost.
TEST_F(HostileFilesCliTest, LostOutputIsAnError) {
  const std::string frame =
      "--depth '" + Frame("depth.png") + "' --intrinsics '" + Frame("intrinsics.json") + "'";
  ExpectFailsNaming("estimate " + frame + " --json > /dev/full", "standard output");
  ExpectFailsNaming("estimate " + frame + " > /dev/full", "standard output");
  ExpectFailsNaming("replay '" + (*dir_ / "frame") + "' --out /dev/full", "/dev/full");
  ExpectFailsNaming("replay '" + (*dir_ / "frame") + "' > /dev/full", "standard output");
  ExpectFailsNaming("estimate " + frame + " --picture /dev/full", "/dev/full");
  ExpectFailsNaming(
      "template info '" + std::string(HPOSE_SOURCE_DIR) + "/templates/standing.bt' > /dev/full",
      "standard output");
  // The device was written in place, never replaced by a renamed file.
  struct stat st;
  ASSERT_EQ(::stat("/dev/full", &st), 0);
  EXPECT_TRUE(S_ISCHR(st.st_mode));
  // And the ordinary case still succeeds.
  EXPECT_EQ(Run("estimate " + frame + " --json").exit_code, 0);
}

}  // namespace
}  // namespace hpose
