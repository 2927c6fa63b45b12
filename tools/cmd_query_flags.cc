#include "tools/cmd_query_flags.h"

namespace hpose::tools {

FlagParser QueryFlags::Parser() {
  FlagParser flags(
      "hpose query [--server ADDR] (latest | stream | estimate FILE | estimate-stereo LEFT RIGHT "
      "| status | templates)",
      "Asks a running hposed. latest: the newest estimate of the daemon's source (--estimator); "
      "stream: estimates of both estimators as they are made, each line marked depth or stereo, "
      "until Ctrl-C, --count or the end of the daemon's source (a finished recording); with "
      "--compare each line shows the newest world-frame robot "
      "pose of both estimators side by side and the difference between the poses both made of "
      "the same instant (frames that reached the daemon within --max-dt), with a summary at the "
      "end; estimate FILE: sends a depth "
      "PNG (millimetres; intrinsics.json beside it or --intrinsics) or a PCD cloud and prints "
      "the estimate; estimate-stereo LEFT RIGHT: sends a stereo pair of colour images to the "
      "stereo-marker estimator; status: source states, counters, rates, latency, floor, world "
      "frame; templates: the loaded templates. Poses are printed in mm and degrees, world-frame "
      "poses after a '|'; --json prints the API messages (SI units).");
  flags.AddString("server", &server, "daemon address", "ADDR");
  flags.AddBool("json", &json, "print JSON (one object per line) instead of text");
  flags.AddInt("count", &count,
               "stream: stop after N estimates (0 = until Ctrl-C or the source ends)", "N");
  flags.AddDouble("timeout", &timeout_s, "deadline of each call, seconds (stream: none)", "S");
  flags.AddString("intrinsics", &intrinsics, "estimate: intrinsics.json of a PNG", "FILE");
  flags.AddString("estimator", &estimator,
                  "latest, stream: depth, stereo or all (latest: all = the depth source when "
                  "there is one)",
                  "NAME");
  flags.AddBool("compare", &compare,
                "stream: both estimators' world-frame poses side by side (text output)");
  flags.AddDouble("max-dt", &max_dt_s,
                  "stream --compare: frames of the two estimators at most this far apart in "
                  "arrival time are of the same instant",
                  "S");
  flags.AddStrings("template", &templates, "estimate: only these templates", "NAME");
  flags.AddString("tls-ca", &tls_ca,
                  "PEM CA that signed the daemon's certificate: connect with TLS", "FILE");
  flags.AddString("tls-cert", &tls_cert, "PEM client certificate (mutual TLS; with --tls-key)",
                  "FILE");
  flags.AddString("tls-key", &tls_key, "PEM private key of --tls-cert", "FILE");
  flags.AddString("token-file", &token_file,
                  "file holding the bearer token sent with every call (first line)", "FILE");
  flags.AllowPositional("COMMAND [FILE...]");
  flags.SetEpilog(
      "examples:\n  hpose query status\n  hpose query stream --count 10\n"
      "  hpose query stream --compare\n"
      "  hpose query --server 127.0.0.1:50051 estimate frames/depth_000.png\n"
      "  hpose query estimate-stereo seq/left/000000.png seq/right/000000.png\n");
  flags.Within("count", 0, 2147483647.0);
  return flags;
}

}  // namespace hpose::tools
