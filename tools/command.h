#ifndef HPOSE_TOOLS_COMMAND_H_
#define HPOSE_TOOLS_COMMAND_H_

namespace hpose::tools {

// A command's entry point: argv[0] names it ("hpose <name>"), its flags follow.
using CommandFn = int (*)(int argc, char** argv);

// One `hpose <name> ...` subcommand. `run` receives argv with argv[0] = "hpose <name>".
struct Command {
  const char* name;
  const char* summary;
  CommandFn run;
};

// Runs `hpose <c.name> ...` with argv[1] = c.name, as `hpose` and the command programs do:
// argv[1] becomes "hpose <name>" for the command's messages, and what the command wrote to
// standard output must have been written (a full disk or a closed pipe is an error).
int RunCommand(const Command& c, int argc, char** argv);

// Subcommand entry points, each in its own cmd_<name>.cc.
int RunDemo(int argc, char** argv);
int RunEstimate(int argc, char** argv);
int RunSimulate(int argc, char** argv);
int RunTemplate(int argc, char** argv);
// `hpose template` subcommands in their own files (argv[1] is the subcommand).
int TemplateFromUrdf(int argc, char** argv);  // cmd_template_urdf.cc
int TemplateInfo(int argc, char** argv);      // cmd_template_view.cc
int TemplateShow(int argc, char** argv);      // cmd_template_view.cc
// Daemon tools (cmd_record.cc, cmd_replay.cc, cmd_query.cc).
int RunRecord(int argc, char** argv);
int RunReplay(int argc, char** argv);
int RunQuery(int argc, char** argv);
// A picture of a track of estimates (cmd_plot.cc).
int RunPlot(int argc, char** argv);
// Stereo-marker estimator (cmd_stereo.cc). RunSimulateStereo also serves `hpose simulate stereo`.
int RunEstimateStereo(int argc, char** argv);
int RunSimulateStereo(int argc, char** argv);
// Template from captures (cmd_template_captures.cc) and their simulation
// (cmd_simulate_turntable.cc, served as `hpose simulate turntable`).
int RunTemplateFromCaptures(int argc, char** argv);
int RunSimulateTurntable(int argc, char** argv);
// Calibration tools (cmd_calibrate.cc): `calibrate stereo`, `calibrate world-from-ground`.
int RunCalibrate(int argc, char** argv);

}  // namespace hpose::tools

#endif  // HPOSE_TOOLS_COMMAND_H_
