#include "core/stereo/stereo_scene_simulator.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <random>

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "core/io/decoded_image.h"
#include "core/io/jpeg_codec.h"

namespace hpose {
namespace {

// Camera axes of a level camera looking along world +x: x right = -y_world, y down = -z_world.
Eigen::Matrix3d LevelCameraAxes() {
  Eigen::Matrix3d r;
  r.col(0) = Eigen::Vector3d(0, -1, 0);
  r.col(1) = Eigen::Vector3d(0, 0, -1);
  r.col(2) = Eigen::Vector3d(1, 0, 0);
  return r;
}

std::uint32_t Hash(std::int64_t a, std::int64_t b, std::uint32_t seed) {
  std::uint64_t h =
      static_cast<std::uint64_t>(a) * 0x9E3779B97F4A7C15ull ^
      (static_cast<std::uint64_t>(b) + 0x632BE59BD9B4E019ull + seed) * 0xBF58476D1CE4E5B9ull;
  h ^= h >> 31;
  h *= 0x94D049BB133111EBull;
  h ^= h >> 29;
  return static_cast<std::uint32_t>(h);
}

// Smooth value noise in [-1, 1] over the floor: bilinear interpolation of hashed lattice values
// with a smoothstep.
double ValueNoise(double x, double y, std::uint32_t seed) {
  const double fx = std::floor(x), fy = std::floor(y);
  const auto ix = static_cast<std::int64_t>(fx), iy = static_cast<std::int64_t>(fy);
  auto lattice = [&](std::int64_t a, std::int64_t b) {
    return (Hash(a, b, seed) & 0xFFFF) / 32767.5 - 1.0;
  };
  auto smooth = [](double t) { return t * t * (3 - 2 * t); };
  const double tx = smooth(x - fx), ty = smooth(y - fy);
  const double top = lattice(ix, iy) * (1 - tx) + lattice(ix + 1, iy) * tx;
  const double bottom = lattice(ix, iy + 1) * (1 - tx) + lattice(ix + 1, iy + 1) * tx;
  return top * (1 - ty) + bottom * ty;
}

}  // namespace

bool SimPatch::Contains(const Eigen::Vector2d& p) const {
  const Eigen::Vector2d d = p - centre_m;
  const double c = std::cos(yaw_rad), s = std::sin(yaw_rad);
  return std::abs(c * d.x() + s * d.y()) <= half_size_m.x() &&
         std::abs(-s * d.x() + c * d.y()) <= half_size_m.y();
}

double DiscCapFraction(double d, double r) {
  const double u = std::clamp(d / r, -1.0, 1.0);
  return (std::acos(u) - u * std::sqrt(1 - u * u)) / kPi;
}

StereoSimCameraOptions VgaRigCameraOptions() {
  StereoSimCameraOptions c;
  c.width = 640;
  c.height = 480;
  c.hfov_deg = 66.0;
  c.pixel_aspect = 1.0;
  c.distortion = {-0.31, 0.12, 0.0011, -0.0007, -0.025};
  c.baseline_m = 0.076;
  c.right_yaw_deg = -0.9;
  c.right_roll_deg = 0.7;
  c.right_focal_scale = 0.992;
  c.head_height_m = 0.47;
  c.head_tilt_deg = 22.0;
  return c;
}

HeadSway HeadSwayModel::At(double t_s) const {
  const double phase = kPi * step_frequency_hz * t_s;  // one sway cycle per two steps.
  HeadSway s;
  s.lateral_m = lateral_m * std::sin(phase);
  s.vertical_m = vertical_m * std::cos(2 * phase);
  s.roll_rad = DegToRad(roll_deg) * std::sin(phase);
  s.pitch_rad = DegToRad(pitch_deg) * std::sin(2 * phase + 0.7);
  s.yaw_rad = DegToRad(yaw_deg) * std::sin(phase + 0.5);
  return s;
}

StereoSceneSimulator::StereoSceneSimulator(const StereoSimCameraOptions& camera,
                                           const StereoSimNoiseOptions& noise)
    : camera_(camera), noise_(noise) {
  assert(camera_.width > 0 && camera_.height > 0 && noise_.supersample >= 1);
  const double fx = 0.5 * camera_.width / std::tan(DegToRad(camera_.hfov_deg) / 2);
  const double aspect = camera_.pixel_aspect > 0
                            ? camera_.pixel_aspect
                            : static_cast<double>(camera_.height) / (0.75 * camera_.width);
  const double fy = fx * aspect;
  Eigen::Matrix3d kl;
  kl << fx, 0, (camera_.width - 1) / 2.0 + 3.1, 0, fy, (camera_.height - 1) / 2.0 - 2.3, 0, 0, 1;
  Eigen::Matrix3d kr;
  const double s = camera_.right_focal_scale;
  kr << fx * s, 0, (camera_.width - 1) / 2.0 - 4.2, 0, fy * s, (camera_.height - 1) / 2.0 + 1.7, 0,
      0, 1;
  calibration_.left.camera_matrix = kl;
  calibration_.right.camera_matrix = kr;
  calibration_.left.distortion = camera_.distortion;
  calibration_.right.distortion = camera_.distortion;
  if (!calibration_.right.distortion.empty()) calibration_.right.distortion[0] *= 1.03;
  const Eigen::Matrix3d r =
      (Eigen::AngleAxisd(DegToRad(camera_.right_yaw_deg), Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(DegToRad(camera_.right_roll_deg), Eigen::Vector3d::UnitZ()))
          .toRotationMatrix();
  calibration_.right_R_left = r;
  calibration_.right_t_left = -r * Eigen::Vector3d(camera_.baseline_m, 0, 0);
  calibration_.image_width = camera_.width;
  calibration_.image_height = camera_.height;

  const int ss = noise_.supersample;
  const CameraModel* cams[2] = {&calibration_.left, &calibration_.right};
  for (int c = 0; c < 2; ++c) {
    std::vector<cv::Point2d> src;
    src.reserve(static_cast<size_t>(camera_.width) * camera_.height * ss * ss);
    for (int v = 0; v < camera_.height; ++v)
      for (int u = 0; u < camera_.width; ++u)
        for (int j = 0; j < ss; ++j)
          for (int i = 0; i < ss; ++i)
            src.emplace_back(u + (i + 0.5) / ss - 0.5, v + (j + 0.5) / ss - 0.5);
    cv::Mat k(3, 3, CV_64F);
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) k.at<double>(a, b) = cams[c]->camera_matrix(a, b);
    const cv::Mat d =
        cams[c]->distortion.empty() ? cv::Mat() : cv::Mat(cams[c]->distortion, true).reshape(1, 1);
    std::vector<cv::Point2d> dst;
    cv::undistortPoints(
        src, dst, k, d, cv::noArray(), cv::noArray(),
        cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 50, 1e-14));
    rays_[c].resize(dst.size());
    for (size_t i = 0; i < dst.size(); ++i) {
      rays_[c][i] = Eigen::Vector2f(static_cast<float>(dst[i].x), static_cast<float>(dst[i].y));
    }
  }
}

StereoSceneSimulator::~StereoSceneSimulator() = default;

Eigen::Isometry3d StereoSceneSimulator::WorldFromLeft(const Pose2D& robot,
                                                      const HeadSway& sway) const {
  const Eigen::Matrix3d world_r_head =
      (Eigen::AngleAxisd(robot.theta + sway.yaw_rad, Eigen::Vector3d::UnitZ()) *
       Eigen::AngleAxisd(DegToRad(camera_.head_tilt_deg) + sway.pitch_rad,
                         Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(sway.roll_rad, Eigen::Vector3d::UnitX()))
          .toRotationMatrix() *
      LevelCameraAxes();
  const Eigen::Vector3d head =
      Eigen::Vector3d(robot.x, robot.y, 0) +
      Eigen::AngleAxisd(robot.theta, Eigen::Vector3d::UnitZ()) *
          Eigen::Vector3d(0, sway.lateral_m, camera_.head_height_m + sway.vertical_m);
  Eigen::Isometry3d world_from_left = Eigen::Isometry3d::Identity();
  world_from_left.linear() = world_r_head;
  world_from_left.translation() = head - 0.5 * camera_.baseline_m * world_r_head.col(0);
  return world_from_left;
}

RgbImage StereoSceneSimulator::Render(StereoSide side, const Eigen::Isometry3d& world_from_camera,
                                      const SimScene& scene, double gain,
                                      std::uint64_t seed) const {
  const int w = camera_.width, h = camera_.height, ss = noise_.supersample;
  const std::vector<Eigen::Vector2f>& rays = rays_[side == StereoSide::kLeft ? 0 : 1];
  const Eigen::Matrix3d rot = world_from_camera.linear();
  const Eigen::Vector3d origin = world_from_camera.translation();
  const Eigen::Vector3d light = scene.light_direction.normalized();
  std::mt19937_64 rng(seed);
  std::normal_distribution<float> noise(0.f, static_cast<float>(noise_.pixel_noise_sigma));
  const std::uint32_t texture_seed = 1234u;
  RgbImage image(w, h);
  size_t k = 0;
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      Eigen::Vector3d acc = Eigen::Vector3d::Zero();
      for (int s = 0; s < ss * ss; ++s, ++k) {
        const Eigen::Vector3d d = rot * Eigen::Vector3d(rays[k].x(), rays[k].y(), 1.0);
        double best = std::numeric_limits<double>::infinity();
        Eigen::Vector3d color = Eigen::Vector3d::Zero();
        for (const SimBall& ball : scene.balls) {
          const Eigen::Vector3d oc = origin - ball.centre_m;
          const double a = d.squaredNorm(), b = oc.dot(d);
          const double c = oc.squaredNorm() - ball.radius_m * ball.radius_m;
          const double disc = b * b - a * c;
          if (disc < 0) continue;
          const double t = (-b - std::sqrt(disc)) / a;
          if (t <= 0 || t >= best) continue;
          best = t;
          const Eigen::Vector3d n = (origin + t * d - ball.centre_m) / ball.radius_m;
          const double shade = 0.6 + 0.4 * std::max(0.0, n.dot(light));
          color = Eigen::Vector3d(ball.color[0], ball.color[1], ball.color[2]) * shade;
        }
        if (!std::isfinite(best)) {
          const double t = d.z() < -1e-9 ? -origin.z() / d.z() : -1;
          const Eigen::Vector3d p = origin + t * d;
          if (t <= 0 || (p - origin).head<2>().norm() > 6.0) {
            color = Eigen::Vector3d(scene.wall_color[0], scene.wall_color[1], scene.wall_color[2]);
          } else {
            const SimDisc* hit = nullptr;
            for (const SimDisc& disc : scene.discs) {
              if ((p.head<2>() - disc.centre_m).squaredNorm() <= disc.radius_m * disc.radius_m) {
                hit = &disc;
              }
            }
            const SimPatch* patch = nullptr;
            for (const SimPatch& pt : scene.patches) {
              if (pt.Contains(p.head<2>())) patch = &pt;
            }
            if (patch != nullptr) {
              color = Eigen::Vector3d(patch->color[0], patch->color[1], patch->color[2]);
            } else if (hit != nullptr) {
              color = Eigen::Vector3d(hit->color[0], hit->color[1], hit->color[2]);
            } else {
              const double gx = p.x() / scene.grid_spacing_m, gy = p.y() / scene.grid_spacing_m;
              const double line = 0.5 * scene.grid_line_width_m / scene.grid_spacing_m;
              const bool on_line =
                  std::abs(gx - std::round(gx)) < line || std::abs(gy - std::round(gy)) < line;
              const Rgb8& base = on_line ? scene.grid_color : scene.floor_color;
              const std::uint32_t hsh =
                  Hash(static_cast<std::int64_t>(std::floor(p.x() * 50)),
                       static_cast<std::int64_t>(std::floor(p.y() * 50)), texture_seed);
              double texture = 1.0 + scene.carpet_fine_contrast * ((hsh & 0xFFFF) / 32767.5 - 1.0);
              if (scene.carpet_coarse_contrast > 0) {
                texture *= 1.0 + scene.carpet_coarse_contrast *
                                     ValueNoise(p.x() / scene.carpet_scale_m,
                                                p.y() / scene.carpet_scale_m, texture_seed + 7);
              }
              color = Eigen::Vector3d(base[0], base[1], base[2]) * texture;
            }
          }
        }
        acc += color;
      }
      acc /= ss * ss;
      const double g = gain * (1.0 + noise_.gradient * (static_cast<double>(u) / w - 0.5));
      std::uint8_t* px = image.at(u, v);
      for (int c = 0; c < 3; ++c) {
        const double value = acc[c] * g + (noise_.bayer ? 0.f : noise(rng));
        px[c] = static_cast<std::uint8_t>(std::clamp(std::lround(value), 0L, 255L));
      }
    }
  }
  ApplySensor(&image, seed ^ 0x5DEECE66Dull);
  return image;
}

void StereoSceneSimulator::ApplySensor(RgbImage* image, std::uint64_t seed) const {
  const int w = image->width, h = image->height;
  std::mt19937_64 rng(seed);
  if (noise_.speckles_per_image > 0 && !noise_.speckle_colors.empty()) {
    std::uniform_int_distribution<int> count(0, noise_.speckles_per_image);
    std::uniform_int_distribution<int> ux(0, w - 1), uy(0, h - 1), size(2, 4);
    std::uniform_int_distribution<size_t> pick(0, noise_.speckle_colors.size() - 1);
    const int n = count(rng);
    for (int i = 0; i < n; ++i) {
      const int x0 = ux(rng), y0 = uy(rng), sx = size(rng), sy = size(rng);
      const Rgb8 c = noise_.speckle_colors[pick(rng)];
      for (int y = y0; y < std::min(h, y0 + sy); ++y)
        for (int x = x0; x < std::min(w, x0 + sx); ++x)
          for (int k = 0; k < 3; ++k) image->at(x, y)[k] = c[k];
    }
  }
  if (noise_.vignetting > 0) {
    const double cx = 0.5 * (w - 1), cy = 0.5 * (h - 1), r2max = cx * cx + cy * cy;
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const double f =
            1.0 - noise_.vignetting * ((x - cx) * (x - cx) + (y - cy) * (y - cy)) / r2max;
        std::uint8_t* px = image->at(x, y);
        for (int k = 0; k < 3; ++k) px[k] = static_cast<std::uint8_t>(std::lround(px[k] * f));
      }
    }
  }
  if (noise_.bayer) {
    // RGGB: even rows R G R G..., odd rows G B G B...
    cv::Mat raw(h, w, CV_8UC1);
    std::normal_distribution<double> unit(0.0, 1.0);
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const int channel = (y % 2 == 0) ? (x % 2 == 0 ? 0 : 1) : (x % 2 == 0 ? 1 : 2);
        const double level = image->at(x, y)[channel];
        const double sigma = std::sqrt(noise_.pixel_noise_sigma * noise_.pixel_noise_sigma +
                                       noise_.shot_noise * noise_.shot_noise * level);
        raw.at<std::uint8_t>(y, x) =
            static_cast<std::uint8_t>(std::clamp(std::lround(level + sigma * unit(rng)), 0L, 255L));
      }
    }
    // OpenCV names Bayer patterns by the second row's second and third pixels: RGGB is "BG".
    cv::Mat rgb(h, w, CV_8UC3, image->pixels.data());
    cv::demosaicing(raw, rgb, cv::COLOR_BayerBG2RGB_EA);
  }
  if (noise_.jpeg_quality > 0) {
    DecodedImage rgb;
    rgb.width = w;
    rgb.height = h;
    rgb.channels = 3;
    rgb.bits_per_sample = 8;
    rgb.bytes = image->pixels;
    // The image is valid and the quality in range: neither step can fail but for memory.
    const Result<std::string> encoded = EncodeJpeg(rgb, std::clamp(noise_.jpeg_quality, 1, 100));
    Result<DecodedImage> decoded = encoded.ok() ? DecodeJpeg(*encoded, "the simulated image")
                                                : Result<DecodedImage>(encoded.error());
    assert(decoded.ok() && decoded->width == w && decoded->height == h && decoded->channels == 3);
    if (decoded.ok()) image->pixels = std::move(decoded->bytes);
  }
}

StereoSceneSimulator::Pair StereoSceneSimulator::RenderPair(const Pose2D& robot,
                                                            const HeadSway& sway,
                                                            const SimScene& scene,
                                                            std::uint64_t seed) const {
  Pair pair;
  const Eigen::Isometry3d world_from_left = WorldFromLeft(robot, sway);
  Eigen::Isometry3d right_from_left = Eigen::Isometry3d::Identity();
  right_from_left.linear() = calibration_.right_R_left;
  right_from_left.translation() = calibration_.right_t_left;
  const Eigen::Isometry3d world_from_right = world_from_left * right_from_left.inverse();
  std::mt19937_64 rng(seed ^ 0xA5A5A5A5ull);
  std::uniform_real_distribution<double> gain_dist(noise_.gain_min, noise_.gain_max);
  std::uniform_real_distribution<double> lr(-noise_.left_right_gain_difference,
                                            noise_.left_right_gain_difference);
  const double gain = gain_dist(rng);
  pair.left = Render(StereoSide::kLeft, world_from_left, scene, gain, seed * 2 + 1);
  pair.right =
      Render(StereoSide::kRight, world_from_right, scene, gain * (1 + lr(rng)), seed * 2 + 2);

  StereoSimTruth& t = pair.truth;
  t.robot_nominal = robot;
  t.world_from_left = world_from_left;
  t.head_position_m = world_from_left * (0.5 * Eigen::Vector3d(camera_.baseline_m, 0, 0));
  const Eigen::Vector3d axis = world_from_left.linear().col(2);
  t.head.x = t.head_position_m.x();
  t.head.y = t.head_position_m.y();
  t.head.theta = NormalizeAngle(std::atan2(axis.y(), axis.x()));
  if (!scene.balls.empty()) {
    t.object_present = true;
    t.object_world_m = scene.balls.front().centre_m;
  }
  return pair;
}

SimScene MakeFieldScene(const std::array<Eigen::Vector3d, 3>& landmarks, bool distractors,
                        std::uint64_t seed) {
  SimScene scene;
  for (const Eigen::Vector3d& p : landmarks) {
    SimDisc d;
    d.centre_m = p.head<2>();
    d.radius_m = 0.06;
    d.color = kSimLandmarkColor;
    scene.discs.push_back(d);
  }
  if (distractors) {
    const Rgb8 colors[] = {
        {210, 190, 40}, {190, 50, 150}, {200, 40, 40}, {230, 230, 230}, {40, 160, 170}};
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> ux(-0.9, 0.9), uy(-0.5, 1.0), ur(0.03, 0.06);
    int placed = 0;
    for (int attempt = 0; attempt < 200 && placed < 5; ++attempt) {
      const Eigen::Vector2d c(ux(rng), uy(rng));
      const double r = ur(rng);
      bool clear = true;
      for (const Eigen::Vector3d& p : landmarks) clear &= (c - p.head<2>()).norm() > r + 0.1;
      if (!clear) continue;
      scene.discs.push_back(SimDisc{c, r, colors[placed % 5]});
      ++placed;
    }
  }
  return scene;
}

}  // namespace hpose
