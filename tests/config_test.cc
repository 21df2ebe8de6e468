#include "finecap/config/config.h"

#include <filesystem>
#include <fstream>
#include <set>

#include <gtest/gtest.h>

#include "finecap/util/error.h"

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

TEST(ConfigTest, SubdivisionSchemeIsAChoiceOfLoopAndButterfly) {
  EXPECT_EQ(LoadConfig("", {}).refine.subdivision, SubdivisionScheme::kLoop);
  const std::string file = WriteTempFile("butterfly.yaml", "model:\n  subdivision: butterfly\n");
  EXPECT_EQ(LoadConfig(file, {}).refine.subdivision, SubdivisionScheme::kButterfly);
  EXPECT_EQ(LoadConfig("", {{"model.subdivision", "loop", "--set"}}).refine.subdivision,
            SubdivisionScheme::kLoop);
  const std::string message = ErrorMessage([] {
    LoadConfig("", {{"model.subdivision", "catmull_clark", "--set"}});
  });
  EXPECT_NE(message.find("model.subdivision"), std::string::npos) << message;
  EXPECT_NE(message.find("loop, butterfly"), std::string::npos) << message;
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

TEST(ConfigTest, SceneLengthsAreAutoUnlessSetAndASetValueWins) {
  const Config defaults = LoadConfig("", {});
  EXPECT_TRUE(defaults.refine.scene_lengths.sigma_hat);
  EXPECT_TRUE(defaults.refine.scene_lengths.k_max);
  EXPECT_TRUE(defaults.refine.scene_lengths.depth_tolerance);
  EXPECT_TRUE(defaults.refine.scene_lengths.initial_step);
  EXPECT_TRUE(defaults.refine.scene_lengths.max_step);

  // A file that sets a length keeps it, as before; the others stay auto.
  const std::string file =
      WriteTempFile("lengths.yaml", "model:\n  sigma_hat: 0.004\nenergy:\n  k_max: auto\n");
  const Config from_file = LoadConfig(file, {});
  EXPECT_FALSE(from_file.refine.scene_lengths.sigma_hat);
  EXPECT_DOUBLE_EQ(from_file.refine.sigma_hat, 0.004);
  EXPECT_TRUE(from_file.refine.scene_lengths.k_max);
  EXPECT_TRUE(from_file.refine.scene_lengths.depth_tolerance);

  // --set wins over the file, both ways.
  const Config overridden =
      LoadConfig(file, {{"model.sigma_hat", "auto", "--set"}, {"energy.k_max", "0.03", "--set"}});
  EXPECT_TRUE(overridden.refine.scene_lengths.sigma_hat);
  EXPECT_FALSE(overridden.refine.scene_lengths.k_max);
  EXPECT_DOUBLE_EQ(overridden.refine.energy.k_max, 0.03);

  Config config;
  const ConfigSchema schema = MakeConfigSchema(&config);
  EXPECT_EQ(schema.ValueText("model.sigma_hat"), "auto");
  EXPECT_NE(schema.HelpText().find("model.sigma_hat (float [1e-05, 1] or auto, default auto)"),
            std::string::npos)
      << schema.HelpText();
}

TEST(ConfigTest, ASceneLengthThatIsNeitherANumberNorAutoIsRefused) {
  const std::string message = ErrorMessage([] {
    LoadConfig("", {{"energy.k_max", "automatic", "--set"}});
  });
  EXPECT_NE(message.find("energy.k_max"), std::string::npos) << message;
  EXPECT_NE(message.find("a number or auto"), std::string::npos) << message;
  const std::string range = ErrorMessage([] {
    LoadConfig("", {{"model.sigma_hat", "2", "--set"}});
  });
  EXPECT_NE(range.find("outside [1e-05, 1]"), std::string::npos) << range;
}

TEST(ConfigTest, HelpListsEveryKeyWithItsDefault) {
  Config config;
  const std::string help = MakeConfigSchema(&config).HelpText();
  EXPECT_NE(help.find("output.mesh_format (choice ply, obj, default ply)"), std::string::npos)
      << help;
  EXPECT_NE(help.find("runtime.threads"), std::string::npos);
}

// Every config the repository ships loads as it is, and so does every variant of the compare
// configs: a key renamed or a range narrowed breaks the files users copy first.
TEST(ConfigTest, EveryShippedConfigAndVariantLoads) {
  const std::filesystem::path configs = std::filesystem::path(FINECAP_SOURCE_DIR) / "configs";
  int num_configs = 0;
  int num_variants = 0;
  for (const auto& entry : std::filesystem::directory_iterator(configs)) {
    if (entry.path().extension() != ".yaml") continue;
    SCOPED_TRACE(entry.path().string());
    Config config;
    ASSERT_NO_THROW(config = LoadConfig(entry.path().string(), {}));
    ++num_configs;
    for (const CompareVariant& variant : config.compare.variants) {
      SCOPED_TRACE(variant.name);
      EXPECT_NO_THROW(VariantConfig(config, variant));
      ++num_variants;
    }
  }
  EXPECT_GT(num_configs, 0);
  EXPECT_GT(num_variants, 0);
}

// The side-by-side comparison of the similarities selects each of the three.
TEST(ConfigTest, CompareSimilaritiesSetsAllThree) {
  const std::string file = std::string(FINECAP_SOURCE_DIR) + "/configs/compare_similarities.yaml";
  const Config config = LoadConfig(file, {});
  std::set<SimilarityType> similarities;
  for (const CompareVariant& variant : config.compare.variants) {
    similarities.insert(VariantConfig(config, variant).refine.energy.similarity);
  }
  EXPECT_EQ(similarities.size(), 3u);
}

}  // namespace
}  // namespace finecap
