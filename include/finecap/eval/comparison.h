// The figures of `finecap compare`: each variant's per-frame statistics records (frame_stats.h)
// summarised into one row, and the rows as CSV, Markdown and report tables.
#ifndef FINECAP_EVAL_COMPARISON_H_
#define FINECAP_EVAL_COMPARISON_H_

#include <string>
#include <vector>

#include "finecap/eval/html_report.h"
#include "finecap/refine/frame_stats.h"

namespace finecap {

// One variant over the frames it refined. Energies are means over the frames (they differ from
// frame to frame, so only variants on the same frames compare); errors are root mean squares of
// the per-frame RMS, millimetres; times are medians over the frames, seconds.
struct VariantSummary {
  std::string name;
  std::string solver;      // solver.type.
  std::string similarity;  // energy.similarity: which energy `energy_end` is.
  int frames = 0;
  double energy_end = 0.0;           // E of the variant's own energy at its result.
  double paper_similarity = 0.0;     // The paper's E_sim at the result; NaN when not measured.
  double ls_cost_end = 0.0;          // 1/2 sum of squared residuals of the least-squares form.
  double rms_input_mm = 0.0;         // Textured region, the input mesh as given; NaN without truth.
  double rms_textured_mm = 0.0;      // Textured region, the result.
  double rms_textureless_mm = 0.0;   // Textureless region, the result; NaN when there is none.
  double flicker_textured_mm = 0.0;  // Over the frames with one (FrameStats); NaN: none has.
  double detail_recovered = 0.0;     // 1 - rms_textured_mm / rms_input_mm (metrics.h).
  double iterations = 0.0;           // Mean per frame.
  double evaluations = 0.0;          // Mean per frame.
  double seconds_per_frame = 0.0;    // The whole frame: reading, preparation, solve, writing.
  double seconds_solve = 0.0;
  double seconds_evaluation = 0.0;     // Of the solve.
  double seconds_linear_solver = 0.0;  // Of the solve; Ceres only.
  double time_ratio = 0.0;  // seconds_per_frame over the reference variant's; see SetTimeRatios.
};

// Summarises the records of one variant's frames; `paper_similarity` holds the paper's E_sim
// per frame (same order; NaN entries where unknown). Throws Error when `frames` is empty or the
// sizes differ.
VariantSummary SummarizeVariant(const std::string& name, const std::vector<FrameStats>& frames,
                                const std::vector<double>& paper_similarity);

// The index of the reference variant: the one named `reference` when it is not empty, else the
// first whose solver is gradient_ascent, else 0. Throws Error when `reference` names no row.
int ReferenceVariant(const std::vector<VariantSummary>& rows, const std::string& reference);

// Sets every row's time_ratio to its seconds_per_frame over that of rows[reference].
void SetTimeRatios(int reference, std::vector<VariantSummary>* rows);

// The rows as CSV: a header line of snake_case column names, then one line per variant;
// numbers with 10 significant digits, "nan" where unknown.
std::string ComparisonCsv(const std::vector<VariantSummary>& rows);

// The column headings of the readable tables, with units.
std::vector<std::string> ComparisonTableHeader();
// The rows for HtmlReport::AddTable and ComparisonMarkdown (4 significant digits, "n/a").
std::vector<std::vector<TableCell>> ComparisonTableRows(const std::vector<VariantSummary>& rows);

// A Markdown table of the rows.
std::string ComparisonMarkdown(const std::vector<VariantSummary>& rows);

}  // namespace finecap

#endif  // FINECAP_EVAL_COMPARISON_H_
