// server/hposed.example.yaml is the defaults (except lines marked "# changed:"), works copied
// anywhere, and paths in a config resolve against the config's directory, errors naming the
// resolved path.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>

#include "server/daemon.h"
#include "tests/integration/test_util.h"

namespace hpose {
namespace {

namespace tu = hpose::testing_util;

const std::string kExample = std::string(HPOSE_SOURCE_DIR) + "/server/hposed.example.yaml";

std::string Hposed() { return std::string(HPOSE_BINARY_DIR) + "/server/hposed"; }

// Runs hposed with `args` in `cwd`; returns its exit status, stdout in *out, stderr in *err.
int RunHposed(const std::string& args, const std::string& cwd, std::string* out, std::string* err) {
  const std::string err_file = cwd + "/.stderr";
  const int code = tu::RunCommand(
      "cd '" + cwd + "' && '" + Hposed() + "' " + args + " 2>'" + err_file + "'", out);
  std::ifstream in(err_file);
  std::stringstream ss;
  ss << in.rdbuf();
  *err = ss.str();
  return code;
}

// "section.key" -> value text for every scalar; sequences as "[a, b]".
void Flatten(const YAML::Node& node, const std::string& prefix,
             std::map<std::string, std::string>* out) {
  if (node.IsMap()) {
    for (const auto& kv : node) {
      Flatten(
          kv.second,
          prefix.empty() ? kv.first.as<std::string>() : prefix + "." + kv.first.as<std::string>(),
          out);
    }
  } else if (node.IsSequence()) {
    std::string joined = "[";
    for (size_t i = 0; i < node.size(); ++i) joined += (i ? ", " : "") + node[i].as<std::string>();
    (*out)[prefix] = joined + "]";
  } else {
    (*out)[prefix] = node.IsNull() ? "" : node.as<std::string>();
  }
}

// The keys of lines marked "# changed:" in the example ("section.key").
std::set<std::string> ChangedKeys(const std::string& path) {
  std::set<std::string> keys;
  std::ifstream in(path);
  std::string line, section;
  while (std::getline(in, line)) {
    const size_t hash = line.find('#');
    const std::string body = line.substr(0, hash);
    const size_t colon = body.find(':');
    if (colon == std::string::npos || body.find_first_not_of(' ') == std::string::npos) continue;
    const size_t indent = body.find_first_not_of(' ');
    const std::string key = body.substr(indent, colon - indent);
    if (indent == 0) section = key;
    if (hash != std::string::npos && line.compare(hash, 10, "# changed:") == 0) {
      keys.insert(indent == 0 ? key : section + "." + key);
    }
  }
  return keys;
}

TEST(ExampleConfigTest, EqualsTheDefaultsExceptMarkedLines) {
  const std::string dir = tu::MakeTempDir("example_config");
  std::string defaults_text, example_text, err;
  ASSERT_EQ(RunHposed("--print-config", dir, &defaults_text, &err), 0) << err;
  ASSERT_EQ(RunHposed("--config '" + kExample + "' --print-config", dir, &example_text, &err), 0)
      << err;
  std::map<std::string, std::string> defaults, example;
  Flatten(YAML::Load(defaults_text), "", &defaults);
  Flatten(YAML::Load(example_text), "", &example);
  ASSERT_GT(defaults.size(), 20u);
  const std::set<std::string> changed = ChangedKeys(kExample);
  for (const auto& [key, value] : defaults) {
    ASSERT_TRUE(example.count(key)) << key;
    if (changed.count(key)) {
      EXPECT_NE(example[key], value) << key << " is marked changed but equals the default";
    } else {
      EXPECT_EQ(example[key], value)
          << key << ": the example says " << example[key] << " but the default is " << value;
    }
  }
  EXPECT_EQ(example.size(), defaults.size());
  std::filesystem::remove_all(dir);
}

TEST(ExampleConfigTest, ACopyWorksAnywhereAndRelativePathsFollowTheFile) {
  const std::string dir = tu::MakeTempDir("example_copy");
  std::filesystem::create_directories(dir + "/conf");
  std::filesystem::create_directories(dir + "/elsewhere");
  std::filesystem::copy_file(kExample, dir + "/conf/hposed.yaml");
  std::string original, copied, err;
  ASSERT_EQ(RunHposed("--config '" + kExample + "' --print-config", dir, &original, &err), 0);
  ASSERT_EQ(
      RunHposed("--config ../conf/hposed.yaml --print-config", dir + "/elsewhere", &copied, &err),
      0)
      << err;
  EXPECT_EQ(copied, original);

  // A relative path in a config resolves against the config's directory, and the error names
  // the resolved path.
  std::ofstream(dir + "/conf/bad.yaml") << "templates:\n  - mine/robot.bt\n";
  std::string out;
  const int code =
      RunHposed("--config ../conf/bad.yaml --print-config", dir + "/elsewhere", &out, &err);
  EXPECT_EQ(code, 0) << err;  // printing does not load templates...
  EXPECT_NE(out.find(dir + "/conf/mine/robot.bt"), std::string::npos) << out;
  // ...starting does, and the message names the file it looked for.
  EXPECT_NE(
      RunHposed("--config ../conf/bad.yaml --listen 127.0.0.1:0", dir + "/elsewhere", &out, &err),
      0);
  EXPECT_NE(err.find(dir + "/conf/mine/robot.bt"), std::string::npos) << err;
  EXPECT_EQ(err.find("hpose hposed"), std::string::npos) << err;
  // A name that is no shipped template says which are, before anything starts.
  EXPECT_EQ(RunHposed("--template standng --listen 127.0.0.1:0", dir, &out, &err), 1);
  EXPECT_NE(
      err.find("hposed: 'standng' is no shipped template (those are arms_swung, right_arm_raised, "
               "standing, in "),
      std::string::npos)
      << err;
  std::filesystem::remove_all(dir);
}

// The messages a new user meets first read as sentences: no doubled prefixes, no gRPC dumps or
// status numbers, and the exit statuses of docs/API.md.
TEST(HposedMessagesTest, FlagsPortInUseAndQueryErrorsReadAsSentences) {
  const std::string dir = tu::MakeTempDir("hposed_messages");
  std::string out, err;
  EXPECT_EQ(RunHposed("--fps 0", dir, &out, &err), 2);
  EXPECT_NE(err.find("hposed: --fps:"), std::string::npos) << err;
  EXPECT_EQ(err.find("config:"), std::string::npos) << err;
  EXPECT_EQ(RunHposed("--stereo-fps 0", dir, &out, &err), 2);
  EXPECT_NE(err.find("--stereo-fps must be within [0.01, 10000], got 0"), std::string::npos) << err;
  EXPECT_EQ(err.find("config:"), std::string::npos) << err;
  // A cap on the vector paths that names no level: refused before anything starts.
  const std::string level_err = dir + "/level.err";
  EXPECT_EQ(tu::RunCommand("HPOSE_VECTOR_LEVEL=sse9 '" + Hposed() +
                           "' --print-config >/dev/null 2>'" + level_err + "'"),
            1);
  std::ifstream level_in(level_err);
  std::string level_line;
  std::getline(level_in, level_line);
  EXPECT_EQ(level_line,
            "hposed: HPOSE_VECTOR_LEVEL: unknown vector level \"sse9\" (expected scalar, avx2 or "
            "avx512)");

  server::DaemonConfig config;
  config.grpc.listen = "127.0.0.1:0";
  config.templates = {tu::TemplatePath("standing")};
  Result<std::unique_ptr<server::Daemon>> daemon = server::Daemon::Start(config);
  ASSERT_TRUE(daemon.ok()) << daemon.error().ToString();
  const std::string address = "127.0.0.1:" + std::to_string((*daemon)->port());

  // A second daemon on the same port: one sentence, exit 5, before the long start-up.
  EXPECT_EQ(RunHposed("--listen " + address, dir, &out, &err), 5);
  EXPECT_EQ(err, "hposed: cannot listen on '" + address + "': port " +
                     std::to_string((*daemon)->port()) +
                     " is already in use (another hposed running?)\n");
  // The web view's port taken: the same, naming the web view.
  EXPECT_EQ(RunHposed("--listen 127.0.0.1:0 --http " + address, dir, &out, &err), 5);
  EXPECT_EQ(err, "hposed: cannot serve the web view on '" + address + "' (http.listen): port " +
                     std::to_string((*daemon)->port()) +
                     " is already in use (another hposed running?)\n");

  // hpose query against a daemon without a source: the reason, no status number, exit 1.
  const std::string err_file = dir + "/query.err";
  const int code = tu::RunCommand(tu::HposeProgram() + " query latest --server " + address +
                                  " 2>'" + err_file + "'");
  EXPECT_EQ(code, 1);
  std::ifstream in(err_file);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "hpose query latest: the daemon has no depth source; send frames with Estimate");
  (*daemon)->Shutdown();
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace hpose
