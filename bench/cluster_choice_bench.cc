// Which cluster the estimator names the humanoid when clutter passes the thresholds too. Scenes
// of one humanoid among 4-10 clutter objects, seen from random mounts (0.3-1.6 m high, pitched
// 5 degrees up to 45 down, the floor in view), 0.9-3.5 m away within 20 degrees of the optical
// axis, at any heading, with Kinect-like correlated depth noise. Each scene is estimated once
// (default options, the body's two templates); the humanoid detections are then ranked by each
// order below, side by side, and the first one is checked against the truth: the cluster
// (within 5 cm) and the pose (within 5 cm and 10 degrees).
//
// Orders: the search score (the order before), the refined fit, and the covered voxels times the
// refined fit to the power 1, 2, 4, 6, 8 (DetectionBefore's, the estimator's), 12 and 16. A check
// counts the scenes whose first detection in the estimate is not DetectionBefore's first (should
// be none).
//
// A column counts the scenes with a humanoid detection 0.3 m or more from the robot (clutter
// taken for one), the next those of them without a detection on the robot (where a reader is
// given clutter for the robot). --far-ratio sets EstimatorOptions::far_score_ratio (1: one score
// threshold at every range, as before far clusters had their own), --two-points-within M
// EstimatorOptions::two_points_a_voxel_within_m (e.g. 2.5; 0: off, the default) and
// --min-evidence E EstimatorOptions::min_humanoid_evidence (0: off), to compare either in runs
// of the same seed. --dump FILE writes every humanoid detection as a CSV row (its scene, whether
// it is on the robot, its search and refined evidence, its cluster's size), to study what tells
// clutter from robots. --extra-pose NAME searches a third template of each parametric body,
// made in that joint preset (arms_swung), beside its two.
//
// usage: cluster_choice_bench [--scenes N] [--bodies a,b] [--seed S] [--threads N]
//                             [--far-ratio R] [--two-points-within M] [--min-evidence E]
//                             [--dump FILE] [--extra-pose NAME]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "bench/bench_bodies.h"
#include "bench/bench_threads.h"
#include "core/search/detection_order.h"
#include "core/search/estimator.h"
#include "core/sim/frame_simulator.h"

namespace {

using namespace hpose;
using bench::Body;

struct Scene {
  int body = 0, shape = 0, clutter = 0;
  double height_m = 0.0, pitch_deg = 0.0;
  Pose2D truth;
  std::uint64_t seed = 0;
};

// A humanoid detection as the orders see it.
struct Seen {
  Detection detection;
  ClusterSummary cluster;  // the detection's cluster.
  bool on_robot = false;   // within 5 cm of the truth.
  bool off_robot = false;  // 0.3 m or more from it.
  bool pose_ok = false;    // and its heading within 10 degrees.
};

struct Outcome {
  bool estimated = false;       // simulated and estimated (a floor found).
  std::vector<Seen> humanoids;  // in the estimator's order.
};

struct Order {
  std::string name;
  std::function<bool(const Candidate&, const Candidate&)> before;
};

double Power(double fit, int k) { return std::pow(fit / 100.0, k); }

std::vector<Order> Orders() {
  std::vector<Order> out;
  out.push_back(
      {"score (before)", [](const Candidate& a, const Candidate& b) { return a.score > b.score; }});
  out.push_back({"fit", [](const Candidate& a, const Candidate& b) {
                   return a.fit.fit != b.fit.fit ? a.fit.fit > b.fit.fit : a.score > b.score;
                 }});
  for (int k : {1, 2, 4, 6, 8, 12, 16}) {
    const std::string name =
        "hits x fit^" + std::to_string(k) + (k == 8 ? " (DetectionBefore)" : "");
    out.push_back({name, [k](const Candidate& a, const Candidate& b) {
                     const double ea = a.hits * Power(a.fit.fit, k);
                     const double eb = b.hits * Power(b.fit.fit, k);
                     return ea != eb ? ea > eb : a.score > b.score;
                   }});
  }
  return out;
}

// Random scenes of `body`, drawn from `rng`. The floor must be in view below the humanoid: a
// mount whose lowest ray meets the floor beyond 3.8 m is drawn again.
std::vector<Scene> DrawScenes(int body, int count, std::mt19937_64* rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Scene> out;
  while (static_cast<int>(out.size()) < count) {
    Scene s;
    s.body = body;
    s.height_m = 0.3 + 1.3 * u(*rng);
    s.pitch_deg = s.height_m > 0.6 ? -5.0 + 50.0 * u(*rng) : -5.0 + 20.0 * u(*rng);
    const double lowest_ray_deg = s.pitch_deg + 21.5;  // Kinect v1: 43 degrees vertically.
    const double d = 0.9 + 2.6 * u(*rng);
    const double bearing = DegToRad(-20.0 + 40.0 * u(*rng));
    s.truth = Pose2D{d * std::cos(bearing), d * std::sin(bearing),
                     NormalizeAngle(DegToRad(-180.0 + 360.0 * u(*rng)))};
    s.shape = u(*rng) < 0.5 ? 0 : 1;
    s.clutter = 4 + static_cast<int>(7.0 * u(*rng));
    s.seed = (*rng)();
    if (s.height_m / std::tan(DegToRad(lowest_ray_deg)) > 3.8) continue;
    out.push_back(s);
  }
  return out;
}

Outcome Run(const Scene& s, const Body& body, const Estimator& estimator) {
  Outcome o;
  FrameSpec spec;
  spec.preset = bench::kShapes[s.shape];
  if (body.meshes.empty()) {
    spec.body = body.variant;
  } else {
    spec.robot_mesh = body.meshes[s.shape];
  }
  spec.humanoid_pose = s.truth;
  spec.sensor_height_m = s.height_m;
  spec.sensor_pitch_rad = DegToRad(s.pitch_deg);
  spec.clutter = s.clutter;
  spec.seed = s.seed;
  spec.noise_correlated_share = 0.9;
  const Result<SimulatedFrame> frame = SimulateFrame(spec);
  if (!frame.ok()) return o;
  const Result<Estimate> e = estimator.EstimateDepth(frame->depth, spec.intrinsics);
  if (!e.ok()) return o;
  o.estimated = true;
  for (const Detection& d : e->Humanoids()) {
    Seen seen;
    seen.detection = d;
    for (const ClusterSummary& c : e->clusters) {
      if (c.index == d.best.cluster_index) seen.cluster = c;
    }
    const double miss = std::hypot(d.best.pose.x - s.truth.x, d.best.pose.y - s.truth.y);
    seen.on_robot = miss < 0.05;
    seen.off_robot = miss >= 0.3;
    seen.pose_ok =
        seen.on_robot && std::abs(AngleDiff(d.best.pose.theta, s.truth.theta)) < DegToRad(10.0);
    o.humanoids.push_back(seen);
  }
  return o;
}

// Every humanoid detection, one CSV row each (--dump), to `f`, which it closes.
bool WriteDump(std::FILE* f, std::uint64_t seed, const std::vector<Scene>& scenes,
               const std::vector<Body>& bodies, const std::vector<Outcome>& outcomes) {
  std::fprintf(
      f,
      "seed,body,scene,rank,on_robot,off_robot,pose_ok,template,range_m,score,coverage,fit,"
      "explained,contradicted,fit_sigma,hits,cluster_voxels,template_voxels,"
      "evidence_share,free_space_hits,cluster_points,cluster_width_m,cluster_depth_m,"
      "cluster_height_m,sensor_height_m,sensor_pitch_deg,in_view\n");
  for (size_t i = 0; i < scenes.size(); ++i) {
    const Scene& s = scenes[i];
    for (size_t r = 0; r < outcomes[i].humanoids.size(); ++r) {
      const Seen& h = outcomes[i].humanoids[r];
      const Candidate& c = h.detection.best;
      const Eigen::Vector3f size = h.cluster.max - h.cluster.min;
      std::fprintf(
          f,
          "%llu,%s,%zu,%zu,%d,%d,%d,%s,%.3f,%.2f,%.2f,%.2f,%.4f,%.4f,%.2f,%d,%d,%d,%.5f,%d,%d,"
          "%.3f,%.3f,%.3f,%.2f,%.1f,%.3f\n",
          static_cast<unsigned long long>(seed), bodies[s.body].name.c_str(), i, r,
          h.on_robot ? 1 : 0, h.off_robot ? 1 : 0, h.pose_ok ? 1 : 0, c.template_name.c_str(),
          std::hypot(c.pose.x, c.pose.y), c.score, c.coverage, c.fit.fit, c.fit.explained,
          c.fit.contradicted, c.fit.fit_sigma, c.hits, c.cluster_voxels, c.template_voxels,
          HumanoidEvidenceShare(c), c.free_space_hits, h.cluster.points, size.x(), size.y(),
          size.z(), s.height_m, s.pitch_deg, c.fit.in_view);
    }
  }
  return std::fclose(f) == 0;
}

}  // namespace

int main(int argc, char** argv) {
  int scenes_per_body = 100, threads = 2;
  double far_ratio = DefaultEstimatorOptions().far_score_ratio;
  double two_points_within = DefaultEstimatorOptions().two_points_a_voxel_within_m;
  double min_evidence = DefaultEstimatorOptions().min_humanoid_evidence;
  std::uint64_t seed = 1;
  std::vector<std::string> body_names = {"nao", "long_legs", "darwin_op"};
  std::string dump_path, extra_pose;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const std::string v = i + 1 < argc ? argv[i + 1] : "";
    if (a == "--scenes" && !v.empty()) {
      scenes_per_body = std::max(1, std::atoi(v.c_str())), ++i;
    } else if (a == "--bodies" && !v.empty()) {
      body_names = bench::ParseNames(v), ++i;
    } else if (a == "--seed" && !v.empty()) {
      seed = std::strtoull(v.c_str(), nullptr, 10), ++i;
    } else if (a == "--threads" && !v.empty()) {
      threads = std::max(1, std::atoi(v.c_str())), ++i;
    } else if (a == "--far-ratio" && !v.empty()) {
      far_ratio = std::atof(v.c_str()), ++i;
    } else if (a == "--two-points-within" && !v.empty()) {
      two_points_within = std::atof(v.c_str()), ++i;
    } else if (a == "--min-evidence" && !v.empty()) {
      min_evidence = std::atof(v.c_str()), ++i;
    } else if (a == "--dump" && !v.empty()) {
      dump_path = v, ++i;
    } else if (a == "--extra-pose" && !v.empty()) {
      extra_pose = v, ++i;
    } else {
      std::fprintf(stderr,
                   "usage: cluster_choice_bench [--scenes N] [--bodies a,b] [--seed S] "
                   "[--threads N] [--far-ratio R] [--two-points-within M] [--min-evidence E] "
                   "[--dump FILE] [--extra-pose NAME]\n"
                   "  --scenes N   random scenes per body (default 100)\n"
                   "  --bodies     nao, long_legs, tall, darwin_op (default: all but tall;\n"
                   "               darwin_op needs the shared data, skipped without it)\n"
                   "  --seed S     seed of the scene draws (default 1)\n"
                   "  --threads N  scenes estimated at once (default 2)\n"
                   "  --far-ratio R  EstimatorOptions::far_score_ratio (default the "
                   "estimator's; 1: one\n"
                   "               score threshold at every range)\n"
                   "  --two-points-within M  EstimatorOptions::two_points_a_voxel_within_m\n"
                   "               (default the estimator's, 0: off)\n"
                   "  --min-evidence E  EstimatorOptions::min_humanoid_evidence (default the\n"
                   "               estimator's; 0: off)\n"
                   "  --dump FILE  every humanoid detection as a CSV row\n"
                   "  --extra-pose NAME  a third template of each parametric body, made in this\n"
                   "               joint preset (e.g. arms_swung), searched beside its two\n");
      return a == "--help" ? 0 : 2;
    }
  }
  std::vector<Body> bodies;
  for (const std::string& name : body_names) {
    Result<Body> body = bench::BodyByName(name, HPOSE_SHARED_DATA_DIR, HPOSE_SOURCE_DIR);
    if (body.ok() && !extra_pose.empty()) {
      Result<VoxelTemplate> extra = bench::PoseTemplate(*body, extra_pose);
      if (!extra.ok()) {
        std::fprintf(stderr, "cluster_choice_bench: %s\n", extra.error().message.c_str());
        return 2;
      }
      body->templates.push_back(*extra);
    }
    if (body.ok()) {
      bodies.push_back(*body);
    } else if (name == "darwin_op") {  // the shared data may be absent.
      std::fprintf(stderr, "cluster_choice_bench: skipping darwin_op (%s)\n",
                   body.error().message.c_str());
    } else {
      std::fprintf(stderr, "cluster_choice_bench: %s\n", body.error().message.c_str());
      return 2;
    }
  }
  std::FILE* dump = nullptr;  // opened now: a path that cannot be written fails before the work.
  if (!dump_path.empty() && (dump = std::fopen(dump_path.c_str(), "w")) == nullptr) {
    std::fprintf(stderr, "cluster_choice_bench: cannot write %s\n", dump_path.c_str());
    return 2;
  }
  std::mt19937_64 rng(seed);
  std::vector<Scene> scenes;
  for (size_t b = 0; b < bodies.size(); ++b) {
    for (const Scene& s : DrawScenes(static_cast<int>(b), scenes_per_body, &rng))
      scenes.push_back(s);
  }
  std::fprintf(stderr, "cluster_choice_bench: %zu scenes on %d threads\n", scenes.size(), threads);
  std::vector<Outcome> outcomes(scenes.size());
  bench::ForEachOnThreads(threads, scenes.size(), "scene", [&]() -> std::function<void(size_t)> {
    // This thread's estimators, one per body.
    auto estimators = std::make_shared<std::vector<std::unique_ptr<Estimator>>>();
    EstimatorOptions options = DefaultEstimatorOptions();
    options.far_score_ratio = far_ratio;
    options.two_points_a_voxel_within_m = two_points_within;
    options.min_humanoid_evidence = min_evidence;
    for (const Body& b : bodies) {
      Result<std::unique_ptr<Estimator>> e = Estimator::Create(options, b.templates);
      if (!e.ok()) {
        std::fprintf(stderr, "cluster_choice_bench: %s\n", e.error().message.c_str());
        std::exit(2);
      }
      estimators->push_back(std::move(*e));
    }
    return [&, estimators](size_t i) {
      outcomes[i] = Run(scenes[i], bodies[scenes[i].body], *(*estimators)[scenes[i].body]);
    };
  });

  if (dump != nullptr && !WriteDump(dump, seed, scenes, bodies, outcomes)) {
    std::fprintf(stderr, "cluster_choice_bench: cannot write %s\n", dump_path.c_str());
    return 2;
  }
  const std::vector<Order> orders = Orders();
  const long not_estimated = std::count_if(outcomes.begin(), outcomes.end(),
                                           [](const Outcome& o) { return !o.estimated; });
  std::printf(
      "%d scenes a body (seed %llu, far_score_ratio %.2f, min_humanoid_evidence %.3f), "
      "%ld not estimated (no floor found, or not simulated); "
      "a cell: scenes whose first humanoid detection is on the robot / "
      "also within 10 degrees of its heading\n\n"
      "| body | scenes | robot among the humanoids | 2+ humanoids | clutter taken for one | "
      "… and not the robot |",
      scenes_per_body, static_cast<unsigned long long>(seed), far_ratio, min_evidence,
      not_estimated);
  for (const Order& o : orders) std::printf(" %s |", o.name.c_str());
  std::printf(" estimator's own order differs |\n|---|---|---|---|---|---|");
  for (size_t k = 0; k < orders.size(); ++k) std::printf("---|");
  std::printf("---|\n");
  for (int b = -1; b < static_cast<int>(bodies.size()); ++b) {  // -1: all bodies.
    int n = 0, robot_among = 0, several = 0, differs = 0, clutter = 0, clutter_only = 0;
    std::vector<int> cluster_ok(orders.size(), 0), pose_ok(orders.size(), 0);
    for (size_t i = 0; i < scenes.size(); ++i) {
      if (b >= 0 && scenes[i].body != b) continue;
      ++n;
      const std::vector<Seen>& h = outcomes[i].humanoids;
      if (h.empty()) continue;
      const bool robot = std::any_of(h.begin(), h.end(), [](const Seen& s) { return s.on_robot; });
      const bool other = std::any_of(h.begin(), h.end(), [](const Seen& s) { return s.off_robot; });
      robot_among += robot ? 1 : 0;
      clutter += other ? 1 : 0;
      clutter_only += other && !robot ? 1 : 0;
      several += h.size() >= 2 ? 1 : 0;
      for (size_t k = 0; k < orders.size(); ++k) {
        const Seen* first = &h[0];
        for (const Seen& s : h) {
          if (orders[k].before(s.detection.best, first->detection.best)) first = &s;
        }
        cluster_ok[k] += first->on_robot ? 1 : 0;
        pose_ok[k] += first->pose_ok ? 1 : 0;
      }
      const Seen* own = &h[0];
      for (const Seen& s : h) {
        if (DetectionBefore(s.detection, own->detection)) own = &s;
      }
      differs += own != &h[0] ? 1 : 0;
    }
    std::printf("| %s | %d | %d | %d | %d | %d |", b < 0 ? "all" : bodies[b].name.c_str(), n,
                robot_among, several, clutter, clutter_only);
    for (size_t k = 0; k < orders.size(); ++k) std::printf(" %d / %d |", cluster_ok[k], pose_ok[k]);
    std::printf(" %d |\n", differs);
  }
  return 0;
}
