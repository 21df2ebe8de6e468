// A solver's convergence trace as a CSV file: `finecap refine` saves one per frame
// (traces/<frame>.csv) so that convergence plots can be redrawn from the files alone.
//
//   iteration,energy,seconds
//   0,-12.5,0.0001
//   1,-9.75,0.25
//
// `energy` is E of the configured energy (larger is better; see SolverIteration), `seconds` the
// wall time since the start of the solve.
#ifndef FINECAP_SOLVER_TRACE_H_
#define FINECAP_SOLVER_TRACE_H_

#include <string>
#include <vector>

#include "finecap/solvers/solver.h"

namespace finecap {

// The CSV text of `trace`: the header line, then one line per row, numbers with 10 significant
// digits.
std::string SolverTraceCsv(const std::vector<SolverIteration>& trace);

// Reads a file written from SolverTraceCsv. Throws Error naming the file and the line when the
// header is missing or a line does not hold three numbers.
std::vector<SolverIteration> ReadSolverTraceCsv(const std::string& path);

}  // namespace finecap

#endif  // FINECAP_SOLVER_TRACE_H_
