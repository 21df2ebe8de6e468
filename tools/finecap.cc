// finecap: fine-scale surface detail for multi-view performance capture.
//
//   finecap <subcommand> [--config FILE] [flags]
//
// Parameters live in a YAML config; flags override single keys. Each subcommand is one row of
// kSubcommands below; `finecap --help` and `finecap <subcommand> --help` describe everything.
#include <algorithm>
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include <gflags/gflags.h>
#include <glog/logging.h>

#include "finecap/commands/commands.h"
#include "finecap/config/config.h"
#include "finecap/util/error.h"
#include "finecap/util/process.h"
#include "finecap/util/threads.h"

DECLARE_bool(help);

DEFINE_string(config, "", "YAML config file; every key is listed by `finecap --help`.");
DEFINE_string(capture, "", "Capture folder; overrides capture.dir.");
DEFINE_string(mesh, "",
              "Coarse mesh of a one-frame capture (a COLMAP workspace, say); overrides "
              "capture.mesh.");
DEFINE_string(out, "", "Output folder; overrides output.dir.");
DEFINE_string(frames, "", "Frames to process, A:B (indices A..B-1); overrides capture.frames.");
DEFINE_int32(threads, -1, "Worker threads (0 = all cores); overrides runtime.threads.");
DEFINE_string(solver, "",
              "Solver: ceres, gradient-ascent (the paper's) or lbfgs; overrides solver.type.");
DEFINE_string(shard, "",
              "I/N: refine part I (from 0) of N contiguous near-equal parts of the frames, e.g. "
              "$SLURM_ARRAY_TASK_ID/4; overrides runtime.shard.");
DEFINE_bool(config_keys_markdown, false, "Print every config key as a Markdown table and exit.");
DEFINE_int32(frame, -1, "probe: the frame (index) to probe; -1 = the last.");
DEFINE_bool(one_malloc_arena, true,
            "One malloc arena for every thread (lower peak memory; finecap/util/process.h).");
DEFINE_int32(huge_page_heap_mb, 1024,
             "Address space reserved at the heap's end on transparent huge pages, MB (fewer page "
             "faults); 0: glibc's defaults (finecap/util/process.h).");
DEFINE_string(set, "",
              "Overrides of any config keys, comma separated: "
              "--set output.mesh_format=obj,runtime.threads=2");

namespace finecap {
namespace {

struct Subcommand {
  const char* name;
  const char* summary;
  const char* usage;
  int (*run)(const Config& config);
  std::vector<const char*> flags;  // The flags that mean something to this subcommand.
};

const std::vector<Subcommand>& Subcommands() {
  static const std::vector<Subcommand> kSubcommands = {
      {"synth",
       "Generate a synthetic capture with ground truth (cameras, images, meshes, gt/).",
       "finecap synth --config configs/synth_demo.yaml --out data/demo",
       &RunSynth,
       {"config", "out", "set"}},
      {"probe",
       "Diagnostic: the configured energy along k = alpha * k_true on a frame with ground truth; "
       "ends with alpha_optimum. Writes its plot and reference colours into --out, else into a "
       "new folder under $TMPDIR (default /tmp), never into the current directory.",
       "finecap probe --config FILE --capture DIR [--frame N] [--out DIR]",
       [](const Config& config) { return RunProbe(config, FLAGS_frame); },
       {"config", "capture", "mesh", "out", "frame", "set"}},
      {"export",
       "Write a refined run for animation tools: a PC2 point cache (Blender's Mesh Cache) and "
       "per-frame PLY with the displacement as vertex quality (MeshLab).",
       "finecap export --config FILE [--capture DIR] [--out DIR] [--frames A:B]",
       &RunExport,
       {"config", "capture", "mesh", "out", "frames", "set"}},
      {"refine",
       "Refine the coarse meshes of a capture with fine surface detail.",
       "finecap refine --config configs/demo.yaml [--frames A:B] [--shard I/N] [--solver "
       "ceres|gradient-ascent|lbfgs]"
       " [--capture DIR] [--mesh FILE] [--out DIR]",
       &RunRefine,
       {"config", "capture", "mesh", "out", "frames", "shard", "solver", "threads", "set"}},
      {"info",
       "Show the capture as finecap reads it and what refining it would take (lengths chosen "
       "from the scene, vertices refined, memory and time per frame), without refining or "
       "writing anything.",
       "finecap info --config FILE [--capture DIR] [--frames A:B] [--shard I/N] [--solver ...]",
       &RunInfo,
       {"config", "capture", "mesh", "out", "frames", "shard", "solver", "threads", "set"}},
      {"status",
       "List the configured frames (of one shard with --shard) that a refine output folder "
       "lacks; exit code 0 when none, 3 when some are missing.",
       "finecap status --config FILE [--capture DIR] [--out DIR] [--frames A:B] [--shard I/N]",
       &RunStatus,
       {"config", "capture", "mesh", "out", "frames", "shard", "set"}},
      {"eval",
       "Measure a refined run against the capture's ground truth: pictures, plots, "
       "eval/metrics.json and eval/report.html in the output folder.",
       "finecap eval --config FILE [--capture DIR] [--out DIR] [--frames A:B]",
       &RunEval,
       {"config", "capture", "mesh", "out", "frames", "set"}},
      {"compare",
       "Refine the same frames with several variants (section compare) and compare them: "
       "comparison.csv, comparison.md, convergence plots and report.html in the output folder.",
       "finecap compare --config configs/compare_solvers.yaml [--frames A:B] [--out DIR]",
       &RunCompare,
       {"config", "capture", "mesh", "out", "frames", "threads", "set"}},
  };
  return kSubcommands;
}

const Subcommand* FindSubcommand(const std::string& name) {
  for (const Subcommand& subcommand : Subcommands()) {
    if (name == subcommand.name) return &subcommand;
  }
  return nullptr;
}

std::string FlagHelp(const char* name) {
  gflags::CommandLineFlagInfo info;
  gflags::GetCommandLineFlagInfo(name, &info);
  std::string text = "  --" + info.name + " (" + info.type + ")";
  if (!info.default_value.empty() && info.default_value != "-1") {
    text += " default " + info.default_value;
  }
  return text + "\n      " + info.description + "\n";
}

std::string ConfigKeysHelp() {
  Config defaults;
  return MakeConfigSchema(&defaults).HelpText();
}

void PrintMainHelp() {
  std::string text = "finecap " FINECAP_VERSION
                     ": fine-scale surface detail for multi-view performance capture.\n\n"
                     "Usage: finecap <subcommand> [--config FILE] [flags]\n\nSubcommands:\n";
  for (const Subcommand& subcommand : Subcommands()) {
    text += "  " + std::string(subcommand.name) + "\n      " + subcommand.summary + "\n";
  }
  text += "\nFlags (a flag overrides its config key):\n";
  for (const char* flag : {"config", "capture", "mesh", "out", "frames", "shard", "solver", "frame",
                           "threads", "set"}) {
    text += FlagHelp(flag);
  }
  text += "\nProcess settings (finecap/util/process.h; the defaults are what measured best):\n";
  for (const char* flag : {"one_malloc_arena", "huge_page_heap_mb"}) text += FlagHelp(flag);
  text += "\nConfig keys (YAML sections and keys; type, default, meaning):\n" + ConfigKeysHelp();
  text += "\n`finecap <subcommand> --help` describes one subcommand.\n";
  std::cout << text;
}

void PrintSubcommandHelp(const Subcommand& subcommand) {
  std::string text =
      std::string(subcommand.summary) + "\n\nUsage: " + subcommand.usage + "\n\nFlags:\n";
  for (const char* flag : subcommand.flags) text += FlagHelp(flag);
  text += "\nConfig keys:\n" + ConfigKeysHelp();
  std::cout << text;
}

// Splits "a=1,b=2" into overrides; a value may not itself contain a comma.
std::vector<ConfigOverride> ParseSetFlag(const std::string& text) {
  std::vector<ConfigOverride> overrides;
  size_t start = 0;
  while (start < text.size()) {
    const size_t comma = std::min(text.find(',', start), text.size());
    const std::string item = text.substr(start, comma - start);
    const size_t equals = item.find('=');
    Require(equals != std::string::npos && equals > 0, "--set",
            "expected key=value, got '" + item + "'");
    overrides.push_back({item.substr(0, equals), item.substr(equals + 1), "--set"});
    start = comma + 1;
  }
  return overrides;
}

std::vector<ConfigOverride> FlagOverrides() {
  std::vector<ConfigOverride> overrides;
  if (!FLAGS_capture.empty()) overrides.push_back({"capture.dir", FLAGS_capture, "--capture"});
  if (!FLAGS_mesh.empty()) overrides.push_back({"capture.mesh", FLAGS_mesh, "--mesh"});
  if (!FLAGS_out.empty()) overrides.push_back({"output.dir", FLAGS_out, "--out"});
  if (!FLAGS_frames.empty()) overrides.push_back({"capture.frames", FLAGS_frames, "--frames"});
  if (!FLAGS_shard.empty()) overrides.push_back({"runtime.shard", FLAGS_shard, "--shard"});
  if (!FLAGS_solver.empty()) {
    // The command line spells it with a hyphen, as the paper's method name reads.
    std::string solver = FLAGS_solver;
    std::replace(solver.begin(), solver.end(), '-', '_');
    overrides.push_back({"solver.type", solver, "--solver"});
  }
  if (FLAGS_threads >= 0) {
    overrides.push_back({"runtime.threads", std::to_string(FLAGS_threads), "--threads"});
  }
  for (ConfigOverride& override_value : ParseSetFlag(FLAGS_set)) {
    overrides.push_back(std::move(override_value));
  }
  return overrides;
}

int Main(int argc, char** argv) {
  gflags::SetVersionString(FINECAP_VERSION);
  gflags::SetUsageMessage("finecap <subcommand> [--config FILE] [flags]; see finecap --help");
  gflags::ParseCommandLineNonHelpFlags(&argc, &argv, /*remove_flags=*/true);
  // Before any thread starts (none has: flag parsing starts none).
  const ProcessOptions process{.one_malloc_arena = FLAGS_one_malloc_arena,
                               .huge_page_heap_mb = FLAGS_huge_page_heap_mb};
  try {
    process.Check();
  } catch (const Error& error) {
    throw Error("--huge_page_heap_mb", error.problem());  // Its only option with a range.
  }
  const bool huge_pages = ApplyProcessOptions(process);
  FLAGS_logtostderr = true;
  google::InitGoogleLogging(argv[0]);
  VLOG(1) << (SleepingWorkersSetByFinecap()
                  ? "OpenMP's workers sleep between loops (OMP_WAIT_POLICY=passive)"
                  : "OpenMP's wait policy is the environment's")
          << "; " << (FLAGS_one_malloc_arena ? "one malloc arena" : "glibc's malloc arenas") << "; "
          << (huge_pages ? "the heap on huge pages" : "the heap on the system's pages");

  if (FLAGS_config_keys_markdown) {
    Config defaults;
    std::cout << MakeConfigSchema(&defaults).MarkdownTable();
    return 0;
  }
  if (argc < 2) {
    PrintMainHelp();
    return FLAGS_help ? 0 : 2;
  }
  const Subcommand* subcommand = FindSubcommand(argv[1]);
  if (subcommand == nullptr) {
    std::cerr << "finecap: unknown subcommand '" << argv[1] << "' (see finecap --help)\n";
    return 2;
  }
  if (FLAGS_help) {
    PrintSubcommandHelp(*subcommand);
    return 0;
  }
  if (argc > 2) {
    std::cerr << "finecap " << subcommand->name << ": unexpected argument '" << argv[2]
              << "' (see finecap " << subcommand->name << " --help)\n";
    return 2;
  }
  const Config config = LoadConfig(FLAGS_config, FlagOverrides());
  SetWorkerThreads(config.runtime.threads);
  return subcommand->run(config);
}

}  // namespace
}  // namespace finecap

int main(int argc, char** argv) {
  try {
    return finecap::Main(argc, argv);
  } catch (const finecap::Error& error) {
    std::cerr << "finecap: error: " << finecap::InConfigTerms(error.what()) << "\n";
  } catch (const std::exception& error) {
    std::cerr << "finecap: internal error: " << error.what() << "\n";
  }
  return 1;
}
