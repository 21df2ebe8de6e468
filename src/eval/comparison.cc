#include "finecap/eval/comparison.h"

#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include "finecap/measure/metrics.h"
#include "finecap/solvers/solver.h"
#include "finecap/util/error.h"

namespace finecap {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double Mean(const std::vector<double>& values) {
  double sum = 0.0;
  for (double value : values) sum += value;
  return sum / values.size();
}

double RootMeanSquare(const std::vector<double>& values) {
  double sum = 0.0;
  for (double value : values) sum += value * value;
  return std::sqrt(sum / values.size());
}

// Over the finite values only: NaN when there is none.
double RootMeanSquareOfFinite(const std::vector<double>& values) {
  std::vector<double> finite;
  for (double value : values) {
    if (std::isfinite(value)) finite.push_back(value);
  }
  return RootMeanSquare(finite);
}

// One number of every record, as double.
template <typename Number>
std::vector<double> Column(const std::vector<FrameStats>& frames, Number FrameStats::*field) {
  std::vector<double> values;
  for (const FrameStats& stats : frames) values.push_back(static_cast<double>(stats.*field));
  return values;
}

double Median(const std::vector<double>& values) { return Percentile(values, 50.0); }

// The numeric columns of every table after variant, solver, similarity and frames, in order:
// CSV name, heading with unit, field, the factor it is shown with, and the significant digits
// of the readable tables (energies of variants that converged differ in the fourth digit).
struct NumberColumn {
  const char* csv;
  const char* heading;
  double VariantSummary::*field;
  double scale;
  int digits = 4;
};

const std::vector<NumberColumn>& NumberColumns() {
  using V = VariantSummary;
  static const std::vector<NumberColumn> kColumns = {
      {"energy_end", "E reached (own energy)", &V::energy_end, 1.0, 6},
      {"paper_e_sim", "paper's E_sim at result", &V::paper_similarity, 1.0, 6},
      {"ls_cost_end", "LS cost", &V::ls_cost_end, 1.0, 6},
      {"rms_input_mm", "RMS input mm", &V::rms_input_mm, 1.0},
      {"rms_textured_mm", "RMS textured mm", &V::rms_textured_mm, 1.0},
      {"rms_textureless_mm", "RMS textureless mm", &V::rms_textureless_mm, 1.0},
      {"flicker_textured_mm", "flicker textured mm", &V::flicker_textured_mm, 1.0},
      {"detail_recovered_percent", "detail recovered %", &V::detail_recovered, 100.0},
      {"iterations", "iterations", &V::iterations, 1.0},
      {"evaluations", "evaluations", &V::evaluations, 1.0},
      {"seconds_per_frame", "s/frame", &V::seconds_per_frame, 1.0},
      {"seconds_solve", "solve s", &V::seconds_solve, 1.0},
      {"seconds_evaluation", "evaluation s", &V::seconds_evaluation, 1.0},
      {"seconds_linear_solver", "linear solver s", &V::seconds_linear_solver, 1.0},
      {"time_ratio", "time ratio", &V::time_ratio, 1.0},
  };
  return kColumns;
}

double Value(const NumberColumn& column, const VariantSummary& row) {
  return column.scale * (row.*column.field);
}

}  // namespace

VariantSummary SummarizeVariant(const std::string& name, const std::vector<FrameStats>& frames,
                                const std::vector<double>& paper_similarity) {
  Require(!frames.empty(), name, "no refined frame to summarise");
  Require(paper_similarity.size() == frames.size(), name,
          "one paper E_sim per frame expected, got " + std::to_string(paper_similarity.size()));
  VariantSummary row;
  row.name = name;
  row.solver = frames.front().solver;
  row.similarity = frames.front().similarity;
  row.frames = static_cast<int>(frames.size());
  row.energy_end = Mean(Column(frames, &FrameStats::energy_end));
  row.paper_similarity = Mean(paper_similarity);
  row.ls_cost_end = Mean(Column(frames, &FrameStats::ls_cost_end));
  row.rms_input_mm = RootMeanSquare(Column(frames, &FrameStats::rms_coarse_mm));
  row.rms_textured_mm = RootMeanSquare(Column(frames, &FrameStats::rms_refined_mm));
  row.rms_textureless_mm = RootMeanSquare(Column(frames, &FrameStats::rms_textureless_refined_mm));
  row.flicker_textured_mm = RootMeanSquareOfFinite(Column(frames, &FrameStats::flicker_refined_mm));
  row.detail_recovered = DetailRecovered(row.rms_textured_mm, row.rms_input_mm);
  row.iterations = Mean(Column(frames, &FrameStats::iterations));
  row.evaluations = Mean(Column(frames, &FrameStats::evaluations));
  row.seconds_per_frame = Median(Column(frames, &FrameStats::seconds));
  row.seconds_solve = Median(Column(frames, &FrameStats::seconds_solve));
  row.seconds_evaluation = Median(Column(frames, &FrameStats::seconds_evaluation));
  row.seconds_linear_solver = Median(Column(frames, &FrameStats::seconds_linear_solver));
  return row;
}

namespace {

// Whether the row's solver is the paper's: the reference of a comparison unless one is named.
bool SolvesAsThePaper(const VariantSummary& row) {
  SolverType type = SolverType::kCeres;  // Names the enum; StringToEnum sets it.
  return StringToEnum(row.solver, &type) && type == SolverType::kGradientAscent;
}

}  // namespace

int ReferenceVariant(const std::vector<VariantSummary>& rows, const std::string& reference) {
  for (size_t i = 0; i < rows.size(); ++i) {
    if (reference.empty() ? SolvesAsThePaper(rows[i]) : rows[i].name == reference) {
      return static_cast<int>(i);
    }
  }
  Require(reference.empty(), "reference variant", "'" + reference + "' is not a variant");
  return 0;
}

void SetTimeRatios(int reference, std::vector<VariantSummary>* rows) {
  const double base = rows->at(reference).seconds_per_frame;
  for (VariantSummary& row : *rows) row.time_ratio = row.seconds_per_frame / base;
}

std::string ComparisonCsv(const std::vector<VariantSummary>& rows) {
  std::ostringstream csv;
  csv << "variant,solver,similarity,frames";
  for (const NumberColumn& column : NumberColumns()) csv << "," << column.csv;
  csv << "\n";
  csv.precision(10);
  for (const VariantSummary& row : rows) {
    csv << row.name << "," << row.solver << "," << row.similarity << "," << row.frames;
    for (const NumberColumn& column : NumberColumns()) {
      const double value = Value(column, row);
      csv << ",";
      if (std::isfinite(value)) {
        csv << value;
      } else {
        csv << "nan";
      }
    }
    csv << "\n";
  }
  return csv.str();
}

std::vector<std::string> ComparisonTableHeader() {
  std::vector<std::string> header = {"variant", "solver", "similarity", "frames"};
  for (const NumberColumn& column : NumberColumns()) header.push_back(column.heading);
  return header;
}

std::vector<std::vector<TableCell>> ComparisonTableRows(const std::vector<VariantSummary>& rows) {
  std::vector<std::vector<TableCell>> cells;
  for (const VariantSummary& row : rows) {
    std::vector<TableCell> line = {row.name, row.solver, row.similarity, row.frames};
    for (const NumberColumn& column : NumberColumns()) {
      line.push_back(TableCell::Number(Value(column, row), column.digits));
    }
    cells.push_back(line);
  }
  return cells;
}

std::string ComparisonMarkdown(const std::vector<VariantSummary>& rows) {
  std::ostringstream text;
  const std::vector<std::string> header = ComparisonTableHeader();
  std::string rule = "|";
  for (const std::string& heading : header) {
    text << "| " << heading << " ";
    rule += "---|";
  }
  text << "|\n" << rule << "\n";
  for (const std::vector<TableCell>& line : ComparisonTableRows(rows)) {
    for (const TableCell& cell : line) text << "| " << cell.text() << " ";
    text << "|\n";
  }
  return text.str();
}

}  // namespace finecap
