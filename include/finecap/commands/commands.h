// The subcommands of the `finecap` command line. Each takes a fully loaded configuration (the
// command line has already merged the YAML file and the flags), does its job, and returns the
// process exit code. Bad input raises finecap::Error; the command line prints it and exits 1.
#ifndef FINECAP_COMMANDS_COMMANDS_H_
#define FINECAP_COMMANDS_COMMANDS_H_

#include "finecap/config/config.h"

namespace finecap {

// Loads the capture, refines the configured frames and writes the results to output.dir.
int RunRefine(const Config& config);

// Evaluates the configured energy on frame `frame` (-1: the last) of a capture with ground truth
// along k = alpha * k_true, alpha in [-0.5, 1.5]; prints the table, plots it into output.dir (or
// the working directory) and ends with the line "alpha_optimum: <value>".
int RunProbe(const Config& config, int frame);

// Measures the refined run in output.dir (a previous RunRefine on the same capture and config)
// against the capture's ground truth and writes output.dir/eval/: frame_<frame>.png (image,
// input normals, refined normals of camera eval.camera), error_<frame>.png (|k - k_true| as a
// heat map), rms.png and normal_error.png, metrics.json and report.html. Frames without ground
// truth get pictures and null figures. With validation.cameras, also the held-out score of the
// input and the refined mesh (heldout_score.h) in metrics.json and the report, and
// heldout_<frame>_<camera>.png per held-out view. Throws Error naming output.dir when it holds no
// refined frame of the configured range.
int RunEval(const Config& config);

// Writes a refined run (output.dir) as a PC2 point cache and per-frame PLY files with the
// displacement as vertex quality, in output.dir/export/.
int RunExport(const Config& config);

// Refines the configured frames once per variant of section compare, each into
// output.dir/<variant>/ as RunRefine does, and compares them: output.dir/comparison.csv and
// comparison.md (one row per variant), convergence_iterations.png and convergence_time.png (the
// last frame's solver traces) and report.html. Every variant is checked before anything is
// written; a rerun skips the frames already done.
int RunCompare(const Config& config);

// Prints the capture as finecap reads it (cameras and their format, frames, mesh sizes before and
// after subdivision, the scene's extent and the lengths chosen from it) and the problem a
// refinement would solve (vertices refined, pairs, the forecast of peak memory and time per
// frame, the same as RunRefine prints), with a warning for a camera that sees nothing and for
// vertices no camera sees within the view-angle cap. Refines nothing and writes nothing.
int RunInfo(const Config& config);

// Generates a synthetic capture with ground truth (section synth) into output.dir.
int RunSynth(const Config& config);

// The exit code of RunStatus when frames are missing (1 stays the code of bad input).
constexpr int kStatusIncomplete = 3;

// Reports which of the configured frames (of shard runtime.shard) are done in output.dir, a
// folder of `finecap refine` (mesh, displacement and stats record: see docs/usage.md): prints
// "<folder>: D of T frames done (frames A:B)" and a "missing ..." line per run of consecutive
// missing frames. Returns 0 when every frame is done, kStatusIncomplete otherwise; throws Error
// naming output.dir when there is no such folder. Writes nothing.
int RunStatus(const Config& config);

}  // namespace finecap

#endif  // FINECAP_COMMANDS_COMMANDS_H_
