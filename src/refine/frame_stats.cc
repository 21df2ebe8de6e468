#include "finecap/refine/frame_stats.h"

#include <malloc.h>
#include <sys/resource.h>

#include <cmath>
#include <ctime>
#include <fstream>
#include <limits>
#include <sstream>

#include "finecap/util/error.h"
#include "util/flat_json.h"
#include "util/io_util.h"

namespace finecap {

using internal::JsonNumber;
using internal::JsonString;

double PeakResidentMegabytes() {
  rusage usage = {};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;  // Linux reports kilobytes.
}

double HeapInUseMegabytes() {
  const struct mallinfo2 heap = mallinfo2();
  return static_cast<double>(heap.uordblks + heap.hblkhd) / (1 << 20);
}

double ProcessCpuSeconds() {
  timespec now = {};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &now);
  return static_cast<double>(now.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec);
}

FrameStats MakeFrameStats(const std::string& frame, const RefineOptions& options,
                          const FrameResult& result) {
  FrameStats stats;
  const SolverSummary& summary = result.summary;
  stats.frame = frame;
  stats.solver = EnumToString(options.solver.type);
  stats.similarity = EnumToString(options.energy.similarity);
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
  stats.seconds_similarity = summary.seconds_similarity;
  stats.surface_gaussians = result.num_surface_gaussians;
  stats.confident_share = ConfidentShare(result);
  stats.k_max_mm = 1000.0 * result.k_max;
  stats.camera_shift_px = result.camera_shift;
  stats.image_gaussians = result.num_image_gaussians;
  stats.pairs = result.num_pairs;
  stats.worse = result.worse;
  stats.kept_input = result.kept_input;
  stats.prepared_ahead = result.prepared_ahead;
  stats.rms_coarse_mm = stats.rms_subdivided_mm = stats.rms_refined_mm = std::nan("");
  stats.rms_textureless_coarse_mm = stats.rms_textureless_subdivided_mm =
      stats.rms_textureless_refined_mm = std::nan("");
  stats.peak_rss_mb = PeakResidentMegabytes();
  stats.heap_in_use_mb = HeapInUseMegabytes();
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
       << ", \"seconds_similarity\": " << JsonNumber(s.seconds_similarity)
       << ", \"seconds_heldout\": " << JsonNumber(s.seconds_heldout)
       << ", \"cpu_seconds\": " << JsonNumber(s.cpu_seconds)
       << ", \"surface_gaussians\": " << s.surface_gaussians
       << ", \"confident_share\": " << JsonNumber(s.confident_share)
       << ", \"k_max_mm\": " << JsonNumber(s.k_max_mm)
       << ", \"camera_shift_px\": " << JsonNumber(s.camera_shift_px)
       << ", \"image_gaussians\": " << s.image_gaussians << ", \"pairs\": " << s.pairs
       << ", \"worse\": " << (s.worse ? "true" : "false")
       << ", \"kept_input\": " << (s.kept_input ? "true" : "false")
       << ", \"prepared_ahead\": " << (s.prepared_ahead ? "true" : "false")
       << ", \"rms_coarse_mm\": " << JsonNumber(s.rms_coarse_mm)
       << ", \"rms_subdivided_mm\": " << JsonNumber(s.rms_subdivided_mm)
       << ", \"rms_refined_mm\": " << JsonNumber(s.rms_refined_mm)
       << ", \"flicker_coarse_mm\": " << JsonNumber(s.flicker_coarse_mm)
       << ", \"flicker_subdivided_mm\": " << JsonNumber(s.flicker_subdivided_mm)
       << ", \"flicker_refined_mm\": " << JsonNumber(s.flicker_refined_mm)
       << ", \"rms_textureless_coarse_mm\": " << JsonNumber(s.rms_textureless_coarse_mm)
       << ", \"rms_textureless_subdivided_mm\": " << JsonNumber(s.rms_textureless_subdivided_mm)
       << ", \"rms_textureless_refined_mm\": " << JsonNumber(s.rms_textureless_refined_mm)
       << ", \"heldout_ncc_input\": " << JsonNumber(s.heldout_ncc_input)
       << ", \"heldout_ncc_subdivided\": " << JsonNumber(s.heldout_ncc_subdivided)
       << ", \"heldout_ncc_refined\": " << JsonNumber(s.heldout_ncc_refined)
       << ", \"heldout_mad_input\": " << JsonNumber(s.heldout_mad_input)
       << ", \"heldout_mad_subdivided\": " << JsonNumber(s.heldout_mad_subdivided)
       << ", \"heldout_mad_refined\": " << JsonNumber(s.heldout_mad_refined)
       << ", \"peak_rss_mb\": " << JsonNumber(s.peak_rss_mb)
       << ", \"heap_in_use_mb\": " << JsonNumber(s.heap_in_use_mb) << ", \"skipped_cameras\": [";
  for (size_t c = 0; c < s.skipped_cameras.size(); ++c) {
    json << (c > 0 ? ", " : "") << JsonString(s.skipped_cameras[c]);
  }
  json << "]}";
  return json.str();
}

namespace {

using internal::FlatJsonValue;

// Which field of FrameStats each key of a record fills.
struct StatsFields {
  std::vector<std::pair<const char*, std::string FrameStats::*>> strings = {
      {"frame", &FrameStats::frame},
      {"solver", &FrameStats::solver},
      {"similarity", &FrameStats::similarity},
      {"termination", &FrameStats::termination}};
  std::vector<std::pair<const char*, double FrameStats::*>> reals = {
      {"energy_start", &FrameStats::energy_start},
      {"energy_end", &FrameStats::energy_end},
      {"ls_cost_start", &FrameStats::ls_cost_start},
      {"ls_cost_end", &FrameStats::ls_cost_end},
      {"seconds", &FrameStats::seconds},
      {"seconds_preparation", &FrameStats::seconds_preparation},
      {"seconds_solve", &FrameStats::seconds_solve},
      {"seconds_evaluation", &FrameStats::seconds_evaluation},
      {"seconds_linear_solver", &FrameStats::seconds_linear_solver},
      {"seconds_similarity", &FrameStats::seconds_similarity},
      {"seconds_heldout", &FrameStats::seconds_heldout},
      {"cpu_seconds", &FrameStats::cpu_seconds},
      {"confident_share", &FrameStats::confident_share},
      {"k_max_mm", &FrameStats::k_max_mm},
      {"camera_shift_px", &FrameStats::camera_shift_px},
      {"rms_coarse_mm", &FrameStats::rms_coarse_mm},
      {"rms_subdivided_mm", &FrameStats::rms_subdivided_mm},
      {"rms_refined_mm", &FrameStats::rms_refined_mm},
      {"flicker_coarse_mm", &FrameStats::flicker_coarse_mm},
      {"flicker_subdivided_mm", &FrameStats::flicker_subdivided_mm},
      {"flicker_refined_mm", &FrameStats::flicker_refined_mm},
      {"rms_textureless_coarse_mm", &FrameStats::rms_textureless_coarse_mm},
      {"rms_textureless_subdivided_mm", &FrameStats::rms_textureless_subdivided_mm},
      {"rms_textureless_refined_mm", &FrameStats::rms_textureless_refined_mm},
      {"heldout_ncc_input", &FrameStats::heldout_ncc_input},
      {"heldout_ncc_subdivided", &FrameStats::heldout_ncc_subdivided},
      {"heldout_ncc_refined", &FrameStats::heldout_ncc_refined},
      {"heldout_mad_input", &FrameStats::heldout_mad_input},
      {"heldout_mad_subdivided", &FrameStats::heldout_mad_subdivided},
      {"heldout_mad_refined", &FrameStats::heldout_mad_refined},
      {"peak_rss_mb", &FrameStats::peak_rss_mb},
      {"heap_in_use_mb", &FrameStats::heap_in_use_mb}};
  std::vector<std::pair<const char*, int FrameStats::*>> ints = {
      {"iterations", &FrameStats::iterations},
      {"evaluations", &FrameStats::evaluations},
      {"surface_gaussians", &FrameStats::surface_gaussians}};
  std::vector<std::pair<const char*, long FrameStats::*>> longs = {
      {"image_gaussians", &FrameStats::image_gaussians}, {"pairs", &FrameStats::pairs}};
  std::vector<std::pair<const char*, bool FrameStats::*>> bools = {
      {"worse", &FrameStats::worse},
      {"kept_input", &FrameStats::kept_input},
      {"prepared_ahead", &FrameStats::prepared_ahead}};
  std::vector<std::pair<const char*, std::vector<std::string> FrameStats::*>> lists = {
      {"skipped_cameras", &FrameStats::skipped_cameras}};
};

void RequireKind(const FlatJsonValue& value, FlatJsonValue::Kind kind, const std::string& where,
                 const std::string& key, const std::string& expected) {
  Require(value.kind == kind, where, "key \"" + key + "\" must be " + expected);
}

// A whole number within [min, max], as a long.
long ReadWholeNumber(const FlatJsonValue& value, const std::string& where, const std::string& key,
                     long min, long max) {
  RequireKind(value, FlatJsonValue::Kind::kNumber, where, key, "an integer");
  Require(value.number == std::floor(value.number) && value.number >= static_cast<double>(min) &&
              value.number <= static_cast<double>(max),
          where,
          "key \"" + key + "\" must be an integer in [" + std::to_string(min) + ", " +
              std::to_string(max) + "]");
  return static_cast<long>(value.number);
}

// Sets the field of `fields` named `key` to convert(); false when none has that name.
template <typename Field, typename Convert>
bool AssignNamed(const std::vector<std::pair<const char*, Field FrameStats::*>>& fields,
                 const std::string& key, FrameStats* stats, Convert convert) {
  for (const auto& [name, field] : fields) {
    if (key != name) continue;
    stats->*field = convert();
    return true;
  }
  return false;
}

// Fills the field named `key`; false when no field has that name.
bool AssignField(const std::string& key, const FlatJsonValue& value, const std::string& where,
                 FrameStats* stats) {
  using Kind = FlatJsonValue::Kind;
  static const StatsFields fields;
  const auto text = [&] {
    RequireKind(value, Kind::kString, where, key, "a string");
    return value.text;
  };
  const auto real = [&] {
    Require(value.kind == Kind::kNumber || value.kind == Kind::kNull, where,
            "key \"" + key + "\" must be a number or null");
    return value.kind == Kind::kNull ? std::nan("") : value.number;
  };
  const auto whole_int = [&] {
    return static_cast<int>(ReadWholeNumber(value, where, key, std::numeric_limits<int>::min(),
                                            std::numeric_limits<int>::max()));
  };
  // 2^53: the largest range in which every whole double is exact.
  const auto whole_long = [&] { return ReadWholeNumber(value, where, key, -(1L << 53), 1L << 53); };
  const auto boolean = [&] {
    RequireKind(value, Kind::kBool, where, key, "true or false");
    return value.boolean;
  };
  const auto texts = [&] {
    RequireKind(value, Kind::kStringList, where, key, "a list of strings");
    return value.texts;
  };
  return AssignNamed(fields.strings, key, stats, text) ||
         AssignNamed(fields.reals, key, stats, real) ||
         AssignNamed(fields.ints, key, stats, whole_int) ||
         AssignNamed(fields.longs, key, stats, whole_long) ||
         AssignNamed(fields.bools, key, stats, boolean) ||
         AssignNamed(fields.lists, key, stats, texts);
}

}  // namespace

FrameStats ParseFrameStats(const std::string& line, const std::string& where) {
  FrameStats stats;
  bool has_frame = false;
  for (const auto& [key, value] : internal::ParseFlatJsonObject(line, where)) {
    Require(AssignField(key, value, where, &stats), where, "unknown key \"" + key + "\"");
    has_frame = has_frame || key == "frame";
  }
  Require(has_frame, where, "missing key \"frame\"");
  return stats;
}

FrameStats ReadFrameStats(const std::string& path) {
  std::ifstream file(path);
  Require(file.good(), path, "cannot open the statistics record");
  std::string line;
  std::getline(file, line);
  return ParseFrameStats(line, path);
}

}  // namespace finecap
