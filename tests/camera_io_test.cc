#include "finecap/io/camera_io.h"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <sstream>

#include <gtest/gtest.h>
#include <Eigen/Geometry>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include "finecap/util/error.h"
#include "test_util.h"

namespace finecap {
namespace {

using testing_util::ExpectErrorMentions;
using testing_util::MakeTempDir;
using testing_util::WriteText;

Camera MakeCamera(const std::string& name, double angle) {
  Camera camera;
  camera.name = name;
  camera.width = 1004;
  camera.height = 1002;
  camera.K << 1234.5678901234567, 0.25, 501.123456789, 0.0, 1180.0000000001, 498.7, 0.0, 0.0, 1.0;
  camera.R =
      Eigen::AngleAxisd(angle, Eigen::Vector3d(0.2, 1.0, -0.1).normalized()).toRotationMatrix();
  camera.t = Eigen::Vector3d(0.1 / 3.0, -0.2, 3.0 + 1e-13);
  camera.distortion = {-0.21, 0.08, 0.001 / 7.0, -0.002, 0.01};
  return camera;
}

void ExpectSameCamera(const Camera& expected, const Camera& actual) {
  EXPECT_EQ(expected.name, actual.name);
  EXPECT_EQ(expected.width, actual.width);
  EXPECT_EQ(expected.height, actual.height);
  EXPECT_EQ(expected.K, actual.K);
  EXPECT_EQ(expected.R, actual.R);
  EXPECT_EQ(expected.t, actual.t);
  EXPECT_EQ(expected.distortion, actual.distortion);
}

// ---------------------------------------------------------------------------------------------
// cameras.yaml

TEST(CamerasYamlTest, RoundTripIsBitExact) {
  const std::string path = MakeTempDir("yaml") + "/cameras.yaml";
  const std::vector<Camera> cameras = {MakeCamera("cam0", 0.3), MakeCamera("cam 1: side", -2.1)};
  WriteCamerasYaml(cameras, path);
  const std::vector<Camera> read = ReadCamerasYaml(path);
  ASSERT_EQ(read.size(), 2u);
  for (size_t i = 0; i < read.size(); ++i) ExpectSameCamera(cameras[i], read[i]);
}

TEST(CamerasYamlTest, WrittenFileStatesTheConvention) {
  const std::string path = MakeTempDir("yaml") + "/cameras.yaml";
  WriteCamerasYaml({MakeCamera("cam0", 0.3)}, path);
  std::ifstream stream(path);
  std::string first_line;
  std::getline(stream, first_line);
  EXPECT_EQ(first_line.rfind("#", 0), 0u);
  const std::string contents = first_line + std::string(std::istreambuf_iterator<char>(stream), {});
  EXPECT_NE(contents.find("x_cam = R * X + t"), std::string::npos);
  EXPECT_NE(contents.find("metres"), std::string::npos);
  EXPECT_NE(contents.find("(0, 0)"), std::string::npos);
}

TEST(CamerasYamlTest, DistortionIsOptional) {
  const std::string path = MakeTempDir("yaml") + "/cameras.yaml";
  WriteText(path,
            "cameras:\n"
            "  - name: cam0\n    width: 640\n    height: 480\n"
            "    K: [500, 0, 320, 0, 510, 240, 0, 0, 1]\n"
            "    R: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n    t: [0, 0, 2.5]\n");
  const std::vector<Camera> cameras = ReadCamerasYaml(path);
  ASSERT_EQ(cameras.size(), 1u);
  EXPECT_FALSE(cameras[0].HasDistortion());
  EXPECT_EQ(cameras[0].K(1, 1), 510.0);
  EXPECT_EQ(cameras[0].t.z(), 2.5);
}

std::string CameraEntry(const std::string& name, const std::string& r, const std::string& extra) {
  return "  - name: " + name + "\n    width: 640\n    height: 480\n" +
         "    K: [500, 0, 320, 0, 500, 240, 0, 0, 1]\n    R: " + r + "\n    t: [0, 0, 2]\n" + extra;
}

const std::string kIdentity = "[1, 0, 0, 0, 1, 0, 0, 0, 1]";

TEST(CamerasYamlTest, RationalAndThinPrismDistortionRoundTrip) {
  const std::string path = MakeTempDir("yaml") + "/cameras.yaml";
  Camera rational = MakeCamera("rational", 0.3);
  rational.distortion = {-0.2, 0.07, 0.001, -0.002, 0.01, 0.03, -0.01, 0.004};
  Camera prism = MakeCamera("prism", -0.4);
  prism.distortion[10] = 0.0003;
  WriteCamerasYaml({rational, prism, MakeCamera("plain", 1.0)}, path);
  const std::string text = testing_util::FileBytes(path);
  // As OpenCV counts them: 8 for the rational model, 12 with thin prism, else 5.
  EXPECT_NE(text.find("distortion: [-0.20000000000000001, 0.070000000000000007, 0.001, -0.002, "
                      "0.01, 0.029999999999999999, -0.01, 0.0040000000000000001]"),
            std::string::npos)
      << text;
  const std::vector<Camera> read = ReadCamerasYaml(path);
  ASSERT_EQ(read.size(), 3u);
  ExpectSameCamera(rational, read[0]);
  ExpectSameCamera(prism, read[1]);
  ExpectSameCamera(MakeCamera("plain", 1.0), read[2]);
}

TEST(CamerasYamlTest, FourDistortionCoefficientsAreK1K2P1P2) {
  const std::string path = MakeTempDir("yaml") + "/cameras.yaml";
  WriteText(path, "cameras:\n" + CameraEntry("cam0", kIdentity,
                                             "    distortion: [-0.1, 0.02, 0.001, 0.002]\n"));
  const std::array<double, 12> expected = {-0.1, 0.02, 0.001, 0.002};
  EXPECT_EQ(ReadCamerasYaml(path).at(0).distortion, expected);
}

// A rotation written to 6 significant digits, as a published calibration's is (orthonormal to
// about 1.4e-6): read as the nearest rotation, with one warning for the whole file.
TEST(CamerasYamlTest, RoundedRotationIsMadeExactWithOneWarning) {
  const std::string path = MakeTempDir("yaml") + "/cameras.yaml";
  std::string cameras = "cameras:\n";
  const Eigen::Matrix3d exact =
      Eigen::AngleAxisd(0.9, Eigen::Vector3d(0.2, 1.0, -0.4).normalized()).toRotationMatrix();
  std::string rounded = "[";
  for (int i = 0; i < 9; ++i) {
    char number[32];
    std::snprintf(number, sizeof(number), "%.6g", exact(i / 3, i % 3));
    rounded += std::string(i ? ", " : "") + number;
  }
  rounded += "]";
  for (const char* name : {"a", "b", "c"}) cameras += CameraEntry(name, rounded, "");
  WriteText(path, cameras);
  ::testing::internal::CaptureStderr();
  const std::vector<Camera> read = ReadCamerasYaml(path);
  const std::string warnings = ::testing::internal::GetCapturedStderr();
  ASSERT_EQ(read.size(), 3u);
  for (const Camera& camera : read) {
    EXPECT_LT((camera.R.transpose() * camera.R - Eigen::Matrix3d::Identity()).norm(), 1e-14);
    EXPECT_LT((camera.R - exact).norm(), 5e-6);
  }
  EXPECT_EQ(std::count(warnings.begin(), warnings.end(), '\n'), 1) << warnings;
  EXPECT_NE(warnings.find(path), std::string::npos) << warnings;
  EXPECT_NE(warnings.find("3 cameras"), std::string::npos) << warnings;
  EXPECT_NE(warnings.find("nearest rotation"), std::string::npos) << warnings;
}

TEST(CamerasYamlTest, WriterRefusesAnInvalidCameraAndLeavesNoFile) {
  const std::string dir = MakeTempDir("yaml");
  Camera camera = MakeCamera("cam0", 0.3);
  camera.R(0, 0) = 5.0;
  ExpectErrorMentions([&] { WriteCamerasYaml({camera}, dir + "/cameras.yaml"); },
                      {"cameras.yaml", "cam0", "rotation"});
  EXPECT_TRUE(std::filesystem::is_empty(dir));
}

struct BadYamlCase {
  const char* label;
  std::string contents;
  std::vector<std::string> expected_parts;  // Besides the file name.
};
void PrintTo(const BadYamlCase& c, std::ostream* os) { *os << c.label; }

class BadCamerasYamlTest : public ::testing::TestWithParam<BadYamlCase> {};

TEST_P(BadCamerasYamlTest, ErrorNamesFileAndProblem) {
  const std::string path = MakeTempDir("bad_yaml") + "/cameras.yaml";
  WriteText(path, GetParam().contents);
  std::vector<std::string> parts = GetParam().expected_parts;
  parts.push_back(path);
  ExpectErrorMentions([&] { ReadCamerasYaml(path); }, parts);
}

INSTANTIATE_TEST_SUITE_P(
    Cases, BadCamerasYamlTest,
    ::testing::Values(
        BadYamlCase{"Malformed", "cameras: [ {name: cam0, width: 640\n", {"malformed YAML"}},
        BadYamlCase{"NoCameras", "rig: []\n", {"missing key 'cameras'"}},
        BadYamlCase{"UnknownTopLevelKey",
                    "cameras:\n" + CameraEntry("cam0", kIdentity, "") + "units: mm\n",
                    {"unknown top-level key 'units'"}},
        BadYamlCase{
            "UnknownKey",
            "cameras:\n" + CameraEntry("cam0", kIdentity, "    focal: 500\n"),
            {"cam0", "'focal'", "unknown key; allowed: name, width, height, K, R, t, distortion"}},
        BadYamlCase{"MissingKey",
                    "cameras:\n  - name: cam0\n    width: 640\n    height: 480\n"
                    "    R: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n    t: [0, 0, 2]\n",
                    {"cam0", "'K'", "missing key"}},
        BadYamlCase{
            "WrongType",
            "cameras:\n" + CameraEntry("cam0", kIdentity, "    distortion: [a, 0, 0, 0, 0]\n"),
            {"cam0", "'distortion'", "must be a number"}},
        BadYamlCase{"ThreeDistortionCoefficients",
                    "cameras:\n" + CameraEntry("cam0", kIdentity, "    distortion: [0.1, 0, 0]\n"),
                    {"cam0", "'distortion'", "4, 5, 8, 12 or 14 coefficients", "not 3"}},
        BadYamlCase{"TiltedSensor",
                    "cameras:\n" + CameraEntry("cam0", kIdentity,
                                               "    distortion: [0.1, 0, 0, 0, 0, 0, 0, 0, 0, 0, "
                                               "0, 0, 0.01, 0]\n"),
                    {"cam0", "'distortion'", "tauX, tauY"}},
        BadYamlCase{"ShearedR",
                    "cameras:\n" + CameraEntry("cam0", "[1, 0.01, 0, 0, 1, 0, 0, 0, 1]", ""),
                    {"cam0", "not a rotation", "||R^T R - I||"}},
        BadYamlCase{"FractionalWidth",
                    "cameras:\n  - name: cam0\n    width: 640.5\n    height: 480\n"
                    "    K: [500, 0, 320, 0, 500, 240, 0, 0, 1]\n"
                    "    R: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n    t: [0, 0, 2]\n",
                    {"cam0", "'width'", "must be an integer"}},
        BadYamlCase{"WrongLength",
                    "cameras:\n" + CameraEntry("cam0", "[1, 0, 0, 0, 1, 0]", ""),
                    {"cam0", "'R'", "list of 9 numbers"}},
        BadYamlCase{
            "DuplicateName",
            "cameras:\n" + CameraEntry("cam0", kIdentity, "") + CameraEntry("cam0", kIdentity, ""),
            {"cam0", "appears twice"}},
        BadYamlCase{"SingularR",
                    "cameras:\n" + CameraEntry("cam0", "[0, 0, 0, 0, 0, 0, 0, 0, 0]", ""),
                    {"cam0", "not a rotation"}},
        BadYamlCase{"NonRotationR",
                    "cameras:\n" + CameraEntry("cam0", "[2, 0, 0, 0, 1, 0, 0, 0, 1]", ""),
                    {"cam0", "not a rotation"}},
        BadYamlCase{"ReflectionR",
                    "cameras:\n" + CameraEntry("cam0", "[-1, 0, 0, 0, 1, 0, 0, 0, 1]", ""),
                    {"cam0", "not a rotation"}}),
    [](const ::testing::TestParamInfo<BadYamlCase>& info) { return info.param.label; });

TEST(CamerasYamlTest, MissingFileIsNamed) {
  const std::string path = MakeTempDir("yaml") + "/cameras.yaml";
  ExpectErrorMentions([&] { ReadCamerasYaml(path); }, {path, "not found"});
}

// ---------------------------------------------------------------------------------------------
// COLMAP text model

// COLMAP's own projection of a camera-space point for each supported model, written from COLMAP's
// model definitions; pixel centres at +0.5.
Eigen::Vector2d ColmapProject(const std::string& model, const std::vector<double>& p,
                              const Eigen::Vector3d& camera_point) {
  const double x = camera_point.x() / camera_point.z();
  const double y = camera_point.y() / camera_point.z();
  const double r2 = x * x + y * y;
  double fx = p[0], fy = p[0], cx = p[1], cy = p[2];
  double xd = x, yd = y;
  const bool two_focals = model == "PINHOLE" || model == "OPENCV" || model == "FULL_OPENCV";
  if (two_focals) fy = p[1], cx = p[2], cy = p[3];
  if (model == "SIMPLE_RADIAL") xd = x * (1 + p[3] * r2), yd = y * (1 + p[3] * r2);
  if (model == "RADIAL") {
    const double radial = 1 + p[3] * r2 + p[4] * r2 * r2;
    xd = x * radial, yd = y * radial;
  }
  if (model == "OPENCV") {
    const double k1 = p[4], k2 = p[5], p1 = p[6], p2 = p[7];
    const double radial = 1 + k1 * r2 + k2 * r2 * r2;
    xd = x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x);
    yd = y * radial + 2 * p2 * x * y + p1 * (r2 + 2 * y * y);
  }
  if (model == "FULL_OPENCV") {
    const double k1 = p[4], k2 = p[5], p1 = p[6], p2 = p[7];
    const double k3 = p[8], k4 = p[9], k5 = p[10], k6 = p[11];
    const double r4 = r2 * r2, r6 = r4 * r2;
    const double radial = (1 + k1 * r2 + k2 * r4 + k3 * r6) / (1 + k4 * r2 + k5 * r4 + k6 * r6);
    xd = x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x);
    yd = y * radial + 2 * p2 * x * y + p1 * (r2 + 2 * y * y);
  }
  return Eigen::Vector2d(fx * xd + cx, fy * yd + cy);
}

struct ColmapModelCase {
  std::string model;
  std::vector<double> params;
};
void PrintTo(const ColmapModelCase& c, std::ostream* os) { *os << c.model; }

class ColmapModelTest : public ::testing::TestWithParam<ColmapModelCase> {};

TEST_P(ColmapModelTest, ProjectsLikeColmapShiftedByHalfAPixel) {
  const ColmapModelCase& c = GetParam();
  const std::string dir = MakeTempDir("colmap");
  std::ostringstream params;
  params.precision(17);
  for (double value : c.params) params << " " << value;
  WriteText(dir + "/cameras.txt", "# Camera list\n7 " + c.model + " 800 600" + params.str() + "\n");
  const Eigen::Quaterniond q =
      Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()));
  const Eigen::Vector3d t(0.1, -0.3, 4.0);
  std::ostringstream images;
  images.precision(17);
  images << "# Image list\n\n3 " << q.w() << " " << q.x() << " " << q.y() << " " << q.z() << " "
         << t.x() << " " << t.y() << " " << t.z() << " 7 rig/cam03/000000.jpg\n"
         << "10.5 20.5 -1 30.5 40.5 12\n";
  WriteText(dir + "/images.txt", images.str());

  const std::vector<Camera> cameras = ReadColmapTextModel(dir).cameras;
  ASSERT_EQ(cameras.size(), 1u);
  EXPECT_EQ(cameras[0].name, "cam03");
  EXPECT_EQ(cameras[0].width, 800);
  EXPECT_EQ(cameras[0].height, 600);
  for (const Eigen::Vector3d& point :
       {Eigen::Vector3d(0.2, -0.1, 0.3), Eigen::Vector3d(-0.5, 0.4, -0.2),
        Eigen::Vector3d(0, 0, 0)}) {
    const Eigen::Vector2d colmap = ColmapProject(c.model, c.params, q * point + t);
    const Eigen::Vector2d ours = cameras[0].Project(point);
    EXPECT_NEAR(ours.x(), colmap.x() - 0.5, 1e-9) << c.model;
    EXPECT_NEAR(ours.y(), colmap.y() - 0.5, 1e-9) << c.model;
  }
}

INSTANTIATE_TEST_SUITE_P(
    Models, ColmapModelTest,
    ::testing::Values(ColmapModelCase{"SIMPLE_PINHOLE", {700, 401, 299}},
                      ColmapModelCase{"PINHOLE", {700, 710, 401, 299}},
                      ColmapModelCase{"SIMPLE_RADIAL", {700, 401, 299, -0.12}},
                      ColmapModelCase{"RADIAL", {700, 401, 299, -0.12, 0.03}},
                      ColmapModelCase{"OPENCV", {700, 710, 401, 299, -0.12, 0.03, 0.002, -0.001}},
                      ColmapModelCase{"FULL_OPENCV",
                                      {700, 710, 401, 299, -0.12, 0.03, 0.002, -0.001, 0.004, 0.05,
                                       -0.01, 0.002}}),
    [](const ::testing::TestParamInfo<ColmapModelCase>& info) { return info.param.model; });

// Runs `command` with sh; its output goes to `log`. True when it exits 0.
bool RunCommand(const std::string& command, const std::string& log) {
  return std::system((command + " > '" + log + "' 2>&1").c_str()) == 0;
}

// A model made from known cameras (OPENCV, PINHOLE, SIMPLE_RADIAL and RADIAL intrinsics, one
// posed image each), converted by COLMAP itself to its binary model and back to text; what COLMAP
// wrote is read and must give the known cameras.
TEST(ColmapTextModelTest, ReadsWhatColmapItselfWrote) {
  if (std::system("command -v colmap > /dev/null 2>&1") != 0) {
    GTEST_SKIP() << "colmap is not installed (Debian: apt-get install colmap, which "
                    "scripts/install-deps.sh does): the COLMAP-written model is not tested";
  }
  const std::string dir = MakeTempDir("colmap_tool");
  struct Known {
    std::string model;
    std::vector<double> params;
    Camera camera;
  };
  std::vector<Known> known = {
      {"OPENCV", {1234.5, 1236.25, 640.5, 360.25, -0.12, 0.034, 0.0011, -0.0007}, {}},
      {"PINHOLE", {900.0, 905.5, 512.0, 384.0}, {}},
      {"SIMPLE_RADIAL", {1500.75, 960.0, 540.0, -0.05}, {}},
      {"RADIAL", {1111.0, 700.5, 400.5, 0.02, -0.003}, {}}};
  std::ostringstream cameras_txt, images_txt;
  cameras_txt.precision(17);
  images_txt.precision(17);
  for (size_t i = 0; i < known.size(); ++i) {
    const int id = static_cast<int>(i) + 1;
    Camera& camera = known[i].camera;
    camera.name = "cam" + std::to_string(i);
    camera.width = 1280 + 10 * id;
    camera.height = 720 + 10 * id;
    // finecap's camera by hand from COLMAP's model definitions: pixel centres at +0.5 there.
    const std::vector<double>& p = known[i].params;
    const bool one_focal = known[i].model == "SIMPLE_RADIAL" || known[i].model == "RADIAL";
    const size_t c = one_focal ? 1 : 2;
    camera.K << p[0], 0.0, p[c] - 0.5, 0.0, one_focal ? p[0] : p[1], p[c + 1] - 0.5, 0.0, 0.0, 1.0;
    if (known[i].model == "OPENCV") camera.distortion = {p[4], p[5], p[6], p[7]};
    if (known[i].model == "SIMPLE_RADIAL") camera.distortion = {p[3]};
    if (known[i].model == "RADIAL") camera.distortion = {p[3], p[4]};
    const Eigen::Quaterniond q(
        Eigen::AngleAxisd(0.3 + 0.9 * id, Eigen::Vector3d(0.1 * id, 1.0, -0.2).normalized()));
    camera.R = q.toRotationMatrix();
    camera.t = Eigen::Vector3d(0.1 * id, -0.25, 3.0 + 0.5 * id);
    cameras_txt << id << " " << known[i].model << " " << camera.width << " " << camera.height;
    for (double value : p) cameras_txt << " " << value;
    cameras_txt << "\n";
    images_txt << id << " " << q.w() << " " << q.x() << " " << q.y() << " " << q.z() << " "
               << camera.t.x() << " " << camera.t.y() << " " << camera.t.z() << " " << id << " "
               << camera.name << "/000000.png\n\n";
  }
  WriteText(dir + "/text/cameras.txt", cameras_txt.str());
  WriteText(dir + "/text/images.txt", images_txt.str());
  WriteText(dir + "/text/points3D.txt", "");
  std::filesystem::create_directories(dir + "/binary");
  std::filesystem::create_directories(dir + "/colmap");
  const std::string log = dir + "/colmap.log";
  ASSERT_TRUE(RunCommand("colmap model_converter --input_path " + dir + "/text --output_path " +
                             dir + "/binary --output_type BIN",
                         log))
      << testing_util::FileBytes(log);
  ASSERT_TRUE(RunCommand("colmap model_converter --input_path " + dir + "/binary --output_path " +
                             dir + "/colmap --output_type TXT",
                         log))
      << testing_util::FileBytes(log);
  const std::string written = testing_util::FileBytes(dir + "/colmap/cameras.txt");
  ASSERT_NE(written.find("# Camera list"), std::string::npos) << "not COLMAP's own header";

  const std::vector<Camera> cameras = ReadColmapTextModel(dir + "/colmap").cameras;
  ASSERT_EQ(cameras.size(), known.size());
  for (size_t i = 0; i < known.size(); ++i) {
    const Camera& expected = known[i].camera;
    EXPECT_EQ(cameras[i].name, expected.name);
    EXPECT_EQ(cameras[i].width, expected.width);
    EXPECT_EQ(cameras[i].height, expected.height);
    EXPECT_LT((cameras[i].K - expected.K).norm(), 1e-9) << known[i].model;
    EXPECT_LT((cameras[i].R - expected.R).norm(), 1e-14) << known[i].model;
    EXPECT_LT((cameras[i].t - expected.t).norm(), 1e-14) << known[i].model;
    EXPECT_EQ(cameras[i].distortion, expected.distortion) << known[i].model;
    const Eigen::Vector3d point(0.2, -0.1, 0.3);
    EXPECT_LT((cameras[i].Project(point) - expected.Project(point)).norm(), 1e-9);
  }
}

TEST(ColmapTextModelTest, NamesCamerasAndTakesTheSmallestImageIdPerCamera) {
  const std::string dir = MakeTempDir("colmap");
  WriteText(dir + "/cameras.txt",
            "1 PINHOLE 640 480 500 500 320 240\n2 PINHOLE 640 480 600 600 320 240\n");
  WriteText(dir + "/images.txt",
            "# two lines per image\n"
            "5 1 0 0 0 9 9 9 1 cam1/000001.png\n\n"
            "2 1 0 0 0 0 0 1 2 side.png\n"
            "\n"
            "4 1 0 0 0 0 0 2 1 cam1/000000.png\n"
            "1.0 2.0 -1\n");
  const ColmapModel model = ReadColmapTextModel(dir);
  EXPECT_EQ(model.image_names, (std::vector<std::string>{"side.png", "cam1/000000.png"}));
  const std::vector<Camera>& cameras = model.cameras;
  ASSERT_EQ(cameras.size(), 2u);
  EXPECT_EQ(cameras[0].name, "side");
  EXPECT_EQ(cameras[0].fx(), 600.0);
  EXPECT_EQ(cameras[1].name, "cam1");
  EXPECT_EQ(cameras[1].t, Eigen::Vector3d(0, 0, 2));  // IMAGE_ID 4, not 5.
  EXPECT_EQ(cameras[1].K(0, 2), 319.5);
}

TEST(ColmapTextModelTest, BadInputsNameTheFileAndProblem) {
  const std::string dir = MakeTempDir("colmap");
  const std::string good_images = "1 1 0 0 0 0 0 1 1 cam0.png\n\n";
  WriteText(dir + "/images.txt", good_images);
  WriteText(dir + "/cameras.txt", "1 OPENCV_FISHEYE 640 480 1 1 1 1 0 0 0 0\n");
  ExpectErrorMentions([&] { ReadColmapTextModel(dir); },
                      {"cameras.txt line 1", "unsupported camera model 'OPENCV_FISHEYE'"});
  WriteText(dir + "/cameras.txt", "# header\n1 PINHOLE 640 480 500 500 320\n");
  ExpectErrorMentions([&] { ReadColmapTextModel(dir); },
                      {"cameras.txt line 2", "takes 4 parameters, not 3"});
  WriteText(dir + "/cameras.txt", "2 PINHOLE 640 480 500 500 320 240\n");
  ExpectErrorMentions([&] { ReadColmapTextModel(dir); }, {"images.txt", "CAMERA_ID 1"});
  WriteText(dir + "/cameras.txt", "1 PINHOLE 640 480 500 500 320 240\n");
  WriteText(dir + "/images.txt", "1 2 0 0 0 0 0 1 1 cam0.png\n\n");
  ExpectErrorMentions([&] { ReadColmapTextModel(dir); }, {"images.txt line 1", "unit length"});
  std::filesystem::remove(dir + "/images.txt");
  ExpectErrorMentions([&] { ReadColmapTextModel(dir); }, {"images.txt", "not found"});
}

// ---------------------------------------------------------------------------------------------
// intri.yml / extri.yml

cv::Mat ToCv(const Eigen::Matrix3d& matrix) {
  cv::Mat result(3, 3, CV_64F);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) result.at<double>(r, c) = matrix(r, c);
  return result;
}

// Writes a two-camera rig as EasyMocap does: cam0 with a Rodrigues R_ and its size, cam1 with a
// Rot_ matrix, a 4x1 distortion and no size.
void WriteIntriExtri(const std::string& dir, const Camera& cam0, const Camera& cam1) {
  cv::FileStorage intri(dir + "/intri.yml", cv::FileStorage::WRITE);
  intri << "names" << std::vector<std::string>{cam0.name, cam1.name};
  intri << "K_" + cam0.name << ToCv(cam0.K);
  intri << "dist_" + cam0.name
        << cv::Mat(1, 5, CV_64F, const_cast<double*>(cam0.distortion.data()));
  intri << "H_" + cam0.name << cam0.height << "W_" + cam0.name << cam0.width;
  intri << "K_" + cam1.name << ToCv(cam1.K);
  intri << "dist_" + cam1.name
        << cv::Mat(4, 1, CV_64F, const_cast<double*>(cam1.distortion.data()));
  intri.release();
  cv::FileStorage extri(dir + "/extri.yml", cv::FileStorage::WRITE);
  cv::Mat rvec;
  cv::Rodrigues(ToCv(cam0.R), rvec);
  extri << "names" << std::vector<std::string>{cam0.name, cam1.name};
  extri << "R_" + cam0.name << rvec;
  extri << "T_" + cam0.name << (cv::Mat_<double>(3, 1) << cam0.t.x(), cam0.t.y(), cam0.t.z());
  extri << "Rot_" + cam1.name << ToCv(cam1.R);
  extri << "T_" + cam1.name << (cv::Mat_<double>(3, 1) << cam1.t.x(), cam1.t.y(), cam1.t.z());
}

TEST(IntriExtriTest, ReadsWhatFileStorageWrote) {
  const std::string dir = MakeTempDir("intri");
  const Camera cam0 = MakeCamera("01", 0.3);
  Camera cam1 = MakeCamera("02", -1.0);
  cam1.distortion[4] = 0.0;  // Only four coefficients are stored.
  WriteIntriExtri(dir, cam0, cam1);

  const std::vector<Camera> cameras = ReadIntriExtri(dir + "/intri.yml", dir + "/extri.yml");
  ASSERT_EQ(cameras.size(), 2u);
  EXPECT_EQ(cameras[0].name, "01");
  EXPECT_EQ(cameras[0].width, cam0.width);
  EXPECT_EQ(cameras[0].height, cam0.height);
  EXPECT_EQ(cameras[0].K, cam0.K);
  EXPECT_LT((cameras[0].R - cam0.R).norm(), 1e-12);  // Through a rotation vector.
  EXPECT_EQ(cameras[0].t, cam0.t);
  EXPECT_EQ(cameras[0].distortion, cam0.distortion);
  EXPECT_EQ(cameras[1].width, 0);  // No H_/W_: taken from the first image later.
  EXPECT_EQ(cameras[1].height, 0);
  EXPECT_EQ(cameras[1].R, cam1.R);
  EXPECT_EQ(cameras[1].distortion, cam1.distortion);
}

TEST(IntriExtriTest, BadInputsNameTheFileAndKey) {
  const std::string dir = MakeTempDir("intri");
  Camera cam1 = MakeCamera("cam1", -1.0);
  cam1.R(1, 1) = 3.0;
  WriteIntriExtri(dir, MakeCamera("cam0", 0.3), cam1);
  ExpectErrorMentions([&] { ReadIntriExtri(dir + "/intri.yml", dir + "/extri.yml"); },
                      {"extri.yml", "cam1", "not a rotation"});
  ExpectErrorMentions([&] { ReadIntriExtri(dir + "/intri.yml", dir + "/missing.yml"); },
                      {"missing.yml", "not found"});
  WriteText(dir + "/bad.yml", "%YAML:1.0\n---\nnames: [cam0\nK_cam0: !!opencv-matrix {\n");
  ExpectErrorMentions([&] { ReadIntriExtri(dir + "/bad.yml", dir + "/extri.yml"); },
                      {"bad.yml", "malformed"});
  WriteText(dir + "/nok.yml", "%YAML:1.0\n---\nnames: [cam0]\n");
  ExpectErrorMentions([&] { ReadIntriExtri(dir + "/nok.yml", dir + "/extri.yml"); },
                      {"nok.yml", "K_cam0", "missing key"});
}

// ---------------------------------------------------------------------------------------------
// ReadRig

TEST(ReadRigTest, FindsEachFormat) {
  const std::string yaml_dir = MakeTempDir("rig");
  WriteCamerasYaml({MakeCamera("cam0", 0.3)}, yaml_dir + "/cameras.yaml");
  EXPECT_EQ(ReadRig(yaml_dir).cameras.at(0).name, "cam0");

  const std::string intri_dir = MakeTempDir("rig");
  WriteIntriExtri(intri_dir, MakeCamera("a", 0.3), MakeCamera("b", 0.1));
  EXPECT_EQ(ReadRig(intri_dir).cameras.size(), 2u);

  const std::string colmap_dir = MakeTempDir("rig");
  WriteText(colmap_dir + "/sparse/0/cameras.txt", "1 PINHOLE 640 480 500 500 320 240\n");
  WriteText(colmap_dir + "/sparse/0/images.txt", "1 1 0 0 0 0 0 1 1 c/0.png\n\n");
  const Rig colmap = ReadRig(colmap_dir);
  EXPECT_EQ(colmap.cameras.at(0).name, "c");
  EXPECT_EQ(colmap.source, "COLMAP text model in sparse/0");
  EXPECT_EQ(colmap.colmap_images, std::vector<std::string>{colmap_dir + "/images/c/0.png"});

  const std::string empty_dir = MakeTempDir("rig");
  ExpectErrorMentions([&] { ReadRig(empty_dir); }, {empty_dir, "no camera rig found"});
  ExpectErrorMentions([&] { ReadRig(empty_dir + "/nowhere"); }, {"nowhere", "not found"});
}

}  // namespace
}  // namespace finecap
