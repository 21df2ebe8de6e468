// finecap's configuration: every option of every stage, read from a YAML file and overridden from
// the command line. Each section is the options struct of one stage; `MakeConfigSchema` binds them
// to their YAML keys, with documentation and allowed ranges (see config_schema.h).
#ifndef FINECAP_CONFIG_CONFIG_H_
#define FINECAP_CONFIG_CONFIG_H_

#include <string>
#include <utility>
#include <vector>

#include "finecap/config/compare_config.h"
#include "finecap/config/config_schema.h"
#include "finecap/io/frame_range.h"
#include "finecap/measure/heldout_score.h"
#include "finecap/refine/refine.h"
#include "finecap/refine/sequence.h"
#include "finecap/refine/shard.h"
#include "finecap/synth/synth.h"

namespace finecap {

// Where the input comes from.
struct CaptureConfig {
  // Capture folder (layout: docs/capture-format.md); a relative path is from the working directory.
  std::string dir;
  // The coarse mesh of a one-frame capture (a COLMAP workspace, say), named after its file stem,
  // instead of the capture's meshes/ folder or COLMAP's meshed-*.ply; a relative path is from the
  // working directory. "" (default): the capture's own.
  std::string mesh;
  // Frames to process, "A:B" = indices A to B-1 of the sorted frame list; "" = all frames.
  std::string frames;
  // When a camera's image of a frame cannot be read (missing, empty, truncated, undecodable, of
  // the wrong size, past the end of its video), refine the frame without that camera, with a
  // warning, and list it in the frame's stats record (skipped_cameras). The first frame's images
  // are checked when the capture opens and are never skipped. Default false: stop with an error.
  bool skip_unreadable_cameras = false;
};

// Where the results go.
struct OutputConfig {
  // Output folder; created if missing. Files already in it are never overwritten.
  std::string dir;
  // Format of the refined meshes: "ply" (binary) or "obj".
  std::string mesh_format = "ply";
};

// How the work is run.
struct RuntimeConfig {
  // Worker threads for parallel stages; 0 = all cores.
  int threads = 0;
  // Which part of the configured frames this process refines ("I/N", 0-based; see shard.h), so
  // that N processes can share one output folder. Default 0/1: all of them.
  Shard shard;
  // finecap refine refuses a run whose forecast peak memory exceeds this many megabytes, as it
  // refuses one that exceeds the memory available (SequenceOptions::max_memory_mb). 0: only the
  // memory available. Default 0.
  int max_memory_mb = 0;
};

// How `finecap eval` evaluates a refined run.
struct EvalConfig {
  // Index of the camera whose view the per-frame pictures show (0 = the first of the rig); must
  // be < the capture's camera count, which eval checks. Default 0.
  int camera = 0;
  // The optical-flow figures (flow_evaluation.h): "dis" (OpenCV's DIS, default), "deepflow"
  // (opencv_contrib's DeepFlow; slower) or "none" (not measured, null in metrics.json).
  std::string flow = "dis";
  // DIS preset: "ultrafast", "fast" or "medium" (default).
  std::string flow_dis_preset = "medium";
  // Cameras the flow is measured in: "all" (default; their pixels pooled, which averages out
  // the view-dependence of a single camera) or "eval_camera" (only `camera`, as the paper's
  // Figure 6 shows one view).
  std::string flow_cameras = "all";
};

// Cameras left out of the refinement to measure it by (heldout_score.h): `finecap refine` uses
// them for nothing (not for the reference colours, not in the energy, not for visibility) and
// scores each frame's input and refined surface in them; `finecap eval` reports the figures and
// pictures. A name that is not a camera of the capture, or holding out every camera, is an error.
struct ValidationConfig {
  // Names of the held-out cameras; empty (default): none, and no held-out figures.
  std::vector<std::string> cameras;
  // How the score is measured.
  HeldOutOptions score;
};

struct Config {
  CaptureConfig capture;
  OutputConfig output;
  RuntimeConfig runtime;
  EvalConfig eval;
  ValidationConfig validation;
  // Index, in the capture's sorted frame list, of the frame whose images colour the surface
  // Gaussians. Default 0 (the paper: "typically the first frame").
  int reference_frame = 0;
  // Where the reference colours are taken and whether they follow the sequence (section model).
  ReferenceColorOptions colors;
  // Everything the refinement of a frame uses (sections model, image_gaussians, visibility,
  // energy, solver, refine).
  RefineOptions refine;
  // `finecap synth` (section synth).
  SynthOptions synth;
  // `finecap compare` (section compare).
  CompareConfig compare;

  // Cross-key checks that a single key's range cannot express. Throws Error naming the keys.
  void Check() const;
  FrameRange frame_range() const { return ParseFrameRange(capture.frames, "capture.frames"); }
};

// The config key that holds the options field a Check() names (Error::where(), e.g.
// "RefineOptions::sigma_hat" -> "model.sigma_hat"; a part of a key, such as
// "synth.folds[1].profile", for a field inside a list); "" when no key holds it.
std::string ConfigKeyOfField(const std::string& field);

// `text` (an error or a warning of the library) with every options field it names
// ("RefineOptions::sigma_hat") replaced by the config key that holds it ("model.sigma_hat"), so
// that a user of the command line reads the keys they write; a field no key holds stays.
std::string InConfigTerms(const std::string& text);

// config.Check(), throwing an Error that names `source` (a file, or a variant) and, where a key
// holds the field that failed, that key.
void CheckConfig(const Config& config, const std::string& source);

// Binds every config key to a field of `*config`, which must outlive the schema.
ConfigSchema MakeConfigSchema(Config* config);

// The keys of section `synth` (config_synth.cc), bound to `*options`.
void AddSynthKeys(SynthOptions* options, ConfigSchema* schema);

// The keys of section `compare` (config_compare.cc), bound to `*compare`. Each variant's
// settings are checked against a schema of their own when read.
void AddCompareKeys(CompareConfig* compare, ConfigSchema* schema);

// A key=value override from the command line; `source` names it in errors (e.g. "--set").
struct ConfigOverride {
  std::string key;
  std::string value;
  std::string source;
};

// Defaults, then `file` (unless empty), then the overrides in order; then Config::Check().
// Throws Error naming the file (or override) and the key on any problem.
Config LoadConfig(const std::string& file, const std::vector<ConfigOverride>& overrides);

// `base` with the settings of `variant` applied in order, then Config::Check(). Throws Error
// naming variant.source and the key on any problem.
Config VariantConfig(const Config& base, const CompareVariant& variant);

}  // namespace finecap

#endif  // FINECAP_CONFIG_CONFIG_H_
