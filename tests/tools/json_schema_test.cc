// `hpose estimate --json` and `hpose replay` (JSON Lines) write one schema: every line is read
// by the same reader, which checks it field by field against hpose.v1.PoseEstimate (every
// field present, 64-bit integers as numbers), and docs/API.md names every field.
#include <google/protobuf/descriptor.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "core/io/depth_png.h"
#include "hpose/v1/pose_service.pb.h"
#include "tests/tools/cli_test_util.h"

namespace hpose {
namespace {

using google::protobuf::Descriptor;
using google::protobuf::FieldDescriptor;
using nlohmann::json;
using testing::CliRun;
using testing::RunHpose;
using testing::TempDir;

// The one reader: appends to *problems every way `j` differs from the schema of `d`.
void CheckValue(const json& v, const FieldDescriptor* f, const std::string& path,
                std::vector<std::string>* problems);

void CheckMessage(const json& j, const Descriptor* d, const std::string& path,
                  std::vector<std::string>* problems) {
  if (d->full_name() == "google.protobuf.Timestamp") {
    if (!j.is_string()) problems->push_back(path + ": expected an RFC 3339 string");
    return;
  }
  if (!j.is_object()) {
    problems->push_back(path + ": expected an object");
    return;
  }
  std::set<std::string> known;
  for (int i = 0; i < d->field_count(); ++i) {
    const FieldDescriptor* f = d->field(i);
    known.insert(f->name());
    const std::string at = path + "." + f->name();
    if (!j.contains(f->name())) {
      problems->push_back(at + ": missing");
      continue;
    }
    const json& v = j.at(f->name());
    if (f->is_repeated()) {
      if (!v.is_array()) {
        problems->push_back(at + ": expected an array");
        continue;
      }
      for (size_t k = 0; k < v.size(); ++k) {
        CheckValue(v[k], f, at + "[" + std::to_string(k) + "]", problems);
      }
    } else if (v.is_null()) {
      // Only messages that are not set and oneof members not chosen may be null (and doubles
      // that are not finite).
      if (f->cpp_type() != FieldDescriptor::CPPTYPE_MESSAGE && f->containing_oneof() == nullptr &&
          f->cpp_type() != FieldDescriptor::CPPTYPE_DOUBLE) {
        problems->push_back(at + ": null for a scalar");
      }
    } else {
      CheckValue(v, f, at, problems);
    }
  }
  for (const auto& item : j.items()) {
    if (known.count(item.key()) == 0) problems->push_back(path + "." + item.key() + ": unknown");
  }
}

void CheckValue(const json& v, const FieldDescriptor* f, const std::string& path,
                std::vector<std::string>* problems) {
  bool ok = true;
  switch (f->cpp_type()) {
    case FieldDescriptor::CPPTYPE_INT32:
    case FieldDescriptor::CPPTYPE_INT64:
      ok = v.is_number_integer();
      break;
    case FieldDescriptor::CPPTYPE_UINT32:
    case FieldDescriptor::CPPTYPE_UINT64:
      ok = v.is_number_unsigned() || (v.is_number_integer() && v.get<long long>() >= 0);
      break;
    case FieldDescriptor::CPPTYPE_DOUBLE:
    case FieldDescriptor::CPPTYPE_FLOAT:
      ok = v.is_number();
      break;
    case FieldDescriptor::CPPTYPE_BOOL:
      ok = v.is_boolean();
      break;
    case FieldDescriptor::CPPTYPE_ENUM:
      ok = v.is_string() && f->enum_type()->FindValueByName(v.get<std::string>()) != nullptr;
      break;
    case FieldDescriptor::CPPTYPE_STRING:
      ok = v.is_string();
      break;
    case FieldDescriptor::CPPTYPE_MESSAGE:
      CheckMessage(v, f->message_type(), path, problems);
      return;
  }
  if (!ok) problems->push_back(path + ": wrong type (" + v.dump() + ")");
}

std::vector<std::string> ReadPoseEstimate(const std::string& line) {
  std::vector<std::string> problems;
  const json j = json::parse(line, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) return {"not JSON: " + line.substr(0, 80)};
  CheckMessage(j, v1::PoseEstimate::descriptor(), "$", &problems);
  return problems;
}

class JsonSchemaTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TempDir("json_schema");
    const CliRun sim = RunHpose("simulate --out '" + (*dir_ / "rec") +
                                    "' --frames 2 --width 320 --height 240 --no-cloud "
                                    "--x 1.1 --theta-deg 30 --clutter 1 --seed 3",
                                *dir_);
    ASSERT_EQ(sim.exit_code, 0) << sim.err;
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  static TempDir* dir_;
};
TempDir* JsonSchemaTest::dir_ = nullptr;

TEST_F(JsonSchemaTest, EstimateAndReplayShareOneSchema) {
  const std::string rec = *dir_ / "rec";
  const CliRun replay = RunHpose("replay '" + rec + "' --no-progress", *dir_);
  ASSERT_EQ(replay.exit_code, 0) << replay.err;
  std::istringstream lines(replay.out);
  std::vector<json> replayed;
  for (std::string line; std::getline(lines, line);) {
    const std::vector<std::string> problems = ReadPoseEstimate(line);
    EXPECT_TRUE(problems.empty()) << "replay: " << problems.front();
    replayed.push_back(json::parse(line));
  }
  ASSERT_EQ(replayed.size(), 2u);

  const CliRun est = RunHpose("estimate --depth '" + rec + "/depth_000.png' --intrinsics '" + rec +
                                  "/intrinsics.json' --json",
                              *dir_);
  ASSERT_EQ(est.exit_code, 0) << est.err;
  const std::vector<std::string> problems = ReadPoseEstimate(est.out);
  EXPECT_TRUE(problems.empty()) << "estimate: " << problems.front();
  const json e = json::parse(est.out);

  // 64-bit integers are numbers, and false / zero values are present.
  EXPECT_TRUE(replayed[0].at("sequence").is_number_unsigned());
  EXPECT_TRUE(replayed[0].at("source_epoch").is_number_unsigned());
  EXPECT_TRUE(replayed[0].at("stale").is_boolean());
  // The same frame gives the same best candidate through both commands.
  const json& a = replayed[0].at("depth_template").at("best").at("best");
  const json& b = e.at("depth_template").at("best").at("best");
  EXPECT_EQ(a.at("template_name"), b.at("template_name"));
  EXPECT_EQ(a.at("cluster_index"), b.at("cluster_index"));
  EXPECT_DOUBLE_EQ(a.at("score").get<double>(), b.at("score").get<double>());
  EXPECT_DOUBLE_EQ(a.at("pose").at("x").get<double>(), b.at("pose").at("x").get<double>());
  EXPECT_NEAR(b.at("pose").at("x").get<double>(), 1.1, 0.05);
  // replay follows the recording (source.tracking): the second frame starts from the first's
  // pose on the first's floor; a single estimate is searched cold.
  const json& t0 = replayed[0].at("depth_template").at("tracking");
  const json& t1 = replayed[1].at("depth_template").at("tracking");
  EXPECT_FALSE(t0.at("prior_given").get<bool>());
  EXPECT_TRUE(t1.at("prior_given").get<bool>());
  EXPECT_TRUE(t1.at("tracked").get<bool>());
  EXPECT_TRUE(t1.at("floor_reused").get<bool>());
  EXPECT_EQ(t1.at("prior_template"), a.at("template_name"));
  // The robot passes on the floor: each frame searched once.
  EXPECT_EQ(t0.at("height_searches").get<int>(), 1);
  EXPECT_EQ(t1.at("height_searches").get<int>(), 1);
  // The tracked frame confirms the first frame's heading (the robot stands still, seen near), so
  // it searched no runner-up; the cold frames did not ask.
  const json& a1 = replayed[1].at("depth_template").at("best").at("best");
  EXPECT_FALSE(a.at("heading_confirmed").get<bool>());
  EXPECT_FALSE(b.at("heading_confirmed").get<bool>());
  EXPECT_TRUE(a1.at("heading_confirmed").get<bool>());
  EXPECT_FALSE(a1.at("has_runner_up").get<bool>());
  EXPECT_NEAR(a1.at("pose").at("theta").get<double>(), 30.0 * M_PI / 180.0, 3.0 * M_PI / 180.0);
  EXPECT_FALSE(e.at("depth_template").at("tracking").at("tracked").get<bool>());
}

TEST_F(JsonSchemaTest, AFailedFrameKeepsEveryField) {
  // A frame without any reading cannot be estimated: the JSON carries the error and still every
  // field.
  const std::string empty = *dir_ / "empty.png";
  ASSERT_TRUE(WriteDepthPng(DepthImage(320, 240), empty).ok());
  const CliRun est = RunHpose("estimate --depth '" + empty + "' --json", *dir_);
  EXPECT_EQ(est.exit_code, 1) << est.err;
  const std::vector<std::string> problems = ReadPoseEstimate(est.out);
  EXPECT_TRUE(problems.empty()) << problems.front();
  const json j = json::parse(est.out);
  EXPECT_EQ(j.at("error").at("code"), "invalid_argument");
  EXPECT_TRUE(j.at("depth_template").is_null());
}

TEST(JsonSchemaDocTest, ApiDocNamesEveryField) {
  std::ifstream in(std::string(HPOSE_SOURCE_DIR) + "/docs/API.md");
  ASSERT_TRUE(in) << "docs/API.md";
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string doc = ss.str();
  std::set<const Descriptor*> seen;
  std::vector<const Descriptor*> todo = {v1::PoseEstimate::descriptor()};
  while (!todo.empty()) {
    const Descriptor* d = todo.back();
    todo.pop_back();
    if (!seen.insert(d).second || d->full_name() == "google.protobuf.Timestamp") continue;
    for (int i = 0; i < d->field_count(); ++i) {
      const FieldDescriptor* f = d->field(i);
      EXPECT_NE(doc.find("`" + f->name() + "`"), std::string::npos)
          << d->name() << "." << f->name() << " is not documented in docs/API.md";
      if (f->message_type() != nullptr) todo.push_back(f->message_type());
    }
  }
}

}  // namespace
}  // namespace hpose
