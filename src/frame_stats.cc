#include "finecap/frame_stats.h"

#include <sys/resource.h>

#include <cmath>
#include <sstream>

#include "io_util.h"

namespace finecap {

using internal::JsonNumber;
using internal::JsonString;

double PeakResidentMegabytes() {
  rusage usage = {};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;  // Linux reports kilobytes.
}

FrameStats MakeFrameStats(const std::string& frame, const RefineOptions& options,
                          const FrameResult& result) {
  FrameStats stats;
  const SolverSummary& summary = result.summary;
  stats.frame = frame;
  stats.solver = options.solver.type;
  stats.similarity = options.energy.similarity;
  stats.energy_start = summary.energy_start;
  stats.energy_end = summary.energy_end;
  stats.ls_cost_start = summary.ls_cost_start;
  stats.ls_cost_end = summary.ls_cost_end;
  stats.iterations = summary.iterations;
  stats.evaluations = summary.evaluations;
  stats.termination = summary.termination;
  stats.seconds = result.seconds_total;
  stats.seconds_preparation = result.seconds_preparation;
  stats.seconds_solve = summary.seconds;
  stats.seconds_evaluation = summary.seconds_evaluation;
  stats.seconds_linear_solver = summary.seconds_linear_solver;
  stats.surface_gaussians = result.num_surface_gaussians;
  stats.image_gaussians = result.num_image_gaussians;
  stats.pairs = result.num_pairs;
  stats.worse = result.worse;
  stats.kept_input = result.kept_input;
  stats.rms_coarse_mm = stats.rms_refined_mm = std::nan("");
  stats.rms_textureless_coarse_mm = stats.rms_textureless_refined_mm = std::nan("");
  stats.peak_rss_mb = PeakResidentMegabytes();
  return stats;
}

std::string ToJson(const FrameStats& s) {
  std::ostringstream json;
  json << "{\"frame\": " << JsonString(s.frame) << ", \"solver\": " << JsonString(s.solver)
       << ", \"similarity\": " << JsonString(s.similarity)
       << ", \"energy_start\": " << JsonNumber(s.energy_start)
       << ", \"energy_end\": " << JsonNumber(s.energy_end)
       << ", \"ls_cost_start\": " << JsonNumber(s.ls_cost_start)
       << ", \"ls_cost_end\": " << JsonNumber(s.ls_cost_end) << ", \"iterations\": " << s.iterations
       << ", \"evaluations\": " << s.evaluations
       << ", \"termination\": " << JsonString(s.termination)
       << ", \"seconds\": " << JsonNumber(s.seconds)
       << ", \"seconds_preparation\": " << JsonNumber(s.seconds_preparation)
       << ", \"seconds_solve\": " << JsonNumber(s.seconds_solve)
       << ", \"seconds_evaluation\": " << JsonNumber(s.seconds_evaluation)
       << ", \"seconds_linear_solver\": " << JsonNumber(s.seconds_linear_solver)
       << ", \"surface_gaussians\": " << s.surface_gaussians
       << ", \"image_gaussians\": " << s.image_gaussians << ", \"pairs\": " << s.pairs
       << ", \"worse\": " << (s.worse ? "true" : "false")
       << ", \"kept_input\": " << (s.kept_input ? "true" : "false")
       << ", \"rms_coarse_mm\": " << JsonNumber(s.rms_coarse_mm)
       << ", \"rms_refined_mm\": " << JsonNumber(s.rms_refined_mm)
       << ", \"rms_textureless_coarse_mm\": " << JsonNumber(s.rms_textureless_coarse_mm)
       << ", \"rms_textureless_refined_mm\": " << JsonNumber(s.rms_textureless_refined_mm)
       << ", \"peak_rss_mb\": " << JsonNumber(s.peak_rss_mb) << "}";
  return json.str();
}

}  // namespace finecap
