// Accuracy of the depth-template estimator on simulated frames, following the paper's protocol
// (SPEC §1): sensor 0.34 m high and level, humanoid 1 m away turned every 30 degrees over the
// full circle with the standing and the right-arm-raised shapes, and the standing humanoid at
// 1, 2, 3 and 4 m facing away. Several noise seeds per case. Both searches (the paper's
// two-pass search and the exact search) run on the very same frames. Prints Markdown tables.
//
// usage: accuracy_bench [--seeds N] [--templates DIR] [--stride N] [--clutter N]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iterator>
#include <map>
#include <string>
#include <vector>

#include "core/search/estimator.h"
#include "core/sim/frame_simulator.h"
#include "core/templates/template_io.h"

namespace {

using namespace hpose;

struct Trial {
  std::string table;   // "orientation" or "distance"
  std::string preset;  // humanoid shape in the frame.
  double truth_theta_deg = 0.0;
  double distance_m = 1.0;
  // Per search: errors with the matching template alone, and whether the pair of templates
  // picked the right one.
  struct Outcome {
    bool found = false;
    double theta_err_deg = 0.0, x_err_mm = 0.0, y_err_mm = 0.0, score = 0.0;
    bool identity_ok = false;
    double search_ms = 0.0;
    double clutter_best = -1.0;  // best score of any cluster that is not the humanoid.
  };
  std::map<std::string, Outcome> by_search;
};

double Median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double MaxAbs(const std::vector<double>& v) {
  double m = 0.0;
  for (double x : v) m = std::max(m, std::abs(x));
  return m;
}

double Mean(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x;
  return v.empty() ? NAN : s / v.size();
}

// The best candidate of `name` over all clusters (the frame holds one humanoid).
const Candidate* BestOf(const Estimate& e, const std::string& name) {
  for (const Candidate& c : e.candidates) {
    if (c.template_name == name) return &c;  // candidates are sorted best first.
  }
  return nullptr;
}

// The estimator variants compared side by side on the same frames.
struct Variant {
  const char* name;
  SearchKind search;
  ScoreKind score;
  int hit_weight;
  int free_weight;
};
const Variant kVariants[] = {
    {"paper", SearchKind::kPaper, ScoreKind::kPaper, 1, 1},          // the paper's method.
    {"exact", SearchKind::kExact, ScoreKind::kPaper, 1, 1},          // optimum of its score.
    {"exact+fs1", SearchKind::kExact, ScoreKind::kFreeSpace, 1, 1},  // a free voxel costs 1 hit.
    {"exact+fs½", SearchKind::kExact, ScoreKind::kFreeSpace, 2, 1},  // ... half a hit.
};

}  // namespace

int main(int argc, char** argv) {
  int seeds = 5;
  int stride = 1;
  int clutter = 0;
  std::string template_dir = HPOSE_TEMPLATE_DIR;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "%s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--seeds") {
      seeds = std::atoi(next().c_str());
    } else if (a == "--templates") {
      template_dir = next();
    } else if (a == "--stride") {
      stride = std::atoi(next().c_str());
    } else if (a == "--clutter") {
      clutter = std::atoi(next().c_str());
    } else {
      std::fprintf(stderr,
                   "usage: accuracy_bench [--seeds N] [--templates DIR] [--stride N] "
                   "[--clutter N]\n");
      return a == "--help" ? 0 : 2;
    }
  }
  std::vector<VoxelTemplate> templates;
  for (const char* name : {"standing", "right_arm_raised"}) {
    Result<VoxelTemplate> t = LoadTemplate(template_dir + "/" + name + ".bt");
    if (!t.ok()) {
      std::fprintf(stderr, "accuracy_bench: %s\n", t.error().message.c_str());
      return 1;
    }
    templates.push_back(*t);
  }
  std::map<std::string, std::unique_ptr<Estimator>> single, pair;  // key: variant + template.
  for (const Variant& v : kVariants) {
    EstimatorOptions o = DefaultEstimatorOptions();
    o.search = v.search;
    o.score = v.score;
    o.hit_weight = v.hit_weight;
    o.free_space_weight = v.free_weight;
    o.cloud.stride = stride;
    o.score_threshold = 0.0;
    for (const VoxelTemplate& t : templates) {
      single[std::string(v.name) + "/" + t.name] = std::move(Estimator::Create(o, {t}).value());
    }
    pair[v.name] = std::move(Estimator::Create(o, templates).value());
  }

  std::vector<Trial> trials;
  for (const char* preset : {"standing", "right_arm_raised"}) {
    for (int deg = -180; deg < 180; deg += 30) {
      for (int s = 0; s < seeds; ++s) {
        Trial t;
        t.table = "orientation";
        t.preset = preset;
        t.truth_theta_deg = deg;
        t.distance_m = 1.0;
        trials.push_back(t);
      }
    }
  }
  for (double d : {1.0, 2.0, 3.0, 4.0}) {
    for (int s = 0; s < seeds; ++s) {
      Trial t;
      t.table = "distance";
      t.preset = "standing";
      t.truth_theta_deg = 0.0;
      t.distance_m = d;
      trials.push_back(t);
    }
  }

  std::fprintf(stderr, "accuracy_bench: %zu frames, %d seed(s) each case\n", trials.size(), seeds);
  for (size_t i = 0; i < trials.size(); ++i) {
    Trial& t = trials[i];
    FrameSpec spec;
    spec.preset = t.preset;
    spec.humanoid_pose = Pose2D{t.distance_m, 0.0, NormalizeAngle(DegToRad(t.truth_theta_deg))};
    spec.seed = 1000 + i;
    spec.clutter = clutter;
    Result<SimulatedFrame> frame = SimulateFrame(spec);
    if (!frame.ok()) {
      std::fprintf(stderr, "simulate: %s\n", frame.error().message.c_str());
      return 1;
    }
    for (const Variant& variant : kVariants) {
      const char* search = variant.name;
      Trial::Outcome& o = t.by_search[search];
      Result<Estimate> e = single[std::string(search) + "/" + t.preset]->EstimateDepth(
          frame->depth, spec.intrinsics);
      if (e.ok()) {
        const Candidate* c = BestOf(*e, t.preset);
        if (c != nullptr) {
          o.found = true;
          o.theta_err_deg = RadToDeg(AngleDiff(c->pose.theta, spec.humanoid_pose.theta));
          o.x_err_mm = 1000.0 * (c->pose.x - spec.humanoid_pose.x);
          o.y_err_mm = 1000.0 * (c->pose.y - spec.humanoid_pose.y);
          o.score = c->score;
          o.search_ms = e->timings.search_ms;
        }
      }
      Result<Estimate> both = pair[search]->EstimateDepth(frame->depth, spec.intrinsics);
      o.identity_ok = both.ok() && !both->candidates.empty() &&
                      both->candidates.front().template_name == t.preset;
      if (both.ok()) {
        for (const Candidate& c : both->candidates) {
          const ClusterSummary& cl = both->clusters[c.cluster_index];
          const double d = std::hypot(cl.centroid.x() - spec.humanoid_pose.x,
                                      cl.centroid.y() - spec.humanoid_pose.y);
          if (d > 0.3) o.clutter_best = std::max(o.clutter_best, c.score);
        }
      }
    }
    std::fprintf(stderr, "\r  frame %zu/%zu", i + 1, trials.size());
  }
  std::fprintf(stderr, "\n");

  // Per-case tables, paper and exact side by side (means over seeds).
  auto print_case_table = [&](const std::string& table, const std::string& preset,
                              const char* key_name) {
    std::printf("\n#### %s: %s\n\n", table.c_str(), preset.c_str());
    std::printf("| %s |", key_name);
    for (const Variant& v : kVariants) {
      std::printf(" %s θ err (°) | %s x, y err (mm) | %s score |", v.name, v.name, v.name);
    }
    std::printf("\n|---|");
    for (size_t i = 0; i < std::size(kVariants); ++i) std::printf("---|---|---|");
    std::printf("\n");
    std::map<double, std::vector<const Trial*>> groups;
    for (const Trial& t : trials) {
      if (t.table != table || t.preset != preset) continue;
      groups[table == "distance" ? t.distance_m * 1000 : t.truth_theta_deg].push_back(&t);
    }
    for (const auto& [key, ts] : groups) {
      std::printf("| %.0f |", key);
      for (const Variant& variant : kVariants) {
        const char* search = variant.name;
        std::vector<double> th, x, y, sc;
        for (const Trial* t : ts) {
          const Trial::Outcome& o = t->by_search.at(search);
          if (!o.found) continue;
          th.push_back(o.theta_err_deg);
          x.push_back(o.x_err_mm);
          y.push_back(o.y_err_mm);
          sc.push_back(o.score);
        }
        std::printf(" %+.1f (max %.0f) | %+.0f, %+.0f | %.1f |", Mean(th), MaxAbs(th), Mean(x),
                    Mean(y), Mean(sc));
      }
      std::printf("\n");
    }
  };
  print_case_table("orientation", "standing", "truth θ (°)");
  print_case_table("orientation", "right_arm_raised", "truth θ (°)");
  print_case_table("distance", "standing", "distance (mm)");

  // Summary against the targets.
  std::printf("\n#### Summary (all seeds)\n\n");
  std::printf(
      "| set | search | frames | median abs θ err (°) | max abs θ err (°) | "
      "median pos err (mm) | max pos err (mm) | θ within 5° | right template | "
      "humanoid score min / median | clutter score median / max | median search (ms) |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  struct Set {
    const char* name;
    bool (*in)(const Trial&);
  };
  const Set sets[] = {
      {"1-2 m (orientation + distance)", [](const Trial& t) { return t.distance_m <= 2.0; }},
      {"3 m", [](const Trial& t) { return t.distance_m == 3.0; }},
      {"4 m", [](const Trial& t) { return t.distance_m == 4.0; }},
  };
  for (const Set& set : sets) {
    for (const Variant& variant : kVariants) {
      const char* search = variant.name;
      std::vector<double> th, pos, ms, human_scores, clutter_scores;
      int n = 0, within5 = 0, identity = 0;
      for (const Trial& t : trials) {
        if (!set.in(t)) continue;
        ++n;
        const Trial::Outcome& o = t.by_search.at(search);
        identity += o.identity_ok;
        if (o.clutter_best >= 0.0) clutter_scores.push_back(o.clutter_best);
        if (!o.found) continue;
        human_scores.push_back(o.score);
        th.push_back(std::abs(o.theta_err_deg));
        pos.push_back(std::hypot(o.x_err_mm, o.y_err_mm));
        ms.push_back(o.search_ms);
        within5 += std::abs(o.theta_err_deg) <= 5.0;
      }
      const double human_min =
          human_scores.empty() ? NAN : *std::min_element(human_scores.begin(), human_scores.end());
      const double clutter_max =
          clutter_scores.empty() ? NAN
                                 : *std::max_element(clutter_scores.begin(), clutter_scores.end());
      std::printf(
          "| %s | %s | %d | %.1f | %.1f | %.1f | %.1f | %.0f%% | %.0f%% | %.1f / %.1f | %.1f / "
          "%.1f | %.1f |\n",
          set.name, search, n, Median(th), MaxAbs(th), Median(pos), MaxAbs(pos),
          100.0 * within5 / std::max(1, n), 100.0 * identity / std::max(1, n), human_min,
          Median(human_scores), Median(clutter_scores), clutter_max, Median(ms));
    }
  }
  return 0;
}
