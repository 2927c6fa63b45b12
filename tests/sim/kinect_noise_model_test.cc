#include "core/sim/kinect_noise_model.h"

#include <cmath>
#include <set>
#include <vector>

#include <gtest/gtest.h>

namespace hpose {
namespace {

struct Stats {
  double mean = 0.0;
  double std = 0.0;
};

Stats ComputeStats(const std::vector<double>& v) {
  Stats s;
  for (const double x : v) s.mean += x;
  s.mean /= v.size();
  for (const double x : v) s.std += (x - s.mean) * (x - s.mean);
  s.std = std::sqrt(s.std / (v.size() - 1));
  return s;
}

KinectNoiseModel Model(const KinectNoiseOptions& options = {}) {
  Result<KinectNoiseModel> m = KinectNoiseModel::Create(options);
  EXPECT_TRUE(m.ok());
  return *m;
}

// Errors (mm) of readings of true depths spread over one quantisation step around z_m.
std::vector<double> Errors(const KinectNoiseModel& model, double z_m, int n) {
  const double step = 3.0711016e-3 * z_m * z_m;
  std::vector<double> errors;
  for (int i = 0; i < n; ++i) {
    const double z = z_m + step * ((i + 0.5) / n - 0.5);
    const KinectNoiseModel::PixelDraw d = model.Draw(11, static_cast<std::uint64_t>(i));
    const std::uint16_t mm = model.Measure(z, 0.0, d.axial_normal);
    EXPECT_NE(mm, 0);
    errors.push_back(mm - z * 1000.0);
  }
  return errors;
}

TEST(KinectNoiseModelTest, AxialStdFollowsTheModelWithoutQuantisation) {
  KinectNoiseOptions options;
  options.quantise_disparity = false;
  const KinectNoiseModel model = Model(options);
  for (const double z : {1.0, 3.0}) {
    const Stats s = ComputeStats(Errors(model, z, 40000));
    const double sigma_mm = 1.425e-3 * z * z * 1000.0;
    const double expected = std::sqrt(sigma_mm * sigma_mm + 1.0 / 12.0);  // + 1 mm rounding.
    EXPECT_NEAR(s.std, expected, 0.04 * expected) << z;
    EXPECT_NEAR(s.mean, 0.0, 0.05 * expected) << z;
  }
}

TEST(KinectNoiseModelTest, QuantisationAddsTheStepVariance) {
  const KinectNoiseModel model = Model();
  for (const double z : {1.0, 3.0}) {
    const Stats s = ComputeStats(Errors(model, z, 40000));
    const double sigma_mm = 1.425e-3 * z * z * 1000.0;
    const double step_mm = 3.0711016e-3 * z * z * 1000.0;
    const double expected = std::sqrt(sigma_mm * sigma_mm + step_mm * step_mm / 12.0);
    EXPECT_NEAR(s.std, expected, 0.1 * expected) << z;
  }
}

TEST(KinectNoiseModelTest, ReadingsSitOnTheDisparityGrid) {
  const KinectNoiseModel model = Model();
  std::set<int> values;
  for (int i = 0; i < 5000; ++i) {
    const KinectNoiseModel::PixelDraw d = model.Draw(3, i);
    const std::uint16_t mm = model.Measure(2.9 + 0.2 * i / 5000.0, 0.0, d.axial_normal);
    ASSERT_NE(mm, 0);
    const int raw = KinectNoiseModel::RawFromDepth(mm / 1000.0);
    EXPECT_EQ(mm, std::lround(KinectNoiseModel::DepthFromRaw(raw) * 1000.0));
    values.insert(mm);
  }
  // Neighbouring readings near 3 m are one disparity step (about 28 mm) apart.
  ASSERT_GT(values.size(), 5u);
  std::vector<int> sorted(values.begin(), values.end());
  for (size_t i = 1; i < sorted.size(); ++i) {
    const double z = sorted[i] / 1000.0;
    const double step_mm = 3.0711016e-3 * z * z * 1000.0;
    EXPECT_NEAR(sorted[i] - sorted[i - 1], step_mm, 0.1 * step_mm + 1.0);
  }
}

TEST(KinectNoiseModelTest, DisparityConversionInvertsItself) {
  for (int raw = 600; raw <= 1050; raw += 50) {
    EXPECT_EQ(KinectNoiseModel::RawFromDepth(KinectNoiseModel::DepthFromRaw(raw)), raw);
  }
  EXPECT_NEAR(KinectNoiseModel::DepthFromRaw(KinectNoiseModel::RawFromDepth(1.0)), 1.0, 0.002);
  EXPECT_EQ(KinectNoiseModel::DepthFromRaw(2047), 0.0);
  EXPECT_EQ(KinectNoiseModel::DepthFromRaw(-1), 0.0);
}

TEST(KinectNoiseModelTest, NoReadingOutOfRangeOrAtGrazingIncidence) {
  const KinectNoiseModel model = Model();
  int valid_near_limit = 0;
  for (int i = 0; i < 2000; ++i) {
    const double n = model.Draw(5, i).axial_normal;
    EXPECT_EQ(model.Measure(4.3, 0.0, n), 0);
    EXPECT_EQ(model.Measure(0.7, 0.0, n), 0);
    EXPECT_EQ(model.Measure(2.0, 1.50, n), 0);  // 86 degrees.
    EXPECT_NE(model.Measure(2.0, 1.0, n), 0);   // 57 degrees.
    const std::uint16_t near_limit = model.Measure(3.97, 0.0, n);
    EXPECT_LE(near_limit, 4000);
    valid_near_limit += near_limit != 0 ? 1 : 0;
  }
  EXPECT_GT(valid_near_limit, 0);
}

TEST(KinectNoiseModelTest, DrawsAreReproducibleAndDisabledNoiseIsExact) {
  const KinectNoiseModel model = Model();
  const auto a = model.Draw(9, 1234);
  const auto b = model.Draw(9, 1234);
  const auto c = model.Draw(10, 1234);
  EXPECT_EQ(a.du_px, b.du_px);
  EXPECT_EQ(a.axial_normal, b.axial_normal);
  EXPECT_NE(a.axial_normal, c.axial_normal);
  std::vector<double> du;
  for (int i = 0; i < 20000; ++i) du.push_back(model.Draw(1, i).du_px);
  EXPECT_NEAR(ComputeStats(du).std, 0.8, 0.04);

  KinectNoiseOptions off;
  off.noise_enabled = false;
  const KinectNoiseModel exact = Model(off);
  EXPECT_EQ(exact.Draw(9, 1234).du_px, 0.0);
  EXPECT_EQ(exact.Measure(1.2345, 0.0, 3.0), 1235);
  EXPECT_EQ(exact.Measure(4.5, 0.0, 0.0), 0);  // range limits still apply.
}

// Correlation of the axial normals of pixels `du` apart in a row, and their variance.
struct FieldStats {
  double variance = 0.0;
  double correlation = 0.0;
};
FieldStats AxialFieldStats(const std::vector<KinectNoiseModel::PixelDraw>& d, int width, int height,
                           int du) {
  double sum2 = 0.0, cross = 0.0;
  int n = 0, pairs = 0;
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const double a = d[static_cast<size_t>(v) * width + u].axial_normal;
      sum2 += a * a;
      ++n;
      if (u + du < width) {
        cross += a * d[static_cast<size_t>(v) * width + u + du].axial_normal;
        ++pairs;
      }
    }
  }
  FieldStats s;
  s.variance = sum2 / n;
  s.correlation = (cross / pairs) / s.variance;
  return s;
}

// Without a correlated share the image's draws are each pixel's own; with one, neighbouring
// pixels err alike (the share times the windows' overlap), farther ones less, and the variance
// of both the axial error and the ray jitter stays what the model says.
TEST(KinectNoiseModelTest, CorrelatedShareMakesNeighboursErrAlikeAtTheSameVariance) {
  constexpr int kWidth = 160, kHeight = 120;
  const KinectNoiseModel independent = Model();
  const std::vector<KinectNoiseModel::PixelDraw> own = independent.Draws(3, kWidth, kHeight);
  ASSERT_EQ(own.size(), static_cast<size_t>(kWidth * kHeight));
  for (size_t i = 0; i < own.size(); i += 97) {
    const KinectNoiseModel::PixelDraw d = independent.Draw(3, i);
    EXPECT_EQ(own[i].du_px, d.du_px);
    EXPECT_EQ(own[i].dv_px, d.dv_px);
    EXPECT_EQ(own[i].axial_normal, d.axial_normal);
  }
  const FieldStats flat = AxialFieldStats(own, kWidth, kHeight, 1);
  EXPECT_NEAR(flat.variance, 1.0, 0.05);
  EXPECT_LT(std::abs(flat.correlation), 0.03);

  KinectNoiseOptions o;
  o.correlated_share = 0.9;
  o.correlation_radius_px = 4;
  const KinectNoiseModel correlated = Model(o);
  const std::vector<KinectNoiseModel::PixelDraw> mixed = correlated.Draws(3, kWidth, kHeight);
  EXPECT_EQ(mixed.size(), own.size());
  const FieldStats near = AxialFieldStats(mixed, kWidth, kHeight, 1);
  const FieldStats far = AxialFieldStats(mixed, kWidth, kHeight, 6);
  const FieldStats beyond = AxialFieldStats(mixed, kWidth, kHeight, 12);
  EXPECT_NEAR(near.variance, 1.0, 0.1);
  // A window of 9 pixels shifted by 1 keeps 8 of them: 0.9 * 8 / 9 = 0.8; by 6, 0.9 * 3 / 9.
  EXPECT_NEAR(near.correlation, 0.8, 0.08);
  EXPECT_NEAR(far.correlation, 0.3, 0.08);
  EXPECT_LT(std::abs(beyond.correlation), 0.08);
  std::vector<double> du;
  for (const KinectNoiseModel::PixelDraw& d : mixed) du.push_back(d.du_px);
  EXPECT_NEAR(ComputeStats(du).std, 0.8, 0.08);
  // A pure function of the seed.
  const std::vector<KinectNoiseModel::PixelDraw> again = correlated.Draws(3, kWidth, kHeight);
  const std::vector<KinectNoiseModel::PixelDraw> other = correlated.Draws(4, kWidth, kHeight);
  EXPECT_EQ(again[777].axial_normal, mixed[777].axial_normal);
  EXPECT_NE(other[777].axial_normal, mixed[777].axial_normal);

  KinectNoiseOptions off = o;
  off.noise_enabled = false;
  for (const KinectNoiseModel::PixelDraw& d : Model(off).Draws(3, 8, 8)) {
    EXPECT_EQ(d.axial_normal, 0.0);
    EXPECT_EQ(d.du_px, 0.0);
  }
}

TEST(KinectNoiseModelTest, InvalidOptionsAreRejected) {
  KinectNoiseOptions o;
  o.max_range_m = 0.5;  // below min_range_m.
  EXPECT_FALSE(KinectNoiseModel::Create(o).ok());
  o = {};
  o.lateral_sigma_px = std::nan("");
  const auto r = KinectNoiseModel::Create(o);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("lateral_sigma_px"), std::string::npos);
  o = {};
  o.correlated_share = 1.5;
  const auto share = KinectNoiseModel::Create(o);
  ASSERT_FALSE(share.ok());
  EXPECT_NE(share.error().message.find("correlated_share"), std::string::npos);
  o = {};
  o.correlated_share = 0.5;
  o.correlation_radius_px = 0;
  const auto radius = KinectNoiseModel::Create(o);
  ASSERT_FALSE(radius.ok());
  EXPECT_NE(radius.error().message.find("correlation_radius_px"), std::string::npos);
}

}  // namespace
}  // namespace hpose
