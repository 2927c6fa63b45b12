// hpose's own PCD, PLY and .pclzf readers (and PCD writer) against PCL's io as the reference:
// clouds written by PCL in every format and layout, hand-made big-endian PLYs, the shared real
// Kinect files (../shared/data, skipped when absent), and damaged files.
#include <gtest/gtest.h>
#include <pcl/PCLPointCloud2.h>
#include <pcl/conversions.h>
#include <pcl/io/lzf_image_io.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "core/io/cloud_io.h"
#include "core/io/depth_frame_io.h"
#include "core/io/lzf.h"
#include "core/io/pclzf_reader.h"
#include "tests/io/temp_dir.h"

namespace hpose {
namespace {

const std::string kKinect = std::string(HPOSE_SHARED_DATA_DIR) + "/kinect/";

// The reference: PCL's readers, x, y, z taken from the blob as hpose's former reader did.
struct Reference {
  std::vector<Eigen::Vector3f> points;
  std::uint32_t width = 0;
  std::uint32_t height = 0;
};

Reference ReadWithPcl(const std::string& path) {
  pcl::PCLPointCloud2 blob;
  const bool ply = path.size() > 4 && path.substr(path.size() - 4) == ".ply";
  int result = -1;
  if (ply) {
    pcl::PLYReader reader;
    result = reader.read(path, blob);
  } else {
    pcl::PCDReader reader;
    result = reader.read(path, blob);
  }
  EXPECT_GE(result, 0) << "PCL cannot read " << path;
  Reference out;
  out.width = blob.width;
  out.height = blob.height;
  const pcl::PCLPointField* fields[3] = {};
  for (const pcl::PCLPointField& f : blob.fields) {
    for (int c = 0; c < 3; ++c) {
      if (f.name == std::string(1, static_cast<char>('x' + c)) && !fields[c]) fields[c] = &f;
    }
  }
  for (int c = 0; c < 3; ++c) {
    if (fields[c] == nullptr) {
      ADD_FAILURE() << path << ": no field " << c;
      return out;
    }
  }
  for (std::size_t row = 0; row < blob.height; ++row) {
    for (std::size_t col = 0; col < blob.width; ++col) {
      const std::uint8_t* point = blob.data.data() + row * blob.row_step + col * blob.point_step;
      Eigen::Vector3f p;
      for (int c = 0; c < 3; ++c) {
        if (fields[c]->datatype == pcl::PCLPointField::FLOAT64) {
          double d;
          std::memcpy(&d, point + fields[c]->offset, 8);
          p[c] = static_cast<float>(d);
        } else {
          std::memcpy(&p[c], point + fields[c]->offset, 4);
        }
      }
      out.points.push_back(p);
    }
  }
  return out;
}

bool SameFloat(float a, float b) { return (std::isnan(a) && std::isnan(b)) || a == b; }

// hpose's reader gives PCL's points and shape.
void ExpectReadsLikePcl(const std::string& path, const std::string& what) {
  const Reference reference = ReadWithPcl(path);
  const Result<PointCloud> ours = ReadCloud(path);
  ASSERT_TRUE(ours.ok()) << what << ": " << ours.error().ToString();
  ASSERT_EQ(ours->points.size(), reference.points.size()) << what;
  const bool organised = reference.width > 1 && reference.height > 1;
  EXPECT_EQ(ours->organised(), organised) << what;
  if (organised) {
    EXPECT_EQ(ours->width, static_cast<int>(reference.width)) << what;
    EXPECT_EQ(ours->height, static_cast<int>(reference.height)) << what;
  }
  int differing = 0;
  for (std::size_t i = 0; i < reference.points.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      if (!SameFloat(ours->points[i][c], reference.points[i][c])) ++differing;
    }
  }
  EXPECT_EQ(differing, 0) << what << ": coordinates differing from PCL's";
}

template <typename PointT>
pcl::PointCloud<PointT> RandomCloud(std::uint32_t width, std::uint32_t height, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-5.0f, 5.0f);
  pcl::PointCloud<PointT> cloud;
  cloud.width = width;
  cloud.height = height;
  cloud.is_dense = false;
  cloud.points.resize(static_cast<std::size_t>(width) * height);
  for (std::size_t i = 0; i < cloud.points.size(); ++i) {
    PointT& p = cloud.points[i];
    p.x = i % 7 == 3 ? std::numeric_limits<float>::quiet_NaN() : u(rng);
    p.y = i % 7 == 3 ? std::numeric_limits<float>::quiet_NaN() : u(rng) * 1e-3f;
    p.z = i % 7 == 3 ? std::numeric_limits<float>::quiet_NaN() : u(rng) * 1e3f;
  }
  return cloud;
}

template <typename PointT>
void WriteEveryFormat(const TempDir& dir, const pcl::PointCloud<PointT>& cloud,
                      const std::string& name) {
  pcl::PCDWriter pcd;
  ASSERT_EQ(pcd.writeASCII(dir.File(name + "_ascii.pcd"), cloud, 8), 0);
  ASSERT_EQ(pcd.writeBinary(dir.File(name + "_binary.pcd"), cloud), 0);
  ASSERT_EQ(pcd.writeBinaryCompressed(dir.File(name + "_compressed.pcd"), cloud), 0);
  pcl::PLYWriter ply;
  ASSERT_EQ(ply.write(dir.File(name + "_ascii.ply"), cloud, false), 0);
  ASSERT_EQ(ply.write(dir.File(name + "_binary.ply"), cloud, true), 0);
}

TEST(CloudReadersTest, AgreeWithPclOnEveryFormatPclWrites) {
  TempDir dir;
  unsigned seed = 1;
  for (const auto& [w, h] :
       std::vector<std::pair<std::uint32_t, std::uint32_t>>{{1, 1}, {37, 1}, {16, 12}, {640, 48}}) {
    const std::string size = std::to_string(w) + "x" + std::to_string(h);
    WriteEveryFormat(dir, RandomCloud<pcl::PointXYZ>(w, h, seed++), "xyz_" + size);
    WriteEveryFormat(dir, RandomCloud<pcl::PointXYZRGBA>(w, h, seed++), "xyzrgba_" + size);
    WriteEveryFormat(dir, RandomCloud<pcl::PointNormal>(w, h, seed++), "normal_" + size);
  }
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir.path())) {
    ExpectReadsLikePcl(entry.path().string(), entry.path().filename().string());
    ++files;
  }
  EXPECT_EQ(files, 4 * 3 * 5);
}

// x, y, z as doubles and an int field before them (PCL writes a PCLPointCloud2 as it is).
TEST(CloudReadersTest, AgreeWithPclOnDoubleCoordinates) {
  TempDir dir;
  pcl::PCLPointCloud2 blob;
  blob.width = 9;
  blob.height = 4;
  blob.point_step = 4 + 3 * 8;
  blob.row_step = blob.point_step * blob.width;
  const char* names[] = {"label", "x", "y", "z"};
  for (int i = 0; i < 4; ++i) {
    pcl::PCLPointField f;
    f.name = names[i];
    f.offset = i == 0 ? 0 : 4 + 8 * (i - 1);
    f.datatype = i == 0 ? pcl::PCLPointField::UINT32 : pcl::PCLPointField::FLOAT64;
    f.count = 1;
    blob.fields.push_back(f);
  }
  blob.data.resize(blob.row_step * blob.height);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  for (std::size_t p = 0; p < blob.width * blob.height; ++p) {
    const std::uint32_t label = static_cast<std::uint32_t>(p);
    std::memcpy(&blob.data[p * blob.point_step], &label, 4);
    for (int c = 0; c < 3; ++c) {
      const double v = u(rng);
      std::memcpy(&blob.data[p * blob.point_step + 4 + 8 * c], &v, 8);
    }
  }
  pcl::PCDWriter pcd;
  ASSERT_EQ(pcd.writeASCII(dir.File("d_ascii.pcd"), blob, Eigen::Vector4f::Zero(),
                           Eigen::Quaternionf::Identity(), 17),
            0);
  ASSERT_EQ(pcd.writeBinary(dir.File("d_binary.pcd"), blob), 0);
  ASSERT_EQ(pcd.writeBinaryCompressed(dir.File("d_compressed.pcd"), blob), 0);
  pcl::PLYWriter ply;
  ASSERT_EQ(ply.writeASCII(dir.File("d_ascii.ply"), blob, Eigen::Vector4f::Zero(),
                           Eigen::Quaternionf::Identity(), 17),
            0);
  ASSERT_EQ(ply.writeBinary(dir.File("d_binary.ply"), blob), 0);
  for (const char* name :
       {"d_ascii.pcd", "d_binary.pcd", "d_compressed.pcd", "d_ascii.ply", "d_binary.ply"}) {
    ExpectReadsLikePcl(dir.File(name), name);
  }
}

// Big-endian PLY (PCL does not write it): a face element before the vertices, a list inside.
TEST(CloudReadersTest, AgreeWithPclOnBigEndianPly) {
  TempDir dir;
  std::string file =
      "ply\nformat binary_big_endian 1.0\ncomment made by hand\nelement face 2\n"
      "property list uchar int vertex_indices\nelement vertex 5\nproperty float x\n"
      "property double y\nproperty float z\nproperty uchar red\nend_header\n";
  auto put = [&file](const void* value, int bytes) {
    std::string b(static_cast<const char*>(value), static_cast<std::size_t>(bytes));
    std::reverse(b.begin(), b.end());
    file += b;
  };
  for (int face = 0; face < 2; ++face) {
    const std::uint8_t n = 3;
    put(&n, 1);
    for (int k = 0; k < 3; ++k) {
      const std::int32_t index = face + k;
      put(&index, 4);
    }
  }
  for (int v = 0; v < 5; ++v) {
    const float x = 0.5f * v - 1.0f, z = 2.0f + v;
    const double y = -0.125 * v;
    const std::uint8_t red = static_cast<std::uint8_t>(40 * v);
    put(&x, 4);
    put(&y, 8);
    put(&z, 4);
    put(&red, 1);
  }
  const std::string path = dir.Write("be.ply", file);
  ExpectReadsLikePcl(path, "big-endian PLY");
  const Result<PointCloud> ours = ReadCloud(path);
  ASSERT_TRUE(ours.ok()) << ours.error().ToString();
  EXPECT_EQ(ours->points[4], Eigen::Vector3f(1.0f, -0.5f, 6.0f));
}

TEST(CloudReadersTest, AgreeWithPclOnRealKinectClouds) {
  if (!std::filesystem::exists(kKinect + "five_people.pcd")) {
    GTEST_SKIP() << "Kinect clouds not found in " << kKinect << " (third-party data)";
  }
  std::vector<std::string> paths = {kKinect + "five_people.pcd"};
  for (const auto& e : std::filesystem::directory_iterator(kKinect + "grabber_sequences/pcd")) {
    paths.push_back(e.path().string());
  }
  for (const std::string& path : paths) ExpectReadsLikePcl(path, path);
}

TEST(CloudReadersTest, PclReadsWhatWritePcdWrites) {
  TempDir dir;
  for (const auto& [w, h] :
       std::vector<std::pair<std::uint32_t, std::uint32_t>>{{0, 1}, {5, 1}, {16, 12}}) {
    const pcl::PointCloud<pcl::PointXYZ> source = RandomCloud<pcl::PointXYZ>(w, h, w + h);
    PointCloud cloud;
    for (const pcl::PointXYZ& p : source.points) cloud.points.emplace_back(p.x, p.y, p.z);
    if (h > 1) {
      cloud.width = static_cast<int>(w);
      cloud.height = static_cast<int>(h);
    }
    const std::string path = dir.File("ours_" + std::to_string(w) + ".pcd");
    ASSERT_TRUE(WritePcd(cloud, path).ok());
    const Reference reference = ReadWithPcl(path);
    ASSERT_EQ(reference.points.size(), cloud.points.size());
    if (h > 1) {
      EXPECT_EQ(reference.width, w);
      EXPECT_EQ(reference.height, h);
    }
    for (std::size_t i = 0; i < cloud.points.size(); ++i) {
      for (int c = 0; c < 3; ++c) {
        EXPECT_TRUE(SameFloat(reference.points[i][c], cloud.points[i][c])) << i;
      }
    }
  }
}

TEST(CloudReadersTest, DamagedFilesFailClearly) {
  TempDir dir;
  const pcl::PointCloud<pcl::PointXYZ> cloud = RandomCloud<pcl::PointXYZ>(200, 1, 8);
  pcl::PCDWriter pcd;
  ASSERT_EQ(pcd.writeBinaryCompressed(dir.File("c.pcd"), cloud), 0);
  std::string bytes = Slurp(dir.File("c.pcd"));
  // Damage a back reference's distance inside the LZF stream (the header's sizes stay right).
  const std::size_t data = bytes.find("DATA binary_compressed\n") + 23 + 8;
  std::string damaged = bytes;
  for (std::size_t i = data; i < damaged.size(); ++i) damaged[i] = static_cast<char>(0xff);
  for (const auto& [name, text] : std::vector<std::pair<std::string, std::string>>{
           {"lzf.pcd", damaged},
           {"cut_ascii.pcd",
            "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
            "WIDTH 3\nHEIGHT 1\nPOINTS 3\nDATA ascii\n1 2 3\n4 5 6\n7 8\n"},
           {"word.pcd",
            "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
            "WIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n1 two 3\n"},
           {"shape.pcd",
            "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
            "WIDTH 2\nHEIGHT 2\nPOINTS 3\nDATA ascii\n1 2 3\n4 5 6\n7 8 9\n"},
           {"cut.ply",
            "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\n"
            "property float y\nproperty float z\nend_header\n1 2 3\n4 5\n"}}) {
    const Result<PointCloud> read = ReadCloud(dir.Write(name, text));
    ASSERT_FALSE(read.ok()) << name;
    EXPECT_EQ(read.error().code, ErrorCode::kDataLoss) << name << ": " << read.error().ToString();
    EXPECT_NE(read.error().message.find(name), std::string::npos) << read.error().message;
  }
}

TEST(LzfTest, RefusesCorruptStreamsWithinItsBuffer) {
  // A literal run of 3 bytes, then a back reference copying 4 bytes from 2 back: "abcbcbc".
  const std::uint8_t good[] = {2, 'a', 'b', 'c', (2 << 5) | 0, 1};
  std::uint8_t out[8] = {};
  ASSERT_TRUE(LzfDecompress(good, sizeof(good), out, 7));
  EXPECT_EQ(std::string(reinterpret_cast<char*>(out), 7), "abcbcbc");
  std::memset(out, 0, sizeof(out));
  EXPECT_FALSE(LzfDecompress(good, sizeof(good), out, 6));  // more data than room.
  EXPECT_EQ(out[6], 0);
  EXPECT_FALSE(LzfDecompress(good, sizeof(good), out, 8));  // less data than announced.
  const std::uint8_t before_start[] = {0, 'a', (1 << 5) | 0, 5};
  EXPECT_FALSE(LzfDecompress(before_start, sizeof(before_start), out, 4));
  const std::uint8_t cut_literal[] = {5, 'a', 'b'};
  EXPECT_FALSE(LzfDecompress(cut_literal, sizeof(cut_literal), out, 6));
  const std::uint8_t cut_reference[] = {0, 'a', (7 << 5) | 0};
  EXPECT_FALSE(LzfDecompress(cut_reference, sizeof(cut_reference), out, 8));
}

// PCL's .pclzf reader opened up to give the raw values and camera, the reference.
class PclLzfDepthReader final : public pcl::io::LZFDepth16ImageReader {
 public:
  bool Raw(const std::string& path, std::vector<std::uint16_t>* values) {
    std::uint32_t size = 0;
    std::vector<char> packed;
    if (!loadImageBlob(path, packed, size)) return false;
    std::vector<char> raw(size);
    if (!decompress(packed, raw)) return false;
    values->resize(size / 2);
    std::memcpy(values->data(), raw.data(), size);
    return true;
  }
  double ZFactor() const { return z_multiplication_factor_; }
};

void ExpectPclzfLikePcl(const std::string& path, const std::string& xml) {
  PclLzfDepthReader pcl_reader;
  ASSERT_TRUE(pcl_reader.readParameters(xml)) << xml;
  std::vector<std::uint16_t> reference;
  ASSERT_TRUE(pcl_reader.Raw(path, &reference)) << path;
  const Result<PclzfDepth16> ours = ReadPclzfDepth16(path);
  ASSERT_TRUE(ours.ok()) << ours.error().ToString();
  EXPECT_EQ(ours->width, static_cast<int>(pcl_reader.getWidth()));
  EXPECT_EQ(ours->height, static_cast<int>(pcl_reader.getHeight()));
  EXPECT_TRUE(ours->values == reference) << path;
  const Result<PclzfDepthCamera> camera = ReadPclzfDepthCamera(xml);
  ASSERT_TRUE(camera.ok()) << camera.error().ToString();
  const pcl::io::CameraParameters p = pcl_reader.getParameters();
  EXPECT_EQ(camera->focal_length_x, p.focal_length_x);
  EXPECT_EQ(camera->focal_length_y, p.focal_length_y);
  EXPECT_EQ(camera->principal_point_x, p.principal_point_x);
  EXPECT_EQ(camera->principal_point_y, p.principal_point_y);
  EXPECT_EQ(camera->z_multiplication_factor, pcl_reader.ZFactor());
}

TEST(PclzfReaderTest, AgreesWithPclOnImagesPclWrites) {
  TempDir dir;
  std::mt19937 rng(5);
  std::vector<std::uint16_t> depth(320 * 240);
  for (std::size_t i = 0; i < depth.size(); ++i) {
    depth[i] = i % 11 == 0 ? 0 : static_cast<std::uint16_t>(500 + (i % 320) * 3 + rng() % 4);
  }
  pcl::io::LZFDepth16ImageWriter writer;
  const std::string path = dir.File("f_depth.pclzf");
  ASSERT_TRUE(writer.write(reinterpret_cast<const char*>(depth.data()), 320, 240, path));
  pcl::io::CameraParameters camera{};
  camera.focal_length_x = 286.5;
  camera.focal_length_y = 287.25;
  camera.principal_point_x = 160.5;
  camera.principal_point_y = 119.75;
  ASSERT_TRUE(writer.writeParameters(camera, dir.File("f.xml")));
  ExpectPclzfLikePcl(path, dir.File("f.xml"));
  const Result<PclzfDepth16> ours = ReadPclzfDepth16(path);
  ASSERT_TRUE(ours.ok());
  EXPECT_TRUE(ours->values == depth);

  const std::string bytes = Slurp(path);
  const std::string cut = dir.Write("cut_depth.pclzf", bytes.substr(0, bytes.size() / 2));
  EXPECT_EQ(ReadPclzfDepth16(cut).error().code, ErrorCode::kDataLoss);
  std::string huge = bytes;
  huge[5] = huge[6] = huge[7] = '\x7f';  // width about 2 billion.
  EXPECT_EQ(ReadPclzfDepth16(dir.Write("huge_depth.pclzf", huge)).error().code,
            ErrorCode::kOutOfRange);
}

TEST(PclzfReaderTest, AgreesWithPclOnRealKinectFrames) {
  const std::string dir = kKinect + "grabber_sequences/pclzf/";
  if (!std::filesystem::is_directory(dir)) {
    GTEST_SKIP() << "Kinect .pclzf frames not found in " << dir << " (third-party data)";
  }
  int frames = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    const std::string path = e.path().string();
    if (path.find("_depth.pclzf") == std::string::npos) continue;
    ExpectPclzfLikePcl(path, PclzfParameterPath(path));
    ++frames;
  }
  EXPECT_GE(frames, 1);
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    const std::string path = e.path().string();
    if (path.find("_rgb.pclzf") == std::string::npos) continue;
    const Result<PclzfDepth16> rgb = ReadPclzfDepth16(path);
    ASSERT_FALSE(rgb.ok());
    EXPECT_EQ(rgb.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(rgb.error().message.find("rgb24"), std::string::npos) << rgb.error().message;
  }
}

}  // namespace
}  // namespace hpose
