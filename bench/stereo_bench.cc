// The stereo-marker estimator on simulated frames, following the paper's protocol: robot
// position error on a grid of positions grouped by distance to the nearest landmark (the
// paper's Table 1), object accuracy (robot standing and walking), motion-detection delay and
// path-prediction error for a kicked ball, the local mode, and frame pairs per second on one
// core at 512x240 and 640x480; first the harder frames of both rigs with the three fits side by
// side. Usage: stereo_bench [--quick] [--hard-only | --speed-only] [--rig=paper|vga] [--far]
// (--far: the harder frames on a grid 1.4-2.0 m from the landmarks instead).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "core/common/pose2d.h"
#include "core/stereo/color_segmenter.h"
#include "core/stereo/local_marker_estimator.h"
#include "core/stereo/stereo_estimator.h"
#include "core/stereo/stereo_scene_simulator.h"
#include "core/stereo/stereo_sim_sequence.h"
#include "core/stereo/stereo_tracker.h"
#include "core/stereo/world_from_ground_fit.h"

namespace {

using namespace hpose;

struct Stats {
  std::vector<double> v;
  void Add(double x) { v.push_back(x); }
  double Mean() const {
    double s = 0;
    for (double x : v) s += x;
    return v.empty() ? NAN : s / v.size();
  }
  double Max() const { return v.empty() ? NAN : *std::max_element(v.begin(), v.end()); }
  double Median() const {
    if (v.empty()) return NAN;
    std::vector<double> c = v;
    std::nth_element(c.begin(), c.begin() + c.size() / 2, c.end());
    return c[c.size() / 2];
  }
};

double NearestLandmarkM(const StereoSimSequenceSpec& spec, const Pose2D& p) {
  double best = 1e9;
  for (const auto& l : spec.landmarks_m)
    best = std::min(best, std::hypot(p.x - l.x(), p.y - l.y()));
  return best;
}

// With `calibration_error`, the estimator gets a calibration off by typical residual errors of
// a real stereo calibration: focal lengths +-0.3 %, principal points 0.5 px, k1 2 %, and the
// right camera's rotation 0.05 deg and baseline 0.3 mm.
std::unique_ptr<StereoEstimator> MakeEstimator(const StereoSimSequenceSpec& spec,
                                               RigidFitMethod method,
                                               bool calibration_error = false) {
  const StereoSceneSimulator sim(spec.camera, StereoSimNoiseOptions{0, 1, 1, 0, 0, 1});
  StereoMarkerOptions options;
  options.method = method;
  StereoCalibration cal = sim.calibration();
  if (calibration_error) {
    cal.left.camera_matrix(0, 0) *= 1.003;
    cal.left.camera_matrix(1, 1) *= 1.003;
    cal.right.camera_matrix(0, 0) *= 0.997;
    cal.left.camera_matrix(0, 2) += 0.5;
    cal.right.camera_matrix(1, 2) -= 0.5;
    cal.left.distortion[0] *= 1.02;
    cal.right_R_left =
        cal.right_R_left *
        Eigen::AngleAxisd(DegToRad(0.05), Eigen::Vector3d::UnitY()).toRotationMatrix();
    cal.right_t_left *= 1.0 + 0.0003 / cal.BaselineM();
  }
  auto e = StereoEstimator::Create(cal, options);
  if (!e.ok()) {
    std::fprintf(stderr, "estimator: %s\n", e.error().message.c_str());
    std::exit(1);
  }
  return std::move(e).value();
}

void GridAccuracy(bool quick) {
  StereoSimSequenceSpec spec;
  spec.scenario = StereoSimScenario::kGrid;
  spec.frames_per_position = quick ? 2 : 8;
  spec.seed = 11;
  auto svd = MakeEstimator(spec, RigidFitMethod::kSvd);
  auto closed = MakeEstimator(spec, RigidFitMethod::kClosedForm);
  auto svd_cal = MakeEstimator(spec, RigidFitMethod::kSvd, true);
  auto closed_cal = MakeEstimator(spec, RigidFitMethod::kClosedForm, true);
  Stats cal_svd, cal_cf, cal_object;
  int cal_rejected = 0;
  const double bins[] = {0.0, 1.0, 1.2, 1.5, 1e9};
  const char* names[] = {"< 1000", "1000-1200", "1200-1500", ">= 1500"};
  const double paper_mean[] = {25.9, 32.8, 47.7, 54.0}, paper_max[] = {92.6, 93.0, 157.0, 221.1};
  Stats pos_svd[4], pos_cf[4], all_svd, all_cf, heading_svd, object, averaged;
  int rejected = 0, total = 0, object_missing = 0;
  std::vector<int> reasons(8, 0);
  Eigen::Vector2d sum_est = Eigen::Vector2d::Zero(), sum_true = Eigen::Vector2d::Zero();
  int in_cell = 0;
  Status s = GenerateStereoSimSequence(spec, [&](const StereoSimFrame& f) -> Status {
    ++total;
    auto a = svd->Process(f.left, f.right, f.timestamp_s);
    auto b = closed->Process(f.left, f.right, f.timestamp_s);
    if (!a.ok() || !b.ok()) return a.ok() ? b.error() : a.error();
    const int bin = static_cast<int>(
        std::upper_bound(std::begin(bins), std::end(bins), NearestLandmarkM(spec, f.truth.head)) -
        std::begin(bins) - 1);
    if (f.index % spec.frames_per_position == 0) {
      sum_est.setZero();
      sum_true.setZero();
      in_cell = 0;
    }
    if (!a->ok()) {
      ++rejected;
      ++reasons[static_cast<int>(a->status)];
    } else {
      const double e = std::hypot(a->robot.x - f.truth.head.x, a->robot.y - f.truth.head.y) * 1e3;
      pos_svd[bin].Add(e);
      all_svd.Add(e);
      heading_svd.Add(std::abs(RadToDeg(AngleDiff(a->robot.theta, f.truth.head.theta))));
      sum_est += Eigen::Vector2d(a->robot.x, a->robot.y);
      sum_true += Eigen::Vector2d(f.truth.head.x, f.truth.head.y);
      ++in_cell;
      if (a->object_in_world) {
        object.Add((a->object_world_m - f.truth.object_world_m).head<2>().norm() * 1e3);
      } else {
        ++object_missing;
      }
    }
    if (b->ok()) {
      const double e = std::hypot(b->robot.x - f.truth.head.x, b->robot.y - f.truth.head.y) * 1e3;
      pos_cf[bin].Add(e);
      all_cf.Add(e);
    }
    auto c = svd_cal->Process(f.left, f.right, f.timestamp_s);
    auto d = closed_cal->Process(f.left, f.right, f.timestamp_s);
    if (c.ok() && c->ok()) {
      cal_svd.Add(std::hypot(c->robot.x - f.truth.head.x, c->robot.y - f.truth.head.y) * 1e3);
      if (c->object_in_world) {
        cal_object.Add((c->object_world_m - f.truth.object_world_m).head<2>().norm() * 1e3);
      }
    } else {
      ++cal_rejected;
    }
    if (d.ok() && d->ok()) {
      cal_cf.Add(std::hypot(d->robot.x - f.truth.head.x, d->robot.y - f.truth.head.y) * 1e3);
    }
    if (f.index % spec.frames_per_position == spec.frames_per_position - 1 && in_cell > 0) {
      averaged.Add((sum_est - sum_true).norm() / in_cell * 1e3);
    }
    return Status::Ok();
  });
  if (!s.ok()) {
    std::fprintf(stderr, "grid: %s\n", s.error().message.c_str());
    std::exit(1);
  }
  std::printf("\n## Robot position on the grid (%d frames, %d positions x %d frames, %dx%d)\n\n",
              total, total / spec.frames_per_position, spec.frames_per_position, spec.camera.width,
              spec.camera.height);
  std::printf(
      "| nearest landmark (mm) | frames | SVD mean | SVD max | closed-form mean | "
      "closed-form max | paper mean | paper max |\n|---|---|---|---|---|---|---|---|\n");
  for (int i = 0; i < 4; ++i) {
    std::printf("| %s | %zu | %.1f | %.1f | %.1f | %.1f | %.1f | %.1f |\n", names[i],
                pos_svd[i].v.size(), pos_svd[i].Mean(), pos_svd[i].Max(), pos_cf[i].Mean(),
                pos_cf[i].Max(), paper_mean[i], paper_max[i]);
  }
  std::printf("| overall | %zu | %.1f | %.1f | %.1f | %.1f | 34.1 | 221.1 |\n\n", all_svd.v.size(),
              all_svd.Mean(), all_svd.Max(), all_cf.Mean(), all_cf.Max());
  std::printf(
      "SVD: median %.1f mm; heading error mean %.2f deg, max %.2f deg; mean of each "
      "position's frames (the 8-frame average): mean %.1f mm, max %.1f mm\n",
      all_svd.Median(), heading_svd.Mean(), heading_svd.Max(), averaged.Mean(), averaged.Max());
  std::printf("rejected frames: %d of %d (", rejected, total);
  for (int r = 1; r < 7; ++r) {
    if (reasons[r] > 0) {
      std::printf("%s %d; ", StereoFrameStatusName(static_cast<StereoFrameStatus>(r)), reasons[r]);
    }
  }
  std::printf(")\n");
  std::printf(
      "object (robot standing), horizontal error: mean %.1f mm, median %.1f, max %.1f mm "
      "over %zu frames, %d not located (paper: mean 14.5, max 89.6)\n",
      object.Mean(), object.Median(), object.Max(), object.v.size(), object_missing);
  std::printf(
      "with calibration errors (see MakeEstimator): robot SVD mean %.1f / max %.1f mm, "
      "closed form mean %.1f / max %.1f mm, %d rejected; object mean %.1f / max %.1f mm\n",
      cal_svd.Mean(), cal_svd.Max(), cal_cf.Mean(), cal_cf.Max(), cal_rejected, cal_object.Mean(),
      cal_object.Max());
}

// The harder frames (`simulate stereo --hard`) of both rigs: selection among distractors,
// occlusion handling and the three fits side by side, all from the same Process call (the
// result carries every fit; the head is recomputed from each).
void HardFrames(bool quick, const char* only, bool far) {
  struct RigCase {
    const char* name;
    StereoSimCameraOptions camera;
  };
  const RigCase rigs[] = {{"paper 512x240", StereoSimCameraOptions{}},
                          {"vga 640x480", VgaRigCameraOptions()}};
  const double bins[] = {0.0, 1.0, 1.2, 1.5, 1e9};
  const char* bin_names[] = {"< 1000", "1000-1200", "1200-1500", ">= 1500"};
  std::printf("\n## Harder frames (carpet, vignetting, Bayer, JPEG, distractors, occluders)\n");
  for (const RigCase& rig : rigs) {
    if (only != nullptr && std::strstr(rig.name, only) == nullptr) continue;
    StereoSimSequenceSpec spec;
    spec.scenario = StereoSimScenario::kGrid;
    spec.camera = rig.camera;
    MakeStereoSimHard(&spec);
    spec.frames_per_position = quick ? 1 : 3;
    spec.seed = 21;
    if (far) {  // 1.4-2.0 m from the nearest landmark.
      spec.grid_y_min_m = -2.0;
      spec.grid_y_max_m = -1.4;
    }
    auto est = MakeEstimator(spec, StereoMarkerOptions().method);  // the default fit.
    const Eigen::Vector3d head_in_left = 0.5 * est->rig().RightCentreInLeft();
    Stats err[3][5];  // per method: 4 distance bins + overall.
    Stats occluded_err[3], object, visible_clear, visible_occluded;
    int total = 0, posed = 0, with_distractors = 0, occluded_frames = 0, occluded_flagged = 0;
    int wrong_landmarks = 0, wrong_ball = 0, wrong_ball_blob = 0, ball_missing = 0;
    int extra_blob_frames = 0;
    int cov_better = 0, compared = 0;
    std::vector<std::string> reasons;
    Status s = GenerateStereoSimSequence(spec, [&](const StereoSimFrame& f) -> Status {
      ++total;
      const StereoSimTruth& t = f.truth;
      if (t.landmark_color_distractors + t.ball_color_distractors > 0) ++with_distractors;
      double occluded = 0;
      for (double o : t.landmark_occluded_fraction) occluded = std::max(occluded, o);
      if (occluded > 0) ++occluded_frames;
      auto r = est->Process(f.left, f.right, f.timestamp_s);
      if (!r.ok()) return r.error();
      if (r->landmark_blobs_left > 3 || r->landmark_blobs_right > 3) ++extra_blob_frames;
      if (!r->ok()) {
        reasons.push_back(std::string(StereoFrameStatusName(r->status)) + ": " + r->reason);
        return Status::Ok();
      }
      ++posed;
      const Eigen::Isometry3d left_from_world = t.world_from_left.inverse();
      // The chosen left blob must lie on the true landmark's image (within its radius): a
      // distractor is at least 0.12 m away on the floor.
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector3d truth = left_from_world * spec.landmarks_m[k];
        Eigen::Vector2d px;
        const double radius_px = 0.06 * spec.camera.width /
                                 (2 * std::tan(DegToRad(spec.camera.hfov_deg) / 2)) / truth.norm();
        if (!est->rig().Project(StereoSide::kLeft, truth, &px) ||
            (px - r->landmark_left_px[k]).norm() > radius_px + 2) {
          ++wrong_landmarks;
          std::printf("  frame %d: landmark P%d taken %.1f px from its image\n", f.index, k,
                      (px - r->landmark_left_px[k]).norm());
          break;
        }
      }
      bool flagged = false;
      for (bool d : r->landmark_downweighted) flagged |= d;
      for (int k = 0; k < 3; ++k) {
        (t.landmark_occluded_fraction[k] > 0 ? visible_occluded : visible_clear)
            .Add(r->landmark_visible_fraction[k]);
      }
      if (occluded > 0 && flagged) ++occluded_flagged;
      if (r->object_in_world) {
        const double e = (r->object_world_m - t.object_world_m).head<2>().norm();
        // The chosen blob must lie on the true ball's image (within its radius): a ball-coloured
        // distractor elsewhere is a wrong choice, a right blob placed off by the pose is not.
        const Eigen::Vector3d ball = left_from_world * t.object_world_m;
        Eigen::Vector2d ball_px;
        const double ball_radius_px = spec.ball_radius_m * spec.camera.width /
                                      (2 * std::tan(DegToRad(spec.camera.hfov_deg) / 2)) /
                                      ball.norm();
        if (!est->rig().Project(StereoSide::kLeft, ball, &ball_px) ||
            (ball_px - r->object_left_px).norm() > ball_radius_px + 2) {
          ++wrong_ball_blob;
        }
        if (e > 0.1) {
          ++wrong_ball;
          std::printf(
              "  frame %d: ball %.0f mm off, left blob at (%.0f, %.0f) %.1f px from the "
              "ball's image\n",
              f.index, e * 1e3, r->object_left_px.x(), r->object_left_px.y(),
              (ball_px - r->object_left_px).norm());
        }
        object.Add(e * 1e3);
      } else {
        ++ball_missing;
      }
      const int bin = static_cast<int>(
          std::upper_bound(std::begin(bins), std::end(bins), NearestLandmarkM(spec, t.head)) -
          std::begin(bins) - 1);
      const RigidFit* fits[3] = {&r->svd, &r->closed_form, &r->covariance};
      const bool fit_ok[3] = {true, r->closed_form_ok, r->covariance_ok};
      double e_method[3] = {0, 0, 0};
      for (int m = 0; m < 3; ++m) {
        if (!fit_ok[m]) continue;
        const Eigen::Vector3d head = fits[m]->rotation * head_in_left + fits[m]->translation;
        const double e = std::hypot(head.x() - t.head.x, head.y() - t.head.y) * 1e3;
        err[m][bin].Add(e);
        err[m][4].Add(e);
        if (occluded > 0) occluded_err[m].Add(e);
        e_method[m] = e;
      }
      if (e_method[2] > 50) {
        std::printf("  frame %d: %.0f mm off (default fit); occluded %.2f; %s\n", f.index,
                    e_method[2], occluded, r->landmark_notes.c_str());
      }
      if (fit_ok[1] && fit_ok[2]) {
        ++compared;
        cov_better += e_method[2] < e_method[1];
      }
      return Status::Ok();
    });
    if (!s.ok()) {
      std::fprintf(stderr, "hard frames: %s\n", s.error().message.c_str());
      std::exit(1);
    }
    std::printf("\n### %s%s, %d frames (%d positions x %d)\n\n", rig.name,
                far ? ", far grid (y -2.0..-1.4 m)" : "", total, total / spec.frames_per_position,
                spec.frames_per_position);
    std::printf(
        "frames with a pose: %d of %d (%.1f %%); frames with same-coloured distractors: %d "
        "(%.0f %%), with more than 3 landmark-coloured blobs in an image: %d; frames with an "
        "occluded landmark: %d, of them posed with the landmark down-weighted: %d\n",
        posed, total, 100.0 * posed / total, with_distractors, 100.0 * with_distractors / total,
        extra_blob_frames, occluded_frames, occluded_flagged);
    std::printf(
        "wrong blob taken as a landmark: %d frames; wrong blob taken as the ball: %d; ball "
        "reported > 100 mm from the truth: %d; ball not located: %d; ball horizontal error mean "
        "%.1f / max %.1f mm\n",
        wrong_landmarks, wrong_ball_blob, wrong_ball, ball_missing, object.Mean(), object.Max());
    for (const std::string& why : reasons) std::printf("  rejected: %s\n", why.c_str());
    auto lowest = [](const Stats& st) {
      return st.v.empty() ? NAN : *std::min_element(st.v.begin(), st.v.end());
    };
    std::printf(
        "visible fraction (blob area / predicted): whole landmarks median %.2f, lowest %.2f; "
        "partly covered landmarks median %.2f, highest %.2f\n",
        visible_clear.Median(), lowest(visible_clear), visible_occluded.Median(),
        visible_occluded.Max());
    std::printf(
        "\n| nearest landmark (mm) | frames | SVD 1/z^4 mean / max | closed form mean / max | "
        "covariance mean / max |\n|---|---|---|---|---|\n");
    for (int b = 0; b < 5; ++b) {
      std::printf("| %s | %zu |", b < 4 ? bin_names[b] : "overall", err[0][b].v.size());
      for (int m = 0; m < 3; ++m) std::printf(" %.1f / %.1f |", err[m][b].Mean(), err[m][b].Max());
      std::printf("\n");
    }
    std::printf("| occluded frames | %zu |", occluded_err[0].v.size());
    for (int m = 0; m < 3; ++m) {
      std::printf(" %.1f / %.1f |", occluded_err[m].Mean(), occluded_err[m].Max());
    }
    std::printf("\n");
    std::printf("covariance fit better than the closed form in %d of %d frames\n", cov_better,
                compared);
  }
}

// `calibrate world-from-ground` on a simulated recording: the robot placed over the grid, the
// stereo side from the estimator on rendered pairs, the depth side the robot's true template
// origin seen from a depth sensor at a known placement, with 15 mm / 2 deg noise and 5 % gross
// outliers. Reports the recovered placement's error and how far apart the two estimators'
// robot points are afterwards (what `query stream --compare` shows).
void WorldFromGround(bool quick) {
  StereoSimSequenceSpec spec;
  spec.scenario = StereoSimScenario::kGrid;
  spec.frames_per_position = quick ? 1 : 2;
  spec.seed = 31;
  auto est = MakeEstimator(spec, StereoMarkerOptions().method);
  const Pose2D truth{0.62, -2.35, DegToRad(97.0)};  // world_from_ground.
  const Eigen::Rotation2Dd r(truth.theta);
  const Eigen::Vector2d t(truth.x, truth.y);
  std::mt19937_64 rng(5);
  std::normal_distribution<double> noise(0.0, 0.015), heading(0.0, DegToRad(2.0));
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<GroundWorldPair> pairs;
  Status s = GenerateStereoSimSequence(spec, [&](const StereoSimFrame& f) -> Status {
    auto res = est->Process(f.left, f.right, f.timestamp_s);
    if (!res.ok()) return res.error();
    if (!res->ok()) return Status::Ok();
    const Pose2D& robot = f.truth.robot_nominal;  // the template origin.
    const Eigen::Vector2d ground = r.inverse() * (Eigen::Vector2d(robot.x, robot.y) - t);
    GroundWorldPair p;
    p.timestamp_s = f.timestamp_s;
    p.world = res->robot;
    p.ground = Pose2D{ground.x() + noise(rng), ground.y() + noise(rng),
                      NormalizeAngle(robot.theta - truth.theta + heading(rng))};
    if (unit(rng) < 0.05) p.ground.y += 0.3 + 0.3 * unit(rng);  // another object taken.
    pairs.push_back(p);
    return Status::Ok();
  });
  if (!s.ok()) {
    std::fprintf(stderr, "world-from-ground: %s\n", s.error().message.c_str());
    std::exit(1);
  }
  auto fit = FitWorldFromGround(pairs);
  if (!fit.ok()) {
    std::fprintf(stderr, "world-from-ground: %s\n", fit.error().message.c_str());
    std::exit(1);
  }
  Stats apart;
  for (const GroundWorldPair& p : pairs) {
    const Eigen::Vector2d g =
        Eigen::Rotation2Dd(fit->world_from_ground.theta) * Eigen::Vector2d(p.ground.x, p.ground.y) +
        Eigen::Vector2d(fit->world_from_ground.x, fit->world_from_ground.y);
    apart.Add((g - Eigen::Vector2d(p.world.x, p.world.y)).norm() * 1e3);
  }
  std::printf(
      "\n## calibrate world-from-ground on a simulated recording\n\n%zu pairs, %d kept; "
      "placement error %.1f mm, %.2f deg; residual RMS %.1f mm; the two robot points apart "
      "afterwards: median %.1f mm (all pairs, outliers included)\nobservable: %s\n",
      pairs.size(), fit->inliers,
      std::hypot(fit->world_from_ground.x - truth.x, fit->world_from_ground.y - truth.y) * 1e3,
      std::abs(RadToDeg(AngleDiff(fit->world_from_ground.theta, truth.theta))), fit->rms_m * 1e3,
      apart.Median(), fit->observability.c_str());
}

void WalkingAccuracy(bool quick) {
  StereoSimSequenceSpec spec;
  spec.scenario = StereoSimScenario::kWalking;
  spec.frames = quick ? 30 : 90;
  spec.robot_start = Pose2D{0.05, -1.3, kPi / 2};
  spec.robot_speed_mps = 0.06;
  spec.ball_start_m = Eigen::Vector2d(0.4, -0.3);
  spec.seed = 5;
  auto est = MakeEstimator(spec, RigidFitMethod::kSvd);
  StereoTracker tracker;
  Stats object, robot, robot_avg_vs_nominal, robot_vs_nominal;
  int rejected = 0;
  Status s = GenerateStereoSimSequence(spec, [&](const StereoSimFrame& f) -> Status {
    auto r = est->Process(f.left, f.right, f.timestamp_s);
    if (!r.ok()) return r.error();
    const StereoTrackState t = tracker.Update(*r);
    if (!r->ok()) {
      ++rejected;
      return Status::Ok();
    }
    robot.Add(std::hypot(r->robot.x - f.truth.head.x, r->robot.y - f.truth.head.y) * 1e3);
    robot_vs_nominal.Add(
        std::hypot(r->robot.x - f.truth.robot_nominal.x, r->robot.y - f.truth.robot_nominal.y) *
        1e3);
    robot_avg_vs_nominal.Add(std::hypot(t.robot_mean.x - f.truth.robot_nominal.x,
                                        t.robot_mean.y - f.truth.robot_nominal.y) *
                             1e3);
    if (r->object_in_world) {
      object.Add((r->object_world_m - f.truth.object_world_m).head<2>().norm() * 1e3);
    }
    return Status::Ok();
  });
  if (!s.ok()) std::exit(1);
  std::printf("\n## Robot walking (head sway), ball at rest: %d frames, %d rejected\n\n",
              spec.frames, rejected);
  std::printf("object error mean %.1f mm, max %.1f mm (paper, robot moving: 11.5 / 65.1)\n",
              object.Mean(), object.Max());
  std::printf(
      "robot vs swaying head: mean %.1f, max %.1f mm; vs walking pose without sway: "
      "single frame mean %.1f, 8-frame mean %.1f mm (lag of the average included)\n",
      robot.Mean(), robot.Max(), robot_vs_nominal.Mean(), robot_avg_vs_nominal.Mean());
}

void Motion(bool quick) {
  Stats delay, pred05, pred10, direction, speed_err;
  int runs = quick ? 3 : 10, missed = 0, false_alarms = 0;
  for (int run = 0; run < runs; ++run) {
    StereoSimSequenceSpec spec;
    spec.scenario = StereoSimScenario::kRollingBall;
    spec.seed = 100 + run;
    spec.kick_time_s = 1.3 + 0.037 * run;
    const double angle = DegToRad(-105 + 4 * run);
    const double speed = 0.3 + 0.03 * run;
    spec.ball_velocity_mps = Eigen::Vector2d(std::cos(angle), std::sin(angle)) * speed;
    spec.frames = 50;
    auto est = MakeEstimator(spec, RigidFitMethod::kSvd);
    StereoTracker tracker;
    bool detected = false, predicted = false;
    std::vector<StereoSimFrame> truth_frames;
    PathPrediction path;
    double fit_time = 0;
    std::vector<std::pair<double, Eigen::Vector2d>> truth;
    Status s = GenerateStereoSimSequence(spec, [&](const StereoSimFrame& f) -> Status {
      truth.emplace_back(f.timestamp_s, f.truth.object_world_m.head<2>());
      auto r = est->Process(f.left, f.right, f.timestamp_s);
      if (!r.ok()) return r.error();
      const StereoTrackState t = tracker.Update(*r);
      if (t.object_moving && !detected) {
        detected = true;
        if (f.timestamp_s < spec.kick_time_s) {
          ++false_alarms;
        } else {
          delay.Add(f.timestamp_s - spec.kick_time_s);
        }
      }
      if (t.path_valid && !predicted) {
        predicted = true;
        path = t.path;
        fit_time = f.timestamp_s;
      }
      return Status::Ok();
    });
    if (!s.ok()) std::exit(1);
    if (!detected) ++missed;
    if (!predicted) continue;
    // The true ball position at fit_time + 0.5 s and + 1.0 s from the same rolling model.
    for (double ahead : {0.5, 1.0}) {
      const double tq = fit_time + ahead;
      for (size_t i = 0; i + 1 < truth.size(); ++i) {
        if (truth[i].first <= tq && truth[i + 1].first > tq) {
          const double w = (tq - truth[i].first) / (truth[i + 1].first - truth[i].first);
          const Eigen::Vector2d p = (1 - w) * truth[i].second + w * truth[i + 1].second;
          (ahead < 0.75 ? pred05 : pred10).Add((path.PositionAt(tq) - p).norm() * 1e3);
        }
      }
    }
    direction.Add(std::abs(
        RadToDeg(AngleDiff(std::atan2(path.velocity_mps.y(), path.velocity_mps.x()), angle))));
    speed_err.Add(std::abs(path.Speed() - speed) * 1e3);
  }
  std::printf("\n## Kicked ball (robot standing, head sway on), %d runs at 15 frames/s\n\n", runs);
  std::printf(
      "motion detection delay after the kick: median %.0f ms, mean %.0f ms, max %.0f ms; "
      "missed %d, false alarms %d\n",
      delay.Median() * 1e3, delay.Mean() * 1e3, delay.Max() * 1e3, missed, false_alarms);
  std::printf(
      "path from 8 frames after detection: direction error mean %.1f deg (max %.1f), "
      "speed error mean %.0f mm/s; predicted position error 0.5 s ahead mean %.0f mm "
      "(max %.0f), 1.0 s ahead mean %.0f mm (max %.0f)\n",
      direction.Mean(), direction.Max(), speed_err.Mean(), pred05.Mean(), pred05.Max(),
      pred10.Mean(), pred10.Max());
}

void LocalMode(bool quick) {
  StereoSimCameraOptions cam;
  StereoSimNoiseOptions noise;
  const StereoSceneSimulator sim(cam, noise);
  LocalMarkerOptions options;
  options.marker_spacing_m = 0.12;
  const double ball_r = 0.035;
  options.object_height_above_markers_m = ball_r;
  auto est = LocalMarkerEstimator::Create(sim.calibration().left, options);
  if (!est.ok()) std::exit(1);
  Stats err;
  int failed = 0;
  const int n = quick ? 20 : 100;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> ux(0.06, 0.2), uy(-0.15, 0.15);
  for (int i = 0; i < n; ++i) {
    SimScene scene;
    scene.discs.push_back(SimDisc{Eigen::Vector2d(0, -0.06), 0.015, Rgb8{190, 50, 150}});
    scene.discs.push_back(SimDisc{Eigen::Vector2d(0, 0.06), 0.015, Rgb8{190, 50, 150}});
    const Eigen::Vector2d ball(ux(rng), uy(rng));
    scene.balls.push_back(
        SimBall{Eigen::Vector3d(ball.x(), ball.y(), ball_r), ball_r, Rgb8{225, 105, 25}});
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear().col(0) = Eigen::Vector3d(0, -1, 0);
    pose.linear().col(1) = Eigen::Vector3d(-1, 0, 0);
    pose.linear().col(2) = Eigen::Vector3d(0, 0, -1);
    pose.translation() = Eigen::Vector3d(0.08, 0, 0.45);
    const RgbImage image = sim.Render(StereoSide::kLeft, pose, scene, 1.0, 77 + i);
    auto r = (*est)->Process(image);
    if (!r.ok()) {
      ++failed;
      continue;
    }
    err.Add((r->object_in_robot_m - ball).norm() * 1e3);
  }
  std::printf(
      "\n## Local mode (camera 0.45 m above the floor looking down, markers 120 mm "
      "apart)\n\nobject error mean %.1f mm, max %.1f mm over %zu images, %d failed "
      "(paper: mean 8.3, max 31)\n",
      err.Mean(), err.Max(), err.v.size(), failed);
}

void Speed(int width, int height, bool quick) {
  StereoSimSequenceSpec spec;
  spec.scenario = StereoSimScenario::kRollingBall;
  spec.camera.width = width;
  spec.camera.height = height;
  spec.frames = 20;
  spec.seed = 9;
  auto est = MakeEstimator(spec, StereoMarkerOptions().method);
  std::vector<StereoSimFrame> frames;
  GenerateStereoSimSequence(spec, [&](const StereoSimFrame& f) -> Status {
    frames.push_back(f);
    return Status::Ok();
  });
  auto seg = ColorSegmenter::Create(
      {StereoMarkerOptions().landmark_color, StereoMarkerOptions().object_color});
  const int reps = quick ? 10 : 50;
  int ok = 0;
  auto t0 = std::chrono::steady_clock::now();
  for (int r = 0; r < reps; ++r) {
    for (const StereoSimFrame& f : frames)
      ok += (*est->Process(f.left, f.right, f.timestamp_s)).ok();
  }
  auto t1 = std::chrono::steady_clock::now();
  size_t blobs = 0;
  for (int r = 0; r < reps; ++r) {
    for (const StereoSimFrame& f : frames) {
      blobs += seg->Segment(f.left).size() + seg->Segment(f.right).size();
    }
  }
  auto t2 = std::chrono::steady_clock::now();
  const double n = static_cast<double>(reps * frames.size());
  const double full = std::chrono::duration<double>(t1 - t0).count() / n;
  const double segment = std::chrono::duration<double>(t2 - t1).count() / n;
  std::printf("| %dx%d | %.0f | %.3f | %.3f | %.0f%% | %d/%zu |\n", width, height, 1.0 / full,
              full * 1e3, segment * 1e3, 100.0 * segment / full, ok / reps, frames.size());
  (void)blobs;
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false, hard_only = false, speed_only = false, far = false;
  const char* rig = nullptr;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--quick") == 0) quick = true;
    if (std::strcmp(argv[i], "--hard-only") == 0) hard_only = true;
    if (std::strcmp(argv[i], "--speed-only") == 0) speed_only = true;
    if (std::strcmp(argv[i], "--far") == 0) far = true;
    if (std::strncmp(argv[i], "--rig=", 6) == 0) rig = argv[i] + 6;
  }
  if (!speed_only) {
    HardFrames(quick, rig, far);
    if (hard_only) return 0;
    WorldFromGround(quick);
    GridAccuracy(quick);
    WalkingAccuracy(quick);
    Motion(quick);
    LocalMode(quick);
  }
  std::printf("\n## Speed, one thread (full Process per pair; segmentation = both images)\n\n");
  std::printf(
      "| image | pairs/s | ms/pair | segmentation ms/pair | segmentation share | ok "
      "frames |\n|---|---|---|---|---|---|\n");
  Speed(512, 240, quick);
  Speed(640, 480, quick);
  return 0;
}
