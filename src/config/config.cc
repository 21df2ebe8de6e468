#include "finecap/config/config.h"

#include <cctype>
#include <map>
#include <sstream>
#include <string>

#include <yaml-cpp/yaml.h>

#include "finecap/eval/optical_flow.h"
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
  schema->AddInt("validation.neighbours", &score.neighbours,
                 "Training views warped into each held-out view, the nearest by camera centre.", 1,
                 1000);
  schema->AddCustom(
      "validation.window", "int", "odd, [3, 31]",
      "Side of the windows of the held-out NCC, pixels.",
      [&score](const YAML::Node& value, const std::string& where) {
        Require(value.IsScalar(), where, "expected an odd integer");
        int window = 0;
        Require(YAML::convert<int>::decode(value, window), where,
                "expected an odd integer, got '" + value.Scalar() + "'");
        Require(window >= 3 && window <= 31 && window % 2 == 1, where,
                "value " + value.Scalar() + " is not an odd integer in [3, 31]");
        score.window = window;
      },
      [&score] { return std::to_string(score.window); });
  schema->AddDouble("validation.min_std", &score.min_std,
                    "Held-out NCC windows whose grey levels vary less than this (standard "
                    "deviation, 0-255) are not scored.",
                    0.0, 255.0);
  schema->AddDouble("validation.depth_tolerance_px", &score.depth_tolerance_px,
                    "A point counts as seen by a training view within this many pixel footprints "
                    "behind its depth map there.",
                    0.01, 1000.0);
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
  schema->AddInt(
      "runtime.max_memory_mb", &config->runtime.max_memory_mb,
      "finecap refine: refuse, before it starts, a run whose forecast peak memory "
      "exceeds this many MB; 0 = the memory available (the smaller of the cgroup limit and "
      "MemAvailable), which is always checked.",
      0);
  schema->AddInt("eval.camera", &config->eval.camera,
                 "finecap eval: index of the camera whose view the per-frame pictures show.", 0);
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
  schema->AddInt("model.reference_frame", &config->reference_frame,
                 "Frame (index in the sorted frame list) whose images colour the surface "
                 "Gaussians; the paper: the first.",
                 0);
  schema->AddEnum("model.reference_surface", &config->colors.reference_surface,
                  "Where the reference frame colours the surface Gaussians (surface_color, "
                  "paper): coarse (its input surface, the paper) or refined (that frame refined "
                  "first with the default consensus similarity). No effect under consensus.");
  schema->AddDouble("model.follow_colors", &config->colors.follow_colors,
                    "Rate at which the colours follow the sequence, blended in from each refined "
                    "frame not flagged worse; 0 = fixed at the reference frame (the paper). "
                    "Sequential: not with runtime.shard. No effect under consensus.",
                    0.0, 1.0);
  schema->AddDouble("model.follow_anchor", &config->colors.follow_anchor,
                    "Pull of the followed colours back towards the reference colours after each "
                    "frame (against drift).",
                    0.0, 1.0);
  schema->AddInt("model.subdivision_levels", &refine.subdivision_levels,
                 "Subdivision levels applied to the coarse mesh before refinement.", 0, 4);
  schema->AddEnum("model.subdivision", &refine.subdivision,
                  "Scheme of that subdivision: loop (approximating: moves the input's vertices "
                  "onto a smoother surface), butterfly (modified butterfly, interpolating: "
                  "keeps them and places only the new vertices) or linear (the input's faces "
                  "split, its surface unchanged).");
  schema->AddDoubleOrAuto(
      "model.sigma_hat", &refine.sigma_hat, &refine.scene_lengths.sigma_hat,
      "Standard deviation of every surface Gaussian, metres (paper: 0.007); " + SigmaHatAutoText(),
      1e-5, 1.0);
  schema->AddEnum("model.reference_colors", &refine.reference_colors,
                  "How the reference frame colours the surface Gaussians: pixels (the paper) or "
                  "image_model (what the energy's image model shows in the best camera).");
  schema->AddBool("model.bias_compensation", &refine.bias_compensation,
                  "Add sigma_hat along the normal after solving (the paper's shrink "
                  "compensation).");
  schema->AddEnum("image_gaussians.color_space", &refine.image.color_space,
                  "Colour space in which colours are averaged and compared (paper: hsv).");
  schema->AddInt("image_gaussians.max_depth", &refine.image.max_depth,
                 "Quad-tree depth: leaves are min_leaf_size * 2^(max_depth - depth) pixels "
                 "(paper: 8).",
                 0, 16);
  schema->AddInt("image_gaussians.min_leaf_size", &refine.image.min_leaf_size,
                 "Side of the smallest quad-tree leaf, pixels (its sigma is half of it).", 1,
                 ImageGaussianOptions::kMaxMinLeafSize);
  schema->AddDouble("image_gaussians.split_threshold", &refine.image.split_threshold,
                    "A square is split while the RMS colour distance of its pixels to their "
                    "mean exceeds this.",
                    0.0, 10.0);
  schema->AddDoubleOrAuto("visibility.depth_tolerance", &refine.visibility.depth_tolerance,
                          &refine.scene_lengths.depth_tolerance,
                          "A vertex more than this behind the rendered input surface is occluded, "
                          "m; " +
                              AutoText(SceneLengthFactors().depth_tolerance),
                          0.0, 10.0);
  schema->AddDouble("visibility.max_view_angle_deg", &refine.visibility.max_view_angle_deg,
                    "Largest angle between a normal and the direction to a camera that sees it.",
                    1.0, 90.0);
  schema->AddDouble("visibility.fallback_view_angle_deg",
                    &refine.visibility.fallback_view_angle_deg,
                    "A vertex that fewer cameras see within max_view_angle_deg than the "
                    "similarity compares takes the most frontal up to this angle, with less "
                    "confidence; equal to max_view_angle_deg: none.",
                    1.0, 90.0);
  schema->AddDouble("visibility.border_margin", &refine.visibility.border_margin,
                    "Vertices projecting closer than this to the image border are not used, px.",
                    0.0, 1000.0);
}

void AddEnergyKeys(EnergyOptions* energy, SceneLengths* scene_lengths, ConfigSchema* schema) {
  schema->AddEnum("energy.similarity", &energy->similarity,
                  "paper: the paper's E_sim as printed; surface_color: each surface Gaussian's "
                  "colour against the image around its projection (peaks at the truth); "
                  "consensus: the cameras that see a patch agree on its normalised colours (no "
                  "reference colours).");
  schema->AddDouble("energy.consensus.contrast_floor", &energy->consensus.contrast_floor,
                    "Consensus similarity: patches with less contrast than this (colour units) "
                    "are not normalised to unit variance.",
                    1e-6, 1.0);
  schema->AddInt("energy.consensus.min_cameras", &energy->consensus.min_cameras,
                 "Consensus similarity: cameras that must see a whole patch for it to count.", 2,
                 64);
  schema->AddInt("energy.consensus.passes", &energy->consensus.passes,
                 "Consensus similarity: solves per frame, each later one with patches shaped "
                 "like the surface the one before found.",
                 1, 10);
  schema->AddInt("energy.consensus.shape_smoothing_rounds",
                 &energy->consensus.shape_smoothing_rounds,
                 "Consensus similarity: rounds of averaging over mesh neighbours of the surface a "
                 "pass found before it shapes the next pass's patches (0: as found).",
                 0, 100);
  schema->AddInt("energy.consensus.patch_rings", &energy->consensus.patch_rings,
                 "Consensus similarity: a patch is a surface Gaussian and its neighbours up to "
                 "this many edges of the input subdivided once away (patch_rings x "
                 "2^(model.subdivision_levels - 1) edges of the refined mesh, at most 4).",
                 1, ConsensusOptions::kMaxPatchRings);
  schema->AddBool("energy.consensus.gain_per_channel", &energy->consensus.gain_per_channel,
                  "Consensus similarity: normalise each camera's gain per channel (white "
                  "balance) instead of once for all channels (exposure).");
  schema->AddDouble("energy.consensus.robust_fraction", &energy->consensus.robust_fraction,
                    "Consensus similarity: scale of Cauchy's loss on each patch's disagreement, "
                    "as a fraction of that of unrelated patches; 0: plain least squares.",
                    0.0, 100.0);
  schema->AddDouble("energy.consensus.sample_spacing", &energy->consensus.sample_spacing,
                    "Consensus similarity: 0 reads a patch's colours at its surface Gaussians; "
                    "above 0 at samples of the surface this many pixel footprints apart, at the "
                    "images' own resolution.",
                    0.0, 16.0);
  schema->AddDouble("energy.consensus.sample_blur", &energy->consensus.sample_blur,
                    "Consensus similarity with samples: standard deviation (pixels) of the blur "
                    "of the images the samples read.",
                    0.0, 8.0);
  schema->AddEnum("energy.overlap", &energy->overlap,
                  "Overlap of two Gaussians: the paper's printed form, the exact integral, or "
                  "patch (image Gaussians as the squares they stand for).");
  schema->AddDouble("energy.color_cutoff", &energy->color_cutoff,
                    "Wendland cut-off D of the colour weight of the paper's E_sim (paper: 0.05).",
                    1e-6, 10.0);
  schema->AddDouble("energy.reach_sigmas", &energy->reach_sigmas,
                    "Pairs of Gaussians are evaluated up to this many combined sigmas apart.", 0.5,
                    10.0);
  schema->AddDoubleOrAuto(
      "energy.k_max", &energy->k_max, &scene_lengths->k_max,
      "Bound on the displacement along the normal, m; " + AutoText(SceneLengthFactors().k_max),
      1e-5, 1.0);
  schema->AddDouble("energy.w_reg", &energy->w_reg, "Weight of the regulariser (paper: 1).", 0.0,
                    1e12);
  schema->AddDouble("energy.w_prior", &energy->w_prior,
                    "Weight of a pull of k towards the input surface (not in the paper); keeps "
                    "textureless regions in place.",
                    0.0, 1e12);
  schema->AddDouble("energy.confidence_prior", &energy->confidence_prior,
                    "Strength of a pull of k towards the input surface where the images cannot "
                    "decide it (few cameras, steep views, wide plain regions), in units of the "
                    "median data curvature (not in the paper; 0: off).",
                    0.0, 1e6);
  schema->AddDouble("energy.temporal_weight", &energy->temporal_weight,
                    "Strength of a pull of k towards the frame before's solved k (temporal "
                    "coherence), in units of the median data curvature (not in the paper; 0: "
                    "off).",
                    0.0, 1e6);
  schema->AddDouble("energy.confidence_threshold", &energy->confidence_threshold,
                    "Colour variation, as a fraction of its median, below which the cloth counts "
                    "as plain.",
                    1e-9, 1e3);
  schema->AddInt("energy.confidence_opening", &energy->confidence_opening,
                 "Passes of the opening of the plain region: narrower plain patches are left to "
                 "the regulariser.",
                 0, 20);
  schema->AddInt("energy.reg_rings", &energy->reg_rings,
                 "Regulariser neighbourhood Delta in edges, also its Wendland cut-off (paper: 2).",
                 1, 10);
  schema->AddEnum("energy.reg_unit", &energy->reg_unit,
                  "Unit of k inside E_reg (the paper's lengths are millimetres).");
}

void AddSolverKeys(SolverOptions* solver, RefineOptions* refine, ConfigSchema* schema) {
  schema->AddEnum("solver.type", &solver->type,
                  "ceres (least squares, Levenberg-Marquardt), gradient_ascent (the paper's) "
                  "or lbfgs.");
  schema->AddInt("solver.max_iterations", &solver->max_iterations,
                 "Most iterations per frame (the paper's ascent: 150).", 0, 100000);
  schema->AddDouble("solver.function_tolerance", &solver->function_tolerance,
                    "Stop when the energy changes by less than this fraction.", 0.0, 1.0);
  schema->AddEnum("solver.trust_region", &solver->trust_region, "Ceres' trust-region strategy.");
  schema->AddEnum("solver.linear_solver", &solver->linear_solver,
                  "Ceres' linear solver: sparse Cholesky (SuiteSparse), conjugate gradients on "
                  "the normal equations, or dense QR (tiny problems only).");
  schema->AddEnum("solver.curvature", &solver->curvature,
                  "Ceres: curvature of a similarity block's model, Gauss-Newton's J^T J or the "
                  "secant of its gradient between its last two evaluations (within 0.3-3 J^T J).");
  schema->AddDoubleOrAuto("solver.initial_step", &solver->initial_step,
                          &refine->scene_lengths.initial_step,
                          "Gradient ascent: first step of the steepest k_s, m; " +
                              AutoText(SceneLengthFactors().initial_step),
                          1e-9, 1.0);
  schema->AddDouble("solver.step_growth", &solver->step_growth,
                    "Gradient ascent: step factor growth while a derivative keeps its sign.", 1.0,
                    10.0);
  schema->AddDouble("solver.step_shrink", &solver->step_shrink,
                    "Gradient ascent: step factor shrink when a derivative flips its sign.", 1e-3,
                    0.999);
  schema->AddDoubleOrAuto("solver.max_step", &solver->max_step, &refine->scene_lengths.max_step,
                          "Gradient ascent: largest step of one k_s in one iteration, m; " +
                              AutoText(SceneLengthFactors().max_step),
                          1e-9, 1.0);
  schema->AddBool("refine.keep_input_if_worse", &refine->keep_input_if_worse,
                  "Write the input surface for a frame whose energy, or held-out NCC, got worse "
                  "(always flagged).");
  schema->AddBool("refine.warm_start", &refine->warm_start,
                  "Start each frame from the previous frame's displacement.");
  schema->AddInt("refine.coarse_to_fine.levels", &refine->coarse_to_fine.levels,
                 "Levels of a coarse-to-fine schedule per frame (wider Gaussians and a coarser "
                 "image model first); 1: off.",
                 1, 5);
  schema->AddDouble("refine.coarse_to_fine.scale", &refine->coarse_to_fine.scale,
                    "Factor of sigma_hat and of the smallest quad-tree leaf from one level to the "
                    "next coarser.",
                    1.0001, 4.0);
  schema->AddIntOrOff("refine.sweep.samples", &refine->sweep.samples,
                      "Plane-sweep start: displacements tried per surface Gaussian before solving "
                      "(0 = off, start at k = 0).",
                      SweepOptions::kMinSamples, SweepOptions::kMaxSamples);
  schema->AddInt("refine.sweep.smoothing_rounds", &refine->sweep.smoothing_rounds,
                 "Plane-sweep start: rounds of averaging cost curves over mesh neighbours.", 0,
                 1000);
  schema->AddAlias("solver.sweep_samples", "refine.sweep.samples");
  schema->AddAlias("solver.sweep_smoothing_rounds", "refine.sweep.smoothing_rounds");
}

// The config section of the fields of each options struct, so that a Check() failure naming a
// field ("EnergyOptions::w_reg") is reported at its key ("energy.w_reg"): the sections follow the
// structs, and RefineOptions' own fields are split between `model` and `refine`.
const std::vector<std::pair<std::string, std::vector<std::string>>>& FieldSections() {
  static const std::vector<std::pair<std::string, std::vector<std::string>>> sections = {
      {"RefineOptions::", {"model.", "refine."}},
      {"ReferenceColorOptions::", {"model."}},
      {"ImageGaussianOptions::", {"image_gaussians."}},
      {"VisibilityOptions::", {"visibility."}},
      {"EnergyOptions::", {"energy."}},
      {"ConsensusOptions::", {"energy.consensus."}},
      {"SolverOptions::", {"solver."}},
      {"SweepOptions::", {"refine.sweep."}},
      {"CoarseToFineOptions::", {"refine.coarse_to_fine."}},
      {"HeldOutOptions::", {"validation."}},
      {"SequenceOptions::", {"model.", "refine.", "validation."}},
      {"RunEvaluationOptions::", {"model.", "eval."}},
      {"SynthOptions::", {"synth."}},
      {"SkirtOptions::", {"synth.skirt."}},
      {"TextureOptions::", {"synth.texture."}},
      {"RigOptions::", {"synth.cameras."}},
      {"RenderOptions::", {"synth.render."}}};
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
