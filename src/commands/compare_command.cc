// finecap compare: several variants of the refinement on the same frames of the same capture,
// each refined into output.dir/<variant>/ as `finecap refine` would, then set side by side in
// comparison.csv, comparison.md, convergence plots and report.html (run_comparison.h).
#include <iostream>

#include "commands/command_util.h"
#include "finecap/commands/commands.h"
#include "finecap/eval/run_comparison.h"
#include "finecap/util/error.h"
#include "finecap/util/threads.h"

namespace finecap {
namespace {

struct Variant {
  Config config;  // The shared config with the variant's settings, output.dir its own folder.
  ComparedRun run;
};

std::string SettingsText(const CompareVariant& variant) {
  std::string text = variant.name + ":";
  for (const auto& [path, value] : variant.settings) text += " " + path + "=" + value;
  return variant.settings.empty() ? text + " the config as it is" : text;
}

// Every variant's config, checked before anything is read or written.
std::vector<Config> VariantConfigs(const Config& config) {
  Require(!config.compare.variants.empty(), "compare.variants",
          "no variants to compare (see configs/compare_solvers.yaml)");
  std::vector<Config> configs;
  for (const CompareVariant& spec : config.compare.variants) {
    configs.push_back(VariantConfig(config, spec));
  }
  return configs;
}

// Every variant with its lengths chosen from the scene, refining into out/<variant>.
std::vector<Variant> Variants(const Config& config, const std::vector<Config>& configs,
                              const std::string& out) {
  std::vector<Variant> variants;
  for (size_t i = 0; i < configs.size(); ++i) {
    const CompareVariant& spec = config.compare.variants[i];
    variants.push_back({configs[i], {spec.name, SettingsText(spec), {}, out + "/" + spec.name}});
    variants.back().config.output.dir = variants.back().run.folder;
    variants.back().run.options = internal::SequenceOptionsOf(variants.back().config);
  }
  return variants;
}

}  // namespace

int RunCompare(const Config& config) {
  std::vector<Config> configs = VariantConfigs(config);
  Capture capture = internal::OpenConfiguredCapture(config);
  const FrameRange frames = internal::ConfiguredFrames(config, capture);
  for (size_t i = 0; i < configs.size(); ++i) {
    configs[i] = internal::WithSceneLengths(configs[i], capture,
                                            "compare, " + config.compare.variants[i].name);
  }
  const std::string out = internal::PrepareOutputFolder(config, capture);
  const std::vector<Variant> variants = Variants(config, configs, out);
  std::vector<ComparedRun> runs;
  for (const Variant& variant : variants) runs.push_back(variant.run);

  std::vector<VariantSummary> rows;
  for (size_t i = 0; i < variants.size(); ++i) {
    std::cerr << "finecap compare: variant " << i + 1 << "/" << variants.size() << ", "
              << runs[i].settings << "\n";
    ShareReferenceColors(runs, i);
    SetWorkerThreads(variants[i].config.runtime.threads);  // a variant may set runtime.threads
    internal::RefineConfiguredSequence(variants[i].config, frames, runs[i].folder,
                                       "compare, " + runs[i].name, &capture);
    rows.push_back(MeasureRun(runs[i], frames, &capture));
  }
  SetWorkerThreads(config.runtime.threads);
  const int reference = ReferenceVariant(rows, config.compare.reference);
  SetTimeRatios(reference, &rows);
  const ComparisonFiles files =
      WriteComparison(runs, rows, reference, capture.frame_name(frames.end - 1), out);
  std::cout << ComparisonMarkdown(rows) << "Comparison: " << files.csv << ", " << files.markdown
            << ", " << files.report << "\n";
  return 0;
}

}  // namespace finecap
