#include "finecap/eval/run_comparison.h"

#include <filesystem>

#include "finecap/energy/similarity_needs.h"
#include "finecap/eval/html_report.h"
#include "finecap/refine/frame_reader.h"
#include "finecap/refine/run_folder.h"
#include "finecap/solvers/solver_trace.h"
#include "finecap/util/atomic_file.h"
#include "finecap/util/error.h"
#include "finecap/util/plot.h"
#include "util/io_util.h"

namespace finecap {
namespace {

namespace fs = std::filesystem;

// The paper's E_sim (eq. 6) at a variant's result, with the variant's other settings.
double PaperSimilarityAtResult(const SequenceModel& model, const ReferenceColors& colors,
                               const FrameInput& input, const RefineOptions& refine,
                               const FrameStats& stats, const Eigen::VectorXd& k_fine) {
  RefineOptions options = refine;
  options.energy = WithThePapersSimilarity(options.energy);
  const PreparedFrame frame = PrepareFrame(model, colors, input, options);
  const Eigen::VectorXd k =
      frame.energy->UnknownsAtVertices(SolvedDisplacement(k_fine, stats.kept_input, options));
  double data = 0.0;  // E_data: the paper's similarity, its one data term.
  frame.energy->Evaluate(k, nullptr, &data);
  return data;
}

}  // namespace

VariantSummary MeasureRun(const ComparedRun& run, const FrameRange& frames, Capture* capture) {
  const SequenceOptions& options = run.options;
  const SequenceModel model(capture->ReadCoarseMesh(0), capture->vertex_mask(), options.refine,
                            capture->directory() + "/meshes");
  const ReferenceColors colors =
      ReadReferenceColors(ReferenceColorsPath(run.folder), model.num_fine_vertices());
  std::vector<FrameStats> records;
  std::vector<double> paper_similarity;
  for (int frame = frames.begin; frame < frames.end; ++frame) {
    const FrameFiles files =
        FrameFilesIn(run.folder, capture->frame_name(frame), options.mesh_format);
    records.push_back(ReadFrameStats(files.stats));
    const Eigen::VectorXd k = ReadDisplacement(files.displacement, model.num_fine_vertices());
    FrameInput input = ReadFrameInput(capture, frame);
    TakeHeldOutViews(options.held_out_cameras, &input);  // The energy as its refine saw it.
    paper_similarity.push_back(
        PaperSimilarityAtResult(model, colors, input, options.refine, records.back(), k));
  }
  return SummarizeVariant(run.name, records, paper_similarity);
}

namespace {

// The convergence of every variant on one frame, against iteration and against wall time.
std::vector<std::string> WriteConvergencePlots(const std::vector<ComparedRun>& runs,
                                               const std::string& frame, const std::string& out) {
  std::vector<PlotSeries> by_iteration, by_time;
  for (const ComparedRun& run : runs) {
    const std::string path = FrameFilesIn(run.folder, frame, run.options.mesh_format).trace;
    if (!fs::exists(path)) continue;  // A frame refined before traces were saved.
    PlotSeries iterations{run.name, {}, {}}, times{run.name, {}, {}};
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

void WriteReport(const std::vector<ComparedRun>& runs, const std::vector<VariantSummary>& rows,
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
  for (const ComparedRun& run : runs) report.AddParagraph(run.settings);
  if (!plots.empty()) report.AddSection("Convergence");
  for (const std::string& plot : plots) report.AddImageFile(plot);
  report.Write(path);
}

}  // namespace

void ShareReferenceColors(const std::vector<ComparedRun>& runs, size_t index) {
  const ComparedRun& run = runs[index];
  const std::string path = ReferenceColorsPath(run.folder);
  if (fs::exists(path)) return;
  const std::string recipe = ReferenceColorRecipe(run.options);
  for (size_t earlier = 0; earlier < index; ++earlier) {
    const std::string earlier_path = ReferenceColorsPath(runs[earlier].folder);
    if (ReferenceColorRecipe(runs[earlier].options) == recipe && fs::exists(earlier_path)) {
      fs::create_directories(run.folder);
      WriteTextFileAtomically(path, internal::ReadWholeFile(earlier_path));
      return;
    }
  }
}

ComparisonFiles WriteComparison(const std::vector<ComparedRun>& runs,
                                const std::vector<VariantSummary>& rows, int reference,
                                const std::string& plotted_frame, const std::string& folder) {
  const ComparisonFiles files{folder + "/comparison.csv", folder + "/comparison.md",
                              folder + "/report.html"};
  WriteTextFileAtomically(files.csv, ComparisonCsv(rows));
  WriteTextFileAtomically(files.markdown, ComparisonMarkdown(rows));
  const std::vector<std::string> plots = WriteConvergencePlots(runs, plotted_frame, folder);
  WriteReport(runs, rows, rows[reference].name, plots, files.report);
  return files;
}

}  // namespace finecap
