#include "finecap/config/config.h"

#include <cctype>
#include <map>
#include <sstream>
#include <string>

#include <yaml-cpp/yaml.h>

#include "finecap/energy/term_options.h"
#include "finecap/eval/optical_flow.h"
#include "finecap/eval/run_evaluation.h"
#include "finecap/util/error.h"
#include "refine/scene_scale.h"

namespace finecap {
namespace {

// How a length key that follows from the scene documents its default.
std::string AutoText(double factor) {
  std::ostringstream text;
  text << "auto: " << factor << " scene lengths (scene length: see docs/usage.md).";
  return text.str();
}

// sigma_hat's factor depends on the similarity (scene_scale.h says why).
std::string SigmaHatAutoText() {
  std::ostringstream text;
  text << AutoText(SceneLengthFactors().sigma_hat)
       << " Under surface_color and paper: " << SceneLengthFactors().single_gaussian_sigma_hat
       << " scene lengths.";
  return text.str();
}

std::string NameListText(const std::vector<std::string>& names) {
  std::string text = "[";
  for (size_t i = 0; i < names.size(); ++i) text += (i ? ", " : "") + names[i];
  return text + "]";
}

// A length that follows from the scene unless set ("auto" sets `*is_auto`), with the declared
// field's range and doc.
ConfigSchema::FieldKeyMaker AutoLengthKey(double* value, bool* is_auto,
                                          const std::string& auto_text, ConfigSchema* schema) {
  return [=](const std::string& path, const OptionField& field) {
    schema->AddDoubleOrAuto(path, value, is_auto, field.doc + "; " + auto_text, field.min,
                            field.max);
  };
}

// An odd integer in the declared field's range (a window with a centre pixel).
ConfigSchema::FieldKeyMaker OddIntKey(int* value, ConfigSchema* schema) {
  return [=](const std::string& path, const OptionField& field) {
    const std::string range = "[" + std::to_string(static_cast<int>(field.min)) + ", " +
                              std::to_string(static_cast<int>(field.max)) + "]";
    schema->AddCustom(
        path, "int", "odd, " + range, field.doc,
        [=](const YAML::Node& node, const std::string& where) {
          Require(node.IsScalar(), where, "expected an odd integer");
          int number = 0;
          Require(YAML::convert<int>::decode(node, number), where,
                  "expected an odd integer, got '" + node.Scalar() + "'");
          Require(number >= field.min && number <= field.max && number % 2 == 1, where,
                  "value " + node.Scalar() + " is not an odd integer in " + range);
          *value = number;
        },
        [=] { return std::to_string(*value); });
  };
}

void AddValidationKeys(ValidationConfig* validation, ConfigSchema* schema) {
  schema->AddCustom(
      "validation.cameras", "list of string", "camera names",
      "Cameras held out of the refinement: refine scores the input and refined surface in them "
      "(held-out NCC and MAD in the stats), eval reports them; [] = none.",
      [validation](const YAML::Node& value, const std::string& where) {
        std::vector<std::string> names;
        if (value.IsScalar()) {
          names.push_back(value.Scalar());  // One name without brackets.
        } else {
          Require(value.IsSequence(), where, "expected a list of camera names");
          for (const YAML::Node& item : value) {
            Require(item.IsScalar(), where, "expected camera names, found a list or mapping");
            names.push_back(item.Scalar());
          }
        }
        for (const std::string& name : names) {
          Require(!name.empty(), where, "a camera name is empty");
        }
        validation->cameras = names;
      },
      [validation] { return NameListText(validation->cameras); });
  HeldOutOptions& score = validation->score;
  schema->AddFields("validation.", &score, HeldOutOptions::Fields(),
                    {{"window", OddIntKey(&score.window, schema)}});
}

// eval.flow: a method of the optical flow, or none.
std::vector<std::string> FlowChoices() {
  std::vector<std::string> choices = EnumNameList<FlowMethod>();
  choices.push_back("none");
  return choices;
}

void AddCaptureOutputRuntimeKeys(Config* config, ConfigSchema* schema) {
  schema->AddString(
      "capture.dir", &config->capture.dir,
      "Capture folder (cameras, images or videos, meshes; see docs/capture-format.md).");
  schema->AddString("capture.mesh", &config->capture.mesh,
                    "Coarse mesh of a one-frame capture (e.g. a COLMAP workspace), instead of its "
                    "meshes/ folder or COLMAP's meshed-*.ply; \"\" = the capture's own.");
  schema->AddString("capture.frames", &config->capture.frames,
                    "Frames to process: \"A:B\" = indices A..B-1 of the sorted frame list; "
                    "\"\" = all.");
  schema->AddBool("capture.skip_unreadable_cameras", &config->capture.skip_unreadable_cameras,
                  "Refine a frame without a camera whose image cannot be read (warning; listed in "
                  "the stats record's skipped_cameras) instead of stopping.");
  schema->AddString("output.dir", &config->output.dir,
                    "Output folder; created if missing; existing files are never overwritten.");
  schema->AddChoice("output.mesh_format", &config->output.mesh_format,
                    "Format of refined meshes (PLY is binary).", {"ply", "obj"});
  schema->AddInt("runtime.threads", &config->runtime.threads,
                 "Worker threads for parallel stages; 0 = all cores.", 0, 1024);
  schema->AddCustom(
      "runtime.shard", "string", "I/N, 0 <= I < N",
      "Refine part I (from 0) of N contiguous near-equal parts of the configured frames.",
      [config](const YAML::Node& value, const std::string& where) {
        Require(value.IsScalar(), where, "expected I/N, e.g. 0/4");
        config->runtime.shard = ParseShard(value.Scalar(), where);
      },
      [config] { return config->runtime.shard.ToString(); });
  schema->AddDeclaredInt("runtime.max_memory_mb", &config->runtime.max_memory_mb,
                         SequenceOptions::Fields().Field("max_memory_mb"));
  schema->AddDeclaredInt("eval.camera", &config->eval.camera,
                         RunEvaluationOptions::Fields().Field("camera"));
  schema->AddChoice("eval.flow", &config->eval.flow,
                    "finecap eval: optical flow between the textured model's render and the "
                    "image (the paper's section 7): dis, deepflow (slower) or none.",
                    FlowChoices());
  schema->AddChoice("eval.flow_dis_preset", &config->eval.flow_dis_preset,
                    "finecap eval: preset of the DIS optical flow.", EnumNameList<DisPreset>());
  schema->AddChoice("eval.flow_cameras", &config->eval.flow_cameras,
                    "finecap eval: cameras the flow is measured in, pixels pooled: all, or "
                    "eval_camera (eval.camera only, as the paper's Figure 6).",
                    {"all", "eval_camera"});
  AddValidationKeys(&config->validation, schema);
}

void AddModelKeys(Config* config, ConfigSchema* schema) {
  RefineOptions& refine = config->refine;
  schema->AddDeclaredInt("model.reference_frame", &config->reference_frame,
                         SequenceOptions::Fields().Field("reference_frame"));
  schema->AddFields("model.", &config->colors, ReferenceColorOptions::Fields());
  schema->AddFields("model.", &refine, RefineOptions::ModelFields(),
                    {{"sigma_hat", AutoLengthKey(&refine.sigma_hat, &refine.scene_lengths.sigma_hat,
                                                 SigmaHatAutoText(), schema)}});
  schema->AddFields("image_gaussians.", &refine.image, ImageGaussianOptions::Fields());
  schema->AddFields(
      "visibility.", &refine.visibility, VisibilityOptions::Fields(),
      {{"depth_tolerance",
        AutoLengthKey(&refine.visibility.depth_tolerance, &refine.scene_lengths.depth_tolerance,
                      AutoText(SceneLengthFactors().depth_tolerance), schema)}});
}

void AddEnergyKeys(EnergyOptions* energy, SceneLengths* scene_lengths, ConfigSchema* schema) {
  schema->AddFields("energy.", energy, EnergyOptions::Fields(),
                    {{"k_max", AutoLengthKey(&energy->k_max, &scene_lengths->k_max,
                                             AutoText(SceneLengthFactors().k_max), schema)}});
}

void AddSolverKeys(SolverOptions* solver, RefineOptions* refine, ConfigSchema* schema) {
  SceneLengths& lengths = refine->scene_lengths;
  schema->AddFields(
      "solver.", solver, SolverOptions::Fields(),
      {{"initial_step", AutoLengthKey(&solver->initial_step, &lengths.initial_step,
                                      AutoText(SceneLengthFactors().initial_step), schema)},
       {"max_step", AutoLengthKey(&solver->max_step, &lengths.max_step,
                                  AutoText(SceneLengthFactors().max_step), schema)}});
  schema->AddFields("refine.", refine, RefineOptions::RunFields());
  schema->AddAlias("solver.sweep_samples", "refine.sweep.samples");
  schema->AddAlias("solver.sweep_smoothing_rounds", "refine.sweep.smoothing_rounds");
}

// The config section of the fields of each options struct, so that a Check() failure naming a
// field ("EnergyOptions::w_reg") is reported at its key ("energy.w_reg"): the sections follow the
// structs, and RefineOptions' own fields are split between `model` and `refine`. The terms'
// structs are the registry's (term_options.h).
const std::vector<std::pair<std::string, std::vector<std::string>>>& FieldSections() {
  static const std::vector<std::pair<std::string, std::vector<std::string>>> sections = [] {
    std::vector<std::pair<std::string, std::vector<std::string>>> all = {
        {"RefineOptions::", {"model.", "refine."}},
        {"ReferenceColorOptions::", {"model."}},
        {"ImageGaussianOptions::", {"image_gaussians."}},
        {"VisibilityOptions::", {"visibility."}},
        {"EnergyOptions::", {"energy."}},
        {"ConsensusOptions::", {"energy.consensus."}},
        {"SolverOptions::", {"solver."}},
        {"SweepOptions::", {"refine.sweep."}},
        {"CoarseToFineOptions::", {"refine.coarse_to_fine."}},
        {"CameraAlignmentOptions::", {"refine.camera_alignment."}},
        {"HeldOutOptions::", {"validation."}},
        {"SequenceOptions::", {"model.", "refine.", "validation."}},
        {"RunEvaluationOptions::", {"model.", "eval."}},
        {"SynthOptions::", {"synth."}},
        {"SkirtOptions::", {"synth.skirt."}},
        {"TextureOptions::", {"synth.texture."}},
        {"RigOptions::", {"synth.cameras."}},
        {"RenderOptions::", {"synth.render."}}};
    for (const TermOptionSection& term : TermOptionSections()) {
      all.push_back({term.field_prefix, {term.key_prefix}});
    }
    return all;
  }();
  return sections;
}

// Whether `path` is a key of `schema` or a part of one ("synth.folds[1].profile" of
// "synth.folds").
bool IsKeyOrPart(const std::string& path, const ConfigSchema& schema) {
  for (std::string key = path;;) {
    if (schema.Has(key)) return true;
    const size_t cut = key.find_last_of(".[");
    if (cut == std::string::npos || cut == 0) return false;
    key.resize(cut);
  }
}

// Fields whose key is not their section and name.
const std::map<std::string, std::string>& RenamedFields() {
  static const std::map<std::string, std::string> renamed = {
      {"SequenceOptions::held_out_cameras", "validation.cameras"},
      {"SequenceOptions::max_memory_mb", "runtime.max_memory_mb"},
      {"RunEvaluationOptions::held_out_cameras", "validation.cameras"}};
  return renamed;
}

std::string ConfigKeyOfField(const std::string& field, const ConfigSchema& schema) {
  const auto renamed = RenamedFields().find(field);
  if (renamed != RenamedFields().end()) return renamed->second;
  for (const auto& [prefix, sections] : FieldSections()) {
    if (field.rfind(prefix, 0) != 0) continue;
    for (const std::string& section : sections) {
      const std::string path = section + field.substr(prefix.size());
      if (IsKeyOrPart(path, schema)) return path;
    }
  }
  return "";
}

bool IsMemberStart(char c) { return std::islower(static_cast<unsigned char>(c)) || c == '_'; }

bool IsMemberChar(char c) {
  return IsMemberStart(c) || std::isdigit(static_cast<unsigned char>(c));
}

// The end of a member name ([a-z_][a-z_0-9]*) that starts at `begin`, or `begin` if none does.
size_t MemberEnd(const std::string& text, size_t begin) {
  if (begin >= text.size() || !IsMemberStart(text[begin])) return begin;
  size_t end = begin + 1;
  while (end < text.size() && IsMemberChar(text[end])) ++end;
  return end;
}

// The length of the options field named at text[begin] ("RefineOptions::sigma_hat",
// "SynthOptions::folds[1].wavelength"), or 0 if none starts there. A hand-written scan rather
// than std::regex, whose automaton GCC 12 warns about under the sanitizers.
size_t FieldNameLength(const std::string& text, size_t begin) {
  if (!std::isupper(static_cast<unsigned char>(text[begin]))) return 0;
  size_t end = begin;
  while (end < text.size() && std::isalpha(static_cast<unsigned char>(text[end]))) ++end;
  if (text.compare(end, 2, "::") != 0) return 0;
  const size_t member = end + 2;
  end = MemberEnd(text, member);
  if (end == member) return 0;
  if (end < text.size() && text[end] == '[') {  // An element of a list, and its members.
    size_t close = end + 1;
    while (close < text.size() && std::isdigit(static_cast<unsigned char>(text[close]))) ++close;
    if (close > end + 1 && close < text.size() && text[close] == ']') {
      end = close + 1;
      while (end < text.size() && text[end] == '.' && MemberEnd(text, end + 1) > end + 1) {
        end = MemberEnd(text, end + 1);
      }
    }
  }
  return end - begin;
}

}  // namespace

std::string ConfigKeyOfField(const std::string& field) {
  Config defaults;
  return ConfigKeyOfField(field, MakeConfigSchema(&defaults));
}

std::string InConfigTerms(const std::string& text) {
  Config defaults;
  const ConfigSchema schema = MakeConfigSchema(&defaults);
  std::string result;
  for (size_t i = 0; i < text.size();) {
    const size_t length = FieldNameLength(text, i);
    if (length == 0) {
      result += text[i++];
      continue;
    }
    const std::string field = text.substr(i, length);
    const std::string key = ConfigKeyOfField(field, schema);
    result += key.empty() ? field : key;
    i += length;
  }
  return result;
}

void CheckConfig(const Config& config, const std::string& source) {
  try {
    config.Check();
  } catch (const Error& error) {
    const std::string key = ConfigKeyOfField(error.where());
    if (key.empty()) throw Error(source, error.what());
    throw Error(source + ": key '" + key + "'", error.problem());
  }
}

void Config::Check() const {
  frame_range();
  refine.Check();
  colors.Check();
  Require(!colors.following() || runtime.shard.count == 1, "model.follow_colors",
          "follows the colours frame after frame, which runtime.shard " + runtime.shard.ToString() +
              " splits between processes: run without shards, or set model.follow_colors: 0");
  validation.score.Check();
  synth.Check();
  compare.Check();
}

ConfigSchema MakeConfigSchema(Config* config) {
  ConfigSchema schema;
  AddCaptureOutputRuntimeKeys(config, &schema);
  AddModelKeys(config, &schema);
  AddEnergyKeys(&config->refine.energy, &config->refine.scene_lengths, &schema);
  AddSolverKeys(&config->refine.solver, &config->refine, &schema);
  AddSynthKeys(&config->synth, &schema);
  AddCompareKeys(&config->compare, &schema);
  return schema;
}

Config LoadConfig(const std::string& file, const std::vector<ConfigOverride>& overrides) {
  Config config;
  ConfigSchema schema = MakeConfigSchema(&config);
  if (!file.empty()) schema.ReadFile(file);
  for (const ConfigOverride& override_value : overrides) {
    schema.Set(override_value.key, override_value.value, override_value.source);
  }
  config.refine.solver.num_threads = config.runtime.threads;
  CheckConfig(config, file.empty() ? "config" : file);
  return config;
}

}  // namespace finecap
