#include "finecap/config.h"

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "finecap/error.h"

namespace finecap {
namespace {

std::string WriteTempFile(const std::string& name, const std::string& contents) {
  const std::string path = (std::filesystem::path(::testing::TempDir()) / name).string();
  std::ofstream(path) << contents;
  return path;
}

// Runs `load` and returns the Error message; fails the test if nothing is thrown.
template <typename Load>
std::string ErrorMessage(Load load) {
  try {
    load();
  } catch (const Error& error) {
    return error.what();
  }
  ADD_FAILURE() << "expected an Error";
  return "";
}

TEST(ConfigTest, ReadsKeysAndKeepsDefaultsForAbsentOnes) {
  const std::string file = WriteTempFile("good.yaml",
                                         "capture:\n  dir: data/demo\n  frames: '2:5'\n"
                                         "runtime:\n  threads: 3\n");
  const Config config = LoadConfig(file, {});
  EXPECT_EQ(config.capture.dir, "data/demo");
  EXPECT_EQ(config.runtime.threads, 3);
  EXPECT_EQ(config.output.mesh_format, "ply");
  EXPECT_EQ(config.frame_range().begin, 2);
  EXPECT_EQ(config.frame_range().end, 5);
}

TEST(ConfigTest, OverridesWinOverTheFile) {
  const std::string file = WriteTempFile("override.yaml", "runtime:\n  threads: 3\n");
  const Config config = LoadConfig(
      file, {{"runtime.threads", "1", "--threads"}, {"output.mesh_format", "obj", "--set"}});
  EXPECT_EQ(config.runtime.threads, 1);
  EXPECT_EQ(config.output.mesh_format, "obj");
}

TEST(ConfigTest, UnknownKeyNamesFileAndKeyPath) {
  const std::string file = WriteTempFile("unknown.yaml", "runtime:\n  treads: 3\n");
  const std::string message = ErrorMessage([&] { LoadConfig(file, {}); });
  EXPECT_NE(message.find("unknown.yaml"), std::string::npos) << message;
  EXPECT_NE(message.find("runtime.treads"), std::string::npos) << message;
  EXPECT_NE(message.find("unknown key"), std::string::npos) << message;
}

TEST(ConfigTest, UnknownSectionIsRefused) {
  const std::string file = WriteTempFile("section.yaml", "solvr:\n  x: 1\n");
  EXPECT_NE(ErrorMessage([&] { LoadConfig(file, {}); }).find("solvr"), std::string::npos);
}

TEST(ConfigTest, WrongTypeNamesTheKey) {
  const std::string file = WriteTempFile("type.yaml", "runtime:\n  threads: many\n");
  const std::string message = ErrorMessage([&] { LoadConfig(file, {}); });
  EXPECT_NE(message.find("runtime.threads"), std::string::npos) << message;
  EXPECT_NE(message.find("expected an integer, got 'many'"), std::string::npos) << message;
}

TEST(ConfigTest, OutOfRangeValueIsRefused) {
  const std::string file = WriteTempFile("range.yaml", "runtime:\n  threads: -4\n");
  const std::string message = ErrorMessage([&] { LoadConfig(file, {}); });
  EXPECT_NE(message.find("outside [0, 1024]"), std::string::npos) << message;
}

TEST(ConfigTest, UnknownChoiceListsTheChoices) {
  const std::string message = ErrorMessage([] {
    LoadConfig("", {{"output.mesh_format", "stl", "--set"}});
  });
  EXPECT_NE(message.find("--set: key 'output.mesh_format'"), std::string::npos) << message;
  EXPECT_NE(message.find("ply, obj"), std::string::npos) << message;
}

TEST(ConfigTest, MalformedYamlNamesTheLine) {
  const std::string file = WriteTempFile("broken.yaml", "runtime:\n  threads: [1,\n");
  const std::string message = ErrorMessage([&] { LoadConfig(file, {}); });
  EXPECT_NE(message.find("broken.yaml"), std::string::npos) << message;
  EXPECT_NE(message.find("malformed YAML"), std::string::npos) << message;
}

TEST(ConfigTest, MissingFileIsNamed) {
  const std::string message = ErrorMessage([] { LoadConfig("/nonexistent/x.yaml", {}); });
  EXPECT_NE(message.find("/nonexistent/x.yaml"), std::string::npos) << message;
}

TEST(ConfigTest, BadFrameRangeIsRefused) {
  EXPECT_THROW(LoadConfig("", {{"capture.frames", "5:2", "--frames"}}), Error);
  EXPECT_THROW(LoadConfig("", {{"capture.frames", "a:b", "--frames"}}), Error);
  EXPECT_EQ(LoadConfig("", {{"capture.frames", "3:", "--frames"}}).frame_range().begin, 3);
}

TEST(ConfigTest, HelpListsEveryKeyWithItsDefault) {
  Config config;
  const std::string help = MakeConfigSchema(&config).HelpText();
  EXPECT_NE(help.find("output.mesh_format (choice ply, obj, default ply)"), std::string::npos)
      << help;
  EXPECT_NE(help.find("runtime.threads"), std::string::npos);
}

}  // namespace
}  // namespace finecap
