// End-to-end time of the depth-template estimator per stage on simulated 640x480 Kinect v1
// frames with clutter and the two shipped templates, variants side by side: every frame goes
// through every variant in turn, so drift on a shared machine hits all alike.
//
// Two sets of frames:
//  - scattered: unrelated frames, humanoid 0.9-3.5 m away (--max-distance), headings spread
//    over the circle, both presets: every variant searches cold;
//  - a walk (--sequence N): consecutive frames of a humanoid walking and turning among fixed
//    clutter, estimated cold and with tracking (PoseTracker: each frame seeded with the last).
//
// Per variant: median / p90 (and p99 of the total) wall time of each stage, CPU time per frame
// (all threads), branch-and-bound bounds per frame, how many frames found the humanoid within 5
// cm and 10 degrees, and a digest of every candidate's optimum and runner-up (template, cluster,
// pose, scores; see MixEstimate): equal digests mean equal results; and a digest of each
// frame's humanoids alone (MixHumanoids), equal where variants differ only in candidates no
// humanoid takes. Every variant makes its
// search tables at start (make_tables_at_start, as the daemon does) unless its name says
// otherwise. Pin it to one core for the documented numbers:
//   taskset -c 0 frame_bench [--frames N] [--sequence N] [--clutter N] [--max-distance M]
//                            [--repeat N] [--only VARIANT] [--frames-detail] [--dump]
//                            [--body NAME] [--sensor-height M] [--pitch-deg D] [--walk-far M]
//                            [--noise-correlation SHARE] [--cloud FILE]... [--pick I,J,...]
//                            [--extra-pose NAME]
// With --cloud, recorded point clouds (no truth) go through the scattered frames' variants too,
// each cold, --repeat times. With --repeat 2 or more, a second table sets each frame's least
// total over its runs beside the totals of every run (LeastOfRuns).
// With --body other than nao the humanoid has those proportions and the two templates are made
// from them (BodyTemplates) instead of the shipped ones. --extra-pose NAME adds a third
// template in that joint preset (what searching it costs where no robot holds it).
#include <sys/resource.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include "bench/bench_bodies.h"
#include "bench/bench_frames.h"
#include "core/io/cloud_io.h"
#include "core/search/detection_order.h"
#include "core/search/estimator.h"
#include "core/search/humanoid_view.h"
#include "core/search/pose_tracker.h"

namespace hpose::bench {
namespace {

struct Variant {
  std::string name;
  std::function<void(EstimatorOptions*)> configure;
  bool tracking = false;  // walk only: estimate through a PoseTracker.
  std::unique_ptr<Estimator> estimator;
  std::unique_ptr<PoseTracker> tracker;
  std::vector<double> cloud, floor, cluster, search, refine, total, cpu, bounds;
  std::vector<double> refine_humanoid;  // the refinement of the humanoid's cluster alone.
  std::map<int, std::vector<double>> total_by_distance;  // decimetres -> total ms.
  std::map<int, std::pair<int, int>> found_by_distance;  // half metres -> (found, frames).
  int found = 0;
  int false_humanoids = 0;  // humanoid detections more than 0.3 m from the truth.
  int frames = 0;
  int tracked = 0;
  int searches = 0;  // recorded clouds: (cluster, template) searches of the first run.
  std::uint64_t digest = 1469598103934665603ull;  // FNV-1a.
  // Of what a reader is given: each frame's humanoids (MixHumanoids).
  std::uint64_t humanoid_digest = 1469598103934665603ull;
};

void Mix(std::uint64_t* h, const void* data, size_t n) {
  const unsigned char* p = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < n; ++i) {
    *h ^= p[i];
    *h *= 1099511628211ull;
  }
}

// What the search defines: every candidate's optimum and runner-up, not what depends on the
// order in which blocks were bounded (the bound a search stopped below the threshold with, the
// best pose it had evaluated by then, the bound of a runner-up that reaches no threshold), in
// the order of clusters and templates (candidates come sorted by score, which a stopped
// search's best evaluated pose takes part in).
void MixEstimate(std::uint64_t* h, const Estimate& e) {
  std::vector<const Candidate*> sorted;
  for (const Candidate& c : e.candidates) sorted.push_back(&c);
  std::sort(sorted.begin(), sorted.end(), [](const Candidate* a, const Candidate* b) {
    return std::tie(a->cluster_index, a->template_name) <
           std::tie(b->cluster_index, b->template_name);
  });
  for (const Candidate* cp : sorted) {
    const Candidate& c = *cp;
    Mix(h, c.template_name.data(), c.template_name.size());
    const int ints[] = {c.cluster_index, c.cluster_voxels, c.stopped_below_threshold ? 1 : 0,
                        c.has_runner_up ? 1 : 0};
    Mix(h, ints, sizeof ints);
    if (c.stopped_below_threshold) continue;
    const double values[] = {c.pose.x, c.pose.y, c.pose.theta, c.score, c.coverage};
    Mix(h, values, sizeof values);
    const int hits[] = {c.hits, c.free_space_hits};
    Mix(h, hits, sizeof hits);
    if (!c.has_runner_up) continue;
    const double runner[] = {c.runner_up_pose.x, c.runner_up_pose.y, c.runner_up_pose.theta,
                             c.runner_up_score};
    Mix(h, runner, sizeof runner);
  }
  for (const ClusterSummary& s : e.clusters) {
    const int ints[] = {s.index, s.points, s.searched ? 1 : 0};
    Mix(h, ints, sizeof ints);
    Mix(h, s.centroid.data(), sizeof(float) * 3);
  }
}

// What a reader of the estimate is given: each humanoid's template, cluster, pose and heading
// flags, in their order. Equal where variants differ only in candidates no humanoid takes.
void MixHumanoids(std::uint64_t* h, const Estimate& e) {
  const int count = static_cast<int>(e.Humanoids().size());
  Mix(h, &count, sizeof count);
  for (const Detection& d : e.Humanoids()) {
    const Candidate& c = d.best;
    Mix(h, c.template_name.data(), c.template_name.size());
    const int ints[] = {c.cluster_index, c.heading_ambiguous ? 1 : 0, c.refined ? 1 : 0};
    Mix(h, ints, sizeof ints);
    const double values[] = {c.pose.x, c.pose.y, c.pose.theta};
    Mix(h, values, sizeof values);
  }
}

double CpuMs() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return 1e3 * static_cast<double>(ts.tv_sec) + 1e-6 * static_cast<double>(ts.tv_nsec);
}

// The process's page faults so far that needed no disk (a page's first touch, mostly).
long MinorFaults() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_minflt;
}

// "median / p90" with `decimals` digits after the point.
std::string Cell(const std::vector<double>& v, int decimals = 1) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f / %.*f", decimals, Median(v), decimals, Percentile(v, 90.0));
  return buf;
}

struct Frames {
  std::vector<FrameSpec> specs;
  std::vector<SimulatedFrame> sims;
};

Result<Frames> Render(std::vector<FrameSpec> specs) {
  Frames f;
  f.specs = std::move(specs);
  for (const FrameSpec& s : f.specs) {
    Result<SimulatedFrame> frame = SimulateFrame(s);
    if (!frame.ok()) return frame.error();
    f.sims.push_back(std::move(*frame));
  }
  return f;
}

struct RunFlags {
  bool detail = false;
  bool dump = false;
  int repeat = 1;
};

// What refining the candidates of the humanoid's cluster took (the cluster whose centroid is
// nearest the true pose, within 0.3 m), or -1 when none of them was refined (the humanoid scored
// below the threshold): the refinement per humanoid, which the frame's refinement exceeds by the
// clutter that scores above the threshold too.
double HumanoidRefineMs(const Estimate& e, const Pose2D& truth) {
  int nearest = -1;
  double best = 0.3;
  for (const ClusterSummary& s : e.clusters) {
    const double d = std::hypot(s.centroid.x() - truth.x, s.centroid.y() - truth.y);
    if (d < best) {
      best = d;
      nearest = s.index;
    }
  }
  double ms = -1.0;
  for (const Candidate& c : e.candidates) {
    if (c.cluster_index == nearest && c.refined) ms = std::max(ms, 0.0) + c.refine_ms;
  }
  return ms;
}

// Adds an estimate's stage times and bounds (thousands) to the variant's.
void RecordStages(const Estimate& e, Variant* v) {
  const StageTimings& t = e.timings;
  v->cloud.push_back(t.cloud_ms);
  v->floor.push_back(t.floor_ms);
  v->cluster.push_back(t.cluster_ms);
  v->search.push_back(t.search_ms);
  v->refine.push_back(t.refine_ms);
  v->total.push_back(t.total_ms);
  double bounds = 0.0;
  for (const Candidate& c : e.candidates) bounds += static_cast<double>(c.bounds_evaluated);
  v->bounds.push_back(bounds / 1000.0);
}

// Runs every frame through every variant (frame-major), collecting times and results.
Status RunAll(const Frames& frames, const RunFlags& flags, std::vector<Variant>* variants) {
  for (int r = 0; r < flags.repeat; ++r) {
    for (Variant& v : *variants) {
      if (v.tracker) v.tracker->Reset();
    }
    for (size_t f = 0; f < frames.sims.size(); ++f) {
      const FrameSpec& spec = frames.specs[f];
      for (Variant& v : *variants) {
        const double cpu0 = CpuMs();
        const long faults0 = MinorFaults();
        Result<Estimate> e =
            v.tracker ? v.tracker->EstimateDepth(frames.sims[f].depth, spec.intrinsics)
                      : v.estimator->EstimateDepth(frames.sims[f].depth, spec.intrinsics);
        const double cpu = CpuMs() - cpu0;
        const long faults = MinorFaults() - faults0;
        if (!e.ok()) {
          return MakeError(e.error().code,
                           "frame " + std::to_string(f) + ", " + v.name + ": " + e.error().message);
        }
        const StageTimings& t = e->timings;
        RecordStages(*e, &v);
        const double humanoid_refine_ms = HumanoidRefineMs(*e, spec.humanoid_pose);
        if (humanoid_refine_ms >= 0.0) v.refine_humanoid.push_back(humanoid_refine_ms);
        v.cpu.push_back(cpu);
        const Pose2D& truth = spec.humanoid_pose;
        const int decimetres = static_cast<int>(std::lround(10.0 * std::hypot(truth.x, truth.y)));
        v.total_by_distance[decimetres].push_back(t.total_ms);
        if (r > 0) continue;
        ++v.frames;
        v.tracked += e->tracking.tracked ? 1 : 0;
        MixEstimate(&v.digest, *e);
        MixHumanoids(&v.humanoid_digest, *e);
        if (flags.dump) {
          for (const Candidate& c : e->candidates) {
            std::printf(
                "dump %s frame %zu cluster %d %s: x %.4f y %.4f theta %.4f score %.4f "
                "hits %d free %d bound %d runner %d %.4f bounds %lld poses %lld fit %.1f "
                "runner-up fit %.1f refine %.2f ms\n",
                v.name.c_str(), f, c.cluster_index, c.template_name.c_str(), c.pose.x, c.pose.y,
                c.pose.theta, c.score, c.hits, c.free_space_hits, c.stopped_below_threshold ? 1 : 0,
                c.has_runner_up ? 1 : 0, c.runner_up_score,
                static_cast<long long>(c.bounds_evaluated),
                static_cast<long long>(c.poses_evaluated), c.fit.fit, c.runner_up_fit.fit,
                c.refine_ms);
          }
          for (const Detection& d : e->detections) {
            const Pose2D& p = d.best.pose;
            std::printf(
                "dump %s frame %zu detection cluster %d %s: humanoid %d refused %d threshold "
                "%.1f score %.4f fit %.1f evidence %.4f truth %.3f m\n",
                v.name.c_str(), f, d.best.cluster_index, d.best.template_name.c_str(),
                d.is_humanoid ? 1 : 0, static_cast<int>(d.refused_by), d.score_threshold,
                d.best.score, d.best.fit.fit, HumanoidEvidenceShare(d.best),
                std::hypot(p.x - truth.x, p.y - truth.y));
          }
        }
        const HumanoidView humans = e->Humanoids();
        for (const Detection& d : humans) {
          const Pose2D& p = d.best.pose;
          if (std::hypot(p.x - truth.x, p.y - truth.y) > 0.3) ++v.false_humanoids;
        }
        bool ok = false;
        if (!humans.empty()) {
          const Pose2D& p = humans.front().best.pose;
          ok = std::hypot(p.x - truth.x, p.y - truth.y) < 0.05 &&
               std::abs(AngleDiff(p.theta, truth.theta)) < DegToRad(10.0);
        }
        v.found += ok ? 1 : 0;
        const double distance = std::hypot(truth.x, truth.y);
        auto& [found_here, frames_here] = v.found_by_distance[static_cast<int>(2.0 * distance)];
        found_here += ok ? 1 : 0;
        ++frames_here;
        if (flags.detail) {
          std::printf(
              "frame %2zu %-16s %-34s %.2f m clusters %zu searches %zu total %.1f ms (search "
              "%.1f, refinement %.1f, bounds %.1fk, page faults %ld)%s%s\n",
              f, spec.preset.c_str(), v.name.c_str(), distance, e->clusters.size(),
              e->candidates.size(), t.total_ms, t.search_ms - t.refine_ms, t.refine_ms,
              v.bounds.back(), faults, e->tracking.tracked ? "  (tracked)" : "",
              ok ? "" : "  (humanoid missed)");
        }
      }
    }
  }
  return Status::Ok();
}

// Runs every cloud through every variant (cloud-major), cold, `repeat` times.
Status RunClouds(const std::vector<PointCloud>& clouds, const RunFlags& flags,
                 std::vector<Variant>* variants) {
  for (int r = 0; r < flags.repeat; ++r) {
    for (size_t f = 0; f < clouds.size(); ++f) {
      for (Variant& v : *variants) {
        Result<Estimate> e = v.estimator->EstimateCloud(clouds[f]);
        if (!e.ok()) {
          return MakeError(e.error().code,
                           "cloud " + std::to_string(f) + ", " + v.name + ": " + e.error().message);
        }
        RecordStages(*e, &v);
        if (r > 0) continue;
        ++v.frames;
        v.found += static_cast<int>(e->Humanoids().size());
        v.searches += static_cast<int>(e->candidates.size());
        MixEstimate(&v.digest, *e);
      }
    }
  }
  return Status::Ok();
}

// The clouds' table: no truth, so the humanoids detected rather than found.
void PrintCloudTable(const std::vector<Variant>& variants) {
  std::printf(
      "| variant | floor | clustering | search (incl. refinement) | refinement | total | total "
      "p99 | bounds (k) | searches | humanoids detected | digest |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const Variant& v : variants) {
    std::printf("| %s | %s | %s | %s | %s | %s | %.1f | %s | %d | %d | %016llx |\n", v.name.c_str(),
                Cell(v.floor).c_str(), Cell(v.cluster).c_str(), Cell(v.search).c_str(),
                Cell(v.refine, 2).c_str(), Cell(v.total).c_str(), Percentile(v.total, 99.0),
                Cell(v.bounds).c_str(), v.searches, v.found,
                static_cast<unsigned long long>(v.digest));
  }
}

void PrintTable(const std::vector<Variant>& variants) {
  std::printf(
      "| variant | cloud | floor | clustering | search (incl. refinement) | refinement | "
      "refinement, humanoid's cluster | total | total p99 | CPU per frame | bounds (k) | tracked "
      "| humanoid found | other humanoids | digest | humanoid digest |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const Variant& v : variants) {
    std::printf(
        "| %s | %s | %s | %s | %s | %s | %s | %s | %.1f | %s | %s | %d | %d / %d | %d | %016llx "
        "| %016llx |\n",
        v.name.c_str(), Cell(v.cloud).c_str(), Cell(v.floor).c_str(), Cell(v.cluster).c_str(),
        Cell(v.search).c_str(), Cell(v.refine, 2).c_str(), Cell(v.refine_humanoid, 2).c_str(),
        Cell(v.total).c_str(), Percentile(v.total, 99.0), Cell(v.cpu).c_str(),
        Cell(v.bounds).c_str(), v.tracked, v.found, v.frames, v.false_humanoids,
        static_cast<unsigned long long>(v.digest),
        static_cast<unsigned long long>(v.humanoid_digest));
  }
}

// Each frame's least total over the runs (`total` holds run after run of the same frames): what
// a frame costs where the host took nothing from it in at least one run. A shared host (a
// virtual machine among others) stretches single runs by tens of percent; the least of a few
// runs leaves out its short interruptions, not a load that lasts the whole run.
std::vector<double> LeastOfRuns(const std::vector<double>& total, int runs) {
  const size_t frames = runs > 0 ? total.size() / static_cast<size_t>(runs) : 0;
  std::vector<double> least(frames);
  for (size_t f = 0; f < frames; ++f) {
    least[f] = total[f];
    for (int r = 1; r < runs; ++r) least[f] = std::min(least[f], total[r * frames + f]);
  }
  return least;
}

// Per variant, the median / p90 and p99 of the frames' totals as measured (every run) and as
// the least of the runs, side by side.
void PrintLeastOfRuns(const std::vector<Variant>& variants, int runs) {
  if (runs < 2) return;
  std::printf(
      "\nTotal ms per frame, every run against each frame's least of its %d runs (the same "
      "frames and results):\n\n| variant | total, every run | p99 | total, least of the runs "
      "| p99 |\n|---|---|---|---|---|\n",
      runs);
  for (const Variant& v : variants) {
    const std::vector<double> least = LeastOfRuns(v.total, runs);
    std::printf("| %s | %s | %.1f | %s | %.1f |\n", v.name.c_str(), Cell(v.total).c_str(),
                Percentile(v.total, 99.0), Cell(least).c_str(), Percentile(least, 99.0));
  }
}

// Median total per distance (rounded to 0.1 m), one column per variant.
void PrintByDistance(const std::vector<Variant>& variants) {
  std::printf("\nMedian total ms by distance of the humanoid from the sensor:\n\n| distance |");
  for (const Variant& v : variants) std::printf(" %s |", v.name.c_str());
  std::printf("\n|---|");
  for (size_t i = 0; i < variants.size(); ++i) std::printf("---|");
  std::printf("\n");
  for (const auto& [dm, unused] : variants.front().total_by_distance) {
    std::printf("| %.1f m |", dm / 10.0);
    for (const Variant& v : variants) {
      const auto it = v.total_by_distance.find(dm);
      std::printf(" %.1f |", it == v.total_by_distance.end() ? 0.0 : Median(it->second));
    }
    std::printf("\n");
  }
}

// Humanoids found per half metre of distance, one column per variant.
void PrintFoundByDistance(const std::vector<Variant>& variants) {
  std::printf(
      "\nHumanoid found / frames by distance of the humanoid from the sensor:\n\n| distance |");
  for (const Variant& v : variants) std::printf(" %s |", v.name.c_str());
  std::printf("\n|---|");
  for (size_t i = 0; i < variants.size(); ++i) std::printf("---|");
  std::printf("\n");
  for (const auto& [half_metres, unused] : variants.front().found_by_distance) {
    std::printf("| %.1f-%.1f m |", half_metres / 2.0, (half_metres + 1) / 2.0);
    for (const Variant& v : variants) {
      const auto it = v.found_by_distance.find(half_metres);
      const auto [found, count] = it == v.found_by_distance.end() ? std::pair{0, 0} : it->second;
      std::printf(" %d / %d |", found, count);
    }
    std::printf("\n");
  }
}

Status Prepare(const std::vector<VoxelTemplate>& templates, std::vector<Variant>* variants) {
  for (Variant& v : *variants) {
    EstimatorOptions o = DefaultEstimatorOptions();
    o.make_tables_at_start = true;  // the daemon's setting: what serving frames costs.
    v.configure(&o);
    Result<std::unique_ptr<Estimator>> e = Estimator::Create(o, templates);
    if (!e.ok()) return e.error();
    v.estimator = std::move(*e);
    if (v.tracking) v.tracker = std::make_unique<PoseTracker>(v.estimator.get());
  }
  return Status::Ok();
}

// The variants named in `only` (all when it is empty), in the tables' order.
std::vector<Variant> Only(std::vector<Variant> variants, const std::vector<std::string>& only) {
  if (only.empty()) return variants;
  std::vector<Variant> kept;
  for (Variant& v : variants) {
    if (std::find(only.begin(), only.end(), v.name) != only.end()) kept.push_back(std::move(v));
  }
  return kept;
}

void Exact(EstimatorOptions* o) { o->search = SearchKind::kExact; }
// The exact search before theta_split_ratio: single headings from the top.
void ExactSingleHeadingsBefore(EstimatorOptions* o) {
  Exact(o);
  o->exact.top_theta_level = 0;
}
// The exact search before theta_block_free_part.
void ExactNoThetaBlockFreePart(EstimatorOptions* o) {
  Exact(o);
  o->exact.theta_block_free_part = false;
}
// Theta blocks with a free-space part at single translations only (before the part over blocks
// of 2 steps).
void ExactThetaBlockFreePartAtPointsBefore(EstimatorOptions* o) {
  Exact(o);
  o->exact.theta_block_pair_free_part = false;
}
// The exact search before top_theta_level: blocks of 16 headings at the top, split in theta
// before translation.
void ExactThetaBlocksBefore(EstimatorOptions* o) {
  Exact(o);
  o->exact.top_theta_level = 4;
  o->exact.theta_split_ratio = 0.0;
}
// The exact search as before free_bound_max_level and theta_split_lead: the free-space part of
// every block's bound, theta blocks (of 16 headings at the top) split first only while below 2^4
// times their width.
void ExactBoundsBefore(EstimatorOptions* o) {
  ExactThetaBlocksBefore(o);
  o->exact.free_bound_max_level = 31;
  o->exact.theta_split_lead = 4;
}

std::vector<Variant> ScatteredVariants() {
  std::vector<Variant> v;
  v.push_back({"paper search", [](EstimatorOptions* o) { o->search = SearchKind::kPaper; }});
  v.push_back({"exact search", Exact});
  v.push_back({"exact search, single headings from the top (before)", ExactSingleHeadingsBefore});
  v.push_back(
      {"exact search, theta blocks without a free-space part (before)", ExactNoThetaBlockFreePart});
  v.push_back({"exact search, theta blocks' free part at single translations (before)",
               ExactThetaBlockFreePartAtPointsBefore});
  v.push_back({"exact search, tables made on first use", [](EstimatorOptions* o) {
                 Exact(o);
                 o->make_tables_at_start = false;
               }});
  v.push_back({"exact search, column bounds (before)", [](EstimatorOptions* o) {
                 Exact(o);
                 o->exact.swept_bounds = false;
               }});
  v.push_back({"exact search, free part of every block (before)", ExactBoundsBefore});
  v.push_back({"exact search, theta blocks at the top (before)", ExactThetaBlocksBefore});
  v.push_back({"exact search, the score alone decides (before)", [](EstimatorOptions* o) {
                 Exact(o);
                 o->min_humanoid_fit = 0.0;
               }});
  v.push_back({"exact search, two-word columns (before slabs)", [](EstimatorOptions* o) {
                 Exact(o);
                 o->exact.slabs = false;
                 o->max_height_voxels = 0;  // a tall body on its own voxels.
               }});
  v.push_back({"exact search, the templates' own voxels (before)", [](EstimatorOptions* o) {
                 Exact(o);
                 o->max_height_voxels = 0;
               }});
  v.push_back({"exact search, 2 threads", [](EstimatorOptions* o) {
                 Exact(o);
                 o->threads = 2;
               }});
  v.push_back({"exact search, 2 deg lattice", [](EstimatorOptions* o) {
                 Exact(o);
                 o->lattice.angle_steps = 180;
               }});
  v.push_back({"exact search, 2 deg 8 mm lattice", [](EstimatorOptions* o) {
                 Exact(o);
                 o->lattice.angle_steps = 180;
                 o->lattice.subdivisions = 2;
               }});
  v.push_back({"exact search, reference refinement", [](EstimatorOptions* o) {
                 Exact(o);
                 o->refine.reference_evaluation = true;
               }});
  v.push_back({"exact search, fast refinement", [](EstimatorOptions* o) {
                 Exact(o);
                 o->refine.surface_spacing_m = 0.012;
                 o->refine.max_data_points = 500;
               }});
  v.push_back({"exact search, fits only (no view comparison)", [](EstimatorOptions* o) {
                 Exact(o);
                 o->heading_views.enabled = false;
               }});
  v.push_back({"exact search, pattern-search settle (before)", [](EstimatorOptions* o) {
                 Exact(o);
                 o->heading_views.settle_by_gauss_newton = false;
               }});
  v.push_back({"exact search, full settle", [](EstimatorOptions* o) {
                 Exact(o);
                 o->heading_views.settle_by_gauss_newton = false;
                 o->heading_views.settle_min_step_m = 0.0;
               }});
  v.push_back({"exact search, tiny steps evaluated (before)", [](EstimatorOptions* o) {
                 Exact(o);
                 o->refine.stop_at_tiny_step = false;
               }});
  v.push_back({"exact search, tenfold retries (before)", [](EstimatorOptions* o) {
                 Exact(o);
                 o->refine.min_retry_damping = 0.0;
               }});
  v.push_back({"exact search, both before", [](EstimatorOptions* o) {
                 Exact(o);
                 o->refine.min_retry_damping = 0.0;
                 o->heading_views.settle_by_gauss_newton = false;
               }});
  v.push_back(
      {"exact search, far-behind templates' runner-ups searched (before)", [](EstimatorOptions* o) {
         Exact(o);
         o->refine.search_far_behind_runner_up = true;
       }});
  v.push_back(
      {"exact search, runner-ups searched down to the threshold (before)", [](EstimatorOptions* o) {
         Exact(o);
         o->refine.runner_up_within_score_window = false;
       }});
  v.push_back({"exact search, every template's runner-up (before)", [](EstimatorOptions* o) {
                 Exact(o);
                 o->refine.runner_up_fit_sigmas = 0.0;
               }});
  v.push_back({"exact search, short steps evaluated (before)", [](EstimatorOptions* o) {
                 Exact(o);
                 o->refine.converged_sigmas = 0.0;
               }});
  v.push_back({"exact search, settle's short steps evaluated (before)", [](EstimatorOptions* o) {
                 Exact(o);
                 o->heading_views.settle_converged_sigmas = 0.0;
               }});
  v.push_back({"exact search, refinement stops as before", [](EstimatorOptions* o) {
                 Exact(o);
                 o->refine.converged_sigmas = 0.0;
                 o->refine.runner_up_fit_sigmas = 0.0;
                 o->heading_views.settle_converged_sigmas = 0.0;
               }});
  v.push_back(
      {"exact search, one score threshold at every range (before)", [](EstimatorOptions* o) {
         Exact(o);
         o->far_score_ratio = 1.0;
       }});
  v.push_back({"exact search, no refinement", [](EstimatorOptions* o) {
                 Exact(o);
                 o->refine.enabled = false;
               }});
  v.push_back({"exact search, PCL clustering", [](EstimatorOptions* o) {
                 Exact(o);
                 o->clusters.method = ClusterOptions::Method::kPcl;
               }});
  v.push_back({"exact search, two points a voxel within 2.5 m", [](EstimatorOptions* o) {
                 Exact(o);
                 o->two_points_a_voxel_within_m = 2.5;
               }});
  v.push_back({"exact search, range image over the readings (before)", [](EstimatorOptions* o) {
                 Exact(o);
                 o->range_image_spans_view = false;
               }});
  v.push_back({"exact search, no height offsets", [](EstimatorOptions* o) {
                 Exact(o);
                 o->height_offset_voxels = 0;
               }});
  // The paper's 320x240: every second pixel of every second row (the `stride` option).
  v.push_back({"exact search, every second pixel", [](EstimatorOptions* o) {
                 Exact(o);
                 o->cloud.stride = 2;
               }});
  return v;
}

std::vector<Variant> SequenceVariants() {
  std::vector<Variant> v;
  v.push_back({"walk, cold", Exact});
  v.push_back({"walk, tracked", Exact, true});
  v.push_back(
      {"walk, tracked, single headings from the top (before)", ExactSingleHeadingsBefore, true});
  v.push_back({"walk, tracked, theta blocks without a free-space part (before)",
               ExactNoThetaBlockFreePart, true});
  v.push_back({"walk, tracked, theta blocks' free part at single translations (before)",
               ExactThetaBlockFreePartAtPointsBefore, true});
  v.push_back({"walk, tracked, free part of every block (before)", ExactBoundsBefore, true});
  v.push_back({"walk, tracked, theta blocks at the top (before)", ExactThetaBlocksBefore, true});
  v.push_back({"walk, tracked, column bounds (before)",
               [](EstimatorOptions* o) {
                 Exact(o);
                 o->exact.swept_bounds = false;
               },
               true});
  v.push_back({"walk, tracked, the score alone decides (before)",
               [](EstimatorOptions* o) {
                 Exact(o);
                 o->min_humanoid_fit = 0.0;
               },
               true});
  v.push_back({"walk, tracked, two points a voxel within 2.5 m",
               [](EstimatorOptions* o) {
                 Exact(o);
                 o->two_points_a_voxel_within_m = 2.5;
               },
               true});
  v.push_back({"walk, tracked, every second pixel",
               [](EstimatorOptions* o) {
                 Exact(o);
                 o->cloud.stride = 2;
               },
               true});
  v.push_back({"walk, tracked, one score threshold (before)",
               [](EstimatorOptions* o) {
                 Exact(o);
                 o->tracked_score_threshold = o->score_threshold;
               },
               true});
  v.push_back({"walk, tracked, one score threshold at every range (before)",
               [](EstimatorOptions* o) {
                 Exact(o);
                 o->far_score_ratio = 1.0;
               },
               true});
  v.push_back({"walk, tracked, two-word columns (before slabs)",
               [](EstimatorOptions* o) {
                 Exact(o);
                 o->exact.slabs = false;
                 o->max_height_voxels = 0;  // a tall body on its own voxels.
               },
               true});
  v.push_back({"walk, tracked, the templates' own voxels (before)",
               [](EstimatorOptions* o) {
                 Exact(o);
                 o->max_height_voxels = 0;
               },
               true});
  v.push_back({"walk, tracked, far-behind templates' runner-ups searched (before)",
               [](EstimatorOptions* o) {
                 Exact(o);
                 o->refine.search_far_behind_runner_up = true;
               },
               true});
  v.push_back({"walk, tracked, runner-ups searched down to the threshold (before)",
               [](EstimatorOptions* o) {
                 Exact(o);
                 o->refine.runner_up_within_score_window = false;
               },
               true});
  v.push_back({"walk, tracked, the higher fit across templates whatever the heading (before)",
               [](EstimatorOptions* o) {
                 Exact(o);
                 o->prior_heading_across_templates = false;
               },
               true});
  v.push_back({"walk, tracked, every runner-up searched (before)",
               [](EstimatorOptions* o) {
                 Exact(o);
                 o->tracked_heading_confirm_rad = 0.0;
               },
               true});
  v.push_back({"walk, tracked, every template refined (before)",
               [](EstimatorOptions* o) {
                 Exact(o);
                 o->tracked_other_template_margin = -1.0;
               },
               true});
  v.push_back({"walk, tracked, other templates searched to their optimum (before)",
               [](EstimatorOptions* o) {
                 Exact(o);
                 o->tracked_other_template_stops = false;
               },
               true});
  v.push_back({"walk, tracked, range image over the readings (before)",
               [](EstimatorOptions* o) {
                 Exact(o);
                 o->range_image_spans_view = false;
               },
               true});
  v.push_back({"walk, tracked, depth images asked whatever the fits (before)",
               [](EstimatorOptions* o) {
                 Exact(o);
                 o->heading_views.max_fit_sigmas = 0.0;
               },
               true});
  v.push_back({"walk, tracked, 2 threads",
               [](EstimatorOptions* o) {
                 Exact(o);
                 o->threads = 2;
               },
               true});
  return v;
}

int Usage(FILE* out) {
  std::fprintf(out,
               "usage: frame_bench [--frames N] [--sequence N] [--clutter N] [--max-distance M]\n"
               "                   [--repeat N] [--only VARIANT] [--frames-detail] [--dump]\n"
               "                   [--body NAME] [--sensor-height M] [--pitch-deg D]\n"
               "                   [--walk-far M] [--noise-correlation SHARE] [--cloud FILE]...\n"
               "                   [--pick I,J,...] [--extra-pose NAME]\n"
               "  --frames N        scattered frames, every variant cold (default 30; 0: none)\n"
               "  --sequence N      frames of the walk, cold and tracked (default 30; 0: none)\n"
               "  --clutter N       clutter objects per frame (default 4)\n"
               "  --max-distance M  farthest humanoid of the scattered frames, metres (3.5)\n"
               "  --repeat N        run every frame N times (times of all runs, results of the "
               "first;\n"
               "                    from 2, also each frame's least total of its runs)\n"
               "  --only VARIANT    run this variant (by its name in the tables); repeat the flag\n"
               "                    for several, which then run side by side\n"
               "  --body NAME       humanoid proportions (nao, long_legs, tall); other than nao,\n"
               "                    the templates are made from the body (default nao: the\n"
               "                    shipped templates)\n"
               "  --extra-pose NAME a third template searched beside the two: the shipped\n"
               "                    NAME.bt (nao) or the body made in joint preset NAME\n"
               "                    (e.g. arms_swung); the frames' robots keep the two's\n"
               "                    postures\n"
               "  --sensor-height M optical centre above the floor, metres (0.34)\n"
               "  --pitch-deg D     sensor pitch, degrees, + looks down (0)\n"
               "  --walk-far M      farthest point of the walk's circle, metres (3.0; it starts\n"
               "                    at 1.4 m and gets there after 72 frames)\n"
               "  --noise-correlation SHARE  share (0-1) of the simulated depth noise that\n"
               "                    neighbouring pixels share, as a real Kinect's does (0.9\n"
               "                    resembles one; default 0: every pixel independent)\n"
               "  --cloud FILE      a recorded point cloud (.pcd/.ply, sensor frame) for the\n"
               "                    scattered frames' variants, each cold, --repeat times; may be\n"
               "                    repeated (use --frames 0 --sequence 0 for clouds only)\n"
               "  --pick I,J,...    of the --frames scattered frames, run only these (0-based,\n"
               "                    in this order, repeats allowed), e.g. to profile one slow\n"
               "                    frame: --frames 36 --pick 23,23,23 (lines and tables then\n"
               "                    count the picked frames)\n"
               "  --frames-detail   a line per frame and variant: time, search, refinement,\n"
               "                    bounds and the page faults of the estimate\n"
               "  --dump            a line per candidate: pose, scores, bounds, fits\n");
  return out == stdout ? 0 : 2;
}

int Run(int argc, char** argv) {
  int frames = 30;
  int sequence = 30;
  int clutter = 4;
  double max_distance = 3.5;
  double walk_far = 3.0;
  std::string body = "nao";
  std::vector<std::string> template_names = kBenchTemplateNames;
  double sensor_height = 0.34, pitch_deg = 0.0, noise_correlation = 0.0;
  RunFlags flags;
  std::vector<std::string> only;
  std::vector<std::string> cloud_paths;
  std::vector<int> pick;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool has_value = i + 1 < argc;
    if (a == "--help") return Usage(stdout);
    if (a == "--frames-detail") {
      flags.detail = true;
    } else if (a == "--dump") {
      flags.dump = true;
    } else if (!has_value) {
      std::fprintf(stderr, "frame_bench: %s needs a value (or is unknown)\n", a.c_str());
      return Usage(stderr);
    } else if (a == "--frames") {
      frames = std::atoi(argv[++i]);
    } else if (a == "--sequence") {
      sequence = std::atoi(argv[++i]);
    } else if (a == "--clutter") {
      clutter = std::atoi(argv[++i]);
    } else if (a == "--max-distance") {
      max_distance = std::atof(argv[++i]);
    } else if (a == "--walk-far") {
      walk_far = std::atof(argv[++i]);
    } else if (a == "--repeat") {
      flags.repeat = std::atoi(argv[++i]);
    } else if (a == "--body") {
      body = argv[++i];
    } else if (a == "--extra-pose") {
      template_names.push_back(argv[++i]);
    } else if (a == "--sensor-height") {
      sensor_height = std::atof(argv[++i]);
    } else if (a == "--pitch-deg") {
      pitch_deg = std::atof(argv[++i]);
    } else if (a == "--noise-correlation") {
      noise_correlation = std::atof(argv[++i]);
    } else if (a == "--only") {
      only.push_back(argv[++i]);
    } else if (a == "--cloud") {
      cloud_paths.push_back(argv[++i]);
    } else if (a == "--pick") {
      const std::string list = argv[++i];
      for (const std::string& item : ParseNames(list)) {
        char* end = nullptr;
        const long k = std::strtol(item.c_str(), &end, 10);
        if (item.empty() || *end != '\0' || k < 0 || k > 1000000) {
          pick.clear();
          break;
        }
        pick.push_back(static_cast<int>(k));
      }
      if (pick.empty()) {
        std::fprintf(stderr, "frame_bench: --pick takes frame indices like 3,23,23, not '%s'\n",
                     list.c_str());
        return 2;
      }
    } else {
      std::fprintf(stderr, "frame_bench: unknown flag %s\n", a.c_str());
      return Usage(stderr);
    }
  }
  for (const int k : pick) {
    if (k >= frames) {
      std::fprintf(stderr, "frame_bench: --pick %d: there are %d scattered frames (--frames)\n", k,
                   frames);
      return 2;
    }
  }
  if (frames < 0 || sequence < 0 || clutter < 0 || flags.repeat < 1 ||
      !(max_distance >= 0.9 && max_distance <= 8.0) || !(walk_far >= 1.6 && walk_far <= 8.0)) {
    std::fprintf(stderr,
                 "frame_bench: --frames and --sequence must be >= 0, --clutter >= 0, --repeat >= "
                 "1, --max-distance within [0.9, 8] m, --walk-far within [1.6, 8] m\n");
    return 2;
  }
  if (!(sensor_height > 0.0 && sensor_height <= 3.0) || !(std::abs(pitch_deg) <= 60.0) ||
      !(noise_correlation >= 0.0 && noise_correlation <= 1.0)) {
    std::fprintf(stderr,
                 "frame_bench: --sensor-height must be in (0, 3] m, --pitch-deg in [-60, 60], "
                 "--noise-correlation in [0, 1]\n");
    return 2;
  }
  Result<std::vector<VoxelTemplate>> templates =
      body == "nao" ? LoadShippedTemplates(HPOSE_TEMPLATE_DIR, template_names)
                    : BodyTemplates(body, template_names);
  if (!templates.ok()) {
    std::fprintf(stderr, "frame_bench: %s\n", templates.error().message.c_str());
    return 1;
  }
  std::vector<Variant> scattered =
      frames > 0 ? Only(ScatteredVariants(), only) : std::vector<Variant>{};
  std::vector<Variant> walk =
      sequence > 0 ? Only(SequenceVariants(), only) : std::vector<Variant>{};
  std::vector<Variant> recorded =
      !cloud_paths.empty() ? Only(ScatteredVariants(), only) : std::vector<Variant>{};
  std::vector<PointCloud> clouds;
  for (const std::string& path : cloud_paths) {
    Result<PointCloud> cloud = ReadCloud(path);
    if (!cloud.ok()) {
      std::fprintf(stderr, "frame_bench: %s\n", cloud.error().message.c_str());
      return 1;
    }
    clouds.push_back(std::move(*cloud));
  }
  if (scattered.empty() && walk.empty() && recorded.empty()) {
    std::string names;
    for (const std::string& name : only) names += (names.empty() ? " named '" : "', '") + name;
    std::fprintf(stderr, "frame_bench: no variant to run%s\n",
                 only.empty() ? "" : (names + "'").c_str());
    return 2;
  }
  for (std::vector<Variant>* set : {&scattered, &walk, &recorded}) {
    const Status st = Prepare(*templates, set);
    if (!st.ok()) {
      std::fprintf(stderr, "frame_bench: %s\n", st.error().message.c_str());
      return 1;
    }
  }
  // Renders one set of frames and runs its variants; false (after saying why) on an error.
  const auto run_set = [&](std::vector<FrameSpec> specs, std::vector<Variant>* set) {
    for (FrameSpec& spec : specs) {
      spec.body = body;
      spec.sensor_height_m = sensor_height;
      spec.sensor_pitch_rad = DegToRad(pitch_deg);
      spec.noise_correlated_share = noise_correlation;
    }
    Result<Frames> f = Render(std::move(specs));
    const Status st = f.ok() ? RunAll(*f, flags, set) : Status(f.error());
    if (!st.ok()) std::fprintf(stderr, "frame_bench: %s\n", st.error().message.c_str());
    return st.ok();
  };
  if (!PrintVectorPaths("frame_bench")) return 1;
  if (!scattered.empty()) {
    std::vector<FrameSpec> specs = BenchFrameSpecs(frames, clutter, max_distance);
    if (!pick.empty()) {
      std::vector<FrameSpec> picked;
      for (const int k : pick) picked.push_back(specs[k]);
      specs = std::move(picked);
    }
    if (!run_set(std::move(specs), &scattered)) return 1;
    if (!pick.empty()) std::printf("\nFrames picked: %zu of the %d below.\n", pick.size(), frames);
    std::printf(
        "\n%d scattered simulated 640x480 frames (humanoid '%s' 0.9-%.1f m away, sensor %.2f m "
        "high pitched %.0f deg, %d clutter objects, %zu templates), %d run(s) each; median / "
        "p90 in ms\n\n",
        frames, body.c_str(), max_distance, sensor_height, pitch_deg, clutter,
        template_names.size(), flags.repeat);
    PrintTable(scattered);
    PrintLeastOfRuns(scattered, flags.repeat);
    PrintByDistance(scattered);
    PrintFoundByDistance(scattered);
  }
  if (!walk.empty()) {
    if (!run_set(BenchSequenceSpecs(sequence, clutter, walk_far), &walk)) return 1;
    std::printf(
        "\nA walk of %d consecutive frames (humanoid '%s' on a circle 1.4-%.1f m away, from its "
        "nearest point, 2.5 degrees of turn a frame, sensor %.2f m high pitched %.0f deg, %d "
        "clutter objects), %d run(s) each; median / p90 in ms\n\n",
        sequence, body.c_str(), walk_far, sensor_height, pitch_deg, clutter, flags.repeat);
    PrintTable(walk);
    PrintLeastOfRuns(walk, flags.repeat);
    PrintFoundByDistance(walk);
  }
  if (!recorded.empty()) {
    const Status st = RunClouds(clouds, flags, &recorded);
    if (!st.ok()) {
      std::fprintf(stderr, "frame_bench: %s\n", st.error().message.c_str());
      return 1;
    }
    std::printf("\n%zu recorded cloud(s), each cold, %d run(s) each; median / p90 in ms\n\n",
                clouds.size(), flags.repeat);
    PrintCloudTable(recorded);
    std::printf(
        "\nsearches: (cluster, template) searches over the clouds' first run; humanoids "
        "detected: detections that passed the score and fit thresholds there.\n");
    PrintLeastOfRuns(recorded, flags.repeat);
  }
  std::printf(
      "\nCPU per frame: process CPU time of the call, all threads. tracked: frames whose search "
      "was seeded with the previous pose. refinement, humanoid's cluster: the candidates of the "
      "cluster nearest the true pose, over the frames where they were refined (the humanoid "
      "scored above the threshold). humanoid found: the best humanoid detection within 5 cm and "
      "10 deg of the truth. other humanoids: detections more than 0.3 m from it (clutter taken "
      "for a humanoid). humanoid digest: of each frame's humanoids alone (template, pose, "
      "heading flag).\n");
  return 0;
}

}  // namespace
}  // namespace hpose::bench

int main(int argc, char** argv) { return hpose::bench::Run(argc, argv); }
