// Micro-benchmarks of the depth-template scoring and search on simulated 640x480 frames with
// clutter and the shipped templates:
//  - Scorer/*: the OctoMap reference scorer, the fast scorer and ColumnOccupancy::Hits on the
//    same poses (items_per_second = poses per second); the three are checked equal first.
//  - Search/*: the paper's two-pass search and the exact branch-and-bound search on the same
//    (cluster, template) problems, set up as the estimator does (free-space score). Counters
//    per search: poses (full evaluations), bounds, lattice (poses of the exact search's lattice
//    for that cluster: translations x thetas) and lattice_per_pose (= lattice / poses).
//    "exact" stops below the score threshold like the estimator; "exact_optimum" always proves
//    the optimum.
//  - Projector: the refinement's z-buffer of a template's surface points (TemplateProjector)
//    at poses 1-3.5 m away, every 15 degrees, from a level 0.34 m and a pitched 0.9 m sensor
//    (items_per_second = projections per second).
//
// usage: search_microbench [--frames N] [google benchmark flags]
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "bench/bench_frames.h"
#include "core/scoring/column_occupancy.h"
#include "core/scoring/fast_scorer.h"
#include "core/scoring/octomap_scorer.h"
#include "core/search/exact_search.h"
#include "core/search/surface_model.h"
#include "core/search/template_projector.h"

namespace hpose::bench {
namespace {

struct Data {
  std::vector<VoxelTemplate> templates;
  std::vector<std::unique_ptr<TemplateRotations>> rotations;
  std::vector<BenchProblem> problems;
  std::vector<LatticePose> scorer_poses;  // on problems[0].
  // The projector's problems: a template's surface, a view of it and the z-buffer's bin.
  std::vector<std::unique_ptr<SurfaceModel>> surfaces;
  struct View {
    size_t surface;  // in `surfaces`.
    ViewTransform view;
    double bin;
  };
  std::vector<View> views;
};

Data& GetData() {
  static Data data;
  return data;
}

void BM_Scorer(benchmark::State& state, ScorerKind kind, bool column) {
  const Data& d = GetData();
  const BenchProblem& p = d.problems.front();
  const PoseLattice& lattice = p.rotations->lattice();
  std::unique_ptr<PoseScorer> scorer = MakePoseScorer(kind, p.cluster, lattice);
  const RotatedTemplate& r0 = p.rotations->Get(0);
  const ColumnOccupancy occ(p.cluster, lattice, r0.z_base, r0.z_words, 0);
  for (auto _ : state) {
    long sum = 0;
    for (const LatticePose& q : d.scorer_poses) {
      const RotatedTemplate& r = p.rotations->Get(q.itheta);
      sum += column ? occ.Hits(r, q.ix, q.iy) : scorer->Hits(r, q.ix, q.iy);
    }
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()) *
                          static_cast<int64_t>(d.scorer_poses.size()));
}

enum class Kind { kPaper, kExact, kExactOptimum };

void BM_Search(benchmark::State& state, Kind kind, int index) {
  const BenchProblem& p = GetData().problems[index];
  const PaperSearch paper;
  const ExactSearch exact;
  const PoseSearch& search = kind == Kind::kPaper ? static_cast<const PoseSearch&>(paper) : exact;
  const SearchProblem problem = p.Problem(kind == Kind::kExact);
  SearchResult r;
  for (auto _ : state) {
    r = search.Search(problem);
    benchmark::DoNotOptimize(r.value);
  }
  const ExactSearch::Region g = exact.TranslationRegion(p.cluster, *p.rotations);
  const double lattice = static_cast<double>(g.ix_max - g.ix_min + 1) * (g.iy_max - g.iy_min + 1) *
                         p.rotations->lattice().angle_steps;
  state.counters["poses"] = static_cast<double>(r.poses_evaluated);
  state.counters["bounds"] = static_cast<double>(r.bounds_evaluated);
  state.counters["lattice"] = lattice;
  state.counters["lattice_per_pose"] = lattice / std::max<double>(1.0, r.poses_evaluated);
  state.counters["score"] = r.below_min_value ? -r.score : r.score;
  state.SetLabel(p.label);
}

// Every problem once per iteration: the mean CPU time per (cluster, template) search
// (ms_per_search; process CPU time, so other jobs on a shared machine do not inflate it).
void BM_SearchAll(benchmark::State& state, Kind kind) {
  const Data& d = GetData();
  const PaperSearch paper;
  const ExactSearch exact;
  const PoseSearch& search = kind == Kind::kPaper ? static_cast<const PoseSearch&>(paper) : exact;
  double poses = 0, bounds = 0, lattice = 0, seconds = 0;
  for (auto _ : state) {
    poses = bounds = 0;
    const std::clock_t t0 = std::clock();
    for (const BenchProblem& p : d.problems) {
      const SearchResult r = search.Search(p.Problem(kind == Kind::kExact));
      poses += static_cast<double>(r.poses_evaluated);
      bounds += static_cast<double>(r.bounds_evaluated);
    }
    seconds += static_cast<double>(std::clock() - t0) / CLOCKS_PER_SEC;
  }
  for (const BenchProblem& p : d.problems) {
    const ExactSearch::Region g = exact.TranslationRegion(p.cluster, *p.rotations);
    lattice += static_cast<double>(g.ix_max - g.ix_min + 1) * (g.iy_max - g.iy_min + 1) *
               p.rotations->lattice().angle_steps;
  }
  const double n = static_cast<double>(d.problems.size());
  state.counters["problems"] = n;
  state.counters["poses_per_search"] = poses / n;
  state.counters["bounds_per_search"] = bounds / n;
  state.counters["lattice_per_search"] = lattice / n;
  state.counters["lattice_per_pose"] = lattice / std::max(1.0, poses);
  state.counters["ms_per_search"] =
      1000.0 * seconds / (n * static_cast<double>(state.iterations()));
}

void BM_Projector(benchmark::State& state) {
  const Data& d = GetData();
  std::vector<std::unique_ptr<TemplateProjector>> projectors;
  for (const auto& s : d.surfaces) projectors.push_back(std::make_unique<TemplateProjector>(*s));
  long bins = 0, winners = 0;
  for (auto _ : state) {
    bins = winners = 0;
    for (const Data::View& v : d.views) {
      TemplateProjector& p = *projectors[v.surface];
      p.Project(v.view, v.bin);
      bins += static_cast<long>(p.w()) * p.h();
      winners += std::count_if(p.winner().begin(), p.winner().end(), [](int i) { return i >= 0; });
    }
    benchmark::DoNotOptimize(winners);
  }
  long points = 0;
  for (const Data::View& v : d.views)
    points += static_cast<long>(d.surfaces[v.surface]->xs().size());
  const double n = static_cast<double>(d.views.size());
  state.counters["points_per_projection"] = static_cast<double>(points) / n;
  state.counters["bins_per_projection"] = static_cast<double>(bins) / n;
  state.counters["winners_per_projection"] = static_cast<double>(winners) / n;
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()) *
                          static_cast<int64_t>(d.views.size()));
}

// The projector's views: each shipped template 1-3.5 m in front of a level 0.34 m and a
// pitched 0.9 m (20 degrees down) sensor, every 15 degrees; bins sized as the refinement does.
bool SetupProjector(Data* d) {
  for (const VoxelTemplate& t : d->templates)
    d->surfaces.push_back(std::make_unique<SurfaceModel>(t));
  for (const auto& [height, pitch_deg] : {std::pair{0.34, 0.0}, std::pair{0.9, 20.0}}) {
    FrameSpec spec;
    spec.sensor_height_m = height;
    spec.sensor_pitch_rad = DegToRad(pitch_deg);
    spec.clutter = 0;
    Result<SimulatedFrame> frame = SimulateFrame(spec);
    if (!frame.ok()) {
      std::fprintf(stderr, "search_microbench: %s\n", frame.error().message.c_str());
      return false;
    }
    const Eigen::Isometry3d s_from_g = frame->sensor_mount.ground_from_sensor.inverse();
    for (size_t k = 0; k < d->surfaces.size(); ++k) {
      const SurfaceModel& surface = *d->surfaces[k];
      for (double dist = 1.0; dist <= 3.51; dist += 0.5) {
        for (int deg = 0; deg < 360; deg += 15) {
          const Pose2D pose{dist, 0.1, DegToRad(deg)};
          const Eigen::Vector3d centre =
              s_from_g * (Eigen::Vector3d(pose.x, pose.y, 0.0) + surface.centre().cast<double>());
          const double bin = 1.5 * surface.spacing_m() / std::max(0.3, centre.norm());
          d->views.push_back(
              {k, ViewTransform(std::cos(pose.theta), std::sin(pose.theta), pose, s_from_g), bin});
        }
      }
    }
  }
  return true;
}

int Setup(int frames) {
  Data& d = GetData();
  Result<std::vector<VoxelTemplate>> templates = LoadShippedTemplates(HPOSE_TEMPLATE_DIR);
  if (!templates.ok()) {
    std::fprintf(stderr, "search_microbench: %s\n", templates.error().message.c_str());
    return 1;
  }
  d.templates = std::move(*templates);
  const EstimatorOptions options = DefaultEstimatorOptions();
  for (const VoxelTemplate& t : d.templates) {
    d.rotations.push_back(std::make_unique<TemplateRotations>(t, options.lattice));
  }
  int f = 0;
  for (const FrameSpec& spec : BenchFrameSpecs(frames)) {
    Result<SimulatedFrame> frame = SimulateFrame(spec);
    if (!frame.ok()) {
      std::fprintf(stderr, "search_microbench: %s\n", frame.error().message.c_str());
      return 1;
    }
    const Status st = AppendProblems(*frame, spec.intrinsics, options, d.templates, d.rotations,
                                     "frame " + std::to_string(f++), &d.problems);
    if (!st.ok()) {
      std::fprintf(stderr, "search_microbench: %s\n", st.error().message.c_str());
      return 1;
    }
  }
  if (d.problems.empty()) {
    std::fprintf(stderr, "search_microbench: no cluster passed the height check\n");
    return 1;
  }
  // Scorer poses: every theta, translations within +-128 mm of the first cluster's centre.
  const BenchProblem& p = d.problems.front();
  const PoseLattice& lattice = p.rotations->lattice();
  const LatticePose c = NearestLatticePose(lattice, Pose2D{p.centre.x(), p.centre.y(), 0.0});
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> off(-32, 32), th(0, lattice.angle_steps - 1);
  for (int k = 0; k < 2048; ++k)
    d.scorer_poses.push_back({c.ix + off(rng), c.iy + off(rng), th(rng)});
  // The three scorers must agree before their speed means anything.
  const OctomapScorer reference(p.cluster, lattice);
  const FastScorer fast(p.cluster, lattice);
  const RotatedTemplate& r0 = p.rotations->Get(0);
  const ColumnOccupancy occ(p.cluster, lattice, r0.z_base, r0.z_words, 0);
  for (const LatticePose& q : d.scorer_poses) {
    const RotatedTemplate& r = p.rotations->Get(q.itheta);
    const int want = reference.Hits(r, q.ix, q.iy);
    if (fast.Hits(r, q.ix, q.iy) != want || occ.Hits(r, q.ix, q.iy) != want) {
      std::fprintf(stderr, "search_microbench: scorers disagree at (%d, %d, %d)\n", q.ix, q.iy,
                   q.itheta);
      return 1;
    }
  }
  if (!SetupProjector(&d)) return 1;
  if (!PrintVectorPaths("search_microbench")) return 1;
  std::printf("%zu (cluster, template) problems from %d frames; scorer poses on %s\n",
              d.problems.size(), frames, p.label.c_str());
  return 0;
}

}  // namespace
}  // namespace hpose::bench

int main(int argc, char** argv) {
  using namespace hpose::bench;
  int frames = 4;
  bool per_problem = true;
  std::vector<char*> rest = {argv[0]};
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--frames") == 0 && i + 1 < argc) {
      frames = std::atoi(argv[++i]);
    } else if (std::strcmp(argv[i], "--no-per-problem") == 0) {
      per_problem = false;
    } else {
      rest.push_back(argv[i]);
    }
  }
  if (frames < 1) {
    std::fprintf(stderr, "search_microbench: --frames must be >= 1\n");
    return 2;
  }
  int rest_argc = static_cast<int>(rest.size());
  benchmark::Initialize(&rest_argc, rest.data());
  if (const int rc = Setup(frames); rc != 0) return rc;

  using hpose::ScorerKind;
  benchmark::RegisterBenchmark("Scorer/octomap_reference", BM_Scorer, ScorerKind::kOctomapReference,
                               false);
  benchmark::RegisterBenchmark("Scorer/fast", BM_Scorer, ScorerKind::kFast, false);
  benchmark::RegisterBenchmark("Scorer/column_occupancy", BM_Scorer, ScorerKind::kFast, true);
  benchmark::RegisterBenchmark("Projector", BM_Projector);
  const struct {
    const char* name;
    Kind kind;
  } kinds[] = {
      {"paper", Kind::kPaper}, {"exact", Kind::kExact}, {"exact_optimum", Kind::kExactOptimum}};
  for (const auto& k : kinds) {
    benchmark::RegisterBenchmark((std::string("SearchAll/") + k.name).c_str(), BM_SearchAll, k.kind)
        ->Unit(benchmark::kMillisecond);
  }
  if (per_problem) {
    const int n = static_cast<int>(GetData().problems.size());
    for (int i = 0; i < n; ++i) {
      for (const auto& k : kinds) {
        benchmark::RegisterBenchmark(
            (std::string("Search/") + k.name + "/" + std::to_string(i)).c_str(), BM_Search, k.kind,
            i)
            ->Unit(benchmark::kMillisecond);
      }
    }
  }
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
