#include "finecap/io/capture.h"

#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "finecap/io/camera_io.h"
#include "finecap/io/mesh_io.h"
#include "finecap/util/error.h"
#include "test_util.h"

namespace finecap {
namespace {

namespace fs = std::filesystem;
using testing_util::ExpectErrorMentions;
using testing_util::MakeTempDir;
using testing_util::WriteText;

constexpr int kWidth = 40;
constexpr int kHeight = 30;
const std::vector<std::string> kFrames = {"0", "1", "2", "10"};  // Sorted numerically.

Camera MakeCamera(const std::string& name, double angle) {
  Camera camera;
  camera.name = name;
  camera.width = kWidth;
  camera.height = kHeight;
  camera.K << 50.0, 0.0, 19.5, 0.0, 50.0, 14.5, 0.0, 0.0, 1.0;
  camera.R = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitY()).toRotationMatrix();
  camera.t = Eigen::Vector3d(0, 0, 2);
  camera.distortion = {-0.05, 0.0, 0.0, 0.0, 0.0};
  return camera;
}

// A tetrahedron moved along x by `shift`.
Mesh MakeTetrahedron(double shift) {
  Mesh mesh;
  mesh.vertices.resize(3, 4);
  mesh.vertices << 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1;
  mesh.vertices.row(0).array() += shift;
  mesh.faces.resize(3, 4);
  mesh.faces << 0, 0, 0, 1, 2, 1, 3, 2, 1, 3, 2, 3;
  return mesh;
}

// The brightness of camera c's image of frame f, so a test can tell images apart.
int Level(int camera, int frame) { return 20 + 40 * frame + 10 * camera; }

cv::Mat Uniform(int level, int width = kWidth, int height = kHeight) {
  return cv::Mat(height, width, CV_8UC3, cv::Scalar(level, level, level));
}

std::string AsciiPly(const std::string& vertex_lines) {
  return "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
         "property float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n" +
         vertex_lines + "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
}

// A good capture: cam0 as a PNG folder, cam1 as a Motion-JPEG video, four frames, a mask and
// ground truth for frame 0.
std::string MakeCapture() {
  const std::string dir = MakeTempDir("capture");
  WriteCamerasYaml({MakeCamera("cam0", 0.0), MakeCamera("cam1", 0.4)}, dir + "/cameras.yaml");
  fs::create_directories(dir + "/images/cam0");
  fs::create_directories(dir + "/videos");
  fs::create_directories(dir + "/meshes");
  fs::create_directories(dir + "/gt");
  cv::VideoWriter video(dir + "/videos/cam1.avi", cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 25,
                        cv::Size(kWidth, kHeight));
  for (size_t f = 0; f < kFrames.size(); ++f) {
    cv::imwrite(dir + "/images/cam0/" + kFrames[f] + ".png", Uniform(Level(0, f)));
    video.write(Uniform(Level(1, f)));
    WriteMesh(dir + "/meshes/" + kFrames[f] + ".ply", MakeTetrahedron(0.1 * f));
  }
  WriteText(dir + "/mask.txt", "3 1\n");
  WriteMesh(dir + "/gt/0.ply", MakeTetrahedron(0.5));
  WriteText(dir + "/gt/0_k.txt", "0.001\nnan\n-0.002\n0\n");
  WriteText(dir + "/gt/textureless.txt", "2\n");
  return dir;
}

TEST(CaptureTest, GoodCaptureOpensAndReads) {
  const std::string dir = MakeCapture();
  Capture capture = Capture::Open(dir);
  ASSERT_EQ(capture.num_cameras(), 2);
  EXPECT_EQ(capture.cameras()[1].name, "cam1");
  EXPECT_FALSE(capture.cameras()[0].HasDistortion());
  EXPECT_EQ(capture.cameras()[0].K, MakeCamera("cam0", 0).K);
  EXPECT_EQ(capture.frame_names(), kFrames);
  EXPECT_EQ(capture.frame_name(3), "10");

  EXPECT_EQ(capture.ReadCoarseMesh(3).vertices, MakeTetrahedron(0.1 * 3).vertices);
  EXPECT_EQ(capture.ReadCoarseMesh(0).faces, MakeTetrahedron(0).faces);
  for (int frame : {0, 3, 1}) {
    for (int camera = 0; camera < 2; ++camera) {
      const cv::Mat image = capture.ReadImage(camera, frame);
      EXPECT_EQ(image.size(), cv::Size(kWidth, kHeight));
      // Undistortion moves pixels; the centre of a uniform image keeps its level.
      EXPECT_NEAR(image.at<cv::Vec3b>(15, 20)[0], Level(camera, frame), 3) << camera << frame;
    }
  }
  EXPECT_TRUE(capture.has_vertex_mask());
  EXPECT_EQ(capture.vertex_mask(), (std::vector<int>{1, 3}));
  EXPECT_TRUE(capture.has_ground_truth());
  EXPECT_TRUE(capture.HasTrueSurface(0));
  EXPECT_FALSE(capture.HasTrueSurface(1));
  EXPECT_EQ(capture.ReadTrueSurface(0).vertices, MakeTetrahedron(0.5).vertices);
  const Eigen::VectorXd k = capture.ReadTrueDisplacement(0);
  ASSERT_EQ(k.size(), 4);
  EXPECT_EQ(k(0), 0.001);
  EXPECT_TRUE(std::isnan(k(1)));
  EXPECT_EQ(k(2), -0.002);
  EXPECT_EQ(capture.textureless_vertices(), (std::vector<int>{2}));
  ExpectErrorMentions([&] { capture.ReadTrueDisplacement(2); }, {"gt/2_k.txt", "not found"});
  ExpectErrorMentions([&] { capture.ReadImage(2, 0); }, {dir, "camera index 2"});
}

// Frame 0's images, decoded as the capture opens, serve the first read of that frame: a read
// after it, or after another frame's, decodes the same image again, whatever the caller did to
// the one it was given.
TEST(CaptureTest, FirstFrameReadAgainIsTheSame) {
  const std::string dir = MakeCapture();
  Capture capture = Capture::Open(dir);
  for (int camera = 0; camera < 2; ++camera) {
    cv::Mat first = capture.ReadImage(camera, 0);
    const cv::Mat kept = first.clone();
    first.setTo(cv::Scalar::all(255));
    EXPECT_EQ(cv::norm(capture.ReadImage(camera, 0), kept, cv::NORM_INF), 0.0) << camera;
  }
  Capture other = Capture::Open(dir);
  EXPECT_NEAR(other.ReadImage(1, 2).at<cv::Vec3b>(15, 20)[0], Level(1, 2), 3);
  EXPECT_NEAR(other.ReadImage(1, 0).at<cv::Vec3b>(15, 20)[0], Level(1, 0), 3);
}

TEST(CaptureTest, IntriExtriRigTakesItsSizeFromTheFirstImage) {
  const std::string dir = MakeCapture();
  fs::remove(dir + "/cameras.yaml");
  cv::FileStorage intri(dir + "/intri.yml", cv::FileStorage::WRITE);
  cv::FileStorage extri(dir + "/extri.yml", cv::FileStorage::WRITE);
  const cv::Mat K = (cv::Mat_<double>(3, 3) << 50, 0, 19.5, 0, 50, 14.5, 0, 0, 1);
  intri << "names" << std::vector<std::string>{"cam0", "cam1"};
  for (const std::string name : {"cam0", "cam1"}) {
    intri << "K_" + name << K;
    extri << "R_" + name << cv::Mat(cv::Mat::zeros(3, 1, CV_64F));
    extri << "T_" + name << (cv::Mat_<double>(3, 1) << 0, 0, 2);
  }
  intri.release();
  extri.release();
  const Capture capture = Capture::Open(dir);
  for (const Camera& camera : capture.cameras()) {
    EXPECT_EQ(camera.width, kWidth) << camera.name;
    EXPECT_EQ(camera.height, kHeight) << camera.name;
  }
}

TEST(CaptureTest, MissingFolderAndRig) {
  const std::string dir = MakeCapture();
  ExpectErrorMentions([&] { Capture::Open(dir + "/nothing"); },
                      {dir + "/nothing", "capture folder not found"});
  fs::remove(dir + "/cameras.yaml");
  ExpectErrorMentions([&] { Capture::Open(dir); }, {dir, "cameras.yaml", "no camera rig found"});
}

std::string CamerasYamlWithR(const std::string& r) {
  return "cameras:\n  - name: cam0\n    width: 40\n    height: 30\n"
         "    K: [50, 0, 19.5, 0, 50, 14.5, 0, 0, 1]\n    R: " +
         r + "\n    t: [0, 0, 2]\n";
}

TEST(CaptureTest, BadCamerasYaml) {
  const std::string dir = MakeCapture();
  const std::string path = dir + "/cameras.yaml";
  WriteText(path, "cameras:\n  - name: cam0\n    K: [1, 2\n");
  ExpectErrorMentions([&] { Capture::Open(dir); }, {path, "malformed YAML"});
  WriteText(path, CamerasYamlWithR("[1, 0, 0, 0, 1, 0, 0, 0, 0]"));
  ExpectErrorMentions([&] { Capture::Open(dir); }, {path, "cam0", "not a rotation"});
  WriteText(path, CamerasYamlWithR("[1, 0, 0, 0, 1, 0.5, 0, 0, 1]"));
  ExpectErrorMentions([&] { Capture::Open(dir); }, {path, "cam0", "not a rotation"});
}

TEST(CaptureTest, CameraWithoutImages) {
  const std::string dir = MakeCapture();
  fs::remove(dir + "/videos/cam1.avi");
  ExpectErrorMentions([&] { Capture::Open(dir); }, {dir, "camera cam1", "videos/cam1"});
}

TEST(CaptureTest, ImageOfTheWrongSize) {
  const std::string dir = MakeCapture();
  cv::imwrite(dir + "/images/cam0/0.png", Uniform(50, 20, 10));
  ExpectErrorMentions([&] { Capture::Open(dir); },
                      {dir + "/images/cam0/0.png", "is 20x10 but camera cam0 is 40x30"});
}

TEST(CaptureTest, EmptyAndTruncatedImages) {
  const std::string dir = MakeCapture();
  std::vector<uchar> png;
  cv::Mat noise(kHeight, kWidth, CV_8UC3);
  cv::randu(noise, 0, 255);
  cv::imencode(".png", noise, png);
  WriteText(dir + "/images/cam0/2.png", std::string(png.begin(), png.begin() + png.size() / 2));
  Capture capture = Capture::Open(dir);  // Only the first image is checked up front.
  ExpectErrorMentions([&] { capture.ReadImage(0, 2); }, {dir + "/images/cam0/2.png", "decode"});
  WriteText(dir + "/images/cam0/0.png", "");
  ExpectErrorMentions([&] { Capture::Open(dir); }, {dir + "/images/cam0/0.png", "empty (0 bytes)"});
}

TEST(CaptureTest, MeshFramesWithAnotherTopology) {
  const std::string dir = MakeCapture();
  Mesh fewer = MakeTetrahedron(0);
  fewer.vertices.conservativeResize(3, 3);
  fewer.faces.conservativeResize(3, 1);
  fewer.faces.col(0) << 0, 1, 2;
  WriteMesh(dir + "/meshes/1.ply", fewer);
  Mesh flipped = MakeTetrahedron(0);
  flipped.faces.col(0).reverseInPlace();
  WriteMesh(dir + "/meshes/2.ply", flipped);
  const Capture capture = Capture::Open(dir);
  ExpectErrorMentions([&] { capture.ReadCoarseMesh(1); },
                      {dir + "/meshes/1.ply", "has 3 vertices but the first frame has 4"});
  ExpectErrorMentions([&] { capture.ReadCoarseMesh(2); },
                      {dir + "/meshes/2.ply", "triangles differ from the first frame's"});
}

TEST(CaptureTest, MeshFramesWithBadValues) {
  const std::string dir = MakeCapture();
  fs::remove(dir + "/meshes/1.ply");
  fs::remove(dir + "/meshes/2.ply");
  fs::remove(dir + "/meshes/10.ply");
  WriteText(dir + "/meshes/1.ply", AsciiPly("0 0 0\n1 0 0\nnan 1 0\n0 0 1\n"));
  WriteText(dir + "/meshes/2.ply", AsciiPly("0 0 0\n1 0 inf\n0 1 0\n0 0 1\n"));
  WriteText(dir + "/meshes/10.obj", "this is not a mesh\n");
  const Capture capture = Capture::Open(dir);
  ASSERT_EQ(capture.num_frames(), 4);
  ExpectErrorMentions([&] { capture.ReadCoarseMesh(1); },
                      {dir + "/meshes/1.ply", "NaN or infinite"});
  ExpectErrorMentions([&] { capture.ReadCoarseMesh(2); },
                      {dir + "/meshes/2.ply", "NaN or infinite"});
  ExpectErrorMentions([&] { capture.ReadCoarseMesh(3); },
                      {dir + "/meshes/10.obj", "not an OBJ statement"});
  WriteText(dir + "/meshes/0.ply", "this is not a mesh\n");
  ExpectErrorMentions([&] { Capture::Open(dir); }, {dir + "/meshes/0.ply", "not a PLY file"});
}

TEST(CaptureTest, NoMeshesAndBadMask) {
  const std::string dir = MakeCapture();
  WriteText(dir + "/mask.txt", "1 4\n");
  ExpectErrorMentions([&] { Capture::Open(dir); }, {dir + "/mask.txt line 1", "out of range"});
  fs::remove_all(dir + "/meshes");
  fs::create_directories(dir + "/meshes");
  ExpectErrorMentions([&] { Capture::Open(dir); }, {dir + "/meshes", "no mesh files"});
}

}  // namespace
}  // namespace finecap

namespace finecap {
namespace {

// A mask whose left half is foreground, written as `foreground` (any non-zero value).
cv::Mat LeftHalf(int foreground, int width = kWidth, int height = kHeight) {
  cv::Mat mask = cv::Mat::zeros(height, width, CV_8UC1);
  mask.colRange(0, width / 2).setTo(foreground);
  return mask;
}

// MakeCapture with masks for both cameras in `folder` (masks or mask), as PNG or JPEG.
std::string MakeMaskedCapture(const std::string& folder, const std::string& extension) {
  const std::string dir = MakeCapture();
  for (const std::string camera : {"cam0", "cam1"}) {
    fs::create_directories(dir + "/" + folder + "/" + camera);
    for (const std::string& frame : kFrames) {
      // ZJU-MoCap's masks hold 1 on the subject; a JPEG's hold 255.
      const cv::Mat mask = LeftHalf(extension == ".png" ? 1 : 255);
      cv::imwrite(dir + "/" + folder + "/" + camera + "/" + frame + extension, mask);
    }
  }
  return dir;
}

TEST(CaptureMaskTest, MasksAreReadUndistortedByTheNearestPixel) {
  for (const auto& [folder, extension] :
       std::vector<std::pair<std::string, std::string>>{{"masks", ".png"}, {"mask", ".jpg"}}) {
    Capture capture = Capture::Open(MakeMaskedCapture(folder, extension));
    ASSERT_TRUE(capture.has_masks()) << folder;
    for (int camera = 0; camera < 2; ++camera) {
      const cv::Mat mask = capture.ReadMask(camera, 3);
      ASSERT_EQ(mask.type(), CV_8UC1);
      EXPECT_EQ(mask.size(), cv::Size(kWidth, kHeight));
      // Labels, not blends: nothing but 0 and 255, even where undistortion resampled.
      EXPECT_EQ(cv::countNonZero((mask != 0) & (mask != 255)), 0) << folder << camera;
      EXPECT_EQ(mask.at<unsigned char>(15, 5), 255) << folder << camera;
      EXPECT_EQ(mask.at<unsigned char>(15, 35), 0) << folder << camera;
    }
  }
}

TEST(CaptureMaskTest, ACaptureWithoutMasksHasNone) {
  Capture capture = Capture::Open(MakeCapture());
  EXPECT_FALSE(capture.has_masks());
  EXPECT_TRUE(capture.ReadMask(1, 2).empty());
}

TEST(CaptureMaskTest, BadMasksAreNamed) {
  std::string dir = MakeMaskedCapture("masks", ".png");
  fs::remove_all(dir + "/masks/cam1");
  ExpectErrorMentions([&] { Capture::Open(dir); }, {dir + "/masks/cam1", "mask folder not found"});

  dir = MakeMaskedCapture("masks", ".png");
  cv::imwrite(dir + "/masks/cam0/0.png", LeftHalf(1, 20, 10));
  ExpectErrorMentions(
      [&] { Capture::Open(dir); },
      {dir + "/masks/cam0/0.png", "the mask is 20x10 but camera cam0's images are 40x30"});

  dir = MakeMaskedCapture("masks", ".png");
  cv::imwrite(dir + "/masks/cam1/2.png", LeftHalf(1, 20, 10));
  WriteText(dir + "/masks/cam0/2.png", "not an image");
  fs::remove(dir + "/masks/cam0/10.png");
  Capture capture = Capture::Open(dir);  // Only the first masks are checked up front.
  ExpectErrorMentions([&] { capture.ReadMask(0, 2); }, {dir + "/masks/cam0/2.png", "decode"});
  ExpectErrorMentions([&] { capture.ReadMask(1, 2); }, {dir + "/masks/cam1/2.png", "20x10"});
  ExpectErrorMentions([&] { capture.ReadMask(0, 3); },
                      {dir + "/masks/cam0", "no image for frame '10'"});
}

}  // namespace
}  // namespace finecap
