#include "core/stereo/rigid_fit.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

namespace hpose {
namespace {

const std::array<Eigen::Vector3d, 3> kWorld = {
    Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(-0.25, 0.4, 0), Eigen::Vector3d(0.25, 0.4, 0)};

double AngleBetween(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  const double c = std::clamp(((a * b.transpose()).trace() - 1.0) / 2.0, -1.0, 1.0);
  return std::acos(c);
}

// camera points such that world = rotation * camera + translation.
std::array<Eigen::Vector3d, 3> CameraPoints(const Eigen::Matrix3d& r, const Eigen::Vector3d& t) {
  std::array<Eigen::Vector3d, 3> c;
  for (int i = 0; i < 3; ++i) c[i] = r.transpose() * (kWorld[i] - t);
  return c;
}

TEST(RigidFitTest, ClosedFormAndSvdAreExactWithoutNoise) {
  const Eigen::Matrix3d r =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.2, -0.5, 0.8).normalized()).toRotationMatrix();
  const Eigen::Vector3d t(0.1, -1.2, 0.45);
  const auto cam = CameraPoints(r, t);
  auto cf = FitRigidClosedForm(cam, kWorld);
  ASSERT_TRUE(cf.ok());
  EXPECT_LT((cf->rotation - r).norm(), 1e-9);
  EXPECT_LT((cf->translation - t).norm(), 1e-9);
  EXPECT_LT(cf->orthonormality_error, 1e-9);
  EXPECT_LT(cf->rms_residual_m, 1e-9);
  auto svd = FitRigidSvd({cam.begin(), cam.end()}, {kWorld.begin(), kWorld.end()});
  ASSERT_TRUE(svd.ok());
  EXPECT_LT((svd->rotation - r).norm(), 1e-9);
  EXPECT_LT((svd->translation - t).norm(), 1e-9);
}

TEST(RigidFitTest, NoisyPointsClosedFormIsNotARotationButSvdIs) {
  std::mt19937 rng(4);
  std::normal_distribution<double> noise(0.0, 0.003);
  double cf_angle = 0, svd_angle = 0, cf_ortho = 0;
  const int trials = 300;
  for (int k = 0; k < trials; ++k) {
    const Eigen::Matrix3d r =
        Eigen::AngleAxisd(0.1 * k, Eigen::Vector3d(0.3, 1.0, -0.2).normalized()).toRotationMatrix();
    const Eigen::Vector3d t(0.05 * std::sin(k), -1.0, 0.45);
    auto cam = CameraPoints(r, t);
    for (auto& p : cam) p += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    auto cf = FitRigidClosedForm(cam, kWorld);
    auto svd = FitRigidSvd({cam.begin(), cam.end()}, {kWorld.begin(), kWorld.end()});
    ASSERT_TRUE(cf.ok() && svd.ok());
    EXPECT_LT(svd->orthonormality_error, 1e-9);
    EXPECT_NEAR(svd->rotation.determinant(), 1.0, 1e-9);
    cf_ortho += cf->orthonormality_error;
    // Compare the closed form's rotation after projecting it onto the nearest rotation.
    Eigen::JacobiSVD<Eigen::Matrix3d> proj(cf->rotation, Eigen::ComputeFullU | Eigen::ComputeFullV);
    const Eigen::Matrix3d cf_rot = proj.matrixU() * proj.matrixV().transpose();
    cf_angle += AngleBetween(cf_rot, r);
    svd_angle += AngleBetween(svd->rotation, r);
  }
  EXPECT_GT(cf_ortho / trials, 1e-4);  // noise makes the closed form's basis non-orthonormal.
  EXPECT_LT(svd_angle / trials, 0.02);
  EXPECT_LT(cf_angle / trials, 0.03);
  // Least squares over all three points is at least as accurate on average.
  EXPECT_LE(svd_angle, cf_angle * 1.05);
}

TEST(RigidFitTest, EqualWeightsMatchUnweightedAndWeightsPullTowardsHeavyPoints) {
  std::vector<Eigen::Vector3d> src = {
      {0, 0, 1}, {0.3, 0.1, 1.4}, {-0.2, 0.2, 1.6}, {0.1, -0.3, 1.2}};
  const Eigen::Matrix3d r = Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitY()).toRotationMatrix();
  std::vector<Eigen::Vector3d> dst;
  for (const auto& p : src) dst.push_back(r * p + Eigen::Vector3d(1, 2, 3));
  dst[3] += Eigen::Vector3d(0.02, 0, 0);  // one perturbed point.
  auto plain = FitRigidSvd(src, dst);
  auto equal = FitRigidSvd(src, dst, 0.1, {2, 2, 2, 2});
  ASSERT_TRUE(plain.ok() && equal.ok());
  EXPECT_LT((plain->rotation - equal->rotation).norm(), 1e-9);
  EXPECT_LT((plain->translation - equal->translation).norm(), 1e-9);
  auto light = FitRigidSvd(src, dst, 0.1, {1, 1, 1, 1e-6});
  ASSERT_TRUE(light.ok());
  EXPECT_LT((light->rotation - r).norm(), (plain->rotation - r).norm());
  EXPECT_FALSE(FitRigidSvd(src, dst, 0.1, {1, 1, 1}).ok());
  EXPECT_FALSE(FitRigidSvd(src, dst, 0.1, {1, 1, 0, 1}).ok());
}

TEST(RigidFitTest, CollinearAndTooFewPointsAreRejected) {
  const std::array<Eigen::Vector3d, 3> line = {Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0.1, 0, 1),
                                               Eigen::Vector3d(0.2, 0.001, 1)};
  auto cf = FitRigidClosedForm(line, kWorld);
  ASSERT_FALSE(cf.ok());
  EXPECT_EQ(cf.error().code, ErrorCode::kFailedPrecondition);
  EXPECT_NE(cf.error().message.find("collinear"), std::string::npos);
  auto svd = FitRigidSvd({line.begin(), line.end()}, {kWorld.begin(), kWorld.end()});
  ASSERT_FALSE(svd.ok());
  EXPECT_EQ(svd.error().code, ErrorCode::kFailedPrecondition);
  auto few = FitRigidSvd({line[0], line[1]}, {kWorld[0], kWorld[1]});
  ASSERT_FALSE(few.ok());
  EXPECT_EQ(few.error().code, ErrorCode::kInvalidArgument);
  std::array<Eigen::Vector3d, 3> nan = line;
  nan[0].x() = std::nan("");
  EXPECT_FALSE(FitRigidClosedForm(nan, kWorld).ok());
}

TEST(RigidFitTest, SvdFitIsTheLeastSquaresOptimumOfManyNoisyPoints) {
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, 0.01);
  std::uniform_real_distribution<double> spread(-0.5, 0.5);
  const Eigen::Matrix3d r =
      Eigen::AngleAxisd(2.5, Eigen::Vector3d(-0.4, 0.3, 0.9).normalized()).toRotationMatrix();
  const Eigen::Vector3d t(-0.3, 0.8, 1.6);
  for (const bool planar : {false, true}) {  // planar: the SVD's sign fix decides.
    std::vector<Eigen::Vector3d> src, dst;
    for (int i = 0; i < 12; ++i) {
      src.emplace_back(spread(rng), spread(rng), planar ? 0.0 : spread(rng));
      dst.push_back(r * src.back() + t + Eigen::Vector3d(noise(rng), noise(rng), noise(rng)));
    }
    auto fit = FitRigidSvd(src, dst);
    ASSERT_TRUE(fit.ok());
    EXPECT_NEAR(fit->rotation.determinant(), 1.0, 1e-9);
    EXPECT_LT(fit->orthonormality_error, 1e-9);
    EXPECT_LT(AngleBetween(fit->rotation, r), 0.05);
    auto rms = [&](const Eigen::Matrix3d& rot, const Eigen::Vector3d& tr) {
      double sum = 0;
      for (size_t i = 0; i < src.size(); ++i) sum += (rot * src[i] + tr - dst[i]).squaredNorm();
      return std::sqrt(sum / static_cast<double>(src.size()));
    };
    EXPECT_NEAR(rms(fit->rotation, fit->translation), fit->rms_residual_m, 1e-12);
    // No small turn about any axis, nor shift, fits better.
    for (int axis = 0; axis < 3; ++axis) {
      for (const double step : {-1e-3, 1e-3}) {
        const Eigen::Matrix3d turned =
            Eigen::AngleAxisd(step, Eigen::Vector3d::Unit(axis)).toRotationMatrix() * fit->rotation;
        const Eigen::Vector3d mean_src = [&] {
          Eigen::Vector3d m = Eigen::Vector3d::Zero();
          for (const auto& p : src) m += p;
          return Eigen::Vector3d(m / static_cast<double>(src.size()));
        }();
        // The best translation for the turned rotation keeps the centroids together.
        const Eigen::Vector3d shifted = fit->translation + (fit->rotation - turned) * mean_src;
        EXPECT_GT(rms(turned, shifted), fit->rms_residual_m);
        EXPECT_GT(rms(fit->rotation, fit->translation + step * Eigen::Vector3d::Unit(axis)),
                  fit->rms_residual_m);
      }
    }
  }
  // Many points along a line (with a millimetre's wobble) cannot fix a rotation about it.
  std::vector<Eigen::Vector3d> line, image;
  for (int i = 0; i < 8; ++i) {
    line.emplace_back(0.1 * i, 0.001 * (i % 2), 1.0);
    image.push_back(r * line.back() + t);
  }
  auto collinear = FitRigidSvd(line, image);
  ASSERT_FALSE(collinear.ok());
  EXPECT_EQ(collinear.error().code, ErrorCode::kFailedPrecondition);
  EXPECT_TRUE(FitRigidSvd(line, image, 0.001).ok());  // allowed by a looser limit.
}

TEST(RigidFitTest, TriangleMinSine) {
  EXPECT_NEAR(TriangleMinSine({0, 0, 0}, {1, 0, 0}, {0.5, std::sqrt(3) / 2, 0}), std::sqrt(3) / 2,
              1e-12);
  EXPECT_NEAR(TriangleMinSine({0, 0, 0}, {1, 0, 0}, {2, 0, 0}), 0.0, 1e-12);
}

TEST(RigidFitTest, CovarianceFitEqualsSvdForIsotropicNoiseAndTrustsPreciseAxes) {
  // A camera-frame triangle seen from a known pose, with noise.
  const Eigen::Matrix3d r = (Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(-1.9, Eigen::Vector3d::UnitX()))
                                .toRotationMatrix();
  const Eigen::Vector3d t(0.1, -1.0, 0.45);
  std::vector<Eigen::Vector3d> src, dst(kWorld.begin(), kWorld.end());
  const Eigen::Vector3d noise[3] = {
      {0.004, -0.002, 0.01}, {-0.003, 0.001, -0.02}, {0.002, 0.003, 0.015}};
  for (int i = 0; i < 3; ++i) src.push_back(r.transpose() * (dst[i] - t) + noise[i]);
  const std::vector<Eigen::Matrix3d> iso(3, Eigen::Matrix3d::Identity() * 1e-4);
  auto cov = FitRigidCovariance(src, dst, iso);
  auto svd = FitRigidSvd(src, dst);
  ASSERT_TRUE(cov.ok() && svd.ok());
  EXPECT_LT((cov->rotation - svd->rotation).norm(), 1e-7);
  EXPECT_LT((cov->translation - svd->translation).norm(), 1e-7);
  EXPECT_LT((cov->rotation.transpose() * cov->rotation - Eigen::Matrix3d::Identity()).norm(), 1e-9);
  // Noise only along the camera's z axis, and covariances that say so: the fit recovers the pose
  // better than the SVD that treats every axis alike.
  std::vector<Eigen::Vector3d> zsrc;
  for (int i = 0; i < 3; ++i)
    zsrc.push_back(src[i] - noise[i] + Eigen::Vector3d(0, 0, noise[i].z()));
  std::vector<Eigen::Matrix3d> along_z(3, Eigen::Matrix3d::Identity() * 1e-8);
  for (auto& c : along_z) c(2, 2) = 4e-4;
  auto zcov = FitRigidCovariance(zsrc, dst, along_z);
  auto zsvd = FitRigidSvd(zsrc, dst);
  ASSERT_TRUE(zcov.ok() && zsvd.ok());
  EXPECT_LT((zcov->translation - t).norm(), (zsvd->translation - t).norm());
  // Bad covariances are refused.
  std::vector<Eigen::Matrix3d> bad = iso;
  bad[1] = -bad[1];
  EXPECT_EQ(FitRigidCovariance(src, dst, bad).error().code, ErrorCode::kInvalidArgument);
  EXPECT_FALSE(FitRigidCovariance(src, dst, {iso[0]}).ok());
}

}  // namespace
}  // namespace hpose
