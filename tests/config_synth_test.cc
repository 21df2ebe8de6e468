// The `synth` section of the config: the presets in configs/ load and reach SynthOptions, and bad
// values are refused with an Error naming the file and the key.
#include <algorithm>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "finecap/config/config.h"
#include "finecap/util/error.h"
#include "test_util.h"

namespace finecap {
namespace {

using testing_util::ExpectErrorMentions;

// Expects `--set key=value` to be refused with an Error naming the override, the key and `parts`.
void ExpectSetRefused(const std::string& key, const std::string& value,
                      std::vector<std::string> parts) {
  parts.insert(parts.begin(), "--set: key '" + key);
  ExpectErrorMentions([&] { LoadConfig("", {{key, value, "--set"}}); }, parts);
}

std::vector<std::string> SynthPresets() {
  std::vector<std::string> presets;
  const std::filesystem::path configs = std::filesystem::path(FINECAP_SOURCE_DIR) / "configs";
  for (const auto& entry : std::filesystem::directory_iterator(configs)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("synth_", 0) == 0 && entry.path().extension() == ".yaml") {
      presets.push_back(entry.path().string());
    }
  }
  std::sort(presets.begin(), presets.end());
  return presets;
}

// Leaf key paths of a YAML mapping ("synth.cameras.count"), read without the schema.
void CollectLeafPaths(const YAML::Node& node, const std::string& prefix,
                      std::set<std::string>* paths) {
  for (const auto& entry : node) {
    const std::string path = prefix + entry.first.as<std::string>();
    if (entry.second.IsMap()) {
      CollectLeafPaths(entry.second, path + ".", paths);
    } else {
      paths->insert(path);
    }
  }
}

// The key paths HelpText lists, in order: each key's first line is "  <path> (<type> ...".
std::vector<std::string> HelpPaths(const std::string& help) {
  std::vector<std::string> paths;
  std::istringstream lines(help);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("  ", 0) == 0 && line[2] != ' ')
      paths.push_back(line.substr(2, line.find(' ', 2) - 2));
  }
  return paths;
}

std::string WriteConfig(const std::string& name, const std::string& contents) {
  const std::string path = testing_util::MakeTempDir("config_synth") + "/" + name;
  testing_util::WriteText(path, contents);
  return path;
}

TEST(ConfigSynthTest, ThereArePresets) { EXPECT_GE(SynthPresets().size(), 8u); }

TEST(ConfigSynthTest, EveryPresetLoadsAndItsValuesReachSynthOptions) {
  for (const std::string& preset : SynthPresets()) {
    SCOPED_TRACE(preset);
    const YAML::Node file = YAML::LoadFile(preset)["synth"];
    const SynthOptions synth = LoadConfig(preset, {}).synth;
    EXPECT_EQ(synth.num_frames, file["num_frames"].as<int>());
    EXPECT_EQ(synth.cameras.count, file["cameras"]["count"].as<int>());
    EXPECT_EQ(synth.skirt.around, file["skirt"]["around"].as<int>());
    EXPECT_EQ(synth.single_wavelength, file["single_wavelength"].as<double>());
    EXPECT_EQ(synth.misalignment, file["misalignment"].as<double>());
    EXPECT_EQ(synth.texture.textureless_end, file["texture"]["textureless_end"].as<double>());
    EXPECT_EQ(synth.render.noise_sigma, file["render"]["noise_sigma"].as<double>());
    EXPECT_EQ(synth.seed, file["seed"].as<std::uint64_t>());
    const YAML::Node folds = file["folds"];
    ASSERT_EQ(synth.folds.size(), folds.size());
    for (size_t i = 0; i < folds.size(); ++i) {
      EXPECT_EQ(synth.folds[i].wavelength, folds[i]["wavelength"].as<double>());
      EXPECT_EQ(synth.folds[i].amplitude, folds[i]["amplitude"].as<double>());
      EXPECT_EQ(EnumToString(synth.folds[i].profile), folds[i]["profile"].as<std::string>());
    }
    const YAML::Node distortion = file["cameras"]["distortion"];
    ASSERT_EQ(distortion.size(), 5u);
    for (int i = 0; i < 5; ++i) EXPECT_EQ(synth.cameras.distortion[i], distortion[i].as<double>());
    EXPECT_EQ(synth.render.background.x(), file["render"]["background"][0].as<double>());
  }
}

TEST(ConfigSynthTest, PresetValuesMatchTheirFiles) {
  const std::string configs = std::string(FINECAP_SOURCE_DIR) + "/configs/";
  const SynthOptions demo = LoadConfig(configs + "synth_demo.yaml", {}).synth;
  EXPECT_EQ(demo.cameras.count, 8);
  EXPECT_EQ(demo.fold_ramp_frames, 0);
  EXPECT_EQ(demo.cameras.width, 512);
  EXPECT_EQ(demo.truth_refinement, 3);
  ASSERT_EQ(demo.folds.size(), 4u);
  EXPECT_EQ(demo.folds[1].profile, FoldProfile::kRidge);
  EXPECT_EQ(demo.folds[2].wavelength, 0.08);
  EXPECT_EQ(demo.folds[2].orientation, -15.0);
  EXPECT_EQ(demo.folds[2].phase, 200.0);
  EXPECT_EQ(demo.folds[2].drift, 9.0);
  EXPECT_EQ(demo.texture.width, 1024);
  EXPECT_EQ(demo.render.supersampling, 2);

  const SynthOptions fold = LoadConfig(configs + "synth_fold_3cm.yaml", {}).synth;
  ASSERT_EQ(fold.folds.size(), 1u);
  EXPECT_EQ(fold.folds[0].wavelength, 0.03);
  EXPECT_EQ(fold.folds[0].orientation, 90.0);
  EXPECT_EQ(fold.single_wavelength, 0.0);

  const SynthOptions noisy = LoadConfig(configs + "synth_noisy.yaml", {}).synth;
  EXPECT_EQ(noisy.cameras.distortion[0], -0.12);
  EXPECT_EQ(noisy.cameras.distortion[3], -0.0003);
  EXPECT_EQ(noisy.cameras.rotation_noise, 0.03);
  EXPECT_EQ(noisy.misalignment, 0.004);
  EXPECT_EQ(noisy.render.noise_sigma, 3.0);

  const SynthOptions plain = LoadConfig(configs + "synth_textureless.yaml", {}).synth;
  EXPECT_EQ(plain.texture.textureless_begin, 0.3);
  EXPECT_EQ(plain.texture.textureless_end, 0.6);
  EXPECT_EQ(plain.texture.textureless_color, Eigen::Vector3d(0.62, 0.55, 0.48));
}

// A real capture's reference frame is as coarse as any other, so the presets put folds in frame 0;
// only the variants named *_ramp grow them from zero (an exact reference frame).
TEST(ConfigSynthTest, OnlyRampVariantsRampTheFolds) {
  int ramped = 0;
  for (const std::string& preset : SynthPresets()) {
    SCOPED_TRACE(preset);
    const std::string name = std::filesystem::path(preset).stem().string();
    const bool named_ramped = name.size() > 5 && name.compare(name.size() - 5, 5, "_ramp") == 0;
    const SynthOptions synth = LoadConfig(preset, {}).synth;
    EXPECT_EQ(synth.fold_ramp_frames > 0, named_ramped);
    ramped += named_ramped;
  }
  EXPECT_GE(ramped, 1);  // synth_skirt_ramp at least.
  const std::string configs = std::string(FINECAP_SOURCE_DIR) + "/configs/";
  EXPECT_EQ(LoadConfig(configs + "synth_skirt_ramp.yaml", {}).synth.fold_ramp_frames, 3);
  const SynthOptions smoothed = LoadConfig(configs + "synth_skirt_smoothed.yaml", {}).synth;
  EXPECT_EQ(smoothed.coarse, CoarseInput::kSmoothed);
  EXPECT_EQ(smoothed.fold_ramp_frames, 0);
  EXPECT_EQ(LoadConfig(configs + "synth_skirt.yaml", {}).synth.coarse, CoarseInput::kUnfolded);
  const SynthOptions exact = LoadConfig(configs + "synth_skirt_exact.yaml", {}).synth;
  EXPECT_EQ(exact.coarse, CoarseInput::kExact);
  EXPECT_EQ(exact.fold_ramp_frames, 0);
}

TEST(ConfigSynthTest, CoarseInputAndSmoothingKeys) {
  const Config config = LoadConfig("", {{"synth.coarse", "smoothed", "--set"},
                                        {"synth.smoothing.iterations", "25", "--set"},
                                        {"synth.smoothing.lambda", "0.6307", "--set"},
                                        {"synth.smoothing.mu", "-0.6732", "--set"}});
  EXPECT_EQ(config.synth.coarse, CoarseInput::kSmoothed);
  EXPECT_EQ(config.synth.smoothing.iterations, 25);
  EXPECT_EQ(config.synth.smoothing.lambda, 0.6307);
  EXPECT_EQ(config.synth.smoothing.mu, -0.6732);
  Config defaults;
  EXPECT_EQ(MakeConfigSchema(&defaults).ValueText("synth.coarse"), "unfolded");
  EXPECT_EQ(defaults.synth.coarse, CoarseInput::kUnfolded);
}

TEST(ConfigSynthTest, SmoothingStrengthOutOfRangeIsOneErrorNamingTheKey) {
  ExpectSetRefused("synth.coarse", "blurred", {"unfolded, smoothed, exact"});
  ExpectSetRefused("synth.smoothing.iterations", "0", {"outside [1, 100000]"});
  ExpectSetRefused("synth.smoothing.iterations", "2.5", {"expected an integer"});
  ExpectSetRefused("synth.smoothing.lambda", "0", {"outside [0.001, 1]"});
  ExpectSetRefused("synth.smoothing.mu", "0.5", {"outside [-1, 0]"});
  // Each in range, together unstable: named by the config and the key.
  ExpectErrorMentions(
      [] {
        LoadConfig("", {{"synth.smoothing.lambda", "0.95", "--set"},
                        {"synth.smoothing.mu", "-1", "--set"}});
      },
      {"synth.smoothing.mu", "unstable"});
  const std::string file =
      WriteConfig("smoothing.yaml", "synth:\n  smoothing:\n    iterations: -1\n");
  ExpectErrorMentions([&] { LoadConfig(file, {}); },
                      {"smoothing.yaml", "synth.smoothing.iterations", "outside [1, 100000]"});
}

TEST(ConfigSynthTest, PresetsSetExactlyTheSchemaKeys) {
  Config config;
  const std::vector<std::string> listed = HelpPaths(MakeConfigSchema(&config).HelpText("synth."));
  const std::set<std::string> schema_keys(listed.begin(), listed.end());
  for (const std::string& preset : SynthPresets()) {
    std::set<std::string> preset_keys;
    CollectLeafPaths(YAML::LoadFile(preset), "", &preset_keys);
    EXPECT_EQ(preset_keys, schema_keys) << preset;
  }
}

TEST(ConfigSynthTest, HelpListsEverySynthKeyOnceWithADoc) {
  Config config;
  const std::string help = MakeConfigSchema(&config).HelpText("synth.");
  const std::vector<std::string> listed = HelpPaths(help);
  EXPECT_EQ(listed.size(), 54u) << help;
  EXPECT_EQ(std::set<std::string>(listed.begin(), listed.end()).size(), listed.size()) << help;
  for (const char* key : {"synth.folds", "synth.seed", "synth.cameras.distortion",
                          "synth.render.noise_seed", "synth.texture.textureless_color"}) {
    EXPECT_EQ(std::count(listed.begin(), listed.end(), key), 1) << key;
  }
  EXPECT_NE(help.find("synth.texture.pattern (choice mixed, plaid, stripes, print, noise, default "
                      "mixed)"),
            std::string::npos)
      << help;
  EXPECT_NE(help.find("synth.cameras.distortion (list of 5 floats [-10, 10], default "
                      "[0, 0, 0, 0, 0])"),
            std::string::npos)
      << help;
  // Every key has a documentation line under it.
  std::istringstream lines(help);
  int docs = 0;
  for (std::string line; std::getline(lines, line);) docs += line.rfind("      ", 0) == 0;
  EXPECT_EQ(docs, static_cast<int>(listed.size()));
}

TEST(ConfigSynthTest, SetOverridesASynthKey) {
  EXPECT_EQ(LoadConfig("", {{"synth.cameras.count", "3", "--set"}}).synth.cameras.count, 3);
  const Config config = LoadConfig(
      "", {{"synth.seed", "18446744073709551615", "--set"},
           {"synth.cameras.distortion", "[-0.1, 0.02, 0, 0, 0.001]", "--set"},
           {"synth.render.background", "[1, 0.5, 0]", "--set"},
           {"synth.folds", "[{wavelength: 0.05, profile: ridge}, {amplitude: -0.002}]", "--set"}});
  EXPECT_EQ(config.synth.seed, 18446744073709551615u);
  EXPECT_EQ(config.synth.cameras.distortion[0], -0.1);
  EXPECT_EQ(config.synth.cameras.distortion[4], 0.001);
  EXPECT_EQ(config.synth.render.background, Eigen::Vector3d(1.0, 0.5, 0.0));
  ASSERT_EQ(config.synth.folds.size(), 2u);
  EXPECT_EQ(config.synth.folds[0].wavelength, 0.05);
  EXPECT_EQ(config.synth.folds[0].profile, FoldProfile::kRidge);
  // Keys a fold leaves out keep FoldComponent's defaults.
  EXPECT_EQ(config.synth.folds[0].amplitude, FoldComponent().amplitude);
  EXPECT_EQ(config.synth.folds[1].amplitude, -0.002);
  EXPECT_EQ(config.synth.folds[1].drift, FoldComponent().drift);
}

TEST(ConfigSynthTest, FoldsPrintAsFlowYaml) {
  Config config;
  ConfigSchema schema = MakeConfigSchema(&config);
  schema.Set("synth.folds",
             "[{amplitude: 0.01, wavelength: 0.05, orientation: 90, drift: -2.5, profile: ridge}]",
             "--set");
  EXPECT_EQ(schema.ValueText("synth.folds"),
            "[{amplitude: 0.01, wavelength: 0.05, orientation: 90, phase: 0, drift: -2.5, "
            "profile: ridge}]");
  schema.Set("synth.folds", "[]", "--set");
  EXPECT_EQ(schema.ValueText("synth.folds"), "[]");
}

TEST(ConfigSynthTest, EveryValuePrintsAsYamlThatReadsBackUnchanged) {
  // The printed values come from a preset that differs from the defaults the reader starts with.
  Config noisy;
  ConfigSchema printer = MakeConfigSchema(&noisy);
  printer.ReadFile(std::string(FINECAP_SOURCE_DIR) + "/configs/synth_noisy.yaml");
  Config reread;
  ConfigSchema reader = MakeConfigSchema(&reread);
  const std::vector<std::string> keys = HelpPaths(printer.HelpText("synth."));
  ASSERT_EQ(keys.size(), 54u);
  for (const std::string& key : keys) reader.Set(key, printer.ValueText(key), "test");

  const SynthOptions& expected = noisy.synth;
  const SynthOptions& actual = reread.synth;
  ASSERT_EQ(actual.folds.size(), expected.folds.size());
  for (size_t i = 0; i < expected.folds.size(); ++i) {
    EXPECT_EQ(actual.folds[i].amplitude, expected.folds[i].amplitude);
    EXPECT_EQ(actual.folds[i].wavelength, expected.folds[i].wavelength);
    EXPECT_EQ(actual.folds[i].orientation, expected.folds[i].orientation);
    EXPECT_EQ(actual.folds[i].phase, expected.folds[i].phase);
    EXPECT_EQ(actual.folds[i].drift, expected.folds[i].drift);
    EXPECT_EQ(actual.folds[i].profile, expected.folds[i].profile);
  }
  EXPECT_EQ(actual.cameras.distortion, expected.cameras.distortion);
  EXPECT_EQ(actual.cameras.rotation_noise, expected.cameras.rotation_noise);
  EXPECT_EQ(actual.misalignment, expected.misalignment);
  EXPECT_EQ(actual.num_frames, expected.num_frames);
  EXPECT_EQ(actual.render.noise_sigma, expected.render.noise_sigma);
  EXPECT_EQ(actual.texture.textureless_color, expected.texture.textureless_color);
  EXPECT_EQ(actual.render.light_direction, expected.render.light_direction);
  EXPECT_EQ(actual.render.background, expected.render.background);
}

TEST(ConfigSynthTest, UnknownSynthKeyIsNamed) {
  const std::string file = WriteConfig("unknown_synth.yaml", "synth:\n  cameras:\n    cont: 3\n");
  ExpectErrorMentions([&] { LoadConfig(file, {}); },
                      {"unknown_synth.yaml", "synth.cameras.cont", "unknown key"});
  ExpectSetRefused("synth.sead", "3", {"unknown key"});
}

TEST(ConfigSynthTest, WrongTypeInAFoldNamesTheFoldField) {
  const std::string file = WriteConfig("fold_type.yaml",
                                       "synth:\n  folds:\n    - amplitude: 0.01\n"
                                       "    - wavelength: wide\n");
  ExpectErrorMentions([&] { LoadConfig(file, {}); }, {"fold_type.yaml", "synth.folds[1].wavelength",
                                                      "expected a number", "'wide'"});
}

TEST(ConfigSynthTest, BadFoldsAreRefusedWithTheirPath) {
  ExpectSetRefused("synth.folds", "[{wavelenth: 0.1}]",
                   {"synth.folds[0].wavelenth'", "unknown fold key"});
  ExpectSetRefused("synth.folds", "[{}, {profile: square}]",
                   {"synth.folds[1].profile'", "'square'", "sine, ridge"});
  ExpectSetRefused("synth.folds", "[{amplitude: 0.5}]",
                   {"synth.folds[0].amplitude'", "outside [-0.1, 0.1]"});
  ExpectSetRefused("synth.folds", "[{drift: [1, 2]}]",
                   {"synth.folds[0].drift'", "expected a single value"});
  ExpectSetRefused("synth.folds", "[0.1]", {"synth.folds[0]'", "expected a mapping"});
  ExpectSetRefused("synth.folds", "0.1", {"synth.folds'", "expected a list"});
}

TEST(ConfigSynthTest, FixedLengthListsCheckTheirLength) {
  const std::string file =
      WriteConfig("distortion.yaml", "synth:\n  cameras:\n    distortion: [0.1, 0.0, 0.0, 0.0]\n");
  ExpectErrorMentions([&] { LoadConfig(file, {}); },
                      {"distortion.yaml", "synth.cameras.distortion", "exactly 5", "got 4"});
  ExpectSetRefused("synth.texture.textureless_color", "[0.5, 0.5]", {"exactly 3", "got 2"});
  ExpectSetRefused("synth.render.background", "[0.5, 2, 0]", {"outside [0, 1]"});
}

TEST(ConfigSynthTest, BadSeedsAndChoicesAreRefused) {
  ExpectSetRefused("synth.seed", "-1", {"expected an integer"});
  ExpectSetRefused("synth.render.noise_seed", "18446744073709551616", {"expected an integer"});
  ExpectSetRefused("synth.subject", "dress", {"skirt, mesh"});
  ExpectSetRefused("synth.skirt.around", "4", {"outside [8, 100000]"});
}

}  // namespace
}  // namespace finecap
