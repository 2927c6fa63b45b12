// hpose beside a generic registration pipeline on the very same simulated frames: FPFH features
// matched by RANSAC (PCL's SampleConsensusPrerejective) and refined by ICP, the usual recipe for
// finding a known rigid object in a point cloud (PCL's "robust pose estimation of rigid objects"
// tutorial). For every body, mount, distance, heading and shape one frame with clutter is
// rendered with the Kinect v1 noise model and given to both:
//
// - hpose: the default estimator with both of the body's templates loaded (it chooses between
//   them); its pose is the first humanoid detection's, none when nothing passed.
// - the baseline: the cloud put in the true ground frame (an advantage: no floor fit decides the
//   frame the pose is given in), thinned on a 1 cm grid, the floor removed by a RANSAC plane fit,
//   the rest split into objects (Euclidean clusters) of about the model's size, and the right
//   template's surface (told which shape is in the frame, an advantage hpose does not get)
//   aligned to each by FPFH + RANSAC + ICP, three runs an object; of the alignments that stand
//   upright on the floor (within 15 degrees and 5 cm, as hpose's poses do), the one whose model
//   points have the most scene points near gives the pose. Flags change these choices.
//
// Both poses are compared with the truth: within 5 cm and 10 degrees counts as found; heading
// and position errors are taken over the frames whose pose lies on the robot (within 0.3 m).
// The baseline's RANSAC draws come from std::rand, seeded per object and run: with --threads 1
// its results repeat; with more, the threads' draws interleave and vary a little between runs.
// Times are per frame on one thread (hpose's estimator with one thread; the baseline's PCL
// steps are single-threaded), from the depth image to the pose, the model's features made once.
//
// usage: baseline_bench [--bodies nao,darwin_op] [--distances 1,2,3] [--step-deg D]
//                       [--clutter N] [--threads N] [--iterations N] [--restarts N]
//                       [--similarity S] [--normal-radius M] [--feature-radius M] [--leaf M]
//                       [--six-dof] [--whole-scene]
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <pcl/features/fpfh.h>
#include <pcl/features/normal_3d.h>
#include <pcl/filters/extract_indices.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/registration/icp.h>
#include <pcl/registration/sample_consensus_prerejective.h>
#include <pcl/sample_consensus/method_types.h>
#include <pcl/sample_consensus/model_types.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/extract_clusters.h>
#include <pcl/segmentation/sac_segmentation.h>

#include "bench/bench_bodies.h"
#include "bench/bench_threads.h"
#include "core/common/pose2d.h"
#include "core/depth/depth_to_cloud.h"
#include "core/search/estimator.h"
#include "core/sim/frame_simulator.h"

namespace {

using namespace hpose;
using bench::Body;
using bench::kMounts;
using Clock = std::chrono::steady_clock;

using PointN = pcl::PointNormal;
using CloudN = pcl::PointCloud<PointN>;
using Features = pcl::PointCloud<pcl::FPFHSignature33>;

// The baseline's parameters, at the scale of a 0.3-0.6 m robot seen by a Kinect (flags set them).
struct BaselineOptions {
  float leaf_m = 0.01f;               // thinning grid.
  double floor_inlier_m = 0.015;      // RANSAC plane: points this near are the floor.
  double normal_radius_m = 0.03;      // normals from neighbours within this.
  double feature_radius_m = 0.05;     // FPFH from neighbours within this.
  double match_distance_m = 0.025;    // RANSAC: an inlier is this near its match.
  double icp_distance_m = 0.02;       // ICP: pairs at most this far apart.
  double cluster_tolerance_m = 0.03;  // objects: points this near are one object.
  float similarity = 0.8f;            // RANSAC's edge-length prerejection (0.9 found fewer).
  int iterations = 20000;             // RANSAC iterations (per object).
  bool per_object = true;             // align to each object of the model's size, keep the best.
  // Standing on the floor: alignments tilted more than 15 degrees or more than 5 cm off the
  // floor are dropped (the robot stands; hpose searches only such poses).
  bool upright = true;
  int restarts = 3;  // RANSAC runs per object, from other draws; the one explaining most is kept.
};

struct Outcome {
  bool posed = false;  // the method gave a pose at all.
  double x = 0.0, y = 0.0, theta = 0.0;
  double ms = 0.0;
};

struct Trial {
  int body = 0, mount = 0, shape = 0;
  double distance_m = 1.0, theta_deg = 0.0;
  bool ran = false;  // simulated and estimated.
  Outcome hpose, baseline;
};

// A template's surface as a thinned cloud with normals pointing away from its vertical axis
// (the body is roughly a column), and its FPFH features.
struct Model {
  CloudN::Ptr points{new CloudN};
  Features::Ptr features{new Features};
  float height = 0.0f, width = 0.0f;  // highest point; widest horizontal extent.
};

CloudN::Ptr Thin(const CloudN::ConstPtr& in, const BaselineOptions& o) {
  CloudN::Ptr out(new CloudN);
  pcl::VoxelGrid<PointN> grid;
  grid.setLeafSize(o.leaf_m, o.leaf_m, o.leaf_m);
  grid.setInputCloud(in);
  grid.filter(*out);
  return out;
}

void Normals(const CloudN::Ptr& cloud, const Eigen::Vector3f& viewpoint, const BaselineOptions& o) {
  pcl::NormalEstimation<PointN, PointN> ne;
  ne.setRadiusSearch(o.normal_radius_m);
  ne.setViewPoint(viewpoint.x(), viewpoint.y(), viewpoint.z());
  ne.setInputCloud(cloud);
  ne.compute(*cloud);
}

Features::Ptr Fpfh(const CloudN::Ptr& cloud, const BaselineOptions& o) {
  Features::Ptr out(new Features);
  pcl::FPFHEstimation<PointN, PointN, pcl::FPFHSignature33> fe;
  fe.setRadiusSearch(o.feature_radius_m);
  fe.setInputCloud(cloud);
  fe.setInputNormals(cloud);
  fe.compute(*out);
  return out;
}

Model MakeModel(const VoxelTemplate& tpl, const BaselineOptions& o) {
  CloudN::Ptr raw(new CloudN);
  Eigen::Vector2f centre = Eigen::Vector2f::Zero();
  for (const Eigen::Vector3f& p : tpl.surface) {
    PointN q;
    q.x = p.x(), q.y = p.y(), q.z = p.z();
    raw->push_back(q);
    centre += p.head<2>();
  }
  centre /= std::max<size_t>(1, tpl.surface.size());
  Model m;
  m.points = Thin(raw, o);
  Normals(m.points, Eigen::Vector3f(centre.x(), centre.y(), 0.0f), o);
  for (PointN& q : m.points->points) {  // outwards, away from the body's axis.
    const Eigen::Vector2f out(q.x - centre.x(), q.y - centre.y());
    if (out.x() * q.normal_x + out.y() * q.normal_y < 0.0f) {
      q.normal_x = -q.normal_x, q.normal_y = -q.normal_y, q.normal_z = -q.normal_z;
    }
  }
  m.features = Fpfh(m.points, o);
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(1e9f), hi = -lo;
  for (const Eigen::Vector3f& p : tpl.surface) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  m.height = hi.z();
  m.width = (hi - lo).head<2>().norm();
  return m;
}

double MsSince(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

// Model points placed by `t` with a target point within the ICP's pairing distance.
int Explained(const Model& model, const pcl::search::KdTree<PointN>& tree, const Eigen::Matrix4f& t,
              const BaselineOptions& o) {
  int n = 0;
  std::vector<int> index(1);
  std::vector<float> d2(1);
  const float r2 = static_cast<float>(o.icp_distance_m * o.icp_distance_m);
  for (const PointN& p : model.points->points) {
    PointN q;
    q.getVector3fMap() = t.topLeftCorner<3, 3>() * p.getVector3fMap() + t.topRightCorner<3, 1>();
    if (tree.nearestKSearch(q, 1, index, d2) == 1 && d2[0] <= r2) ++n;
  }
  return n;
}

// The model aligned to `target` (with normals): RANSAC on FPFH matches, then ICP, a few times
// from other draws. The model-to-target transform of the run whose model points have the most
// target points near (as a negative count in `fitness`: lower is better); false when no run
// gave an alignment (upright, with BaselineOptions::upright).
bool Align(const Model& model, const CloudN::Ptr& target, unsigned seed, const BaselineOptions& o,
           Eigen::Matrix4f* pose, double* fitness) {
  const Features::Ptr features = Fpfh(target, o);
  pcl::search::KdTree<PointN>::Ptr tree(new pcl::search::KdTree<PointN>);
  tree->setInputCloud(target);
  bool any = false;
  for (int run = 0; run < o.restarts; ++run) {
    std::srand(seed + 7919u * run);  // the RANSAC draws (std::rand) of this run.
    CloudN aligned;
    pcl::SampleConsensusPrerejective<PointN, PointN, pcl::FPFHSignature33> ransac;
    ransac.setInputSource(model.points);
    ransac.setSourceFeatures(model.features);
    ransac.setInputTarget(target);
    ransac.setTargetFeatures(features);
    ransac.setMaximumIterations(o.iterations);
    ransac.setNumberOfSamples(3);
    ransac.setCorrespondenceRandomness(5);
    ransac.setSimilarityThreshold(o.similarity);
    ransac.setMaxCorrespondenceDistance(o.match_distance_m);
    ransac.setInlierFraction(0.25f);
    ransac.align(aligned);
    if (!ransac.hasConverged()) continue;
    pcl::IterativeClosestPoint<PointN, PointN> icp;
    icp.setInputSource(model.points);
    icp.setInputTarget(target);
    icp.setMaxCorrespondenceDistance(o.icp_distance_m);
    icp.setMaximumIterations(50);
    icp.align(aligned, ransac.getFinalTransformation());
    const Eigen::Matrix4f t =
        icp.hasConverged() ? icp.getFinalTransformation() : ransac.getFinalTransformation();
    // The alignment's worth: how many model points have a target point within the ICP's
    // pairing distance (more is better; a small object fits closely but explains little).
    const double fit = -static_cast<double>(Explained(model, *tree, t, o));
    if (o.upright && (t(2, 2) < std::cos(15.0 * kPi / 180.0) || std::abs(t(2, 3)) > 0.05f)) {
      continue;
    }
    if (!any || fit < *fitness) {
      *pose = t;
      *fitness = fit;
      any = true;
    }
  }
  return any;
}

// The generic pipeline on one depth frame; the pose of the model in the ground frame.
Outcome Baseline(const DepthImage& depth, const Intrinsics& k, const FloorEstimate& truth,
                 const Model& model, unsigned seed, const BaselineOptions& o) {
  Outcome out;
  const Clock::time_point t0 = Clock::now();
  Result<PointCloud> sensor = DepthToCloud(depth, k);
  if (!sensor.ok()) {
    out.ms = MsSince(t0);
    return out;
  }
  CloudN::Ptr scene(new CloudN);
  scene->reserve(sensor->size());
  const Eigen::Affine3f g = truth.ground_from_sensor.cast<float>();
  for (const Eigen::Vector3f& p : sensor->points) {
    const Eigen::Vector3f q = g * p;
    PointN n;
    n.x = q.x(), n.y = q.y(), n.z = q.z();
    scene->push_back(n);
  }
  scene = Thin(scene, o);
  // The floor: the largest plane.
  pcl::ModelCoefficients coefficients;
  pcl::PointIndices::Ptr floor(new pcl::PointIndices);
  pcl::SACSegmentation<PointN> seg;
  seg.setModelType(pcl::SACMODEL_PLANE);
  seg.setMethodType(pcl::SAC_RANSAC);
  seg.setDistanceThreshold(o.floor_inlier_m);
  seg.setMaxIterations(200);
  seg.setInputCloud(scene);
  seg.segment(*floor, coefficients);
  CloudN::Ptr objects(new CloudN);
  pcl::ExtractIndices<PointN> extract;
  extract.setInputCloud(scene);
  extract.setIndices(floor);
  extract.setNegative(true);
  extract.filter(*objects);
  if (objects->size() < 10) {
    out.ms = MsSince(t0);
    return out;
  }
  Normals(objects, truth.ground_from_sensor.translation().cast<float>(), o);

  // The targets: the whole scene, or each object about the model's size.
  std::vector<CloudN::Ptr> targets;
  if (!o.per_object) {
    targets.push_back(objects);
  } else {
    pcl::search::KdTree<PointN>::Ptr tree(new pcl::search::KdTree<PointN>);
    std::vector<pcl::PointIndices> found;
    pcl::EuclideanClusterExtraction<PointN> ec;
    ec.setClusterTolerance(o.cluster_tolerance_m);
    ec.setMinClusterSize(30);
    ec.setSearchMethod(tree);
    ec.setInputCloud(objects);
    ec.extract(found);
    for (const pcl::PointIndices& idx : found) {
      CloudN::Ptr c(new CloudN);
      Eigen::Vector3f lo = Eigen::Vector3f::Constant(1e9f), hi = -lo;
      for (int i : idx.indices) {
        c->push_back(objects->points[i]);
        lo = lo.cwiseMin(objects->points[i].getVector3fMap());
        hi = hi.cwiseMax(objects->points[i].getVector3fMap());
      }
      // Of the model's size: not half as high, nor twice as wide.
      if (hi.z() < 0.5f * model.height || (hi - lo).head<2>().norm() > 2.0f * model.width) continue;
      targets.push_back(c);
    }
  }
  double best = std::numeric_limits<double>::infinity();
  Eigen::Matrix4f t = Eigen::Matrix4f::Identity();
  for (size_t i = 0; i < targets.size(); ++i) {
    Eigen::Matrix4f pose;
    double fitness = 0.0;
    if (Align(model, targets[i], seed * 131u + static_cast<unsigned>(i), o, &pose, &fitness) &&
        fitness < best) {
      best = fitness;
      t = pose;
    }
  }
  out.ms = MsSince(t0);
  if (!std::isfinite(best)) return out;
  out.posed = true;
  out.x = t(0, 3);
  out.y = t(1, 3);
  out.theta = std::atan2(t(1, 0), t(0, 0));
  return out;
}

Outcome Hpose(Estimator& estimator, const DepthImage& depth, const Intrinsics& k) {
  Outcome o;
  const Clock::time_point t0 = Clock::now();
  Result<Estimate> e = estimator.EstimateDepth(depth, k);
  o.ms = MsSince(t0);
  if (!e.ok() || e->detections.empty() || !e->detections.front().is_humanoid) return o;
  const Pose2D& p = e->detections.front().best.pose;
  o.posed = true;
  o.x = p.x, o.y = p.y, o.theta = p.theta;
  return o;
}

double Quantile(std::vector<double> v, double q) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  return v[static_cast<size_t>(q * (v.size() - 1) + 0.5)];
}

// Errors of one outcome against its trial: heading (degrees, absolute) and position (mm).
struct Errors {
  bool on_robot = false;  // within 0.3 m of the truth.
  bool found = false;     // within 5 cm and 10 degrees.
  double theta_deg = 0.0, pos_mm = 0.0;
};

Errors Compare(const Outcome& o, const Trial& t) {
  Errors e;
  if (!o.posed) return e;
  const double d = std::hypot(o.x - t.distance_m, o.y);
  e.on_robot = d < 0.3;
  e.pos_mm = 1000.0 * d;
  e.theta_deg = std::abs(AngleDiff(o.theta, t.theta_deg * kPi / 180.0)) * 180.0 / kPi;
  e.found = d < 0.05 && e.theta_deg < 10.0;
  return e;
}

struct Row {
  int frames = 0, found = 0, on_robot = 0, within3 = 0, within5 = 0, flips = 0;
  std::vector<double> theta, pos, ms;
};

void Add(Row* r, const Outcome& o, const Trial& t) {
  const Errors e = Compare(o, t);
  ++r->frames;
  r->ms.push_back(o.ms);
  if (e.found) ++r->found;
  if (!e.on_robot) return;
  ++r->on_robot;
  if (e.theta_deg <= 3.0) ++r->within3;
  if (e.theta_deg <= 5.0) ++r->within5;
  if (e.theta_deg > 90.0) ++r->flips;
  r->theta.push_back(e.theta_deg);
  r->pos.push_back(e.pos_mm);
}

void PrintRow(const char* body, const char* mount, const char* method, const Row& r) {
  const double n = std::max(1, r.frames);
  std::printf(
      "| %s | %s | %s | %d | %.1f%% | %.1f%% | %.1f%% | %.1f%% | %d | %.2f | %.1f | %.1f / %.1f "
      "|\n",
      body, mount, method, r.frames, 100.0 * r.found / n, 100.0 * r.on_robot / n,
      100.0 * r.within3 / n, 100.0 * r.within5 / n, r.flips, Quantile(r.theta, 0.5),
      Quantile(r.pos, 0.5), Quantile(r.ms, 0.5), Quantile(r.ms, 0.9));
}

}  // namespace

int main(int argc, char** argv) {
  BaselineOptions o;
  int clutter = 3, threads = 2, step_deg = 30;
  std::vector<double> distances = {1.0, 1.5, 2.0, 2.5, 3.0, 3.5};
  std::vector<std::string> body_names = {"nao", "darwin_op"};
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const std::string v = i + 1 < argc ? argv[i + 1] : "";
    if (a == "--clutter" && !v.empty()) {
      clutter = std::atoi(v.c_str()), ++i;
    } else if (a == "--threads" && !v.empty()) {
      threads = std::max(1, std::atoi(v.c_str())), ++i;
    } else if (a == "--step-deg" && !v.empty()) {
      step_deg = std::max(1, std::atoi(v.c_str())), ++i;
    } else if (a == "--iterations" && !v.empty()) {
      o.iterations = std::max(1, std::atoi(v.c_str())), ++i;
    } else if (a == "--normal-radius" && !v.empty()) {
      o.normal_radius_m = std::atof(v.c_str()), ++i;
    } else if (a == "--feature-radius" && !v.empty()) {
      o.feature_radius_m = std::atof(v.c_str()), ++i;
    } else if (a == "--similarity" && !v.empty()) {
      o.similarity = static_cast<float>(std::atof(v.c_str())), ++i;
    } else if (a == "--leaf" && !v.empty()) {
      o.leaf_m = static_cast<float>(std::atof(v.c_str())), ++i;
    } else if (a == "--whole-scene") {
      o.per_object = false;
    } else if (a == "--six-dof") {
      o.upright = false;
    } else if (a == "--restarts" && !v.empty()) {
      o.restarts = std::max(1, std::atoi(v.c_str())), ++i;
    } else if (a == "--distances" && !v.empty()) {
      distances.clear();
      for (const std::string& d : bench::ParseNames(v)) distances.push_back(std::atof(d.c_str()));
      ++i;
    } else if (a == "--bodies" && !v.empty()) {
      body_names = bench::ParseNames(v), ++i;
    } else {
      std::fprintf(stderr,
                   "usage: baseline_bench [--bodies nao,darwin_op] [--distances 1,2,3]\n"
                   "                      [--step-deg D] [--clutter N] [--threads N]\n"
                   "                      [--iterations N] [--restarts N] [--similarity S]\n"
                   "                      [--normal-radius M] [--feature-radius M] [--leaf M]\n"
                   "                      [--six-dof] [--whole-scene]\n"
                   "  hpose and a generic FPFH + RANSAC + ICP pipeline on the same simulated\n"
                   "  frames (two mounts, headings every D degrees (30), two shapes, N clutter\n"
                   "  objects (3)); frames run N at a time (2), each method on one thread.\n"
                   "  --bodies: nao, long_legs, tall, darwin_op (needs the shared data)\n"
                   "  the baseline: --iterations RANSAC iterations a run (20000), --restarts\n"
                   "  runs an object (3), --similarity edge-length prerejection (0.8),\n"
                   "  --normal-radius (0.03), --feature-radius FPFH (0.05), --leaf grid (0.01 m),\n"
                   "  --six-dof keeps poses that do not stand on the floor, --whole-scene aligns\n"
                   "  to the whole scene instead of each object of the model's size\n");
      return a == "--help" ? 0 : 2;
    }
  }
  std::vector<Body> bodies;
  for (const std::string& name : body_names) {
    Result<Body> body = bench::BodyByName(name, HPOSE_SHARED_DATA_DIR, HPOSE_SOURCE_DIR);
    if (!body.ok()) {
      std::fprintf(stderr, "baseline_bench: skipping %s (%s)\n", name.c_str(),
                   body.error().message.c_str());
      continue;
    }
    bodies.push_back(*body);
  }
  if (bodies.empty()) {
    std::fprintf(stderr, "baseline_bench: no body to render\n");
    return 1;
  }
  std::vector<std::vector<Model>> models(bodies.size());
  for (size_t b = 0; b < bodies.size(); ++b) {
    for (const VoxelTemplate& tpl : bodies[b].templates) models[b].push_back(MakeModel(tpl, o));
  }

  std::vector<Trial> trials;
  for (int b = 0; b < static_cast<int>(bodies.size()); ++b) {
    for (int m = 0; m < 2; ++m) {
      for (double d : distances) {
        for (int deg = -180; deg < 180; deg += step_deg) {
          for (int shape = 0; shape < 2; ++shape) {
            Trial t;
            t.body = b, t.mount = m, t.shape = shape, t.distance_m = d, t.theta_deg = deg;
            trials.push_back(t);
          }
        }
      }
    }
  }
  std::fprintf(stderr, "baseline_bench: %zu frames on %d thread(s)\n", trials.size(), threads);

  const Intrinsics intrinsics = Intrinsics::KinectV1(640, 480);
  std::atomic<size_t> failed{0};
  bench::ForEachOnThreads(threads, trials.size(), "frame", [&]() -> std::function<void(size_t)> {
    // This thread's estimators, one per body.
    auto estimators = std::make_shared<std::vector<std::unique_ptr<Estimator>>>();
    for (const Body& body : bodies) {
      estimators->push_back(Estimator::Create(DefaultEstimatorOptions(), body.templates).value());
    }
    return [&, estimators](size_t i) {
      Trial& t = trials[i];
      Result<SimulatedFrame> frame = SimulateFrame(bench::TrialFrame(
          bodies[t.body], t.shape, t.mount, t.distance_m, t.theta_deg, clutter, 1000 + i));
      if (!frame.ok()) {
        ++failed;
        return;
      }
      t.hpose = Hpose(*(*estimators)[t.body], frame->depth, intrinsics);
      t.baseline = Baseline(frame->depth, intrinsics, frame->sensor_mount, models[t.body][t.shape],
                            static_cast<unsigned>(i + 1), o);
      t.ran = true;
    };
  });

  std::printf("clutter %d, headings every %d°, two shapes, distances", clutter, step_deg);
  for (double d : distances) std::printf(" %.1f", d);
  std::printf(
      " m; baseline: %s, %s, %d run(s) an object, %.0f mm grid, normals %.0f mm, FPFH %.0f mm, "
      "similarity %.2f, %d RANSAC "
      "iterations; %zu frame(s) could not be simulated (left out)\n\n",
      o.per_object ? "each object of the model's size" : "the whole scene",
      o.upright ? "upright poses on the floor" : "any 6-DoF pose", o.restarts, 1000.0 * o.leaf_m,
      1000.0 * o.normal_radius_m, 1000.0 * o.feature_radius_m, o.similarity, o.iterations,
      failed.load());
  std::printf(
      "| body | mount | method | frames | found (5 cm, 10°) | on the robot (0.3 m) | θ ≤ 3° | θ ≤ "
      "5° | "
      "flips | median abs θ (°) | median pos (mm) | ms median / p90 |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  Row all_hpose, all_baseline;
  for (size_t b = 0; b < bodies.size(); ++b) {
    for (int m = 0; m < 2; ++m) {
      Row h, g;
      for (const Trial& t : trials) {
        if (t.body != static_cast<int>(b) || t.mount != m || !t.ran) continue;
        Add(&h, t.hpose, t);
        Add(&g, t.baseline, t);
        Add(&all_hpose, t.hpose, t);
        Add(&all_baseline, t.baseline, t);
      }
      PrintRow(bodies[b].name.c_str(), kMounts[m].name, "hpose", h);
      PrintRow(bodies[b].name.c_str(), kMounts[m].name, "FPFH + RANSAC + ICP", g);
    }
  }
  PrintRow("all", "both", "hpose", all_hpose);
  PrintRow("all", "both", "FPFH + RANSAC + ICP", all_baseline);
  std::printf(
      "\nBy distance, all bodies and mounts (θ ≤ 5° and found: of all frames; ms: median):\n\n"
      "| distance | frames | hpose θ ≤ 5° | baseline θ ≤ 5° | hpose found | baseline found | "
      "hpose ms | baseline ms |\n|---|---|---|---|---|---|---|---|\n");
  for (double d : distances) {
    Row h, g;
    for (const Trial& t : trials) {
      if (t.distance_m != d || !t.ran) continue;
      Add(&h, t.hpose, t);
      Add(&g, t.baseline, t);
    }
    const double n = std::max(1, h.frames);
    std::printf("| %.1f m | %d | %.1f%% | %.1f%% | %.1f%% | %.1f%% | %.1f | %.1f |\n", d, h.frames,
                100.0 * h.within5 / n, 100.0 * g.within5 / n, 100.0 * h.found / n,
                100.0 * g.found / n, Quantile(h.ms, 0.5), Quantile(g.ms, 0.5));
  }
  std::printf(
      "\nθ and position: of the frames whose pose lies on the robot; θ ≤ 3° / 5° and found: of "
      "all frames. Median time, baseline / hpose: %.1fx\n",
      Quantile(all_baseline.ms, 0.5) / Quantile(all_hpose.ms, 0.5));
  return 0;
}
