// `hpose`: the command line of hpose. Dispatches to one subcommand per file.
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <string>

#include "tools/command.h"
#include "tools/exit_codes.h"

namespace {

using hpose::tools::Command;

const Command kCommands[] = {
    {"demo", "simulate a frame and estimate the humanoid in it (no input needed)",
     hpose::tools::RunDemo},
    {"estimate", "estimate the humanoid's pose in one depth frame or cloud",
     hpose::tools::RunEstimate},
    {"simulate", "render simulated Kinect frames of a humanoid scene", hpose::tools::RunSimulate},
    {"estimate-stereo", "locate robot and ball from stereo pairs and three landmarks",
     hpose::tools::RunEstimateStereo},
    {"simulate-stereo", "render simulated stereo pairs of the landmark field",
     hpose::tools::RunSimulateStereo},
    {"calibrate", "stereo pair from chessboards; depth sensor's place in the landmark frame",
     hpose::tools::RunCalibrate},
    {"template", "make, inspect and regenerate humanoid templates", hpose::tools::RunTemplate},
    {"record", "record depth from an OpenNI2 device to .oni or PNG frames",
     hpose::tools::RunRecord},
    {"replay", "estimate every frame of a recording (JSON Lines or CSV)", hpose::tools::RunReplay},
    {"query", "ask a running hposed: latest, stream, estimate, status", hpose::tools::RunQuery},
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
               "             4 no floor found, 5 server or device unavailable\n";
}

// Results written to standard output and lost (a full disk, a closed pipe, /dev/full) must
// not be reported as success: flush it and check for any write error.
int CheckStdoutWritten(const std::string& prog, int code) {
  std::cout.flush();
  errno = 0;
  const bool failed = !std::cout || std::fflush(stdout) != 0 || std::ferror(stdout) != 0;
  if (!failed) return code;
  const int err = errno;
  std::cerr << prog << ": cannot write the output to standard output"
            << (err != 0 ? std::string(": ") + std::strerror(err) : std::string()) << "\n";
  return hpose::tools::kExitError;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0 ||
      std::strcmp(argv[1], "help") == 0) {
    PrintHelp();
    return argc < 2 ? hpose::tools::kExitUsage : hpose::tools::kExitOk;
  }
  for (const Command& c : kCommands) {
    if (argv[1] == std::string(c.name)) {
      std::string prog = std::string("hpose ") + c.name;
      argv[1] = prog.data();
      const int code = c.run(argc - 1, argv + 1);
      return CheckStdoutWritten(prog, code);
    }
  }
  std::cerr << "hpose: unknown command '" << argv[1] << "' (see hpose --help)\n";
  return hpose::tools::kExitUsage;
}
