// Inputs that the fuzzers of tests/fuzz found to crash a parser or let an exception other than
// finecap::Error escape, each kept as a string: every one must now be refused with an Error
// naming the file.
#include <string>

#include <gtest/gtest.h>

#include "finecap/config/config.h"
#include "finecap/io/camera_io.h"
#include "test_util.h"

namespace finecap {
namespace {

using testing_util::ExpectErrorMentions;
using testing_util::MakeTempDir;
using testing_util::WriteText;

// OpenCV's YAML parser threw std::length_error on this intri.yml (read with yaml-cpp now, it is
// not a mapping of keys).
TEST(FuzzRegression, IntriYmlThatMadeOpenCvThrowALengthError) {
  const std::string dir = MakeTempDir("fuzz_intri");
  WriteText(dir + "/intri.yml", std::string("%YAML:1.\n   t:d\n   :\x01", 21));
  WriteText(dir + "/extri.yml", "%YAML:1.0\n---\nT_01: 0\n");
  ExpectErrorMentions([&] { ReadIntriExtri(dir + "/intri.yml", dir + "/extri.yml"); },
                      {dir + "/intri.yml", "top level must be a mapping"});
}

// A top level that is a list: OpenCV asserted (cv::Exception) when a key was looked up in it.
TEST(FuzzRegression, IntriYmlWhoseTopLevelIsAList) {
  const std::string dir = MakeTempDir("fuzz_intri_list");
  WriteText(dir + "/intri.yml", "%YAML:1.0\n- 0.\n- 1.\n");
  WriteText(dir + "/extri.yml", "%YAML:1.0\n---\nT_01: 0\n");
  ExpectErrorMentions([&] { ReadIntriExtri(dir + "/intri.yml", dir + "/extri.yml"); },
                      {dir + "/intri.yml", "top level must be a mapping"});
}

// A damaged `cols` made OpenCV allocate 17 GB for K before reading its nine numbers.
TEST(FuzzRegression, IntriYmlWithADamagedMatrixSize) {
  const std::string dir = MakeTempDir("fuzz_intri_size");
  WriteText(dir + "/intri.yml",
            "%YAML:1.0\n---\nnames: [\"01\"]\nK_01: !!opencv-matrix\n   rows: 3\n   cols:\xa0"
            "5\n   dt: d\n   data: [ 60., 0., 31.5, 0., 60., 23.5, 0., 0., 1. ]\n");
  WriteText(dir + "/extri.yml", "%YAML:1.0\n---\nT_01: 0\n");
  ExpectErrorMentions([&] { ReadIntriExtri(dir + "/intri.yml", dir + "/extri.yml"); },
                      {dir + "/intri.yml", "malformed OpenCV YAML file"});
  WriteText(dir + "/intri.yml",
            "%YAML:1.0\n---\nnames: [\"01\"]\nK_01: !!opencv-matrix\n   rows: 3\n   cols: "
            "300000\n   dt: d\n   data: [ 60., 0., 31.5, 0., 60., 23.5, 0., 0., 1. ]\n");
  ExpectErrorMentions([&] { ReadIntriExtri(dir + "/intri.yml", dir + "/extri.yml"); },
                      {dir + "/intri.yml", "K_01", "3x300000", "at most 16"});
}

// OpenCV 4.6's YAML parser looped forever on this intri.yml: it read the NUL byte as the end of its
// buffer. A text file with a NUL byte is damaged, and is refused as such.
TEST(FuzzRegression, IntriYmlWithANulByteThatMadeOpenCvLoopForever) {
  const std::string dir = MakeTempDir("fuzz_intri_nul");
  std::string bytes = "%YAML:1.\xd8";  // a literal of its own: "\xd8AML" would be one escape
  bytes += "AML:1.$";
  bytes += '\0';
  bytes += "\n\n -\"\"\n_0\n-";
  WriteText(dir + "/intri.yml", bytes);
  WriteText(dir + "/extri.yml", "%YAML:1.0\n---\nT_01: 0\n");
  ExpectErrorMentions([&] { ReadIntriExtri(dir + "/intri.yml", dir + "/extri.yml"); },
                      {dir + "/intri.yml", "NUL byte at offset 16"});
}

// OpenCV 4.6's YAML parser never returned on these 20 plain ASCII bytes either: intri/extri files
// are read with yaml-cpp since.
TEST(FuzzRegression, IntriYmlThatMadeOpenCvLoopForeverWithoutANulByte) {
  const std::string dir = MakeTempDir("fuzz_intri_loop");
  WriteText(dir + "/intri.yml", "%YAML:1.\n  -\"\"\n,  -\n");
  WriteText(dir + "/extri.yml", "%YAML:1.0\n---\nT_01: 0\n");
  ExpectErrorMentions([&] { ReadIntriExtri(dir + "/intri.yml", dir + "/extri.yml"); },
                      {dir + "/intri.yml", "top level must be a mapping"});
}

// A camera name with bytes that are not UTF-8 and a control character read, but came back
// different from a round trip through WriteCamerasYaml: such names are refused.
TEST(FuzzRegression, CameraNamesThatAreNotPrintableUtf8) {
  const std::string dir = MakeTempDir("fuzz_camera_name");
  const std::string camera =
      "    width: 64\n    height: 47\n    K: [60, 0, 31.5, 0, 60, 23.5, 0, 0, 1]\n"
      "    R: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n    t: [0, 0, 3]\n";
  for (const std::string& name : {std::string("cam0k\xff\xff\xff\x0bk"), std::string("a\tb"),
                                  std::string("../up"), std::string("\xed\xa0\x80")}) {
    WriteText(dir + "/cameras.yaml", "cameras:\n  - name: \"" + name + "\"\n" + camera);
    ExpectErrorMentions([&] { ReadCamerasYaml(dir + "/cameras.yaml"); },
                        {dir + "/cameras.yaml", "printable UTF-8"});
  }
  WriteText(dir + "/cameras.yaml", "cameras:\n  - name: \"caméra 1\"\n" + camera);
  EXPECT_EQ(ReadCamerasYaml(dir + "/cameras.yaml").at(0).name, "caméra 1");
}

// YAML allows a list or a mapping as a key; yaml-cpp's conversion of it to a string threw
// YAML::TypedBadConversion past our parsers.
TEST(FuzzRegression, YamlKeysThatAreListsOrMappings) {
  const std::string dir = MakeTempDir("fuzz_yaml_keys");
  WriteText(dir + "/top.yaml", "? [a, b]\n: 1\n");
  ExpectErrorMentions([&] { LoadConfig(dir + "/top.yaml", {}); },
                      {dir + "/top.yaml", "a key must be a name", "line 1"});
  WriteText(dir + "/section.yaml", "model: {? [x] : 1}\n");
  ExpectErrorMentions([&] { LoadConfig(dir + "/section.yaml", {}); },
                      {dir + "/section.yaml", "model....", "a key must be a name"});
  WriteText(dir + "/camera.yaml", "cameras:\n  - name: a\n    ? [x]\n    : 1\n");
  ExpectErrorMentions([&] { ReadCamerasYaml(dir + "/camera.yaml"); },
                      {dir + "/camera.yaml", "camera #0", "a key must be a name", "line 3"});
  WriteText(dir + "/rig.yaml", "cameras: [1]\n? [x]\n: 1\n");
  ExpectErrorMentions([&] { ReadCamerasYaml(dir + "/rig.yaml"); },
                      {dir + "/rig.yaml", "a key must be a name", "line 2"});
}

}  // namespace
}  // namespace finecap
