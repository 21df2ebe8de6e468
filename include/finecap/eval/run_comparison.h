// Several refined runs of the same frames of one capture (sequence.h), each in a run folder of its
// own, set side by side: each run measured from its files into a row (comparison.h), the rows
// written as comparison.csv and comparison.md, convergence plots from the solver traces, and
// report.html. Nothing here prints.
#ifndef FINECAP_EVAL_RUN_COMPARISON_H_
#define FINECAP_EVAL_RUN_COMPARISON_H_

#include <string>
#include <vector>

#include "finecap/eval/comparison.h"
#include "finecap/io/capture.h"
#include "finecap/io/frame_range.h"
#include "finecap/refine/sequence.h"

namespace finecap {

// One run of a comparison.
struct ComparedRun {
  std::string name;         // Its name in the tables and plots.
  std::string settings;     // What sets it apart, for the report: "name: key=value ...".
  SequenceOptions options;  // What it is refined with.
  std::string folder;       // Its run folder.
};

// Gives runs[index] the reference colours that an earlier run with the same recipe
// (ReferenceColorRecipe) saved, unless it has its own already: runs that agree on them compute
// them once.
void ShareReferenceColors(const std::vector<ComparedRun>& runs, size_t index);

// One run's row from the files its refinement wrote for `frames` (which must all be done): its
// records, and the paper's E_sim (eq. 6) at each frame's result as solved, with the run's other
// settings. Throws Error naming a file that is missing or malformed.
VariantSummary MeasureRun(const ComparedRun& run, const FrameRange& frames, Capture* capture);

// The files WriteComparison writes.
struct ComparisonFiles {
  std::string csv, markdown, report;
};

// Writes comparison.csv, comparison.md, the convergence plots of frame `plotted_frame` (of the
// runs whose traces hold it) and report.html into `folder`. `rows` are the runs' rows, in order,
// with their time ratios set against rows[reference].
ComparisonFiles WriteComparison(const std::vector<ComparedRun>& runs,
                                const std::vector<VariantSummary>& rows, int reference,
                                const std::string& plotted_frame, const std::string& folder);

}  // namespace finecap

#endif  // FINECAP_EVAL_RUN_COMPARISON_H_
