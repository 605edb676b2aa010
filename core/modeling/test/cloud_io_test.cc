#include "core/modeling/cloud_io.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>
#include <set>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/common/errors.h"

namespace tubepick {
namespace {

using ::testing::HasSubstr;

/// A fresh path in the test's temporary directory.
std::string TempPath(const std::string& name) {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  return ::testing::TempDir() + "cloud_io_" + info->name() + "_" + name;
}

void WriteBytes(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  ASSERT_TRUE(out.good()) << path;
}

template <typename T>
void AppendLittleEndian(std::string* out, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) std::reverse(bytes, bytes + sizeof(T));
  out->append(bytes, sizeof(T));
}

template <typename T>
void AppendBigEndian(std::string* out, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  if constexpr (std::endian::native == std::endian::little) std::reverse(bytes, bytes + sizeof(T));
  out->append(bytes, sizeof(T));
}

/// LZF stream made only of literal runs (control byte n−1, then n ≤ 32 bytes): valid input
/// for any LZF decompressor.
std::string LzfLiteralOnly(const std::string& data) {
  std::string out;
  for (std::size_t i = 0; i < data.size(); i += 32) {
    const std::size_t n = std::min<std::size_t>(32, data.size() - i);
    out += static_cast<char>(n - 1);
    out.append(data, i, n);
  }
  return out;
}

Points SamplePoints() {
  return {Eigen::Vector3f(0.1f, -0.2f, 0.3f), Eigen::Vector3f(1.0f / 3.0f, 2.5e-7f, -1234.5f),
          Eigen::Vector3f(-0.0f, 0.7071068f, 1e-3f), Eigen::Vector3f(42.0f, -42.0f, 0.0f)};
}

void ExpectSamePoints(const Points& actual, const Points& expected) {
  ASSERT_EQ(actual.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(actual[i], expected[i]) << "point " << i;  // bit-exact round trip
  }
}

TEST(CloudIo, PlyBinaryRoundTrip) {
  const std::string path = TempPath("cloud.ply");
  WritePly(path, SamplePoints());
  const CloudFile cloud = ReadCloudFile(path);
  EXPECT_EQ(cloud.format, "ply-binary-le");
  ExpectSamePoints(cloud.points, SamplePoints());
}

TEST(CloudIo, PlyBinaryWithColoursRoundTrip) {
  const std::string path = TempPath("cloud.ply");
  const Points points = SamplePoints();
  std::vector<Rgb> colours;
  for (std::size_t i = 0; i < points.size(); ++i) colours.push_back(LabelColour(static_cast<int>(i)));
  WritePly(path, points, &colours);
  const CloudFile cloud = ReadCloudFile(path);
  ExpectSamePoints(cloud.points, points);
}

TEST(CloudIo, PlyAsciiRoundTrip) {
  const std::string path = TempPath("cloud.ply");
  WritePlyAscii(path, SamplePoints());
  const CloudFile cloud = ReadCloudFile(path);
  EXPECT_EQ(cloud.format, "ply-ascii");
  ExpectSamePoints(cloud.points, SamplePoints());
}

TEST(CloudIo, PlyBinaryBigEndianWithExtraPropertiesAndFaces) {
  // Doubles, colours and other properties around x, y, z; a face element with lists after.
  std::string bytes =
      "ply\nformat binary_big_endian 1.0\ncomment hand written\nelement vertex 2\n"
      "property uchar red\nproperty double x\nproperty float intensity\nproperty double y\n"
      "property double z\nproperty ushort label\nelement face 1\nproperty list uchar int vertex_indices\n"
      "end_header\n";
  const double xyz[2][3] = {{0.25, -1.5, 3.0}, {1e-4, 2.0, -0.125}};
  for (const auto& p : xyz) {
    AppendBigEndian<std::uint8_t>(&bytes, 200);
    AppendBigEndian<double>(&bytes, p[0]);
    AppendBigEndian<float>(&bytes, 7.5f);
    AppendBigEndian<double>(&bytes, p[1]);
    AppendBigEndian<double>(&bytes, p[2]);
    AppendBigEndian<std::uint16_t>(&bytes, 9);
  }
  AppendBigEndian<std::uint8_t>(&bytes, 3);
  for (int v : {0, 1, 0}) AppendBigEndian<std::int32_t>(&bytes, v);
  const std::string path = TempPath("cloud.ply");
  WriteBytes(path, bytes);

  const CloudFile cloud = ReadCloudFile(path);
  EXPECT_EQ(cloud.format, "ply-binary-be");
  ExpectSamePoints(cloud.points,
                   {Eigen::Vector3f(0.25f, -1.5f, 3.0f), Eigen::Vector3f(1e-4f, 2.0f, -0.125f)});
}

TEST(CloudIo, PlyBinaryLittleEndianSkipsListElementBeforeVertices) {
  // Faces come first, with lists of different lengths: the reader must walk them to find the vertices.
  std::string bytes =
      "ply\r\nformat binary_little_endian 1.0\r\nelement face 2\r\nproperty list uchar uint "
      "vertex_indices\r\n"
      "property uchar flags\r\nelement vertex 3\r\nproperty float z\r\nproperty float y\r\nproperty float "
      "x\r\n"
      "property uchar red\r\nproperty uchar green\r\nproperty uchar blue\r\nend_header\r\n";
  AppendLittleEndian<std::uint8_t>(&bytes, 3);
  for (std::uint32_t v : {0u, 1u, 2u}) AppendLittleEndian(&bytes, v);
  AppendLittleEndian<std::uint8_t>(&bytes, 1);
  AppendLittleEndian<std::uint8_t>(&bytes, 4);
  for (std::uint32_t v : {0u, 1u, 2u, 0u}) AppendLittleEndian(&bytes, v);
  AppendLittleEndian<std::uint8_t>(&bytes, 0);
  const Points expected = SamplePoints();
  for (int i = 0; i < 3; ++i) {
    AppendLittleEndian(&bytes, expected[i].z());
    AppendLittleEndian(&bytes, expected[i].y());
    AppendLittleEndian(&bytes, expected[i].x());
    for (int c = 0; c < 3; ++c) AppendLittleEndian<std::uint8_t>(&bytes, 255);
  }
  const std::string path = TempPath("cloud.ply");
  WriteBytes(path, bytes);

  ExpectSamePoints(ReadCloudFile(path).points, Points(expected.begin(), expected.begin() + 3));
}

TEST(CloudIo, PlyAsciiWithExtraPropertiesAndFaceLists) {
  const std::string text =
      "ply\nformat ascii 1.0\nobj_info scanner\nelement face 2\nproperty list uchar int vertex_indices\n"
      "element vertex 3\nproperty uchar red\nproperty float x\nproperty list uchar float extra\n"
      "property float y\nproperty double z\nend_header\n"
      "3 0 1 2\n4 0 1 2 0\n"
      "10 0.5 2 9 9 -1.25 +3\n"
      "20 1e-3 0 2.5 -0\n"
      "30 nan 1 7 inf 1\n";
  const std::string path = TempPath("cloud.ply");
  WriteBytes(path, text);

  const CloudFile cloud = ReadCloudFile(path);
  ASSERT_EQ(cloud.points.size(), 3u);
  EXPECT_EQ(cloud.points[0], Eigen::Vector3f(0.5f, -1.25f, 3.0f));
  EXPECT_EQ(cloud.points[1], Eigen::Vector3f(1e-3f, 2.5f, -0.0f));
  EXPECT_TRUE(std::isnan(cloud.points[2].x()));  // the reader keeps non-finite points
  EXPECT_TRUE(std::isinf(cloud.points[2].y()));
  EXPECT_EQ(cloud.points[2].z(), 1.0f);
}

TEST(CloudIo, PcdAsciiRead) {
  const std::string text =
      "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS rgb x y z normal\nSIZE 4 4 4 4 4\n"
      "TYPE U F F F F\nCOUNT 1 1 1 1 3\nWIDTH 3\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 3\nDATA ascii\n"
      "4278190335 0.1 0.2 0.3 0 0 1\n0 -1 -2 -3 0 1 0\n7 nan nan nan 1 0 0\n";
  const std::string path = TempPath("cloud.pcd");
  WriteBytes(path, text);

  const CloudFile cloud = ReadCloudFile(path);
  EXPECT_EQ(cloud.format, "pcd-ascii");
  ASSERT_EQ(cloud.points.size(), 3u);
  EXPECT_EQ(cloud.points[0], Eigen::Vector3f(0.1f, 0.2f, 0.3f));
  EXPECT_EQ(cloud.points[1], Eigen::Vector3f(-1.0f, -2.0f, -3.0f));
  EXPECT_FALSE(cloud.points[2].allFinite());
}

TEST(CloudIo, PcdAsciiAndBinaryRoundTrip) {
  for (bool binary : {false, true}) {
    const std::string path = TempPath(binary ? "binary.pcd" : "ascii.pcd");
    WritePcd(path, SamplePoints(), binary);
    const CloudFile cloud = ReadCloudFile(path);
    EXPECT_EQ(cloud.format, binary ? "pcd-binary" : "pcd-ascii");
    ExpectSamePoints(cloud.points, SamplePoints());
  }
}

TEST(CloudIo, PcdBinaryWithExtraFieldsRead) {
  std::string bytes =
      "VERSION .7\nFIELDS intensity x y z _\nSIZE 2 4 4 8 1\nTYPE U F F F I\nCOUNT 1 1 1 1 3\nWIDTH 2\n"
      "HEIGHT 1\nPOINTS 2\nDATA binary\n";
  const Points expected = {Eigen::Vector3f(0.5f, 1.5f, -2.0f), Eigen::Vector3f(-0.25f, 0.0f, 8.0f)};
  for (const Eigen::Vector3f& p : expected) {
    AppendLittleEndian<std::uint16_t>(&bytes, 1000);
    AppendLittleEndian(&bytes, p.x());
    AppendLittleEndian(&bytes, p.y());
    AppendLittleEndian<double>(&bytes, p.z());
    bytes.append(3, '\0');
  }
  const std::string path = TempPath("cloud.pcd");
  WriteBytes(path, bytes);

  const CloudFile cloud = ReadCloudFile(path);
  EXPECT_EQ(cloud.format, "pcd-binary");
  ExpectSamePoints(cloud.points, expected);
}

/// A binary_compressed PCD with fields x y z rgb: field-major data, LZF-compressed by `compress`.
std::string CompressedPcd(const Points& points,
                          const std::function<std::string(const std::string&)>& compress) {
  std::string raw;
  for (int axis = 0; axis < 3; ++axis) {
    for (const Eigen::Vector3f& p : points) AppendLittleEndian(&raw, p[axis]);
  }
  for (std::size_t i = 0; i < points.size(); ++i) AppendLittleEndian<std::uint32_t>(&raw, 0x00ff00u);
  const std::string compressed = compress(raw);
  const std::string n = std::to_string(points.size());
  std::string bytes =
      "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F U\nCOUNT 1 1 1 1\nWIDTH " + n +
      "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " + n + "\nDATA binary_compressed\n";
  AppendLittleEndian<std::uint32_t>(&bytes, static_cast<std::uint32_t>(compressed.size()));
  AppendLittleEndian<std::uint32_t>(&bytes, static_cast<std::uint32_t>(raw.size()));
  return bytes + compressed;
}

TEST(CloudIo, PcdBinaryCompressedRead) {
  const std::string path = TempPath("cloud.pcd");
  WriteBytes(path, CompressedPcd(SamplePoints(), LzfLiteralOnly));
  const CloudFile cloud = ReadCloudFile(path);
  EXPECT_EQ(cloud.format, "pcd-binary-compressed");
  ExpectSamePoints(cloud.points, SamplePoints());
}

TEST(CloudIo, PcdBinaryCompressedWithBackReferences) {
  // Four points with z = 1: the z column is one literal float and a 12-byte back reference to it.
  const Points points = {Eigen::Vector3f(1, 2, 1), Eigen::Vector3f(3, 4, 1), Eigen::Vector3f(5, 6, 1),
                         Eigen::Vector3f(7, 8, 1)};
  auto compress = [](const std::string& raw) {
    std::string out = LzfLiteralOnly(raw.substr(0, 36));  // x and y columns, z of point 0
    // Back reference: length 12 = 7 + 3 + 2 (ctrl length 7, extra byte 3), offset 4 = 3 + 1.
    out += static_cast<char>(7 << 5);
    out += static_cast<char>(3);
    out += static_cast<char>(3);
    out += LzfLiteralOnly(raw.substr(48));  // rgb column
    return out;
  };
  const std::string path = TempPath("cloud.pcd");
  WriteBytes(path, CompressedPcd(points, compress));
  ExpectSamePoints(ReadCloudFile(path).points, points);
}

TEST(CloudIo, PcdCorruptCompressedDataIsAnError) {
  auto compress = [](const std::string& raw) {
    std::string out = LzfLiteralOnly(raw);
    out[0] = static_cast<char>(0x20);  // a back reference before any output
    return out;
  };
  const std::string path = TempPath("cloud.pcd");
  WriteBytes(path, CompressedPcd(SamplePoints(), compress));
  try {
    ReadCloudFile(path);
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr(path));
    EXPECT_THAT(e.what(), HasSubstr("corrupt binary_compressed"));
  }
}

/// Expects ReadCloudFile(path) to throw InvalidArgument naming the path and containing every
/// fragment.
void ExpectReadError(const std::string& path, const std::vector<std::string>& fragments) {
  try {
    ReadCloudFile(path);
    ADD_FAILURE() << "expected InvalidArgument reading " << path;
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr(path));
    for (const std::string& fragment : fragments) EXPECT_THAT(e.what(), HasSubstr(fragment));
  }
}

TEST(CloudIo, TruncatedBinaryPlyIsAnError) {
  std::string bytes =
      "ply\nformat binary_little_endian 1.0\nelement vertex 1000\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n";
  for (int i = 0; i < 30; ++i) AppendLittleEndian(&bytes, 1.0f);  // 10 vertices
  const std::string path = TempPath("cloud.ply");
  WriteBytes(path, bytes);
  ExpectReadError(path, {"truncated", "1000 vertices", "120 bytes"});
}

/// A binary PLY whose face element (before the vertices) has a list with a `count_type` count:
/// one face whose count is `count`, followed by one vertex.
template <typename Count>
std::string PlyWithListCount(const std::string& count_type, Count count) {
  std::string bytes = "ply\nformat binary_little_endian 1.0\nelement face 1\nproperty list " + count_type +
                      " uchar vertex_indices\nelement vertex 1\nproperty float x\nproperty float y\n"
                      "property float z\nend_header\n";
  AppendLittleEndian(&bytes, count);
  for (int i = 0; i < 3; ++i) AppendLittleEndian<std::uint8_t>(&bytes, 0);
  for (float v : {1.0f, 2.0f, 3.0f}) AppendLittleEndian(&bytes, v);
  return bytes;
}

TEST(CloudIo, PlyFloatListCountMustBeAWholeNumber) {
  const std::string path = TempPath("cloud.ply");
  WriteBytes(path, PlyWithListCount("float", std::numeric_limits<float>::quiet_NaN()));
  ExpectReadError(path, {"bad list length nan", "element 'face' 0"});
  WriteBytes(path, PlyWithListCount("double", 2.5));
  ExpectReadError(path, {"bad list length 2.5", "element 'face' 0"});
  WriteBytes(path, PlyWithListCount("double", -std::numeric_limits<double>::infinity()));
  ExpectReadError(path, {"bad list length -inf"});
  WriteBytes(path, PlyWithListCount("int", std::int32_t{-1}));
  ExpectReadError(path, {"bad list length -1"});
  // A whole number far beyond the data (and beyond 2^64) is a truncation, not an overflow.
  WriteBytes(path, PlyWithListCount("double", 1e300));
  ExpectReadError(path, {"truncated", "1 face elements"});
}

TEST(CloudIo, PlyFloatListCountThatIsWholeIsALength) {
  const std::string path = TempPath("cloud.ply");
  WriteBytes(path, PlyWithListCount("float", 3.0f));
  const CloudFile cloud = ReadCloudFile(path);
  ASSERT_EQ(cloud.points.size(), 1u);
  EXPECT_EQ(cloud.points[0], Eigen::Vector3f(1.0f, 2.0f, 3.0f));
}

TEST(CloudIo, PlyAsciiElementWithoutPropertiesTakesNoTime) {
  // 2^64 - 1 instances of nothing before the vertices: nothing to read, not a loop of 2^64 steps.
  const std::string path = TempPath("cloud.ply");
  WriteBytes(path,
             "ply\nformat ascii 1.0\nelement marker 18446744073709551615\nelement vertex 1\n"
             "property float x\nproperty float y\nproperty float z\nend_header\n1 2 3\n");
  const CloudFile cloud = ReadCloudFile(path);
  ASSERT_EQ(cloud.points.size(), 1u);
  EXPECT_EQ(cloud.points[0], Eigen::Vector3f(1.0f, 2.0f, 3.0f));
}

TEST(CloudIo, TruncatedAsciiPlyIsAnError) {
  std::string text =
      "ply\nformat ascii 1.0\nelement vertex 1000\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n";
  for (int i = 0; i < 10; ++i) text += "1 2 3\n";
  const std::string path = TempPath("cloud.ply");
  WriteBytes(path, text);
  ExpectReadError(path, {"truncated", "1000", "ends after 10"});
}

TEST(CloudIo, TruncatedBinaryPcdIsAnError) {
  const std::string path = TempPath("cloud.pcd");
  WritePcd(path, SamplePoints(), /*binary=*/true);
  std::ifstream in(path, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  in.close();
  WriteBytes(path, bytes.substr(0, bytes.size() - 5));
  ExpectReadError(path, {"truncated", "4 points"});
}

TEST(CloudIo, TruncatedCompressedPcdIsAnError) {
  const std::string path = TempPath("cloud.pcd");
  const std::string bytes = CompressedPcd(SamplePoints(), LzfLiteralOnly);
  WriteBytes(path, bytes.substr(0, bytes.size() - 10));
  ExpectReadError(path, {"truncated", "compressed bytes"});
}

TEST(CloudIo, EveryTruncationIsReadOrRejectedCleanly) {
  // Each prefix of each format either parses or throws InvalidArgument: never a crash, a
  // different exception or an out-of-bounds read.
  const std::string dir_path = TempPath("");
  std::vector<std::string> files;
  WritePly(dir_path + "a.ply", SamplePoints());
  WritePlyAscii(dir_path + "b.ply", SamplePoints());
  WritePcd(dir_path + "c.pcd", SamplePoints(), true);
  WritePcd(dir_path + "d.pcd", SamplePoints(), false);
  WriteBytes(dir_path + "e.pcd", CompressedPcd(SamplePoints(), LzfLiteralOnly));
  for (const char* name : {"a.ply", "b.ply", "c.pcd", "d.pcd", "e.pcd"}) {
    std::ifstream in(dir_path + name, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string prefix_path = dir_path + "prefix_" + name;
    std::size_t rejected = 0;
    for (std::size_t length = 0; length < bytes.size(); ++length) {
      WriteBytes(prefix_path, bytes.substr(0, length));
      try {
        const CloudFile cloud = ReadCloudFile(prefix_path);
        EXPECT_EQ(cloud.points.size(), SamplePoints().size()) << name << " cut at " << length;
      } catch (const InvalidArgument&) {
        ++rejected;
      }
    }
    EXPECT_GT(rejected, bytes.size() / 2) << name;
  }
}

TEST(CloudIo, MissingFileIsAnError) {
  ExpectReadError(TempPath("does_not_exist.ply"), {"cannot open", "No such file"});
}

TEST(CloudIo, EmptyFileIsAnError) {
  const std::string path = TempPath("empty.ply");
  WriteBytes(path, "");
  ExpectReadError(path, {"empty"});
}

TEST(CloudIo, NotACloudIsAnError) {
  const std::string path = TempPath("notes.ply");
  WriteBytes(path, "solid cube\nfacet normal 0 0 1\n");
  ExpectReadError(path, {"not a supported cloud file"});
}

TEST(CloudIo, PlyWithoutZIsAnError) {
  const std::string path = TempPath("cloud.ply");
  WriteBytes(
      path, "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n1 2\n");
  ExpectReadError(path, {"no 'z' property"});
}

TEST(CloudIo, PlyIntegerCoordinatesAreUnsupported) {
  const std::string path = TempPath("cloud.ply");
  WriteBytes(path,
             "ply\nformat ascii 1.0\nelement vertex 1\nproperty int x\nproperty float y\nproperty float z\n"
             "end_header\n1 2 3\n");
  ExpectReadError(path, {"'x' has type int", "only float and double"});
}

TEST(CloudIo, PlyUnsupportedFormatIsAnError) {
  const std::string path = TempPath("cloud.ply");
  WriteBytes(path, "ply\nformat binary_middle_endian 1.0\nelement vertex 0\nend_header\n");
  ExpectReadError(path, {"unsupported PLY format 'binary_middle_endian'"});
}

TEST(CloudIo, PcdWithoutDataLineIsAnError) {
  const std::string path = TempPath("cloud.pcd");
  WriteBytes(path, "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\n");
  ExpectReadError(path, {"no DATA line"});
}

TEST(CloudIo, WritePlyRejectsColourCountMismatch) {
  const std::vector<Rgb> colours(2);
  try {
    WritePly(TempPath("cloud.ply"), SamplePoints(), &colours);
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("2 colours for 4 points"));
  }
}

TEST(CloudIo, WriteToMissingDirectoryIsAnError) {
  try {
    WritePcd("/nonexistent-dir/cloud.pcd", SamplePoints(), true);
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("/nonexistent-dir/cloud.pcd"));
  }
}

TEST(LabelColour, IsGreyForNegativeLabels) {
  const Rgb grey = LabelColour(-1);
  EXPECT_EQ(grey[0], grey[1]);
  EXPECT_EQ(grey[1], grey[2]);
  EXPECT_EQ(LabelColour(-7), grey);
}

TEST(LabelColour, IsDeterministicAndDistinct) {
  constexpr int kLabels = 64;
  std::set<Rgb> seen;
  for (int i = 0; i < kLabels; ++i) {
    EXPECT_EQ(LabelColour(i), LabelColour(i));
    EXPECT_NE(LabelColour(i), LabelColour(-1));
    seen.insert(LabelColour(i));
  }
  EXPECT_EQ(seen.size(), static_cast<std::size_t>(kLabels));
}

TEST(LabelColour, ConsecutiveLabelsAreFarApart) {
  constexpr int kMinChannelDifference = 60;  // out of 255, in the most different channel
  for (int i = 0; i < 100; ++i) {
    const Rgb a = LabelColour(i), b = LabelColour(i + 1);
    int largest = 0;
    for (int c = 0; c < 3; ++c) largest = std::max(largest, std::abs(int{a[c]} - int{b[c]}));
    EXPECT_GE(largest, kMinChannelDifference) << "labels " << i << " and " << i + 1;
  }
}

}  // namespace
}  // namespace tubepick
