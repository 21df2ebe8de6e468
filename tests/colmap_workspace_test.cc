// COLMAP's binary model and COLMAP workspaces as captures: the binary reader against what COLMAP
// itself writes, its refusals, and a synthetic capture laid out as a COLMAP workspace, which must
// refine exactly as the same capture with a cameras.yaml.
#include <algorithm>
#include <array>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "finecap/commands/commands.h"
#include "finecap/io/camera_io.h"
#include "finecap/io/capture.h"
#include "finecap/synth/synth.h"
#include "finecap/util/error.h"
#include "run_finecap.h"
#include "test_util.h"
#include "tiny_synth.h"

namespace finecap {
namespace {

namespace fs = std::filesystem;

using testing_util::ExpectErrorMentions;
using testing_util::FileBytes;
using testing_util::MakeTempDir;
using testing_util::WriteText;

bool HaveColmap() { return std::system("command -v colmap > /dev/null 2>&1") == 0; }

#define SKIP_WITHOUT_COLMAP()                                                             \
  if (!HaveColmap()) {                                                                    \
    GTEST_SKIP() << "colmap is not installed (Debian: apt-get install colmap, which "     \
                    "scripts/install-deps.sh does): COLMAP's binary model is not tested"; \
  }

// Converts the text model in `text` to COLMAP's binary model in `binary` with COLMAP itself.
void ConvertToBinary(const std::string& text, const std::string& binary) {
  WriteText(text + "/points3D.txt", "");
  fs::create_directories(binary);
  const std::string log = text + "/colmap.log";
  const std::string command = "colmap model_converter --input_path '" + text + "' --output_path '" +
                              binary + "' --output_type BIN > '" + log + "' 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0) << FileBytes(log);
}

// An image line of images.txt (and its empty line of 2D points).
std::string ImageLines(int image_id, const Eigen::Quaterniond& q, const Eigen::Vector3d& t,
                       int camera_id, const std::string& name) {
  std::ostringstream line;
  line.precision(17);
  line << image_id << " " << q.w() << " " << q.x() << " " << q.y() << " " << q.z() << " " << t.x()
       << " " << t.y() << " " << t.z() << " " << camera_id << " " << name << "\n\n";
  return line.str();
}

// A text model of every supported camera model, a camera seen in two frames and images in
// folders and flat.
void WriteEveryModel(const std::string& folder) {
  WriteText(folder + "/cameras.txt",
            "# Camera list\n"
            "1 SIMPLE_PINHOLE 640 480 700.25 320.5 240.75\n"
            "2 PINHOLE 800 600 700 710.5 401 299.25\n"
            "3 SIMPLE_RADIAL 800 600 700 401 299 -0.12\n"
            "4 RADIAL 800 600 700 401 299 -0.12 0.03\n"
            "5 OPENCV 1280 720 1234.5 1236.25 640.5 360.25 -0.12 0.034 0.0011 -0.0007\n"
            "6 FULL_OPENCV 1280 720 1234.5 1236.25 640.5 360.25 -0.12 0.034 0.0011 -0.0007 "
            "0.002 0.01 0.003 0.0004\n");
  std::string images = "# Image list\n";
  const std::vector<std::string> names = {"a.png",  "b/000000.png", "c.JPG",       "d/000000.png",
                                          "e.jpeg", "f/000000.png", "b/000001.png"};
  for (int id = 1; id <= static_cast<int>(names.size()); ++id) {
    const Eigen::Quaterniond q(
        Eigen::AngleAxisd(0.3 * id, Eigen::Vector3d(0.1 * id, 1.0, -0.2).normalized()));
    const int camera_id = id <= 6 ? id : 2;
    images += ImageLines(10 * id, q, Eigen::Vector3d(0.1 * id, -0.25, 3.0 + 0.5 * id), camera_id,
                         names[id - 1]);
  }
  WriteText(folder + "/images.txt", images);
}

void ExpectSameModel(const ColmapModel& a, const ColmapModel& b) {
  EXPECT_EQ(a.image_names, b.image_names);
  ASSERT_EQ(a.cameras.size(), b.cameras.size());
  for (size_t c = 0; c < a.cameras.size(); ++c) {
    const Camera& x = a.cameras[c];
    const Camera& y = b.cameras[c];
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.width, y.width);
    EXPECT_EQ(x.height, y.height);
    EXPECT_EQ(x.K, y.K) << x.name;
    EXPECT_EQ(x.distortion, y.distortion) << x.name;
    EXPECT_EQ(x.R, y.R) << x.name;
    EXPECT_EQ(x.t, y.t) << x.name;
  }
}

TEST(ColmapBinaryModelTest, ReadsWhatColmapWroteAsTheTextModel) {
  SKIP_WITHOUT_COLMAP();
  const std::string dir = MakeTempDir("colmap_bin");
  WriteEveryModel(dir + "/text");
  ConvertToBinary(dir + "/text", dir + "/bin");
  const ColmapModel text = ReadColmapTextModel(dir + "/text");
  const ColmapModel binary = ReadColmapBinaryModel(dir + "/bin");
  ExpectSameModel(binary, text);
  ASSERT_EQ(binary.cameras.size(), 6u);
  EXPECT_EQ(binary.image_names,
            (std::vector<std::string>{"a.png", "b/000000.png", "c.JPG", "d/000000.png", "e.jpeg",
                                      "f/000000.png"}));
  EXPECT_EQ(binary.cameras[0].name, "a");
  EXPECT_EQ(binary.cameras[1].name, "b");
  EXPECT_EQ(binary.cameras[0].K(0, 2), 320.0);  // COLMAP's +0.5 removed.
  // FULL_OPENCV's eight coefficients are OpenCV's k1 k2 p1 p2 k3 k4 k5 k6.
  const std::array<double, 12> full = {-0.12, 0.034, 0.0011, -0.0007, 0.002, 0.01, 0.003, 0.0004};
  EXPECT_EQ(binary.cameras[5].distortion, full);
}

TEST(ColmapBinaryModelTest, RefusesUnsupportedModelsByName) {
  SKIP_WITHOUT_COLMAP();
  const std::string dir = MakeTempDir("colmap_bin");
  for (const std::string model : {"OPENCV_FISHEYE", "FOV", "THIN_PRISM_FISHEYE"}) {
    const std::string params = model == "FOV"              ? "500 500 320 240 0.9"
                               : model == "OPENCV_FISHEYE" ? "500 500 320 240 0.1 0 0 0"
                                                           : "500 500 320 240 0 0 0 0 0 0 0 0";
    const std::string text = dir + "/" + model;
    WriteText(text + "/cameras.txt", "3 " + model + " 640 480 " + params + "\n");
    WriteText(text + "/images.txt", ImageLines(1, Eigen::Quaterniond::Identity(),
                                               Eigen::Vector3d(0, 0, 1), 3, "cam0.png"));
    ConvertToBinary(text, text + "_bin");
    ExpectErrorMentions([&] { ReadColmapBinaryModel(text + "_bin"); },
                        {text + "_bin/cameras.bin (camera 3)",
                         "unsupported camera model '" + model + "'", "FULL_OPENCV"});
    ExpectErrorMentions([&] { ReadColmapTextModel(text); },
                        {"cameras.txt line 1", "unsupported camera model '" + model + "'"});
  }
}

// `path` with `bytes` in place of its own.
void Overwrite(const std::string& path, const std::string& bytes) {
  fs::remove(path);
  WriteText(path, bytes);
}

TEST(ColmapBinaryModelTest, BadFilesNameTheFileAndTheProblem) {
  SKIP_WITHOUT_COLMAP();
  const std::string dir = MakeTempDir("colmap_bin");
  WriteEveryModel(dir + "/text");
  ConvertToBinary(dir + "/text", dir + "/bin");
  const std::string cameras_path = dir + "/bin/cameras.bin";
  const std::string images_path = dir + "/bin/images.bin";
  const std::string cameras = FileBytes(cameras_path);
  const std::string images = FileBytes(images_path);
  const auto read = [&] { ReadColmapBinaryModel(dir + "/bin"); };

  Overwrite(cameras_path, cameras.substr(0, cameras.size() - 3));
  ExpectErrorMentions(read, {cameras_path, "truncated: the file ends in camera ", "'s params"});
  Overwrite(cameras_path, cameras + "x");
  ExpectErrorMentions(read, {cameras_path, "1 bytes follow the last record"});
  std::string unknown_model = cameras;
  unknown_model[12] = 42;  // The first camera's model id follows the count and its id.
  Overwrite(cameras_path, unknown_model);
  ExpectErrorMentions(read, {cameras_path, "unknown camera model id 42"});
  Overwrite(cameras_path, cameras);

  Overwrite(images_path, images.substr(0, images.size() - 20));
  ExpectErrorMentions(read, {images_path, "truncated"});
  Overwrite(images_path, images.substr(0, 5));
  ExpectErrorMentions(read, {images_path, "truncated", "the image count"});
  fs::remove(images_path);
  ExpectErrorMentions(read, {images_path, "not found"});
}

// ---------------------------------------------------------------------------------------------
// A COLMAP workspace as a capture

// The text model of a rig without distortion or skew (a synthetic capture's): one PINHOLE camera
// and one image, images/<camera>.png, per camera.
void WriteColmapTextModelOf(const std::vector<Camera>& rig, const std::string& folder) {
  std::ostringstream cameras;
  cameras.precision(17);
  std::string images;
  for (size_t c = 0; c < rig.size(); ++c) {
    const Camera& camera = rig[c];
    ASSERT_FALSE(camera.HasDistortion());
    ASSERT_EQ(camera.K(0, 1), 0.0);
    const int id = static_cast<int>(c) + 1;
    cameras << id << " PINHOLE " << camera.width << " " << camera.height << " " << camera.fx()
            << " " << camera.K(1, 1) << " " << camera.K(0, 2) + 0.5 << " " << camera.K(1, 2) + 0.5
            << "\n";
    images += ImageLines(id, Eigen::Quaterniond(camera.R), camera.t, id, camera.name + ".png");
  }
  WriteText(folder + "/cameras.txt", cameras.str());
  WriteText(folder + "/images.txt", images);
}

// Every file under `dir` with its size: shows that nothing was written there.
std::vector<std::string> Listing(const std::string& dir) {
  std::vector<std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    files.push_back(entry.path().string() +
                    (entry.is_regular_file() ? " " + std::to_string(entry.file_size()) : ""));
  }
  std::sort(files.begin(), files.end());
  return files;
}

// A one-frame synthetic capture, its COLMAP workspaces (flat images/, sparse/0/ binary; and the
// undistorted dense/0/ layout with a meshed-poisson.ply), and the capture with its cameras.yaml
// holding the cameras as the COLMAP model gives them.
class ColmapWorkspaceTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!HaveColmap()) GTEST_SKIP() << "colmap is not installed: the workspace is not made";
    root_ = MakeTempDir("colmap_workspace");
    const std::string synth = root_ + "/synth";
    GenerateSyntheticCapture(testing_util::TinyRefinableSynthOptions(1), synth);
    const std::vector<Camera> rig = ReadCamerasYaml(synth + "/cameras.yaml");
    WriteColmapTextModelOf(rig, root_ + "/text");
    ConvertToBinary(root_ + "/text", workspace() + "/sparse/0");
    fs::create_directories(workspace() + "/images");
    fs::create_directories(dense() + "/images");
    for (const Camera& camera : rig) {
      const std::string image = synth + "/images/" + camera.name + "/000000.png";
      fs::copy_file(image, workspace() + "/images/" + camera.name + ".png");
      fs::copy_file(image, dense() + "/images/" + camera.name + ".png");
    }
    fs::copy(workspace() + "/sparse/0", dense() + "/sparse");
    fs::copy_file(mesh(), dense() + "/meshed-poisson.ply");

    // The reference: the synthetic capture with the model's cameras, which differ from the
    // synthetic ones by the rounding of the quaternion (R within 1e-14).
    const std::vector<Camera> colmap_rig = ReadColmapBinaryModel(workspace() + "/sparse/0").cameras;
    ASSERT_EQ(colmap_rig.size(), rig.size());
    for (size_t c = 0; c < rig.size(); ++c) {
      EXPECT_EQ(colmap_rig[c].name, rig[c].name);
      EXPECT_EQ(colmap_rig[c].K, rig[c].K);
      EXPECT_EQ(colmap_rig[c].t, rig[c].t);
      EXPECT_LT((colmap_rig[c].R - rig[c].R).norm(), 1e-14);
    }
    fs::create_directories(reference());
    fs::copy(synth + "/images", reference() + "/images", fs::copy_options::recursive);
    fs::copy(synth + "/meshes", reference() + "/meshes");
    WriteCamerasYaml(colmap_rig, reference() + "/cameras.yaml");
  }

  std::string workspace() const { return root_ + "/workspace"; }
  std::string dense() const { return root_ + "/workspace_dense/dense/0"; }
  std::string reference() const { return root_ + "/reference"; }
  std::string mesh() const { return root_ + "/synth/meshes/000000.ply"; }

  std::string root_;
};

Config RunConfig(const std::string& capture, const std::string& out) {
  return testing_util::TinyRunConfig(capture, out, 5);
}

TEST_F(ColmapWorkspaceTest, RefinesWithTheSameDisplacementsAsTheCamerasYamlCapture) {
  const testing_util::OneWorkerThread one_thread;  // Byte-equal results from run to run.
  const std::vector<std::string> workspace_files = Listing(workspace());
  const std::vector<std::string> dense_files = Listing(dense());
  ASSERT_EQ(RunRefine(RunConfig(reference(), root_ + "/out_reference")), 0);
  Config flat = RunConfig(workspace(), root_ + "/out_flat");
  flat.capture.mesh = mesh();
  ASSERT_EQ(RunRefine(flat), 0);
  ASSERT_EQ(RunRefine(RunConfig(dense(), root_ + "/out_dense")), 0);

  const std::string k = FileBytes(root_ + "/out_reference/k/000000.txt");
  ASSERT_FALSE(k.empty());
  EXPECT_NE(k.find_first_of("123456789"), std::string::npos) << "nothing was refined";
  EXPECT_EQ(FileBytes(root_ + "/out_flat/k/000000.txt"), k);
  EXPECT_EQ(FileBytes(root_ + "/out_dense/k/meshed-poisson.txt"), k);
  EXPECT_EQ(Listing(workspace()), workspace_files);
  EXPECT_EQ(Listing(dense()), dense_files);
}

TEST_F(ColmapWorkspaceTest, OpensEachLayoutAsOneFrame) {
  Capture flat = Capture::Open(workspace(), mesh());
  EXPECT_EQ(flat.rig_source(), "COLMAP binary model in sparse/0");
  EXPECT_EQ(flat.frame_names(), std::vector<std::string>{"000000"});
  const Capture yaml = Capture::Open(reference());
  ASSERT_EQ(flat.num_cameras(), yaml.num_cameras());
  const Capture undistorted = Capture::Open(dense());
  EXPECT_EQ(undistorted.rig_source(), "COLMAP binary model in sparse");
  EXPECT_EQ(undistorted.frame_names(), std::vector<std::string>{"meshed-poisson"});
  EXPECT_EQ(undistorted.mesh_path(0), dense() + "/meshed-poisson.ply");
  // meshes/ is found as in any capture.
  fs::create_directories(workspace() + "/meshes");
  fs::copy_file(mesh(), workspace() + "/meshes/7.ply");
  EXPECT_EQ(Capture::Open(workspace()).frame_names(), std::vector<std::string>{"7"});
  // The --mesh flag reaches the capture.
  const testing_util::RunResult info =
      testing_util::RunFinecap("info --capture " + dense() + " --mesh " + mesh() + " --threads 1");
  EXPECT_EQ(info.exit_code, 0) << info.output;
  EXPECT_NE(info.output.find("COLMAP binary model in sparse"), std::string::npos) << info.output;
}

// COLMAP's masks of its flat layout, masks/NAME.png for images/NAME, are the capture's masks: each
// camera's reads back as written (foreground where non-zero); a missing one is named.
TEST_F(ColmapWorkspaceTest, ReadsColmapMasksOfFlatImages) {
  const Capture plain = Capture::Open(workspace(), mesh());
  EXPECT_FALSE(plain.has_masks());
  fs::create_directories(workspace() + "/masks");
  std::vector<cv::Mat> written;
  for (int c = 0; c < plain.num_cameras(); ++c) {
    const Camera& camera = plain.cameras()[c];
    cv::Mat mask(camera.height, camera.width, CV_8UC1, cv::Scalar(0));
    mask(cv::Rect(camera.width / 4, camera.height / 4 + c, camera.width / 2, camera.height / 3))
        .setTo(1);  // COLMAP's masks may hold any non-zero value on the subject.
    ASSERT_TRUE(cv::imwrite(workspace() + "/masks/" + camera.name + ".png.png", mask));
    written.push_back(mask);
  }
  Capture masked = Capture::Open(workspace(), mesh());
  ASSERT_TRUE(masked.has_masks());
  for (int c = 0; c < masked.num_cameras(); ++c) {
    SCOPED_TRACE(masked.cameras()[c].name);
    const cv::Mat read = masked.ReadMask(c, 0);
    EXPECT_EQ(cv::countNonZero((read != 0) != (written[c] != 0)), 0);
  }
  fs::remove(workspace() + "/masks/cam01.png.png");
  ExpectErrorMentions([&] { Capture::Open(workspace(), mesh()); },
                      {workspace() + "/masks/cam01.png.png", "mask not found"});
}

TEST_F(ColmapWorkspaceTest, BadWorkspacesNameTheFileAndTheProblem) {
  ExpectErrorMentions([&] { Capture::Open(workspace()); },
                      {workspace() + "/meshes", "mesh folder not found", "--mesh"});
  ExpectErrorMentions([&] { Capture::Open(workspace(), root_ + "/none.ply"); }, {"none.ply"});

  fs::copy_file(mesh(), dense() + "/meshed-delaunay.ply");
  ExpectErrorMentions([&] { Capture::Open(dense()); },
                      {dense(), "meshed-delaunay.ply, meshed-poisson.ply", "--mesh"});

  fs::create_directories(workspace() + "/meshes");
  fs::copy_file(mesh(), workspace() + "/meshes/0.ply");
  fs::copy_file(mesh(), workspace() + "/meshes/1.ply");
  ExpectErrorMentions([&] { Capture::Open(workspace()); },
                      {workspace() + "/images/cam00.png", "one frame", "2 meshes"});

  fs::remove(workspace() + "/images/cam01.png");
  ExpectErrorMentions([&] { Capture::Open(workspace(), mesh()); },
                      {workspace() + "/images/cam01.png", "not found",
                       "COLMAP binary model in sparse/0", "camera cam01"});
}

}  // namespace
}  // namespace finecap
