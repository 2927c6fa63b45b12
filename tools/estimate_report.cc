#include "tools/estimate_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "core/search/detection_order.h"
#include "core/search/estimator.h"
#include "core/search/humanoid_view.h"

namespace hpose::tools {
namespace {

std::string Fmt(const char* fmt, double a) {
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, a);
  return buf;
}

// The second line of a partly-in-view note.
constexpr const char* kRestBeyondTheEdges =
    "          the rest beyond the image's edges: the fit rests on the part in view\n";

}  // namespace

std::string PartlyInViewNote(const Candidate& c) {
  if (!c.refined || !(c.fit.in_view < kPartlyInViewBelow)) return "";
  return "partly in view: " + Fmt("%.0f", 100.0 * c.fit.in_view) +
         "% of the template's surface facing the sensor lies within the view";
}

std::string NearestMissReason(const Detection& d, const EstimatorOptions* options) {
  const Candidate& c = d.best;
  const std::string score = "score " + Fmt("%.1f", c.score);
  const std::string fit = " a refined fit of " + Fmt("%.1f", c.fit.fit);
  // A threshold's value when the options are known, else `unknown`.
  auto value = [&](const char* fmt, double EstimatorOptions::*field, const char* unknown) {
    return options != nullptr ? " " + Fmt(fmt, options->*field) : std::string(unknown);
  };
  switch (d.refused_by) {
    case Refusal::kNone:
      return "not refused";
    case Refusal::kScore:
      if (c.stopped_below_threshold) {
        return "proved below score " + Fmt("%.0f", d.score_threshold) + ": at most " +
               Fmt("%.1f", c.score_upper_bound);
      }
      return score + ", below " + Fmt("%.0f", d.score_threshold);
    case Refusal::kFit:
      return score + " but" + fit + ", below the fit threshold" +
             value("%.0f", &EstimatorOptions::min_humanoid_fit, "") + ": --min-fit";
    case Refusal::kEvidence:
      return score + " and" + fit + ", but evidence of " + Fmt("%.3f", HumanoidEvidenceShare(c)) +
             " (the share of the template it covers times (fit/100)^8), below" +
             value("%.2f", &EstimatorOptions::min_humanoid_evidence, " the threshold") +
             ": --min-evidence";
    case Refusal::kFarEvidence: {
      // A far cluster that passed only the far score and then lacked the evidence.
      std::string far = "a far cluster that scores under the full threshold needs more evidence";
      if (options != nullptr) {
        far = "a cluster " + Fmt("%.1f", options->far_range_m) +
              " m away or more that scores under " + Fmt("%.0f", options->score_threshold) +
              " needs evidence of " + Fmt("%.2f", options->far_min_evidence);
      }
      return score + " and" + fit + ", but " + far + " and this has " +
             Fmt("%.3f", HumanoidEvidenceShare(c)) +
             ": the share of the template it covers times (fit/100)^8";
    }
    case Refusal::kOffFloorCoverage: {
      const double covered =
          c.template_voxels > 0 ? static_cast<double>(c.hits) / c.template_voxels : 0.0;
      return score + " and" + fit + " with the template " +
             Fmt("%.0f", 1000.0 * std::abs(c.height_offset_m)) + " mm " +
             (c.height_offset_m < 0.0 ? "below" : "above") + " the floor, but covering " +
             Fmt("%.2f", covered) + " of the template, under the" +
             value("%.2f", &EstimatorOptions::height_offset_min_coverage, "") +
             " a body off the floor must cover: search.height_offset_min_coverage";
    }
  }
  return "refused";
}

std::string EstimateToText(const Estimate& e, const EstimatorOptions* options) {
  std::ostringstream os;
  const FloorEstimate& f = e.floor;
  os << "floor     sensor " << Fmt("%.3f", f.height_m) << " m above it, pitch "
     << Fmt("%.1f", RadToDeg(f.pitch_rad)) << " deg, roll " << Fmt("%.1f", RadToDeg(f.roll_rad))
     << " deg" << (f.fitted ? " (fitted, " + std::to_string(f.inliers) + " inliers)" : " (fixed)")
     << "\n";
  int searched = 0;
  for (const ClusterSummary& c : e.clusters) searched += c.searched;
  os << "clusters  " << e.clusters.size() << " on the floor, " << searched << " of humanoid size\n";
  const HumanoidView humans = e.Humanoids();
  if (humans.empty()) {
    os << "humanoid  none found";
    if (!e.detections.empty()) {
      // The detection nearest to passing, and why it did not.
      const Detection& d = e.detections.front();
      const Candidate& c = d.best;
      const double distance = std::hypot(c.pose.x, c.pose.y);
      os << " (best: " << c.template_name << " on cluster " << c.cluster_index << ", "
         << Fmt("%.1f", distance) << " m away, " << NearestMissReason(d, options) << ")\n";
      const bool fit_refused = d.refused_by == Refusal::kFit ||
                               d.refused_by == Refusal::kEvidence ||
                               d.refused_by == Refusal::kFarEvidence;
      if (fit_refused && c.free_limbs_moved) {
        os << "          the frame contradicts the template's free limbs (arms, head) more than "
              "the rest of it:\n"
              "          if this is the robot, it holds them otherwise, which lowers the fit, "
              "and a template of\n"
              "          that posture would fit it (docs/TEMPLATES.md, \"Which postures\"; "
              "for the shipped\n"
              "          templates' robot swinging its arms: arms_swung, given with them by "
              "--template);\n"
              "          clutter often contradicts them too\n";
      }
      const std::string in_view = PartlyInViewNote(c);
      if (!in_view.empty()) os << "          " << in_view << ",\n" << kRestBeyondTheEdges;
      if (d.refused_by == Refusal::kScore && distance >= 2.5) {
        os << "          far humanoids score less (depth noise thickens them): when nothing "
              "passes, a cluster\n"
              "          2.5 m away or more passes from a lower score on strong evidence "
              "(--far-ratio); over\n"
              "          a stream (hposed, hpose replay) one found nearer stays found as it "
              "walks away;\n"
              "          --threshold lowers the bar for this frame (clutter may then pass too)\n";
      }
    } else {
      os << "\n";
    }
  }
  for (const Detection& d : humans) {
    const Candidate& c = d.best;
    os << "humanoid  " << c.template_name << " at x " << Fmt("%.3f", c.pose.x) << " m, y "
       << Fmt("%.3f", c.pose.y) << " m, theta " << Fmt("%.1f", RadToDeg(c.pose.theta))
       << " deg, score " << Fmt("%.1f", c.score) << " (cluster " << c.cluster_index << ")\n";
    if (c.refined) {
      os << "          refined from the lattice pose (" << Fmt("%.3f", c.lattice_pose.x) << ", "
         << Fmt("%.3f", c.lattice_pose.y) << ", " << Fmt("%.1f", RadToDeg(c.lattice_pose.theta))
         << " deg); sigma x " << Fmt("%.1f", 1000.0 * std::sqrt(c.covariance(0, 0))) << " mm, y "
         << Fmt("%.1f", 1000.0 * std::sqrt(c.covariance(1, 1))) << " mm, theta "
         << Fmt("%.2f", RadToDeg(std::sqrt(c.covariance(2, 2)))) << " deg; fit "
         << Fmt("%.1f", c.fit.fit) << "\n";
    }
    const std::string in_view = PartlyInViewNote(c);
    if (!in_view.empty()) os << "          " << in_view << ",\n" << kRestBeyondTheEdges;
    if (c.height_offset_m != 0.0) {
      os << "          template standing " << Fmt("%.0f", 1000.0 * std::abs(c.height_offset_m))
         << " mm " << (c.height_offset_m < 0.0 ? "below" : "above")
         << " the floor (nothing passed on it: the robot stands "
         << (c.height_offset_m < 0.0 ? "lower" : "higher")
         << " than its template, or the floor is off; --height-offset-voxels)\n";
    }
    if (c.free_limbs_left_out) {
      os << "          fitted without the template's free limbs (arms, head): the robot holds "
            "them otherwise\n";
    }
    if (c.has_runner_up) {
      os << "          runner-up theta " << Fmt("%.1f", RadToDeg(c.runner_up_pose.theta))
         << " deg, score " << Fmt("%.1f", c.runner_up_score);
      if (c.refined) os << ", fit " << Fmt("%.1f", c.runner_up_fit.fit);
      os << (c.heading_ambiguous ? " (AMBIGUOUS: as well supported as the pose; trust neither)"
                                 : "")
         << (c.heading_from_prior ? " (pose kept nearer the previous frame's heading)" : "")
         << "\n";
    }
    if (!d.second_template.empty()) {
      // Fit points when both were refined (in a tracked stream a template far behind may not
      // be: EstimatorOptions::tracked_other_template_margin), else score points, at least that
      // many where the second's search stopped (Detection::template_margin_kind).
      os << "          " << d.second_template
         << (d.template_margin_kind == MarginKind::kFit            ? " fits "
             : d.template_margin_kind == MarginKind::kScoreAtLeast ? " scored at least "
                                                                   : " scored ")
         << Fmt("%.1f", d.template_margin) << " lower"
         << (d.template_ambiguous ? " (AMBIGUOUS: within noise)" : "") << "\n";
    }
  }
  os << "timings   cloud " << Fmt("%.1f", e.timings.cloud_ms) << " ms, floor "
     << Fmt("%.1f", e.timings.floor_ms) << " ms, clustering " << Fmt("%.1f", e.timings.cluster_ms)
     << " ms, search " << Fmt("%.1f", e.timings.search_ms) << " ms";
  // Nothing passed at the first height: the frame was searched again off the floor.
  if (e.height_passes > 1) {
    os << " at " << e.height_passes << " heights (--height-offset-voxels)";
  }
  os << ", total " << Fmt("%.1f", e.timings.total_ms) << " ms\n";
  return os.str();
}

std::string SearchVoxelsNote(const Estimator& estimator) {
  const EstimatorOptions& o = estimator.options();
  const double edge = o.lattice.resolution_m;
  std::string names;
  double finest = edge, tallest = 0.0;
  for (const VoxelTemplate& t : estimator.templates()) {
    tallest = std::max(tallest, t.Height());
    if (t.resolution_m >= edge - 1e-9) continue;
    names += (names.empty() ? "'" : ", '") + t.name + "'";
    finest = std::min(finest, t.resolution_m);
  }
  if (names.empty()) return "";
  char buf[320];
  if (o.resolution_from_templates && o.max_height_voxels > 0 &&
      tallest > o.max_height_voxels * finest + 1e-9) {
    std::snprintf(buf, sizeof(buf),
                  "%.1f mm voxels, as the body is %.2f m tall: more than max_height_voxels (%d) "
                  "of its own %.1f mm (0: search on those)",
                  edge * 1000.0, tallest, o.max_height_voxels, finest * 1000.0);
  } else {
    std::snprintf(buf, sizeof(buf), "%.1f mm voxels, the search's edge (finest template %.1f mm)",
                  edge * 1000.0, finest * 1000.0);
  }
  return "template" + std::string(names.find(',') == std::string::npos ? " " : "s ") + names +
         " searched on " + buf + "; poses are still fitted to their own surface";
}

}  // namespace hpose::tools
