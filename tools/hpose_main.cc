// `hpose`: the command line of hpose, a thin front end that starts instantly. It holds every
// command's flags (tools/cmd_*_flags.h: the flags, their defaults and help, without the work)
// and none of their work: it prints the help, rejects unknown commands and bad flags itself, and
// runs an accepted command line in the command's own program, `hpose-<command>` (beside this
// one in the build tree, in ../libexec/hpose once installed), which loads only the libraries
// that command needs.
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

#include "core/common/closest_name.h"
#include "tools/cmd_calibrate_flags.h"
#include "tools/cmd_demo_flags.h"
#include "tools/cmd_estimate_flags.h"
#include "tools/cmd_plot_flags.h"
#include "tools/cmd_query_flags.h"
#include "tools/cmd_record_flags.h"
#include "tools/cmd_replay_flags.h"
#include "tools/cmd_simulate_flags.h"
#include "tools/cmd_simulate_turntable_flags.h"
#include "tools/cmd_stereo_flags.h"
#include "tools/cmd_template_captures_flags.h"
#include "tools/cmd_template_flags.h"
#include "tools/cmd_template_urdf_flags.h"
#include "tools/cmd_template_view_flags.h"
#include "tools/command.h"
#include "tools/exit_codes.h"
#include "tools/flag_parser.h"

namespace {

using hpose::tools::Command;
namespace tools = hpose::tools;

// What a command returns here when its flags parsed: "run it in its program". Never an exit
// status.
constexpr int kFlagsAccepted = 1000;

// A command as the front end runs it: its flags (Flags::Parser()) parsed from argv[first] on;
// the exit status of --help or of a usage error (already reported), else kFlagsAccepted.
template <typename Flags, int kFirst = 1>
int CheckFlags(int argc, char** argv) {
  Flags flags;
  const int code = flags.Parser().ParseOrExitCode(argc, argv, kFirst);
  return code >= 0 ? code : kFlagsAccepted;
}

int CheckSimulate(int argc, char** argv) {
  return tools::RunSimulateSubcommand(
      {CheckFlags<tools::SimulateFlags>, CheckFlags<tools::SimulateStereoFlags>,
       CheckFlags<tools::TurntableFlags>},
      argc, argv);
}

int CheckCalibrate(int argc, char** argv) {
  return tools::RunCalibrateSubcommand(
      {CheckFlags<tools::CalibrateStereoFlags>, CheckFlags<tools::WorldFromGroundFlags>}, argc,
      argv);
}

// `hpose template`'s subcommands parse their flags from argv[2] (argv[1] names them).
int CheckTemplate(int argc, char** argv) {
  return tools::RunTemplateSubcommand(
      {CheckFlags<tools::TemplateGenerateFlags, 2>, CheckFlags<tools::TemplateFromCloudFlags, 2>,
       CheckFlags<tools::TemplateFromCapturesFlags, 2>, CheckFlags<tools::TemplateFromUrdfFlags, 2>,
       CheckFlags<tools::TemplateInfoFlags, 2>, CheckFlags<tools::TemplateShowFlags, 2>},
      argc, argv);
}

const Command kCommands[] = {
    {"demo", "simulate a frame and estimate the humanoid in it (no input needed)",
     CheckFlags<tools::DemoFlags>},
    {"estimate", "estimate the humanoid's pose in one depth frame or cloud",
     CheckFlags<tools::EstimateFlags>},
    {"simulate", "render simulated Kinect frames of a humanoid scene", CheckSimulate},
    {"estimate-stereo", "locate robot and ball from stereo pairs and three landmarks",
     CheckFlags<tools::EstimateStereoFlags>},
    {"simulate-stereo", "render simulated stereo pairs of the landmark field",
     CheckFlags<tools::SimulateStereoFlags>},
    {"calibrate", "stereo pair from chessboards; depth sensor's place in the landmark frame",
     CheckCalibrate},
    {"template", "make, inspect and regenerate humanoid templates", CheckTemplate},
    {"record", "record depth from an OpenNI2 device to .oni or PNG frames",
     CheckFlags<tools::RecordFlags>},
    {"replay", "estimate every frame of a recording (JSON Lines or CSV)",
     CheckFlags<tools::ReplayFlags>},
    {"query", "ask a running hposed: latest, stream, estimate, status",
     CheckFlags<tools::QueryFlags>},
    {"plot", "draw a track of estimates (replay's or a stream's JSON Lines) to a PNG",
     CheckFlags<tools::PlotFlags>},
};

void PrintHelp() {
  std::cout << "usage: hpose COMMAND [--help] [options]\n\n"
               "Off-board humanoid pose estimation from a depth camera.\n\ncommands:\n";
  for (const Command& c : kCommands) {
    std::string name = c.name;
    std::cout << "  " << name << std::string(name.size() < 16 ? 16 - name.size() : 1, ' ')
              << c.summary << "\n";
  }
  std::cout << "\nRun `hpose COMMAND --help` for the options of a command.\n\n"
               "exit status: 0 ok, 1 error (message on stderr), 2 usage, 3 no humanoid found,\n"
               "             4 no floor found, 5 server or device unavailable\n\n"
               "environment:\n"
               "  HPOSE_TEMPLATE_DIR    the directory of the shipped templates (standing, ...)\n"
               "  HPOSE_DRAWING_MODULE  the module that draws --picture (hpose-drawing.so)\n"
               "  HPOSE_VECTOR_LEVEL    scalar, avx2 or avx512: the widest vector paths the\n"
               "                        estimator may take on this CPU (the same results at every\n"
               "                        level; to compare them, or to see a CPU without AVX-512)\n";
}

// The directory of this executable, with a trailing '/' ("" when unknown).
std::string OwnDirectory() {
  std::vector<char> path(4096);
  const ssize_t n = readlink("/proc/self/exe", path.data(), path.size() - 1);
  if (n <= 0) return "";
  const std::string self(path.data(), static_cast<size_t>(n));
  return self.substr(0, self.rfind('/') + 1);
}

// Replaces this process by `hpose-<name>` with the original command line; returns only on
// failure.
int ExecCommandProgram(const std::string& name, const std::vector<std::string>& args) {
  const std::string dir = OwnDirectory();
  const std::string program = "hpose-" + name;
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  std::string tried;
  for (const std::string& path : {dir + program, dir + "../libexec/hpose/" + program}) {
    execv(path.c_str(), argv.data());
    tried += (tried.empty() ? "" : ", ") + path + " (" + std::strerror(errno) + ")";
  }
  std::cerr << "hpose " << name << ": cannot start the program of this command: " << tried
            << "; is hpose fully built or installed?\n";
  return hpose::tools::kExitError;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0 ||
      std::strcmp(argv[1], "help") == 0) {
    PrintHelp();
    return argc < 2 ? hpose::tools::kExitUsage : hpose::tools::kExitOk;
  }
  const std::vector<std::string> args(argv, argv + argc);  // commands may rewrite argv.
  for (const Command& c : kCommands) {
    if (args[1] != c.name) continue;
    const int code = hpose::tools::RunCommand(c, argc, argv);
    return code == kFlagsAccepted ? ExecCommandProgram(c.name, args) : code;
  }
  std::vector<std::string> names;
  for (const Command& c : kCommands) names.push_back(c.name);
  std::cerr << "hpose: unknown command '" << argv[1] << "'" << hpose::DidYouMean(argv[1], names)
            << " (see hpose --help)\n";
  return hpose::tools::kExitUsage;
}
