#include "core/io/cloud_io.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "tests/io/temp_dir.h"

namespace hpose {
namespace {

PointCloud Organised(int w, int h) {
  PointCloud cloud;
  cloud.width = w;
  cloud.height = h;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      if ((u + v) % 5 == 0) {
        cloud.points.emplace_back(nan, nan, nan);
      } else {
        cloud.points.emplace_back(0.01f * u, -0.02f * v, 1.0f + 0.001f * (u * v));
      }
    }
  }
  return cloud;
}

void ExpectSamePoints(const PointCloud& a, const PointCloud& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    if (!a.points[i].allFinite()) {
      EXPECT_TRUE(std::isnan(b.points[i].x())) << i;
      continue;
    }
    EXPECT_EQ(a.points[i], b.points[i]) << i;
  }
}

TEST(CloudIoTest, OrganisedPcdRoundTripKeepsNaNAndShape) {
  TempDir dir;
  const PointCloud cloud = Organised(16, 12);
  const std::string path = dir.File("cloud.pcd");
  ASSERT_TRUE(WritePcd(cloud, path).ok());
  const Result<PointCloud> back = ReadCloud(path);
  ASSERT_TRUE(back.ok()) << back.error().ToString();
  EXPECT_TRUE(back->organised());
  EXPECT_EQ(back->width, 16);
  EXPECT_EQ(back->height, 12);
  ExpectSamePoints(cloud, *back);
}

TEST(CloudIoTest, UnorganisedAndEmptyCloudsRoundTrip) {
  TempDir dir;
  PointCloud cloud;
  cloud.points = {{1, 2, 3}, {-4.5f, 0.25f, 9}};
  ASSERT_TRUE(WritePcd(cloud, dir.File("two.pcd")).ok());
  Result<PointCloud> back = ReadCloud(dir.File("two.pcd"));
  ASSERT_TRUE(back.ok()) << back.error().ToString();
  EXPECT_FALSE(back->organised());
  ExpectSamePoints(cloud, *back);

  ASSERT_TRUE(WritePcd(PointCloud{}, dir.File("empty.pcd")).ok());
  back = ReadCloud(dir.File("empty.pcd"));
  ASSERT_TRUE(back.ok()) << back.error().ToString();
  EXPECT_TRUE(back->empty());
}

TEST(CloudIoTest, ReadsAsciiPcdWithExtraFieldsAndAllNaNCloud) {
  TempDir dir;
  const std::string header =
      "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z intensity\nSIZE 4 4 4 4\nTYPE F F F F\n"
      "COUNT 1 1 1 1\nWIDTH 3\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 3\nDATA ascii\n";
  Result<PointCloud> cloud =
      ReadCloud(dir.Write("a.pcd", header + "1 2 3 9\n4 5 6 9\n7 8 9.5 9\n"));
  ASSERT_TRUE(cloud.ok()) << cloud.error().ToString();
  ASSERT_EQ(cloud->size(), 3u);
  EXPECT_EQ(cloud->points[2], Eigen::Vector3f(7, 8, 9.5f));
  // A cloud without a single finite point is still a cloud (the estimator rejects it later).
  cloud = ReadCloud(dir.Write("nan.pcd", header + "nan nan nan 0\nnan nan nan 0\nnan nan nan 0\n"));
  ASSERT_TRUE(cloud.ok()) << cloud.error().ToString();
  ASSERT_EQ(cloud->size(), 3u);
  EXPECT_FALSE(cloud->points[0].allFinite());
}

TEST(CloudIoTest, ReadsPly) {
  TempDir dir;
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n0.5 1.5 2.5\n-1 -2 -3\n";
  const Result<PointCloud> cloud = ReadCloud(dir.Write("m.ply", ply));
  ASSERT_TRUE(cloud.ok()) << cloud.error().ToString();
  ASSERT_EQ(cloud->size(), 2u);
  EXPECT_EQ(cloud->points[0], Eigen::Vector3f(0.5f, 1.5f, 2.5f));
  EXPECT_EQ(cloud->points[1], Eigen::Vector3f(-1, -2, -3));
}

TEST(CloudIoTest, MissingFileIsNotFound) {
  TempDir dir;
  const Result<PointCloud> cloud = ReadCloud(dir.File("gone.pcd"));
  ASSERT_FALSE(cloud.ok());
  EXPECT_EQ(cloud.error().code, ErrorCode::kNotFound);
  EXPECT_NE(cloud.error().message.find("gone.pcd"), std::string::npos);
}

TEST(CloudIoTest, UnknownExtensionAndMissingFieldsAreInvalidArgument) {
  TempDir dir;
  Result<PointCloud> cloud = ReadCloud(dir.Write("cloud.xyz", "1 2 3\n"));
  ASSERT_FALSE(cloud.ok());
  EXPECT_EQ(cloud.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(
      cloud.error().message.find("unknown cloud file extension '.xyz' (expected .pcd or .ply)"),
      std::string::npos)
      << cloud.error().message;
  cloud = ReadCloud(dir.Write("cloud", "1 2 3\n"));
  ASSERT_FALSE(cloud.ok());
  EXPECT_EQ(cloud.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(cloud.error().message.find("cloud: has no file extension (expected .pcd or .ply)"),
            std::string::npos)
      << cloud.error().message;
  const std::string no_z =
      "VERSION 0.7\nFIELDS x y\nSIZE 4 4\nTYPE F F\nCOUNT 1 1\nWIDTH 1\nHEIGHT 1\n"
      "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 1\nDATA ascii\n1 2\n";
  cloud = ReadCloud(dir.Write("noz.pcd", no_z));
  ASSERT_FALSE(cloud.ok());
  EXPECT_EQ(cloud.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(cloud.error().message.find("x, y and z"), std::string::npos) << cloud.error().message;
}

TEST(CloudIoTest, GarbageEmptyAndTruncatedFilesAreDataLoss) {
  TempDir dir;
  const PointCloud big = Organised(64, 48);
  ASSERT_TRUE(WritePcd(big, dir.File("full.pcd")).ok());
  const std::string bytes = Slurp(dir.File("full.pcd"));
  const std::string cases[] = {
      "",                                 // empty file.
      "complete garbage \x01\x02\x03\n",  // not a PCD.
      bytes.substr(0, 60),                // header cut short.
      bytes.substr(0, bytes.size() / 2),  // binary data cut short.
      bytes.substr(0, bytes.size() - 1),  // one byte missing.
  };
  int i = 0;
  for (const std::string& contents : cases) {
    const std::string name = "bad" + std::to_string(i++) + ".pcd";
    const Result<PointCloud> cloud = ReadCloud(dir.Write(name, contents));
    ASSERT_FALSE(cloud.ok()) << name;
    EXPECT_EQ(cloud.error().code, ErrorCode::kDataLoss) << name << ": " << cloud.error().ToString();
    EXPECT_NE(cloud.error().message.find(name), std::string::npos);
  }
  const Result<PointCloud> ply = ReadCloud(dir.Write("bad.ply", "ply\nformat ascii 1.0\nelem"));
  ASSERT_FALSE(ply.ok());
  EXPECT_EQ(ply.error().code, ErrorCode::kDataLoss);
}

TEST(CloudIoTest, WriteToAMissingDirectoryFails) {
  TempDir dir;
  const Status status = WritePcd(Organised(4, 4), dir.File("missing/dir/c.pcd"));
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.error().message.find("c.pcd"), std::string::npos);
}

}  // namespace
}  // namespace hpose
