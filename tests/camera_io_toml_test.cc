// The Calib.toml of Pose2Sim and anipose, and the strict TOML subset it is read with.
#include <cstdio>
#include <filesystem>
#include <random>

#include <gtest/gtest.h>
#include <Eigen/Geometry>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include "finecap/io/camera_io.h"
#include "finecap/io/capture.h"
#include "finecap/synth/synth.h"
#include "finecap/util/error.h"
#include "test_util.h"
#include "tiny_synth.h"

namespace finecap {
namespace {

using testing_util::ExpectErrorMentions;
using testing_util::MakeTempDir;
using testing_util::WriteText;

std::string Number(double value) {
  char text[40];
  std::snprintf(text, sizeof(text), "%.17g", value);
  return text;
}

Eigen::Vector3d RodriguesOf(const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd angle_axis(R);
  return angle_axis.angle() * angle_axis.axis();
}

// A rig of four cameras around the origin, one with the rational and thin-prism models.
std::vector<Camera> FourCameraRig() {
  std::vector<Camera> cameras;
  for (int c = 0; c < 4; ++c) {
    Camera camera;
    camera.name = "cam_" + std::to_string(c + 1);
    camera.width = 1920;
    camera.height = 1080;
    camera.K << 1600.0 + 13.7 * c, 0.0, 959.5 + c, 0.0, 1598.25 - c, 539.5 - 2 * c, 0.0, 0.0, 1.0;
    const double azimuth = 1.3 * c + 0.2;
    camera.R = (Eigen::AngleAxisd(0.1 * c, Eigen::Vector3d::UnitX()) *
                Eigen::AngleAxisd(azimuth, Eigen::Vector3d::UnitY()))
                   .toRotationMatrix();
    camera.t = Eigen::Vector3d(0.05 * c, -0.1, 3.0 + 0.2 * c);
    camera.distortion = {-0.12 + 0.01 * c, 0.03, 0.0007, -0.0004, 0.002 * c};
    if (c == 3) {
      camera.distortion = {-0.1,  0.02,  0.0005, -0.0003, 0.001,  0.05,
                           -0.01, 0.002, 0.0004, -0.0001, 0.0003, 0.0001};
    }
    cameras.push_back(camera);
  }
  return cameras;
}

// A Calib.toml of `cameras` as aniposelib's CameraGroup.dump writes it (the Python toml package:
// trailing commas in arrays, an empty [metadata] table), to 17 digits.
std::string AniposeToml(const std::vector<Camera>& cameras) {
  std::string text;
  for (size_t c = 0; c < cameras.size(); ++c) {
    const Camera& camera = cameras[c];
    const Eigen::Vector3d r = RodriguesOf(camera.R);
    text += "[cam_" + std::to_string(c) + "]\nname = \"" + camera.name + "\"\n";
    text += "size = [ " + std::to_string(camera.width) + ", " + std::to_string(camera.height) +
            ",]\nmatrix = [";
    for (int row = 0; row < 3; ++row) {
      text += " [";
      for (int col = 0; col < 3; ++col) text += " " + Number(camera.K(row, col)) + ",";
      text += "],";
    }
    text += "]\ndistortions = [";
    const size_t count = camera.distortion[5] != 0.0 ? 12 : 5;
    for (size_t i = 0; i < count; ++i) text += " " + Number(camera.distortion[i]) + ",";
    text += "]\nrotation = [ " + Number(r.x()) + ", " + Number(r.y()) + ", " + Number(r.z()) +
            ",]\ntranslation = [ " + Number(camera.t.x()) + ", " + Number(camera.t.y()) + ", " +
            Number(camera.t.z()) + ",]\n\n";
  }
  return text + "[metadata]\n";
}

TEST(CalibTomlTest, FourCamerasProjectAsTheEquivalentCamerasYaml) {
  const std::string dir = MakeTempDir("toml");
  const std::vector<Camera> rig = FourCameraRig();
  WriteText(dir + "/Calib.toml", AniposeToml(rig));
  WriteCamerasYaml(rig, dir + "/cameras.yaml");
  const std::vector<Camera> from_toml = ReadCalibToml(dir + "/Calib.toml");
  const std::vector<Camera> from_yaml = ReadCamerasYaml(dir + "/cameras.yaml");
  ASSERT_EQ(from_toml.size(), 4u);
  ASSERT_EQ(from_yaml.size(), 4u);

  std::mt19937 rng(3);
  std::uniform_real_distribution<double> coordinate(-0.6, 0.6);
  double worst_px = 0.0;
  int projected = 0;
  for (size_t c = 0; c < rig.size(); ++c) {
    EXPECT_EQ(from_toml[c].name, rig[c].name);
    EXPECT_EQ(from_toml[c].width, 1920);
    EXPECT_EQ(from_toml[c].height, 1080);
    EXPECT_EQ(from_toml[c].distortion, rig[c].distortion);
    for (int i = 0; i < 2000; ++i) {
      const Eigen::Vector3d point(coordinate(rng), coordinate(rng), coordinate(rng));
      if (from_yaml[c].Depth(point) < 0.5) continue;
      worst_px =
          std::max(worst_px, (from_toml[c].Project(point) - from_yaml[c].Project(point)).norm());
      ++projected;
    }
  }
  EXPECT_GT(projected, 4000);
  EXPECT_LT(worst_px, 1e-6);
}

// As Pose2Sim's calibration writes it: sections named after the cameras, the size as floats,
// four distortion coefficients, fisheye = false, translations in metres, [metadata].
TEST(CalibTomlTest, ReadsPose2SimOutput) {
  const std::string path = MakeTempDir("toml") + "/Calib_board.toml";
  WriteText(path,
            "[cam_01]\n"
            "name = \"cam_01\"\n"
            "size = [ 1920.0, 1080.0]\n"
            "matrix = [ [ 1677.0186, 0.0, 959.5], [ 0.0, 1677.0186, 539.5], [ 0.0, 0.0, 1.0]]\n"
            "distortions = [ -0.0283, 0.1432, -0.0012, 0.0005]\n"
            "rotation = [ 1.2114, -1.1818, 1.2114]\n"
            "translation = [ 0.2563, 1.0811, 3.8764]\n"
            "fisheye = false\n"
            "\n"
            "[cam_02]\n"
            "name = \"cam_02\"\n"
            "size = [ 1920.0, 1080.0]\n"
            "matrix = [ [ 1700.5, 0.0, 950.25], [ 0.0, 1701.5, 545.75], [ 0.0, 0.0, 1.0]]\n"
            "distortions = [ -0.03, 0.12, 0.0, 0.0]\n"
            "rotation = [ 0.0, 0.0, 0.0]\n"
            "translation = [ -1.0, 0.0, 4.0]\n"
            "fisheye = false\n"
            "\n"
            "[metadata]\n"
            "adjusted = false\n"
            "error = 0.0\n");
  const std::vector<Camera> cameras = ReadCalibToml(path);
  ASSERT_EQ(cameras.size(), 2u);
  const Camera& camera = cameras[0];
  EXPECT_EQ(camera.name, "cam_01");
  EXPECT_EQ(camera.width, 1920);
  EXPECT_EQ(camera.height, 1080);
  EXPECT_EQ(camera.K(0, 0), 1677.0186);
  EXPECT_EQ(camera.K(0, 2), 959.5);  // OpenCV's principal point: finecap's convention.
  EXPECT_EQ(camera.K(1, 2), 539.5);
  EXPECT_EQ(camera.distortion[0], -0.0283);
  EXPECT_EQ(camera.distortion[3], 0.0005);
  EXPECT_EQ(camera.distortion[4], 0.0);
  EXPECT_EQ(camera.t, Eigen::Vector3d(0.2563, 1.0811, 3.8764));
  cv::Mat R;
  cv::Rodrigues(cv::Mat(cv::Vec3d(1.2114, -1.1818, 1.2114)), R);  // OpenCV's rvec convention.
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(camera.R(r, c), R.at<double>(r, c), 1e-14);
  }
  EXPECT_EQ(cameras[1].R, Eigen::Matrix3d::Identity());
}

// The other Pose2Sim writer (its converters): [cam_1] sections with trailing commas, and a
// comment line before a section.
TEST(CalibTomlTest, ReadsPose2SimConverterOutput) {
  const std::string path = MakeTempDir("toml") + "/Calib_qualisys.toml";
  WriteText(path,
            "# WARNING: Camera 2 has default/placeholder extrinsic calibration\r\n"
            "[cam_1]\r\n"
            "name = \"1\"\r\n"
            "size = [ 1088, 1920,]\r\n"
            "matrix = [ [ 1397.0, 0.0, 543.5,], [ 0.0, 1397.0, 959.5,], [ 0.0, 0.0, 1.0,],]\r\n"
            "distortions = [ 0.0, 0.0, 0.0, 0.0,]\r\n"
            "rotation = [ -0.3, 2.2e-05, 1.1,]  # Rodrigues\r\n"
            "translation = [ 1.5, -0.25, 6,]\r\n"
            "fisheye = false\r\n");
  const std::vector<Camera> cameras = ReadCalibToml(path);
  ASSERT_EQ(cameras.size(), 1u);
  EXPECT_EQ(cameras[0].name, "1");
  EXPECT_EQ(cameras[0].width, 1088);
  EXPECT_EQ(cameras[0].height, 1920);
  EXPECT_EQ(cameras[0].t.z(), 6.0);
}

TEST(CalibTomlTest, MetadataStatesTheUnitAndAMillimetreRigIsRefusedWithout) {
  const std::string dir = MakeTempDir("toml");
  std::vector<Camera> rig = FourCameraRig();
  for (Camera& camera : rig) camera.t *= 1000.0;
  const std::string toml = AniposeToml(rig);
  WriteText(dir + "/calibration.toml", toml);
  ExpectErrorMentions([&] { ReadCalibToml(dir + "/calibration.toml"); },
                      {"calibration.toml", "units = \"mm\"", "[metadata]"});
  WriteText(dir + "/calibration.toml", toml + "units = \"mm\"\n");
  const std::vector<Camera> cameras = ReadCalibToml(dir + "/calibration.toml");
  EXPECT_NEAR((cameras[2].t - FourCameraRig()[2].t).norm(), 0.0, 1e-12);
  WriteText(dir + "/calibration.toml", toml + "units = \"inch\"\n");
  ExpectErrorMentions([&] { ReadCalibToml(dir + "/calibration.toml"); },
                      {"[metadata]", "'units'", "\"inch\""});
}

TEST(CalibTomlTest, ReadRigFindsItAndRefusesTwo) {
  const std::string dir = MakeTempDir("toml");
  WriteText(dir + "/Config.toml", "[project]\nframe_rate = 60\n");  // Pose2Sim's, not a rig.
  WriteText(dir + "/Calib.toml", AniposeToml(FourCameraRig()));
  const Rig rig = ReadRig(dir);
  EXPECT_EQ(rig.cameras.size(), 4u);
  EXPECT_EQ(rig.source, "Calib.toml (Pose2Sim/anipose)");
  const std::string freemocap = MakeTempDir("toml");
  WriteText(freemocap + "/take1_camera_calibration.toml", AniposeToml(FourCameraRig()));
  EXPECT_EQ(ReadRig(freemocap).cameras.size(), 4u);
  WriteText(dir + "/calib_old.TOML", AniposeToml(FourCameraRig()));
  ExpectErrorMentions([&] { ReadRig(dir); },
                      {dir, "Calib.toml", "calib_old.TOML", "more than one"});
}

// A synthetic capture whose cameras.yaml is replaced by the equivalent Calib.toml opens with the
// same cameras.
TEST(CalibTomlTest, CaptureOpensWithACalibTomlInsteadOfCamerasYaml) {
  const std::string dir = MakeTempDir("toml_capture");
  GenerateSyntheticCapture(testing_util::TinySynthOptions(), dir);
  const std::vector<Camera> rig = ReadCamerasYaml(dir + "/cameras.yaml");
  WriteText(dir + "/Calib.toml", AniposeToml(rig));
  std::filesystem::remove(dir + "/cameras.yaml");
  const Capture capture = Capture::Open(dir);
  ASSERT_EQ(capture.num_cameras(), static_cast<int>(rig.size()));
  for (size_t c = 0; c < rig.size(); ++c) {
    EXPECT_EQ(capture.cameras()[c].name, rig[c].name);
    const Eigen::Vector3d point(0.05, -0.1, 0.02);
    EXPECT_LT((capture.cameras()[c].Project(point) - rig[c].Project(point)).norm(), 1e-9);
  }
}

struct BadTomlCase {
  const char* label;
  std::string contents;
  std::vector<std::string> expected_parts;  // Besides the file name.
};
void PrintTo(const BadTomlCase& c, std::ostream* os) { *os << c.label; }

// A valid camera table with `extra` appended and `replace` (key = value lines) in place of the
// lines with the same keys.
std::string CameraTable(const std::string& extra = "") {
  return "[cam_1]\nname = \"c1\"\nsize = [ 640, 480]\n"
         "matrix = [ [ 500.0, 0.0, 319.5], [ 0.0, 500.0, 239.5], [ 0.0, 0.0, 1.0]]\n"
         "distortions = [ 0.0, 0.0, 0.0, 0.0]\nrotation = [ 0.0, 0.0, 0.0]\n"
         "translation = [ 0.0, 0.0, 2.0]\n" +
         extra;
}

std::string WithLine(const std::string& key, const std::string& line) {
  std::string table = CameraTable();
  const size_t start = table.find("\n" + key + " = ") + 1;
  const size_t end = table.find('\n', start);
  return table.replace(start, end - start, line);
}

class BadCalibTomlTest : public ::testing::TestWithParam<BadTomlCase> {};

TEST_P(BadCalibTomlTest, ErrorNamesFileLineAndProblem) {
  const std::string path = MakeTempDir("bad_toml") + "/Calib.toml";
  WriteText(path, GetParam().contents);
  std::vector<std::string> parts = GetParam().expected_parts;
  parts.push_back(path);
  ExpectErrorMentions([&] { ReadCalibToml(path); }, parts);
}

INSTANTIATE_TEST_SUITE_P(
    Cases, BadCalibTomlTest,
    ::testing::Values(
        BadTomlCase{"Empty", "", {"no camera table"}},
        BadTomlCase{"UnknownKey",
                    CameraTable("focal = 500.0\n"),
                    {"line 8", "[cam_1]", "'focal'",
                     "unknown key; allowed: name, size, matrix, "
                     "distortions, rotation, translation, fisheye"}},
        BadTomlCase{"MissingKey",
                    WithLine("rotation", "# no rotation"),
                    {"[cam_1]", "'rotation'", "missing key"}},
        BadTomlCase{"RotationMatrix",
                    WithLine("rotation", "rotation = [ [ 1, 0, 0], [ 0, 1, 0], [ 0, 0, 1]]"),
                    {"line 6", "'rotation'", "found an array"}},
        BadTomlCase{"FlatMatrix",
                    WithLine("matrix", "matrix = [ 500, 0, 320, 0, 500, 240, 0, 0, 1]"),
                    {"line 4", "'matrix'", "3 rows of 3 numbers"}},
        BadTomlCase{"FractionalSize",
                    WithLine("size", "size = [ 640.5, 480]"),
                    {"line 3", "'size'", "whole numbers"}},
        BadTomlCase{"ThreeDistortions",
                    WithLine("distortions", "distortions = [ 0.1, 0.0, 0.0]"),
                    {"'distortions'", "4, 5, 8, 12 or 14", "not 3"}},
        BadTomlCase{"Fisheye",
                    CameraTable("fisheye = true\n"),
                    {"'fisheye'", "fisheye (Kannala-Brandt) lens model is not supported"}},
        BadTomlCase{"StringNumber",
                    WithLine("translation", "translation = [ \"0\", 0, 2]"),
                    {"line 7", "'translation'", "found a string"}},
        BadTomlCase{"KeyOutsideTable",
                    "version = 1\n" + CameraTable(),
                    {"line 1", "'version'", "outside any table"}},
        BadTomlCase{"DuplicateKey",
                    CameraTable("name = \"again\"\n"),
                    {"line 8", "key 'name' appears twice"}},
        BadTomlCase{"DuplicateTable",
                    CameraTable() + CameraTable(),
                    {"line 8", "table [cam_1] appears twice"}},
        BadTomlCase{"DuplicateName",
                    CameraTable() + "[cam_2]\nname = \"c1\"\nsize = [ 640, 480]\n"
                                    "matrix = [ [ 500.0, 0.0, 319.5], [ 0.0, 500.0, 239.5], "
                                    "[ 0.0, 0.0, 1.0]]\nrotation = [ 0.0, 0.0, 0.0]\n"
                                    "translation = [ 0.0, 0.0, 2.0]\n",
                    {"camera name 'c1' appears twice"}},
        BadTomlCase{"UnterminatedArray",
                    WithLine("size", "size = [ 640, 480"),
                    {"line 4", "expected ',' or ']'"}},
        BadTomlCase{"UnterminatedString",
                    WithLine("name", "name = \"c1"),
                    {"line 2", "unterminated string"}},
        BadTomlCase{"InlineTable",
                    WithLine("size", "size = { w = 640, h = 480 }"),
                    {"line 3", "inline tables"}},
        BadTomlCase{"DottedKey", CameraTable("lens.model = \"x\"\n"), {"line 8", "dotted keys"}},
        BadTomlCase{"ArrayOfTables", "[[cameras]]\nname = \"c\"\n", {"line 1", "arrays of tables"}},
        BadTomlCase{"HexNumber",
                    WithLine("size", "size = [ 0x280, 480]"),
                    {"line 3", "'0x280'", "hexadecimal"}},
        BadTomlCase{"LeadingZero", WithLine("size", "size = [ 0640, 480]"), {"line 3", "'0640'"}},
        BadTomlCase{"NonRotation",
                    WithLine("rotation", "rotation = [ nan, 0.0, 0.0]"),
                    {"camera 'c1'", "non-finite"}},
        BadTomlCase{"NotAName", WithLine("name", "name = \"a/b\""), {"'a/b'", "without '/'"}},
        BadTomlCase{"DeepArray",
                    WithLine("size", "size = " + std::string(20, '[')),
                    {"line 3", "nested more than 8 deep"}},
        BadTomlCase{"NulByte",
                    WithLine("name", std::string("name = \"c\0\"", 11)),
                    {"line 2", "control character 0"}},
        BadTomlCase{
            "BadEscape", WithLine("name", "name = \"c\\q\""), {"line 2", "unknown escape"}}),
    [](const ::testing::TestParamInfo<BadTomlCase>& info) { return info.param.label; });

TEST(CalibTomlTest, StringsAndNumbersFollowTheTomlSpecification) {
  const std::string path = MakeTempDir("toml") + "/Calib.toml";
  WriteText(path,
            "[\"cam one\"]\n"
            "name = 'lit\"eral'  # a literal string: no escapes\n"
            "size = [\n  1_920,  # width\n  1080,\n]\n"
            "matrix = [ [ 1.6e3, 0, 959.5], [ 0, +1600, 539.5], [ 0, 0, 1]]\n"
            "rotation = [ -0.0, 0E0, 0.0]\n"
            "translation = [ 0.5, -1e-1, 3]\n"
            "[other]\n"
            "name = \"caf\\u00e9\\t2\"\n"
            "size = [ 16, 16]\n"
            "matrix = [ [ 10, 0, 7.5], [ 0, 10, 7.5], [ 0, 0, 1]]\n"
            "rotation = [ 0, 0, 0]\ntranslation = [ 0, 0, 1]\n");
  ExpectErrorMentions([&] { ReadCalibToml(path); }, {"printable"});  // A tab in a name.
  WriteText(path, testing_util::FileBytes(path).replace(testing_util::FileBytes(path).find("\\t2"),
                                                        3, "\\u00e92"));
  const std::vector<Camera> cameras = ReadCalibToml(path);
  ASSERT_EQ(cameras.size(), 2u);
  EXPECT_EQ(cameras[0].name, "lit\"eral");
  EXPECT_EQ(cameras[0].width, 1920);
  EXPECT_EQ(cameras[0].K(0, 0), 1600.0);
  EXPECT_EQ(cameras[0].K(1, 1), 1600.0);
  EXPECT_EQ(cameras[0].t.y(), -0.1);
  EXPECT_EQ(cameras[1].name,
            "caf\xc3\xa9\xc3\xa9"
            "2");
}

}  // namespace
}  // namespace finecap
