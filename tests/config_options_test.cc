// One home per option: every numeric key takes its range from its options struct's declaration of
// fields (option_fields.h), whose Check() refuses what lies past it naming the C++ field, which
// the config layer reports at its key; choices are enums whose names come from one table, and a
// renamed key keeps its former name.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "finecap/config/config.h"
#include "finecap/energy/term_options.h"
#include "finecap/eval/run_evaluation.h"
#include "finecap/util/error.h"
#include "finecap/util/option_fields.h"
#include "test_util.h"

namespace finecap {
namespace {

// Keys of settings that Config::Check() does not reach (where the input is, where the output goes,
// the threads, what eval shows, the reference frame): the schema checks them, and the library
// struct that holds one, if any (SequenceOptions, RunEvaluationOptions), when a command runs.
bool IsConfigLevelKey(const std::string& path) {
  for (const char* prefix : {"capture.", "output.", "runtime.", "eval.", "compare."}) {
    if (path.rfind(prefix, 0) == 0) return true;
  }
  return path == "model.reference_frame";
}

// Keys whose lower bound is another key's value (Check() refuses a hem narrower than the waist, a
// fallback view or pair angle below its cap):
// only their fixed bounds are walked.
bool LowerBoundFollowsAnotherKey(const std::string& path) {
  return path == "synth.skirt.hem_radius" || path == "synth.texture.textureless_end" ||
         path == "visibility.fallback_view_angle_deg" ||
         path == "visibility.fallback_pair_angle_deg";
}

// The key that the failing field of config.Check() belongs to; "" when the check passes.
std::string FailingKey(const Config& config) {
  try {
    config.Check();
  } catch (const Error& error) {
    const std::string key = ConfigKeyOfField(error.where());
    return key.empty() ? error.where() : key;
  }
  return "";
}

// The config of defaults with `value` written into the field of `path`, past the schema's checks.
Config WithValue(const std::string& path, double value) {
  Config config;
  const ConfigSchema schema = MakeConfigSchema(&config);
  for (const ConfigSchema::NumericKey& key : schema.NumericKeys()) {
    if (key.path == path) key.write_unchecked(value);
  }
  return config;
}

// Values at the inner edges of a key's range, and just outside it (none for an unbounded side).
struct EdgeValues {
  std::vector<double> inside;
  std::vector<double> outside;
};

EdgeValues Edges(const ConfigSchema::NumericKey& key) {
  const double lowest =
      key.is_integer ? std::numeric_limits<int>::lowest() : std::numeric_limits<double>::lowest();
  const double highest =
      key.is_integer ? std::numeric_limits<int>::max() : std::numeric_limits<double>::max();
  EdgeValues edges;
  if (key.zero_also) edges.inside.push_back(0.0);
  if (key.is_integer) {
    // Every integer near a bound: a rule such as "0 or at least 3" hides one step inside.
    for (int step = 0; step < 3; ++step) {
      if (key.min != lowest) edges.inside.push_back(key.min + step);
      if (key.max != highest) edges.inside.push_back(key.max - step);
    }
    if (key.min != lowest && !(key.zero_also && key.min - 1 == 0)) {
      edges.outside.push_back(key.min - 1);
    }
    if (key.zero_also) edges.outside.push_back(-1.0);
    if (key.max != highest) edges.outside.push_back(key.max + 1);
    return edges;
  }
  if (key.min != lowest) {
    edges.inside.push_back(key.min);
    edges.outside.push_back(std::nextafter(key.min, lowest) - 1e-9 * std::abs(key.min));
  }
  if (key.max != highest) {
    edges.inside.push_back(key.max);
    edges.outside.push_back(std::nextafter(key.max, highest) + 1e-9 * std::abs(key.max));
  }
  return edges;
}

// The declared fields of every options struct the config reads, with the prefix its Check()
// names them by.
std::vector<std::pair<std::string, std::vector<OptionField>>> DeclaredFields() {
  std::vector<std::pair<std::string, std::vector<OptionField>>> declared = {
      {"RefineOptions::", RefineOptions::ModelFields().Declared()},
      {"RefineOptions::", RefineOptions::RunFields().Declared()},
      {"ReferenceColorOptions::", ReferenceColorOptions::Fields().Declared()},
      {"ImageGaussianOptions::", ImageGaussianOptions::Fields().Declared()},
      {"VisibilityOptions::", VisibilityOptions::Fields().Declared()},
      {"EnergyOptions::", EnergyOptions::Fields().Declared()},
      {"ConsensusOptions::", ConsensusOptions::Fields().Declared()},
      {"SolverOptions::", SolverOptions::Fields().Declared()},
      {"SweepOptions::", SweepOptions::Fields().Declared()},
      {"CoarseToFineOptions::", CoarseToFineOptions::Fields().Declared()},
      {"CameraAlignmentOptions::", CameraAlignmentOptions::Fields().Declared()},
      {"HeldOutOptions::", HeldOutOptions::Fields().Declared()},
      {"SynthOptions::", SynthOptions::Fields().Declared()},
      {"SynthOptions::smoothing.", TaubinSmoothingOptions::Fields().Declared()},
      {"SkirtOptions::", SkirtOptions::Fields().Declared()},
      {"TextureOptions::", TextureOptions::Fields().Declared()},
      {"RigOptions::", RigOptions::Fields().Declared()},
      {"RenderOptions::", RenderOptions::Fields().Declared()},
      {"SequenceOptions::", SequenceOptions::Fields().Declared()},
      {"RunEvaluationOptions::", RunEvaluationOptions::Fields().Declared()}};
  for (const TermOptionSection& term : TermOptionSections()) {
    declared.push_back({term.field_prefix, term.fields});
  }
  return declared;
}

// A declared bound as the schema states it: an unbounded side of an int is the int's limit.
double DeclaredMin(const OptionField& field) {
  if (field.HasMin() || field.type == OptionField::Type::kDouble) return field.min;
  return std::numeric_limits<int>::lowest();
}

double DeclaredMax(const OptionField& field) {
  if (field.HasMax() || field.type == OptionField::Type::kDouble) return field.max;
  return std::numeric_limits<int>::max();
}

// Every declared number is a key, a numeric key has its field's declared range, and no numeric
// key of a library struct has a range of its own: written in the config, it could drift from
// what Check() enforces.
TEST(ConfigOptionsTest, EveryNumericKeyHasTheRangeDeclaredByItsStruct) {
  Config defaults;
  const ConfigSchema schema = MakeConfigSchema(&defaults);
  std::map<std::string, ConfigSchema::NumericKey> numeric_keys;
  for (const ConfigSchema::NumericKey& key : schema.NumericKeys()) numeric_keys[key.path] = key;
  std::set<std::string> declared_keys;
  for (const auto& [prefix, fields] : DeclaredFields()) {
    for (const OptionField& field : fields) {
      if (!field.IsNumber()) continue;
      const std::string key = ConfigKeyOfField(prefix + field.name);
      ASSERT_TRUE(schema.Has(key)) << prefix << field.name << " has no key";
      declared_keys.insert(key);
      const auto numeric = numeric_keys.find(key);
      if (numeric == numeric_keys.end()) continue;  // A key of its own parsing (an odd window).
      EXPECT_EQ(numeric->second.min, DeclaredMin(field)) << key;
      EXPECT_EQ(numeric->second.max, DeclaredMax(field)) << key;
      EXPECT_EQ(numeric->second.zero_also, field.zero_also) << key;
    }
  }
  for (const auto& [path, key] : numeric_keys) {
    if (IsConfigLevelKey(path)) continue;
    EXPECT_EQ(declared_keys.count(path), 1u) << path << " states a range of its own";
  }
  EXPECT_GT(declared_keys.size(), 70u);
}

// For every numeric key of a library struct: a value at the edge of the key's range passes
// Config::Check() (or fails it naming another key, when a rule across keys refuses it with the
// others at their defaults), and one just outside, written past the schema's checks, fails Check()
// naming this key: the struct's Check() enforces every range it declares.
TEST(ConfigOptionsTest, CheckRefusesAValueJustPastEachBoundOfEveryNumericKey) {
  Config defaults;
  const ConfigSchema schema = MakeConfigSchema(&defaults);
  ASSERT_EQ(FailingKey(defaults), "");
  int walked = 0;
  for (const ConfigSchema::NumericKey& key : schema.NumericKeys()) {
    if (IsConfigLevelKey(key.path)) continue;
    ++walked;
    const EdgeValues edges = Edges(key);
    for (double value : edges.inside) {
      if (value == key.min && LowerBoundFollowsAnotherKey(key.path)) continue;
      EXPECT_NE(FailingKey(WithValue(key.path, value)), key.path)
          << key.path << " = " << value << " is in the schema's range but Check() refuses it";
    }
    for (double value : edges.outside) {
      EXPECT_EQ(FailingKey(WithValue(key.path, value)), key.path)
          << key.path << " = " << value << " is outside the schema's range but Check() takes it";
    }
  }
  EXPECT_GT(walked, 50);
}

TEST(ConfigOptionsTest, FieldsMapToTheirKeys) {
  EXPECT_EQ(ConfigKeyOfField("RefineOptions::sigma_hat"), "model.sigma_hat");
  EXPECT_EQ(ConfigKeyOfField("RefineOptions::warm_start"), "refine.warm_start");
  EXPECT_EQ(ConfigKeyOfField("RefineOptions::subdivision"), "model.subdivision");
  EXPECT_EQ(ConfigKeyOfField("EnergyOptions::w_reg"), "energy.w_reg");
  EXPECT_EQ(ConfigKeyOfField("ConsensusOptions::passes"), "energy.consensus.passes");
  EXPECT_EQ(ConfigKeyOfField("SweepOptions::samples"), "refine.sweep.samples");
  EXPECT_EQ(ConfigKeyOfField("ImageGaussianOptions::min_leaf_size"),
            "image_gaussians.min_leaf_size");
  EXPECT_EQ(ConfigKeyOfField("SynthOptions::folds[1].wavelength"), "synth.folds[1].wavelength");
  EXPECT_EQ(ConfigKeyOfField("SolverOptions::num_threads"), "");
  EXPECT_EQ(ConfigKeyOfField("RefineOptions::no_such_field"), "");
  EXPECT_EQ(ConfigKeyOfField("SequenceOptions::reference_frame"), "model.reference_frame");
  EXPECT_EQ(ConfigKeyOfField("SequenceOptions::held_out_cameras"), "validation.cameras");
  EXPECT_EQ(ConfigKeyOfField("ReferenceColorOptions::follow_colors"), "model.follow_colors");
}

// The library names fields in its messages; the command line shows the keys.
TEST(ConfigOptionsTest, MessagesOfTheLibraryReadInConfigKeys) {
  EXPECT_EQ(InConfigTerms("2.02e+05 times RefineOptions::sigma_hat = 0.007; lower "
                          "RefineOptions::sigma_hat (and EnergyOptions::k_max)"),
            "2.02e+05 times model.sigma_hat = 0.007; lower model.sigma_hat (and energy.k_max)");
  EXPECT_EQ(InConfigTerms("SynthOptions::folds[1].wavelength: must be positive"),
            "synth.folds[1].wavelength: must be positive");
  // A field that no key holds, and text without fields, stay as they are.
  EXPECT_EQ(InConfigTerms("SolverOptions::num_threads: is 0"), "SolverOptions::num_threads: is 0");
  EXPECT_EQ(InConfigTerms("no field here"), "no field here");
  // Half a field name stays; a full stop after the name is not part of it.
  EXPECT_EQ(InConfigTerms("RefineOptions:: x, lower RefineOptions::sigma_hat."),
            "RefineOptions:: x, lower model.sigma_hat.");
}

// A rule across keys is the struct's Check()'s; the config reports it at the key.
TEST(ConfigOptionsTest, ACheckFailureOfTheConfigNamesTheKey) {
  testing_util::ExpectErrorMentions(
      [] {
        LoadConfig("", {{"image_gaussians.max_depth", "16", "--set"},
                        {"image_gaussians.min_leaf_size", "32", "--set"}});
      },
      {"config: key 'image_gaussians.min_leaf_size'", "2^20"});
  testing_util::ExpectErrorMentions(
      [] {
        LoadConfig("", {{"synth.skirt.waist_radius", "0.5", "--set"},
                        {"synth.skirt.hem_radius", "0.4", "--set"}});
      },
      {"key 'synth.skirt.hem_radius'"});
}

TEST(ConfigOptionsTest, ChoicesAreTheNamesOfTheirEnums) {
  Config config;
  ConfigSchema schema = MakeConfigSchema(&config);
  for (const std::string& name : EnumNameList<SolverType>()) {
    schema.Set("solver.type", name, "--set");
    EXPECT_EQ(EnumToString(config.refine.solver.type), name);
  }
  schema.Set("solver.linear_solver", "sparse_normal_cholesky", "--set");
  EXPECT_EQ(config.refine.solver.linear_solver, LinearSolverType::kSparseNormalCholesky);
  schema.Set("energy.overlap", "patch", "--set");
  EXPECT_EQ(config.refine.energy.overlap, OverlapForm::kPatch);
  schema.Set("image_gaussians.color_space", "lab", "--set");
  EXPECT_EQ(config.refine.image.color_space, ColorSpace::kLab);
  // The help lists the table's names as the allowed values.
  EXPECT_NE(schema.HelpText("energy.similarity").find("choice paper, surface_color, consensus"),
            std::string::npos)
      << schema.HelpText("energy.similarity");
  testing_util::ExpectErrorMentions([&] { schema.Set("energy.reg_unit", "cm", "--set"); },
                                    {"energy.reg_unit", "'cm' is not one of: mm, m"});
}

TEST(ConfigOptionsTest, EnumNamesRoundTripAndRefuseOthers) {
  std::set<std::string> names;
  for (const std::string& name : EnumNameList<SimilarityType>()) {
    SimilarityType type = SimilarityType::kPaper;
    ASSERT_TRUE(StringToEnum(name, &type));
    EXPECT_EQ(EnumToString(type), name);
    names.insert(name);
  }
  EXPECT_EQ(names.size(), 3u);
  TrustRegionType trust_region = TrustRegionType::kDogleg;
  EXPECT_FALSE(StringToEnum("Dogleg", &trust_region));
  EXPECT_EQ(trust_region, TrustRegionType::kDogleg);
  std::ostringstream text;
  text << OverlapForm::kExact << " " << LinearSolverType::kDenseQr;
  EXPECT_EQ(text.str(), "exact dense_qr");
  EXPECT_FALSE(IsKnownEnum(static_cast<ReferenceColorSource>(9)));
  EXPECT_EQ(EnumToString(static_cast<ReferenceColorSource>(9)), "unknown");
}

// The plane sweep's keys moved to the section of its struct (RefineOptions::sweep); configs
// written with the former names keep working.
TEST(ConfigOptionsTest, TheSweepsFormerKeysStillWork) {
  const std::string file =
      (std::filesystem::path(::testing::TempDir()) / "former_sweep_keys.yaml").string();
  std::ofstream(file) << "solver:\n  sweep_samples: 0\n  sweep_smoothing_rounds: 7\n";
  const Config old_names = LoadConfig(file, {});
  EXPECT_EQ(old_names.refine.sweep.samples, 0);
  EXPECT_EQ(old_names.refine.sweep.smoothing_rounds, 7);
  const Config new_names = LoadConfig("", {{"refine.sweep.samples", "9", "--set"},
                                           {"solver.sweep_smoothing_rounds", "2", "--set"}});
  EXPECT_EQ(new_names.refine.sweep.samples, 9);
  EXPECT_EQ(new_names.refine.sweep.smoothing_rounds, 2);
  testing_util::ExpectErrorMentions(
      [] {
        LoadConfig("", {{"solver.sweep_samples", "2", "--set"}});
      },
      {"solver.sweep_samples", "neither 0 (off) nor in [3, 1000]"});

  Config config;
  const ConfigSchema schema = MakeConfigSchema(&config);
  EXPECT_NE(schema.MarkdownTable().find("| `solver.sweep_samples` | int | `33` | 0 or [3, 1000] | "
                                        "Former name of `refine.sweep.samples`, still accepted. |"),
            std::string::npos);
}

}  // namespace
}  // namespace finecap
