// finecap compare: several variants of the refinement on the same frames of the same capture,
// each refined into output.dir/<variant>/ as `finecap refine` would, then set side by side in
// comparison.csv, comparison.md, convergence plots and report.html.
#include <filesystem>
#include <iostream>
#include <sstream>

#include "commands/command_util.h"
#include "finecap/atomic_file.h"
#include "finecap/commands.h"
#include "finecap/comparison.h"
#include "finecap/error.h"
#include "finecap/html_report.h"
#include "finecap/plot.h"
#include "finecap/solver_trace.h"
#include "finecap/threads.h"
#include "io_util.h"

namespace finecap {
namespace {

namespace fs = std::filesystem;

struct Variant {
  CompareVariant spec;
  Config config;  // The shared config with the variant's settings, output.dir its own folder.
};

// Every variant's config, checked before anything is written.
std::vector<Variant> VariantConfigs(const Config& config) {
  Require(!config.compare.variants.empty(), "compare.variants",
          "no variants to compare (see configs/compare_solvers.yaml)");
  std::vector<Variant> variants;
  for (const CompareVariant& spec : config.compare.variants) {
    variants.push_back({spec, VariantConfig(config, spec)});
  }
  return variants;
}

// Everything the reference colours depend on (ComputeSequenceColors, and the held-out cameras it
// must not see): variants that agree on it share one computation.
std::string ReferenceColorRecipe(const Config& config) {
  const RefineOptions& refine = config.refine;
  std::ostringstream recipe;
  recipe.precision(17);
  recipe << config.reference_frame << " " << refine.subdivision_levels << " " << refine.sigma_hat
         << " " << EnumToString(refine.reference_colors) << " "
         << ColorSpaceName(refine.image.color_space) << " " << refine.image.max_depth << " "
         << refine.image.min_leaf_size << " " << refine.image.split_threshold << " "
         << refine.visibility.depth_tolerance << " " << refine.visibility.max_view_angle_deg << " "
         << refine.visibility.border_margin << " " << EnumToString(refine.energy.overlap) << " "
         << refine.energy.reach_sigmas;
  for (const std::string& held_out : config.validation.cameras) recipe << "\n" << held_out;
  return recipe.str();
}

std::string ColorsPath(const Variant& variant) {
  return variant.config.output.dir + "/reference_colors.txt";
}

// Gives variants[index] the reference colours an earlier variant with the same recipe saved,
// unless it has its own already.
void ShareReferenceColors(const std::vector<Variant>& variants, size_t index) {
  const Variant& variant = variants[index];
  if (fs::exists(ColorsPath(variant))) return;
  for (size_t earlier = 0; earlier < index; ++earlier) {
    if (ReferenceColorRecipe(variants[earlier].config) == ReferenceColorRecipe(variant.config) &&
        fs::exists(ColorsPath(variants[earlier]))) {
      fs::create_directories(variant.config.output.dir);
      WriteTextFileAtomically(ColorsPath(variant),
                              internal::ReadWholeFile(ColorsPath(variants[earlier])));
      return;
    }
  }
}

// The paper's E_sim (eq. 6) at a variant's result, with the variant's other settings.
double PaperSimilarityAtResult(const SequenceModel& model, const ReferenceColors& colors,
                               const FrameInput& input, const Config& config,
                               const FrameStats& stats, const Eigen::VectorXd& k_fine) {
  RefineOptions options = config.refine;
  options.energy.similarity = SimilarityType::kPaper;
  const PreparedFrame frame = PrepareFrame(model, colors, input, options);
  const std::vector<int>& ids = frame.energy->surface().vertex_ids;
  const double bias = options.bias_compensation && !stats.kept_input ? options.sigma_hat : 0.0;
  Eigen::VectorXd k(ids.size());
  for (size_t s = 0; s < ids.size(); ++s) k[s] = k_fine[ids[s]] - bias;
  double similarity = 0.0;
  frame.energy->Evaluate(k, nullptr, &similarity);
  return similarity;
}

// One variant's row, from the files its refinement wrote.
VariantSummary MeasureVariant(const Variant& variant, const FrameRange& frames, Capture* capture) {
  const Config& config = variant.config;
  const std::string& out = config.output.dir;
  const SequenceModel model(capture->ReadCoarseMesh(0), capture->vertex_mask(), config.refine,
                            capture->directory() + "/meshes");
  const ReferenceColors colors =
      ReadReferenceColors(ColorsPath(variant), model.num_fine_vertices());
  std::vector<FrameStats> records;
  std::vector<double> paper_similarity;
  for (int frame = frames.begin; frame < frames.end; ++frame) {
    const std::string& name = capture->frame_name(frame);
    records.push_back(ReadFrameStats(out + "/frames/" + name + ".json"));
    const Eigen::VectorXd k =
        internal::ReadDisplacement(out + "/k/" + name + ".txt", model.num_fine_vertices());
    FrameInput input = internal::ReadFrameInput(capture, frame);
    internal::TakeHeldOutViews(config, &input);  // The energy as the variant's refine saw it.
    paper_similarity.push_back(
        PaperSimilarityAtResult(model, colors, input, config, records.back(), k));
  }
  return SummarizeVariant(variant.spec.name, records, paper_similarity);
}

// The convergence of every variant on one frame, against iteration and against wall time.
std::vector<std::string> WriteConvergencePlots(const std::vector<Variant>& variants,
                                               const std::string& frame, const std::string& out) {
  std::vector<PlotSeries> by_iteration, by_time;
  for (const Variant& variant : variants) {
    const std::string path = variant.config.output.dir + "/traces/" + frame + ".csv";
    if (!fs::exists(path)) continue;  // A frame refined before traces were saved.
    PlotSeries iterations{variant.spec.name, {}, {}}, times{variant.spec.name, {}, {}};
    for (const SolverIteration& row : ReadSolverTraceCsv(path)) {
      iterations.x.push_back(row.iteration);
      iterations.y.push_back(row.energy);
      times.x.push_back(row.seconds);
      times.y.push_back(row.energy);
    }
    if (iterations.x.empty()) continue;
    by_iteration.push_back(iterations);
    by_time.push_back(times);
  }
  if (by_iteration.empty()) return {};
  PlotOptions options;
  options.y_label = "E (each variant's own energy; larger is better)";
  options.title = "Frame " + frame + ": E against iteration";
  options.x_label = "iteration";
  WriteLinePlot(out + "/convergence_iterations.png", by_iteration, options);
  options.title = "Frame " + frame + ": E against wall time of the solve";
  options.x_label = "seconds";
  WriteLinePlot(out + "/convergence_time.png", by_time, options);
  return {out + "/convergence_iterations.png", out + "/convergence_time.png"};
}

std::string SettingsText(const CompareVariant& variant) {
  std::string text = variant.name + ":";
  for (const auto& [path, value] : variant.settings) text += " " + path + "=" + value;
  return variant.settings.empty() ? text + " the config as it is" : text;
}

void WriteReport(const std::vector<Variant>& variants, const std::vector<VariantSummary>& rows,
                 const std::string& reference, const std::vector<std::string>& plots,
                 const std::string& path) {
  HtmlReport report("finecap comparison");
  report.AddSection("Variants");
  report.AddParagraph(
      "Per variant over the same frames: E reached is the mean over the frames of the variant's "
      "own energy (its similarity column says which), the paper's E_sim is eq. 6 evaluated at "
      "the result with the variant's other settings, errors are RMS of k - k_true over the "
      "refined vertices (root mean square of the per-frame figures), times are medians over the "
      "frames, and the time ratio is seconds per frame over those of " +
      reference + ".");
  report.AddTable(ComparisonTableHeader(), ComparisonTableRows(rows));
  for (const Variant& variant : variants) report.AddParagraph(SettingsText(variant.spec));
  if (!plots.empty()) report.AddSection("Convergence");
  for (const std::string& plot : plots) report.AddImageFile(plot);
  report.Write(path);
}

}  // namespace

int RunCompare(const Config& config) {
  std::vector<Variant> variants = VariantConfigs(config);
  Capture capture = internal::OpenConfiguredCapture(config);
  const FrameRange frames = internal::ConfiguredFrames(config, capture);
  for (Variant& variant : variants) {
    variant.config =
        internal::WithSceneLengths(variant.config, capture, "compare, " + variant.spec.name);
  }
  const std::string out = internal::PrepareOutputFolder(config, capture);
  for (Variant& variant : variants) variant.config.output.dir = out + "/" + variant.spec.name;

  std::vector<VariantSummary> rows;
  for (size_t i = 0; i < variants.size(); ++i) {
    std::cerr << "finecap compare: variant " << i + 1 << "/" << variants.size() << ", "
              << SettingsText(variants[i].spec) << "\n";
    ShareReferenceColors(variants, i);
    SetWorkerThreads(variants[i].config.runtime.threads);  // a variant may set runtime.threads
    RunRefine(variants[i].config);
    rows.push_back(MeasureVariant(variants[i], frames, &capture));
  }
  SetWorkerThreads(config.runtime.threads);
  const int reference = ReferenceVariant(rows, config.compare.reference);
  SetTimeRatios(reference, &rows);

  WriteTextFileAtomically(out + "/comparison.csv", ComparisonCsv(rows));
  WriteTextFileAtomically(out + "/comparison.md", ComparisonMarkdown(rows));
  const std::vector<std::string> plots =
      WriteConvergencePlots(variants, capture.frame_name(frames.end - 1), out);
  WriteReport(variants, rows, rows[reference].name, plots, out + "/report.html");
  std::cout << ComparisonMarkdown(rows) << "Comparison: " << out << "/comparison.csv, " << out
            << "/comparison.md, " << out << "/report.html\n";
  return 0;
}

}  // namespace finecap
