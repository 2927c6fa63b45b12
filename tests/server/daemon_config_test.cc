#include "server/daemon_config.h"

#include <cmath>

#include <gtest/gtest.h>

namespace hpose::server {
namespace {

TEST(DaemonConfigTest, ParsesEveryKeyAndResolvesRelativePaths) {
  const char* yaml = R"(
listen: 127.0.0.1:6000
grpc: {max_receive_message_bytes: 2048, max_concurrent_estimates: 3, warm_up: false}
source: {path: rec/walk.oni, rate: fast, loop: true, fps: 15, queue_capacity: 2,
         estimate_threads: 2, warm_up: false, stale_after_s: 0.5, frame_timeout_s: 0.7,
         driver_reload_interval_s: 600, initial_pose: {x_m: 3.2, y_m: -0.4, theta_deg: 90}}
templates: [t/standing.bt, /abs/arm.bt]
search: {score_threshold: 55, min_humanoid_fit: 70, tracked_score_threshold: 42,
         scorer: reference, far_range_m: 3.0, far_score_ratio: 0.9, far_min_evidence: 0.1,
         two_points_a_voxel_within_m: 1.5, min_humanoid_evidence: 0.03,
         tracked_hold_min_evidence: 0.2}
floor: {mode: fixed, height_m: 0.5, pitch_rad: 0.1, max_tilt_rad: 1.4}
)";
  Result<DaemonConfig> c = ParseDaemonConfig(yaml, "test.yaml", "/etc/hpose");
  ASSERT_TRUE(c.ok()) << c.error().ToString();
  EXPECT_EQ(c->grpc.listen, "127.0.0.1:6000");
  EXPECT_EQ(c->grpc.max_receive_message_bytes, 2048);
  EXPECT_EQ(c->grpc.max_concurrent_estimates, 3);
  EXPECT_FALSE(c->grpc.warm_up);
  EXPECT_EQ(c->source.path, "/etc/hpose/rec/walk.oni");
  EXPECT_FALSE(c->source.realtime);
  EXPECT_TRUE(c->source.loop);
  EXPECT_DOUBLE_EQ(c->source.fps, 15.0);
  EXPECT_EQ(c->source.queue_capacity, 2);
  EXPECT_EQ(c->source.estimate_threads, 2);
  EXPECT_FALSE(c->source.warm_up);
  EXPECT_DOUBLE_EQ(c->source.frame_timeout_s, 0.7);
  EXPECT_DOUBLE_EQ(c->source.driver_reload_interval_s, 600.0);
  ASSERT_TRUE(c->source.has_initial_pose);
  EXPECT_DOUBLE_EQ(c->source.initial_pose.x, 3.2);
  EXPECT_DOUBLE_EQ(c->source.initial_pose.y, -0.4);
  EXPECT_NEAR(c->source.initial_pose.theta, M_PI / 2.0, 1e-12);
  ASSERT_EQ(c->templates.size(), 2u);
  EXPECT_EQ(c->templates[0], "/etc/hpose/t/standing.bt");
  EXPECT_EQ(c->templates[1], "/abs/arm.bt");
  EXPECT_DOUBLE_EQ(c->estimator.score_threshold, 55.0);
  EXPECT_DOUBLE_EQ(c->estimator.min_humanoid_fit, 70.0);
  EXPECT_DOUBLE_EQ(c->estimator.min_humanoid_evidence, 0.03);
  EXPECT_DOUBLE_EQ(c->estimator.tracked_hold_min_evidence, 0.2);
  EXPECT_DOUBLE_EQ(c->estimator.tracked_score_threshold, 42.0);
  EXPECT_DOUBLE_EQ(c->estimator.far_range_m, 3.0);
  EXPECT_DOUBLE_EQ(c->estimator.far_score_ratio, 0.9);
  EXPECT_DOUBLE_EQ(c->estimator.far_min_evidence, 0.1);
  EXPECT_DOUBLE_EQ(c->estimator.two_points_a_voxel_within_m, 1.5);
  EXPECT_EQ(c->estimator.scorer, ScorerKind::kOctomapReference);
  EXPECT_TRUE(c->floor.fixed);
  EXPECT_DOUBLE_EQ(c->floor.height_m, 0.5);
  EXPECT_DOUBLE_EQ(c->estimator.floor_fit.max_tilt_rad, 1.4);
  EXPECT_TRUE(ValidateDaemonConfig(*c).ok());
}

// A frame's searches run on every usable core unless the config says otherwise; the
// estimator library's own default stays one thread.
TEST(DaemonConfigTest, SearchThreadsDefaultToOnePerCore) {
  EXPECT_EQ(DaemonConfig().estimator.threads, 0);
  EXPECT_EQ(DefaultEstimatorOptions().threads, 1);
  Result<DaemonConfig> c = ParseDaemonConfig("search: {threads: 2}", "x", "/base");
  ASSERT_TRUE(c.ok()) << c.error().ToString();
  EXPECT_EQ(c->estimator.threads, 2);
  Result<DaemonConfig> d = ParseDaemonConfig("templates: [standing]", "x", "/base");
  ASSERT_TRUE(d.ok()) << d.error().ToString();
  EXPECT_EQ(d->estimator.threads, 0);
}

// The search's voxel edge: by default the templates' own (0), coarser for a tall body; a
// positive resolution_m fixes it. Both print and parse back.
TEST(DaemonConfigTest, SearchEdgeFollowsTheTemplatesUnlessSet) {
  Result<DaemonConfig> d = ParseDaemonConfig("templates: [standing]", "x", "/base");
  ASSERT_TRUE(d.ok()) << d.error().ToString();
  EXPECT_TRUE(d->estimator.resolution_from_templates);
  EXPECT_EQ(d->estimator.max_height_voxels, 48);
  Result<DaemonConfig> c =
      ParseDaemonConfig("search: {resolution_m: 0.024, max_height_voxels: 0}", "x", "/base");
  ASSERT_TRUE(c.ok()) << c.error().ToString();
  EXPECT_FALSE(c->estimator.resolution_from_templates);
  EXPECT_DOUBLE_EQ(c->estimator.lattice.resolution_m, 0.024);
  EXPECT_EQ(c->estimator.max_height_voxels, 0);
  for (const DaemonConfig& config : {*c, *d}) {
    Result<DaemonConfig> back = ParseDaemonConfig(DaemonConfigToYaml(config), "printed", "");
    ASSERT_TRUE(back.ok()) << back.error().ToString();
    EXPECT_EQ(back->estimator.resolution_from_templates,
              config.estimator.resolution_from_templates);
    EXPECT_EQ(back->estimator.lattice.resolution_m, config.estimator.lattice.resolution_m);
    EXPECT_EQ(back->estimator.max_height_voxels, config.estimator.max_height_voxels);
  }
  Result<DaemonConfig> zero = ParseDaemonConfig("search: {resolution_m: 0}", "x", "/base");
  ASSERT_TRUE(zero.ok()) << zero.error().ToString();
  EXPECT_TRUE(zero->estimator.resolution_from_templates);
}

TEST(DaemonConfigTest, DeviceSpecIsNotResolved) {
  Result<DaemonConfig> c = ParseDaemonConfig("source: {path: 'openni2://'}", "x", "/base");
  ASSERT_TRUE(c.ok());
  EXPECT_EQ(c->source.path, "openni2://");
}

TEST(DaemonConfigTest, ErrorsNameTheKey) {
  struct Case {
    const char* yaml;
    const char* expected;
  } cases[] = {
      {"sourc: {}", "sourc: unknown key (did you mean 'source'?)"},
      {"search: {scor_threshold: 40}",
       "search.scor_threshold: unknown key (did you mean 'score_threshold'?)"},
      {"floor: {max_tilt: 1}", "floor.max_tilt: unknown key (did you mean 'max_tilt_rad'?)"},
      {"floor: {colour: 1}", "floor.colour: unknown key\n"},
      {"source: {rate: slow}", "source.rate"},
      {"source: {fps: abc}", "source.fps"},
      {"source: {bogus: 1}", "source.bogus: unknown key"},
      {"floor: {mode: tilted}", "floor.mode"},
      {"search: {scorer: magic}", "search.scorer"},
      {"templates: {a: 1}", "templates"},
      {"grpc: [1, 2]", "grpc: expected a mapping"},
      {"listen: [", "not valid YAML"},
      {"source: {initial_pose: 3}", "source.initial_pose: expected a mapping"},
      {"source: {initial_pose: {x_m: 3}}", "source.initial_pose: x_m and y_m are required"},
      {"source: {initial_pose: {x_m: 3, y_m: 0, yaw: 1}}", "source.initial_pose.yaw: unknown"},
  };
  for (const Case& c : cases) {
    Result<DaemonConfig> r = ParseDaemonConfig(c.yaml, "cfg.yaml", "");
    ASSERT_FALSE(r.ok()) << c.yaml;
    EXPECT_EQ(r.error().code, ErrorCode::kInvalidArgument);
    // A trailing newline in `expected`: the message ends there (no name suggested).
    EXPECT_NE((r.error().message + "\n").find(c.expected), std::string::npos)
        << c.yaml << " -> " << r.error().message;
    EXPECT_EQ(r.error().message.rfind("cfg.yaml", 0), 0u) << r.error().message;
  }
}

TEST(DaemonConfigTest, ValidationNamesTheKey) {
  DaemonConfig c;
  c.templates = {"standing.bt"};
  ASSERT_TRUE(ValidateDaemonConfig(c).ok());
  DaemonConfig bad = c;
  bad.grpc.listen = "localhost";
  EXPECT_NE(ValidateDaemonConfig(bad).error().message.find("listen"), std::string::npos);
  // Ports beyond 65535, however many digits (a 23-digit one aborted the daemon).
  for (const char* listen : {"127.0.0.1:65536", "127.0.0.1:99999999999999999999999"}) {
    bad.grpc.listen = listen;
    EXPECT_NE(ValidateDaemonConfig(bad).error().message.find("listen"), std::string::npos)
        << listen;
  }
  bad.grpc.listen = "127.0.0.1:65535";
  EXPECT_TRUE(ValidateDaemonConfig(bad).ok());
  bad = c;
  bad.templates.clear();
  EXPECT_NE(ValidateDaemonConfig(bad).error().message.find("templates"), std::string::npos);
  bad = c;
  bad.templates = {"standing.ot"};
  EXPECT_NE(ValidateDaemonConfig(bad).error().message.find("neither a .bt file"),
            std::string::npos);
  bad = c;
  bad.source.queue_capacity = 0;
  EXPECT_NE(ValidateDaemonConfig(bad).error().message.find("source.queue_capacity"),
            std::string::npos);
  // Rates and waits a clock cannot count: 1e-300 frames a second, a 1e300 s timeout.
  bad = c;
  bad.source.fps = 1e-300;
  EXPECT_NE(ValidateDaemonConfig(bad).error().message.find("source.fps"), std::string::npos);
  bad = c;
  bad.source.frame_timeout_s = 1e300;
  EXPECT_NE(ValidateDaemonConfig(bad).error().message.find("source.frame_timeout_s"),
            std::string::npos);
  bad = c;
  bad.source.reconnect_initial_backoff_s = bad.source.reconnect_max_backoff_s = 1e300;
  EXPECT_NE(ValidateDaemonConfig(bad).error().message.find("source.reconnect_initial_backoff_s"),
            std::string::npos);
  bad = c;
  bad.stereo.stale_after_s = 1e300;
  EXPECT_NE(ValidateDaemonConfig(bad).error().message.find("stereo.stale_after_s"),
            std::string::npos);
  bad = c;
  bad.estimator.floor_fit.distance_threshold_m = 1e300;
  EXPECT_NE(ValidateDaemonConfig(bad).error().message.find("floor.distance_threshold_m"),
            std::string::npos);
  bad = c;
  bad.source.estimate_threads = 0;
  EXPECT_NE(ValidateDaemonConfig(bad).error().message.find("source.estimate_threads"),
            std::string::npos);
  bad = c;
  bad.estimator.min_humanoid_fit = -1.0;
  EXPECT_NE(ValidateDaemonConfig(bad).error().message.find("search.min_humanoid_fit"),
            std::string::npos);
  for (const double v : {-0.01, 1.5, std::nan("")}) {
    bad = c;
    bad.estimator.min_humanoid_evidence = v;
    EXPECT_NE(ValidateDaemonConfig(bad).error().message.find("search.min_humanoid_evidence"),
              std::string::npos)
        << v;
    bad = c;
    bad.estimator.tracked_hold_min_evidence = v;
    EXPECT_NE(ValidateDaemonConfig(bad).error().message.find("search.tracked_hold_min_evidence"),
              std::string::npos)
        << v;
  }
  bad = c;
  bad.source.has_initial_pose = true;
  bad.source.initial_pose = Pose2D{300.0, 0.0, 0.0};
  EXPECT_NE(ValidateDaemonConfig(bad).error().message.find("source.initial_pose"),
            std::string::npos);
  bad.source.initial_pose = Pose2D{3.0, 0.0, 0.0};
  EXPECT_TRUE(ValidateDaemonConfig(bad).ok());
  bad.source.tracking = false;
  EXPECT_NE(ValidateDaemonConfig(bad).error().message.find("source.tracking"), std::string::npos);
  bad = c;
  bad.estimator.tracked_score_threshold = 120.0;
  EXPECT_NE(ValidateDaemonConfig(bad).error().message.find("search.tracked_score_threshold"),
            std::string::npos);
  bad = c;
  bad.estimator.far_score_ratio = 1.5;
  EXPECT_NE(ValidateDaemonConfig(bad).error().message.find("search.far_score_ratio"),
            std::string::npos);
  bad = c;
  bad.estimator.far_range_m = std::nan("");
  EXPECT_NE(ValidateDaemonConfig(bad).error().message.find("search.far_range_m"),
            std::string::npos);
  bad = c;
  bad.estimator.two_points_a_voxel_within_m = -1.0;
  EXPECT_NE(ValidateDaemonConfig(bad).error().message.find("search.two_points_a_voxel_within_m"),
            std::string::npos);
  bad = c;
  bad.estimator.far_min_evidence = -0.1;
  EXPECT_NE(ValidateDaemonConfig(bad).error().message.find("search.far_min_evidence"),
            std::string::npos);
  bad = c;
  bad.estimator.floor_fit.min_width_m = -1.0;
  EXPECT_NE(ValidateDaemonConfig(bad).error().message.find("floor.min_width_m"), std::string::npos);
  bad.floor.fixed = true;  // a fixed floor fits nothing: the fit's options do not matter.
  EXPECT_TRUE(ValidateDaemonConfig(bad).ok());
  for (const double v : {0.0, 1.6, std::nan("")}) {
    bad = c;
    bad.estimator.floor_fit.max_tilt_rad = v;
    EXPECT_NE(ValidateDaemonConfig(bad).error().message.find("floor.max_tilt_rad"),
              std::string::npos)
        << v;
  }
  bad = c;
  bad.estimator.floor_fit.distance_threshold_m = 0.0;
  EXPECT_NE(ValidateDaemonConfig(bad).error().message.find("floor.distance_threshold_m"),
            std::string::npos);
  bad = c;
  bad.estimator.resolution_from_templates = false;
  bad.estimator.lattice.resolution_m = -0.01;
  EXPECT_NE(ValidateDaemonConfig(bad).error().message.find("search.resolution_m"),
            std::string::npos);
  bad.estimator.resolution_from_templates = true;  // the edge set is then not used.
  EXPECT_TRUE(ValidateDaemonConfig(bad).ok());
  bad = c;
  bad.estimator.max_height_voxels = 5;
  EXPECT_NE(ValidateDaemonConfig(bad).error().message.find("search.max_height_voxels"),
            std::string::npos);
  // Cloud options every frame would refuse are refused at start.
  bad = c;
  bad.estimator.cloud.stride = 0;
  EXPECT_NE(ValidateDaemonConfig(bad).error().message.find("search.stride: must be in [1, 16]"),
            std::string::npos);
  bad = c;
  bad.estimator.cloud.min_range_m = 5.0;
  bad.estimator.cloud.max_range_m = 1.0;
  EXPECT_NE(ValidateDaemonConfig(bad).error().message.find("search.max_range_m"),
            std::string::npos);
  bad.estimator.cloud.max_range_m = std::nan("");
  EXPECT_FALSE(ValidateDaemonConfig(bad).ok());
  bad.estimator.cloud.min_range_m = 0.5;
  bad.estimator.cloud.max_range_m = 8.0;
  EXPECT_TRUE(ValidateDaemonConfig(bad).ok());
  bad = c;
  bad.source.driver_reload_interval_s = std::nan("");
  EXPECT_NE(ValidateDaemonConfig(bad).error().message.find("source.driver_reload_interval_s"),
            std::string::npos);
  bad.source.driver_reload_interval_s = 0.0;  // reloaded at every retry, as before.
  EXPECT_TRUE(ValidateDaemonConfig(bad).ok());
  bad = c;
  bad.source.reconnect_max_backoff_s = 0.1;
  EXPECT_NE(ValidateDaemonConfig(bad).error().message.find("reconnect_max_backoff_s"),
            std::string::npos);
}

TEST(DaemonConfigTest, DefaultsListenOnLoopbackAndPrintedConfigParsesBack) {
  DaemonConfig c;
  EXPECT_EQ(c.grpc.listen.rfind("127.0.0.1:", 0), 0u);
  c.templates = {"/t/standing.bt"};
  c.source.path = "/rec/frames";
  c.source.loop = true;
  EXPECT_TRUE(c.source.warm_up);
  c.source.warm_up = false;
  c.floor.fixed = true;
  c.floor.height_m = 0.42;
  c.estimator.floor_fit.max_tilt_rad = 1.3;
  c.source.has_initial_pose = true;
  c.source.initial_pose = Pose2D{2.5, 0.25, 0.5};
  Result<DaemonConfig> back = ParseDaemonConfig(DaemonConfigToYaml(c), "printed", "");
  ASSERT_TRUE(back.ok()) << back.error().ToString();
  EXPECT_EQ(back->source.path, c.source.path);
  EXPECT_TRUE(back->source.loop);
  EXPECT_FALSE(back->source.warm_up);
  ASSERT_TRUE(back->source.has_initial_pose);
  EXPECT_NEAR(back->source.initial_pose.theta, 0.5, 1e-9);
  EXPECT_EQ(back->templates, c.templates);
  EXPECT_TRUE(back->floor.fixed);
  EXPECT_DOUBLE_EQ(back->floor.height_m, 0.42);
  EXPECT_DOUBLE_EQ(back->estimator.floor_fit.max_tilt_rad, 1.3);
  EXPECT_EQ(back->estimator.search, c.estimator.search);
  EXPECT_EQ(DaemonConfigToYaml(*back), DaemonConfigToYaml(c));
}

TEST(DaemonConfigTest, WebViewIsOffByDefaultAndLoopbackUnlessInsecure) {
  DaemonConfig c;
  c.templates = {"/t/standing.bt"};
  EXPECT_TRUE(c.http.listen.empty());
  Result<DaemonConfig> parsed = ParseDaemonConfig(
      "http: {listen: '127.0.0.1:8080', max_event_clients: 3}\n"
      "templates: [/t/standing.bt]",
      "web.yaml", "");
  ASSERT_TRUE(parsed.ok()) << parsed.error().ToString();
  EXPECT_EQ(parsed->http.listen, "127.0.0.1:8080");
  EXPECT_EQ(parsed->http.max_event_clients, 3);
  EXPECT_TRUE(ValidateDaemonConfig(*parsed).ok());
  EXPECT_EQ(DaemonConfigToYaml(*ParseDaemonConfig(DaemonConfigToYaml(*parsed), "p", "")),
            DaemonConfigToYaml(*parsed));

  c.http.listen = "0.0.0.0:8080";
  Status exposed = ValidateDaemonConfig(c);
  ASSERT_FALSE(exposed.ok());
  EXPECT_NE(exposed.error().message.find("http.listen"), std::string::npos);
  c.security.insecure = true;
  EXPECT_TRUE(ValidateDaemonConfig(c).ok());
  c.http.listen = "8080";
  EXPECT_FALSE(ValidateDaemonConfig(c).ok());
  c.http.listen = "127.0.0.1:8080";
  c.http.max_event_clients = 0;
  EXPECT_FALSE(ValidateDaemonConfig(c).ok());
  EXPECT_FALSE(ParseDaemonConfig("http: {port: 80}", "web.yaml", "").ok());  // unknown key.
}

}  // namespace
}  // namespace hpose::server

namespace hpose::server {
namespace {

TEST(DaemonConfigTest, ShippedExampleIsValidAndPointsAtTheShippedTemplates) {
  Result<DaemonConfig> c =
      LoadDaemonConfig(std::string(HPOSE_SOURCE_DIR) + "/server/hposed.example.yaml");
  ASSERT_TRUE(c.ok()) << c.error().ToString();
  ASSERT_EQ(c->templates.size(), 2u);
  // Shipped templates by name (hposed looks them up wherever they are installed), so a copy of
  // the example works from any directory.
  EXPECT_EQ(c->templates[0], "standing");
  EXPECT_TRUE(IsTemplateName(c->templates[1]));
  EXPECT_TRUE(c->source.path.empty());
}

TEST(DaemonConfigTest, MissingFileIsNotFound) {
  Result<DaemonConfig> c = LoadDaemonConfig("/nonexistent/hposed.yaml");
  ASSERT_FALSE(c.ok());
  EXPECT_EQ(c.error().code, ErrorCode::kNotFound);
}

}  // namespace
}  // namespace hpose::server
