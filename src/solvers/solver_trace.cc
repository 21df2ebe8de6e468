#include "finecap/solvers/solver_trace.h"

#include <algorithm>
#include <sstream>

#include "finecap/util/error.h"
#include "util/io_util.h"

namespace finecap {
namespace {

constexpr char kHeader[] = "iteration,energy,seconds";

}  // namespace

std::string SolverTraceCsv(const std::vector<SolverIteration>& trace) {
  std::ostringstream csv;
  csv.precision(10);
  csv << kHeader << "\n";
  for (const SolverIteration& row : trace) {
    csv << row.iteration << "," << row.energy << "," << row.seconds << "\n";
  }
  return csv.str();
}

std::vector<SolverIteration> ReadSolverTraceCsv(const std::string& path) {
  std::istringstream text(internal::ReadWholeFile(path));
  std::string line;
  Require(std::getline(text, line) && line == kHeader, path,
          std::string("line 1: expected the header '") + kHeader + "'");
  std::vector<SolverIteration> trace;
  for (int line_number = 2; std::getline(text, line); ++line_number) {
    if (line.empty()) continue;
    std::replace(line.begin(), line.end(), ',', ' ');
    const std::vector<std::string> fields = internal::SplitWhitespace(line);
    SolverIteration row;
    Require(fields.size() == 3 && internal::ParseInt(fields[0], &row.iteration) &&
                internal::ParseDouble(fields[1], &row.energy) &&
                internal::ParseDouble(fields[2], &row.seconds),
            path, "line " + std::to_string(line_number) + ": expected iteration,energy,seconds");
    trace.push_back(row);
  }
  return trace;
}

}  // namespace finecap
