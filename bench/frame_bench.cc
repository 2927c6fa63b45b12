// End-to-end time of the depth-template estimator per stage (cloud, floor, clustering, search,
// total) on simulated 640x480 Kinect v1 frames with clutter and the two shipped templates, for
// the paper's two-pass search and the exact search side by side: every frame is run through
// every variant in turn, so drift on a shared machine hits all variants alike.
// Pin it to one core for the documented numbers:
//   taskset -c 0 frame_bench [--frames N] [--clutter N] [--repeat N] [--frames-detail]
//                            [--only VARIANT] [--dump]
// Besides the Markdown table it prints, per variant, how many frames found the humanoid within
// 5 cm and 10 degrees, and a digest of every candidate (template, cluster, pose, scores): equal
// digests mean equal results, to check that a speed change did not change any result.
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "bench/bench_frames.h"
#include "core/search/estimator.h"

namespace hpose::bench {
namespace {

struct Variant {
  std::string name;
  std::function<void(EstimatorOptions*)> configure;
  std::unique_ptr<Estimator> estimator;
  std::vector<double> cloud, floor, cluster, search, refine, total, bounds;
  int found = 0;
  std::uint64_t digest = 1469598103934665603ull;  // FNV-1a.
};

void Mix(std::uint64_t* h, const void* data, size_t n) {
  const unsigned char* p = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < n; ++i) {
    *h ^= p[i];
    *h *= 1099511628211ull;
  }
}

void MixEstimate(std::uint64_t* h, const Estimate& e) {
  for (const Candidate& c : e.candidates) {
    Mix(h, c.template_name.data(), c.template_name.size());
    const double values[] = {
        c.pose.x,         c.pose.y,           c.pose.theta,       c.score,
        c.coverage,       c.runner_up_pose.x, c.runner_up_pose.y, c.runner_up_pose.theta,
        c.runner_up_score};
    Mix(h, values, sizeof values);
    const int ints[] = {c.cluster_index,         c.hits,
                        c.free_space_hits,       c.cluster_voxels,
                        c.has_runner_up ? 1 : 0, c.stopped_below_threshold ? 1 : 0};
    Mix(h, ints, sizeof ints);
  }
  for (const ClusterSummary& s : e.clusters) {
    const int ints[] = {s.index, s.points, s.searched ? 1 : 0};
    Mix(h, ints, sizeof ints);
    Mix(h, s.centroid.data(), sizeof(float) * 3);
  }
}

std::string Cell(const std::vector<double>& v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.1f / %.1f", Median(v), Percentile(v, 90.0));
  return buf;
}

int Run(int argc, char** argv) {
  int frames = 20;
  int clutter = 4;
  int repeat = 1;
  bool detail = false;
  bool dump = false;
  std::string only;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next_int = [&]() {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "frame_bench: %s needs a value\n", a.c_str());
        std::exit(2);
      }
      return std::atoi(argv[++i]);
    };
    if (a == "--frames") {
      frames = next_int();
    } else if (a == "--clutter") {
      clutter = next_int();
    } else if (a == "--repeat") {
      repeat = next_int();
    } else if (a == "--only" && i + 1 < argc) {
      only = argv[++i];
    } else if (a == "--dump") {
      dump = true;
    } else if (a == "--frames-detail") {
      detail = true;
    } else {
      std::fprintf(stderr,
                   "usage: frame_bench [--frames N] [--clutter N] [--repeat N] "
                   "[--frames-detail] [--dump] [--only VARIANT]\n");
      return a == "--help" ? 0 : 2;
    }
  }
  if (frames < 1 || clutter < 0 || repeat < 1) {
    std::fprintf(stderr, "frame_bench: --frames and --repeat must be >= 1, --clutter >= 0\n");
    return 2;
  }
  Result<std::vector<VoxelTemplate>> templates = LoadShippedTemplates(HPOSE_TEMPLATE_DIR);
  if (!templates.ok()) {
    std::fprintf(stderr, "frame_bench: %s\n", templates.error().message.c_str());
    return 1;
  }

  std::vector<Variant> variants;
  variants.push_back({"paper search", [](EstimatorOptions* o) { o->search = SearchKind::kPaper; }});
  variants.push_back({"exact search", [](EstimatorOptions* o) { o->search = SearchKind::kExact; }});
  variants.push_back({"exact search, fast refinement", [](EstimatorOptions* o) {
                        o->search = SearchKind::kExact;
                        o->refine.surface_spacing_m = 0.012;
                        o->refine.max_data_points = 500;
                      }});
  variants.push_back({"exact search, no refinement", [](EstimatorOptions* o) {
                        o->search = SearchKind::kExact;
                        o->refine.enabled = false;
                      }});
  variants.push_back({"exact search, 2 threads", [](EstimatorOptions* o) {
                        o->search = SearchKind::kExact;
                        o->threads = 2;
                      }});
  variants.push_back({"exact search, 2 deg lattice", [](EstimatorOptions* o) {
                        o->search = SearchKind::kExact;
                        o->lattice.angle_steps = 180;
                      }});
  variants.push_back({"exact search, 2 deg 8 mm lattice", [](EstimatorOptions* o) {
                        o->search = SearchKind::kExact;
                        o->lattice.angle_steps = 180;
                        o->lattice.subdivisions = 2;
                      }});
  variants.push_back({"exact search, PCL clustering", [](EstimatorOptions* o) {
                        o->search = SearchKind::kExact;
                        o->clusters.method = ClusterOptions::Method::kPcl;
                      }});
  if (!only.empty()) {
    std::vector<Variant> kept;
    for (Variant& v : variants) {
      if (v.name == only) kept.push_back(std::move(v));
    }
    if (kept.empty()) {
      std::fprintf(stderr, "frame_bench: no variant named '%s'\n", only.c_str());
      return 2;
    }
    variants.swap(kept);
  }
  for (Variant& v : variants) {
    EstimatorOptions o = DefaultEstimatorOptions();
    v.configure(&o);
    Result<std::unique_ptr<Estimator>> e = Estimator::Create(o, *templates);
    if (!e.ok()) {
      std::fprintf(stderr, "frame_bench: %s\n", e.error().message.c_str());
      return 1;
    }
    v.estimator = std::move(*e);
  }

  const std::vector<FrameSpec> specs = BenchFrameSpecs(frames, clutter);
  std::vector<SimulatedFrame> sims;
  for (const FrameSpec& s : specs) {
    Result<SimulatedFrame> f = SimulateFrame(s);
    if (!f.ok()) {
      std::fprintf(stderr, "frame_bench: %s\n", f.error().message.c_str());
      return 1;
    }
    sims.push_back(std::move(*f));
  }

  for (int r = 0; r < repeat; ++r) {
    for (size_t f = 0; f < sims.size(); ++f) {
      for (Variant& v : variants) {
        Result<Estimate> e = v.estimator->EstimateDepth(sims[f].depth, specs[f].intrinsics);
        if (!e.ok()) {
          std::fprintf(stderr, "frame_bench: frame %zu, %s: %s\n", f, v.name.c_str(),
                       e.error().message.c_str());
          return 1;
        }
        const StageTimings& t = e->timings;
        v.cloud.push_back(t.cloud_ms);
        v.floor.push_back(t.floor_ms);
        v.cluster.push_back(t.cluster_ms);
        v.search.push_back(t.search_ms);
        v.refine.push_back(t.refine_ms);
        v.total.push_back(t.total_ms);
        double nb = 0;
        for (const Candidate& c : e->candidates) nb += static_cast<double>(c.bounds_evaluated);
        v.bounds.push_back(nb / 1000.0);
        if (r > 0) continue;
        MixEstimate(&v.digest, *e);
        if (dump) {
          for (const Candidate& c : e->candidates) {
            std::printf(
                "dump %s frame %zu cluster %d %s: x %.4f y %.4f theta %.4f score %.4f "
                "hits %d free %d bound %d runner %d %.4f\n",
                v.name.c_str(), f, c.cluster_index, c.template_name.c_str(), c.pose.x, c.pose.y,
                c.pose.theta, c.score, c.hits, c.free_space_hits, c.stopped_below_threshold ? 1 : 0,
                c.has_runner_up ? 1 : 0, c.runner_up_score);
          }
        }
        const std::vector<Detection> humans = e->Humanoids();
        const Pose2D& truth = specs[f].humanoid_pose;
        bool ok = false;
        if (!humans.empty()) {
          const Pose2D& p = humans.front().best.pose;
          ok = std::hypot(p.x - truth.x, p.y - truth.y) < 0.05 &&
               std::abs(AngleDiff(p.theta, truth.theta)) < DegToRad(10.0);
        }
        v.found += ok ? 1 : 0;
        if (detail) {
          std::printf("frame %2zu %-16s %-12s clusters %zu searches %zu total %.1f ms%s\n", f,
                      specs[f].preset.c_str(), v.name.c_str(), e->clusters.size(),
                      e->candidates.size(), t.total_ms, ok ? "" : "  (humanoid missed)");
        }
      }
    }
  }

  std::printf(
      "\n%d simulated 640x480 frames (%d clutter objects each, 2 templates), %d run(s) each; "
      "median / p90 in ms\n\n",
      frames, clutter, repeat);
  std::printf(
      "| variant | cloud | floor | clustering | search (incl. refinement) | refinement | total | "
      "bounds (k) | humanoid found | digest |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|\n");
  for (const Variant& v : variants) {
    std::printf("| %s | %s | %s | %s | %s | %s | %s | %s | %d / %d | %016llx |\n", v.name.c_str(),
                Cell(v.cloud).c_str(), Cell(v.floor).c_str(), Cell(v.cluster).c_str(),
                Cell(v.search).c_str(), Cell(v.refine).c_str(), Cell(v.total).c_str(),
                Cell(v.bounds).c_str(), v.found, frames, static_cast<unsigned long long>(v.digest));
  }
  std::printf(
      "\nhumanoid found: the best humanoid detection within 5 cm and 10 deg of the truth\n");
  return 0;
}

}  // namespace
}  // namespace hpose::bench

int main(int argc, char** argv) { return hpose::bench::Run(argc, argv); }
