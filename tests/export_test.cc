#include "finecap/io/export.h"

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "finecap/io/mesh_io.h"
#include "test_util.h"

namespace finecap {
namespace {

namespace fs = std::filesystem;
using testing_util::ExpectErrorMentions;
using testing_util::FileBytes;
using testing_util::FilesIn;
using testing_util::MakeTempDir;
using testing_util::WriteText;

// Sample s of a small animation: point p at (p + s, 2p - s, 0.001 p s).
Eigen::Matrix3Xd Sample(int s, int num_points) {
  Eigen::Matrix3Xd points(3, num_points);
  for (int p = 0; p < num_points; ++p) points.col(p) << p + s, 2.0 * p - s, 0.001 * p * s;
  return points;
}

void WriteCache(const std::string& path, int num_samples, int num_points) {
  Pc2Writer writer(path, num_points, 10.0f, 0.5f);
  for (int s = 0; s < num_samples; ++s) writer.Append(Sample(s, num_points));
  EXPECT_EQ(writer.num_samples(), num_samples);
  writer.Finish();
}

TEST(ExportPc2, HeaderBytesAreLiterallyTheFormat) {
  const std::string path = MakeTempDir("pc2_header") + "/anim.pc2";
  WriteCache(path, 3, 4);
  const std::string bytes = FileBytes(path);
  const unsigned char expected[32] = {'P',  'O',  'I',  'N',  'T', 'C',
                                      'A',  'C',  'H',  'E',  '2', 0,  // signature
                                      0x01, 0x00, 0x00, 0x00,          // version 1
                                      0x04, 0x00, 0x00, 0x00,          // 4 points
                                      0x00, 0x00, 0x20, 0x41,          // start frame 10.0f
                                      0x00, 0x00, 0x00, 0x3f,          // sample rate 0.5f
                                      0x03, 0x00, 0x00, 0x00};         // 3 samples
  ASSERT_EQ(bytes.size(), 32u + 3 * 4 * 3 * 4);
  EXPECT_EQ(bytes.substr(0, 32), std::string(reinterpret_cast<const char*>(expected), 32));
  // The first value after the header: sample 0, point 0, x = 0.0f; then point 1's x = 1.0f.
  EXPECT_EQ(bytes.substr(32, 4), std::string(4, '\0'));
  EXPECT_EQ(bytes.substr(44, 4), std::string("\x00\x00\x80\x3f", 4));
}

TEST(ExportPc2, RoundTripsHeaderAndValues) {
  const std::string dir = MakeTempDir("pc2_round_trip");
  const std::string path = dir + "/anim.pc2";
  WriteCache(path, 5, 7);
  EXPECT_EQ(FilesIn(dir), std::vector<std::string>{"anim.pc2"});
  const Pc2Cache cache = ReadPc2(path);
  EXPECT_EQ(cache.header.num_points, 7);
  EXPECT_EQ(cache.header.num_samples, 5);
  EXPECT_EQ(cache.header.start_frame, 10.0f);
  EXPECT_EQ(cache.header.sample_rate, 0.5f);
  ASSERT_EQ(cache.samples.size(), 5u);
  for (int s = 0; s < 5; ++s) {
    ASSERT_EQ(cache.samples[s].cols(), 7);
    EXPECT_EQ(cache.samples[s], Sample(s, 7).cast<float>()) << "sample " << s;
  }
}

TEST(ExportPc2, UnfinishedWriterLeavesNothing) {
  const std::string dir = MakeTempDir("pc2_unfinished");
  {
    Pc2Writer writer(dir + "/anim.pc2", 2);
    writer.Append(Sample(0, 2));
  }
  EXPECT_TRUE(FilesIn(dir).empty());
}

TEST(ExportPc2, FailedAppendKeepsTheTargetUntouched) {
  const std::string dir = MakeTempDir("pc2_failed");
  const std::string path = dir + "/anim.pc2";
  WriteCache(path, 1, 2);
  const std::string before = FileBytes(path);
  {
    Pc2Writer writer(path, 2);
    Eigen::Matrix3Xd points = Sample(0, 2);
    writer.Append(points);
    points(1, 1) = std::numeric_limits<double>::quiet_NaN();
    ExpectErrorMentions([&] { writer.Append(points); },
                        {path, "sample 1", "non-finite", "point 1"});
    ExpectErrorMentions([&] { writer.Append(Sample(0, 3)); }, {path, "3 points, the cache 2"});
  }
  EXPECT_EQ(FileBytes(path), before);
  EXPECT_EQ(FilesIn(dir), std::vector<std::string>{"anim.pc2"});
}

TEST(ExportPc2, WriterRejectsBadArgumentsAndUseAfterFinish) {
  const std::string path = MakeTempDir("pc2_args") + "/anim.pc2";
  ExpectErrorMentions([&] { Pc2Writer(path, 0); }, {path, "at least one point"});
  ExpectErrorMentions([&] { Pc2Writer(path, 3, 0.0f, 0.0f); }, {path, "sample rate"});
  ExpectErrorMentions([&] { Pc2Writer(path, 3, std::numeric_limits<float>::infinity()); },
                      {path, "start frame"});
  ExpectErrorMentions([&] { Pc2Writer(path + "/missing/dir.pc2", 3); }, {"cannot create"});
  Pc2Writer writer(path, 1);
  writer.Finish();
  EXPECT_EQ(ReadPc2(path).header.num_samples, 0);
  ExpectErrorMentions([&] { writer.Append(Sample(0, 1)); }, {path, "already finished"});
  ExpectErrorMentions([&] { writer.Finish(); }, {path, "already finished"});
}

TEST(ExportPc2, ReaderNamesTheFileAndTheProblem) {
  const std::string dir = MakeTempDir("pc2_read");
  const std::string good = dir + "/good.pc2";
  WriteCache(good, 2, 3);
  const std::string bytes = FileBytes(good);

  const std::string truncated = dir + "/truncated.pc2";
  WriteText(truncated, bytes.substr(0, bytes.size() - 4));
  ExpectErrorMentions([&] { ReadPc2(truncated); },
                      {truncated, "2 samples of 3 points", "68 bytes"});

  const std::string wrong_signature = dir + "/signature.pc2";
  WriteText(wrong_signature, "POINTCACHE3" + bytes.substr(11));
  ExpectErrorMentions([&] { ReadPc2(wrong_signature); }, {wrong_signature, "not a PC2"});

  std::string version_two = bytes;
  version_two[12] = 2;
  const std::string wrong_version = dir + "/version.pc2";
  WriteText(wrong_version, version_two);
  ExpectErrorMentions([&] { ReadPc2(wrong_version); }, {wrong_version, "version 2"});

  std::string huge_counts = bytes;
  huge_counts.replace(16, 4, "\xff\xff\xff\x7f");
  huge_counts.replace(28, 4, "\xff\xff\xff\x7f");
  const std::string overflow = dir + "/overflow.pc2";
  WriteText(overflow, huge_counts);
  ExpectErrorMentions([&] { ReadPc2(overflow); }, {overflow, "header announces"});

  ExpectErrorMentions([&] { ReadPc2(dir + "/absent.pc2"); }, {"absent.pc2"});
}

Mesh Triangle() {
  Mesh mesh;
  mesh.vertices.resize(3, 3);
  mesh.vertices << 0, 1, 0, 0, 0, 1, 0, 0, 0;
  mesh.faces.resize(3, 1);
  mesh.faces << 0, 1, 2;
  return mesh;
}

TEST(ExportPly, WritesTheDisplacementAsVertexQuality) {
  const std::string path = MakeTempDir("ply_quality") + "/frame_0003.ply";
  const Mesh mesh = Triangle();
  WriteDisplacementPly(path, mesh, Eigen::Vector3d(0.001, -0.002, 0.0005));
  const std::string bytes = FileBytes(path);
  const size_t end_of_header = bytes.find("end_header\n");
  ASSERT_NE(end_of_header, std::string::npos);
  const std::string header = bytes.substr(0, end_of_header);
  EXPECT_NE(header.find("element vertex 3"), std::string::npos);
  EXPECT_NE(header.find("property float quality"), std::string::npos);
  // The quality floats are in the file, little-endian.
  const float k = -0.002f;
  std::string k_bytes(4, '\0');
  std::memcpy(k_bytes.data(), &k, 4);  // The test host is little-endian (x86-64 / ARM64).
  EXPECT_NE(bytes.find(k_bytes, end_of_header), std::string::npos);
  EXPECT_EQ(ReadMesh(path).vertices, mesh.vertices);
}

TEST(ExportPly, WrongDisplacementSizeNamesTheFile) {
  const std::string path = MakeTempDir("ply_size") + "/frame.ply";
  ExpectErrorMentions([&] { WriteDisplacementPly(path, Triangle(), Eigen::VectorXd::Zero(2)); },
                      {path, "quality"});
  EXPECT_FALSE(fs::exists(path));
}

}  // namespace
}  // namespace finecap
