// finecap refine: every configured frame of a capture, refined and written to output.dir.
#include <charconv>
#include <cmath>
#include <future>
#include <iostream>
#include <sstream>

#include "commands/command_util.h"
#include "commands/run_folder.h"
#include "finecap/atomic_file.h"
#include "finecap/commands.h"
#include "finecap/comparison.h"
#include "finecap/error.h"
#include "finecap/frame_stats.h"
#include "finecap/heldout_score.h"
#include "finecap/mesh_io.h"
#include "finecap/metrics.h"
#include "finecap/problem_size.h"
#include "finecap/shard.h"
#include "finecap/solver_trace.h"

namespace finecap {
namespace {

// One number per line, written in the shortest form that reads back to the same double, so that
// a frame seeded from this file (a resumed run's warm start) starts exactly where a run that never
// stopped would.
void WriteDisplacement(const std::string& path, const Eigen::VectorXd& k) {
  std::string text =
      "# displacement along the normal of each vertex of the refined mesh, metres; nan where "
      "not refined\n";
  char number[64];
  for (int v = 0; v < k.size(); ++v) {
    const auto written = std::to_chars(number, number + sizeof(number), k[v]);
    text.append(number, written.ptr).push_back('\n');
  }
  WriteTextFileAtomically(path, text);
}

// With refine.warm_start: the saved displacement of the frame before `frame`, as solved (bias
// compensation taken off), which seeds `frame`; empty when that frame is not done in `out` (the
// frame then starts from zero). Always from the saved file, so that a resumed run or a shard
// seeds its first frame exactly as a run that never stopped seeds every frame.
Eigen::VectorXd WarmStart(const std::string& out, const Capture& capture, int frame,
                          const Config& config, const SequenceModel& model) {
  if (!config.refine.warm_start || frame == 0) return {};
  const internal::FrameFiles previous =
      internal::FrameFilesIn(out, capture.frame_name(frame - 1), config.output.mesh_format);
  if (!internal::FrameDone(previous)) return {};
  return SolvedDisplacement(
      internal::ReadDisplacement(previous.displacement, model.num_fine_vertices()),
      ReadFrameStats(previous.stats).kept_input, config.refine);
}

// The refined vertices outside and inside the capture's textureless region.
struct Regions {
  std::vector<int> textured, textureless;
};

Regions SplitByTexture(const SequenceModel& model, const Capture& capture) {
  std::vector<bool> textureless(model.num_fine_vertices(), false);
  for (int v : model.SubdivideIds(capture.textureless_vertices())) textureless[v] = true;
  Regions regions;
  for (int v : model.refined_vertices()) {
    (textureless[v] ? regions.textureless : regions.textured).push_back(v);
  }
  return regions;
}

void AddGroundTruthErrors(const Capture& capture, const SequenceModel& model, const Mesh& coarse,
                          int frame, const Regions& regions, const FrameResult& result,
                          FrameStats* stats) {
  const Eigen::VectorXd truth = internal::TrueFineDisplacement(capture, model, coarse, frame);
  if (truth.size() == 0) return;
  // Only where the result has a displacement: both figures over the same vertices.
  const Eigen::VectorXd input = result.k.array().isFinite().select(0.0 * result.k, result.k);
  stats->rms_coarse_mm = 1000.0 * ComputeErrorStats(input, truth, regions.textured).rms;
  stats->rms_refined_mm = 1000.0 * ComputeErrorStats(result.k, truth, regions.textured).rms;
  stats->rms_textureless_coarse_mm =
      1000.0 * ComputeErrorStats(input, truth, regions.textureless).rms;
  stats->rms_textureless_refined_mm =
      1000.0 * ComputeErrorStats(result.k, truth, regions.textureless).rms;
}

// The held-out score of the frame's input and of its result (as solved), into `stats`; a result
// whose held-out NCC is below the input's is flagged worse and, with keep_input_if_worse,
// replaced by the input.
void ScoreInHeldOutViews(const Config& config, const SequenceModel& model, const FrameInput& input,
                         const std::vector<CalibratedImage>& held_out, FrameResult* result,
                         FrameStats* stats) {
  if (held_out.empty()) return;
  const auto start = std::chrono::steady_clock::now();
  const Mesh fine_input = model.Subdivide(input.coarse);
  const HeldOutScore score =
      ScoreHeldOutViews(internal::CalibratedImagesOf(input), held_out,
                        {&fine_input, &result->refined}, config.validation.score);
  stats->heldout_ncc_input = score.mean[0].ncc;
  stats->heldout_ncc_refined = score.mean[1].ncc;
  stats->heldout_mad_input = score.mean[0].mad;
  stats->heldout_mad_refined = score.mean[1].mad;
  stats->seconds_heldout =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!(score.mean[1].ncc < score.mean[0].ncc)) return;
  result->worse = stats->worse = true;
  if (config.refine.keep_input_if_worse && !result->kept_input) {
    KeepInputSurface(fine_input, result);
    stats->kept_input = true;
  }
}

// The size of the first frame's problem and what it forecasts, before the long part of the run.
void PrintProblemSize(const Config& config, const SequenceModel& model,
                      const ReferenceColors& colors, Capture* capture, int first_frame,
                      int frames) {
  FrameInput first = internal::ReadFrameInput(capture, first_frame);
  internal::TakeHeldOutViews(config, &first);  // Refine never sees them.
  const ProblemSize size = EstimateProblemSize(model, colors, first, config.refine);
  const Camera& camera = first.cameras.front();
  std::cerr << "finecap refine: " << frames << " frames, " << first.cameras.size() << " cameras of "
            << camera.width << "x" << camera.height << ", " << size.num_surface_gaussians
            << " surface Gaussians (of " << size.num_fine_vertices
            << " vertices after subdivision), about " << internal::RoundedCount(size.num_pairs)
            << " pairs; expected peak memory " << std::lround(size.peak_memory_mb) << " MB, about "
            << internal::RoundedSeconds(size.seconds_per_frame) << " per frame\n";
}

// Reads frames' inputs (the coarse mesh, every camera's image decoded and undistorted) one frame
// ahead on a thread of its own, so that reading the next frame overlaps solving this one and both
// cores stay busy. Only this reader reads images from the capture while it lives; at most one
// frame is read ahead (bounded memory).
class FrameReader {
 public:
  FrameReader(Capture* capture, bool skip_unreadable)
      : capture_(capture), skip_unreadable_(skip_unreadable) {}

  // Starts reading `frame` in the background (after any read still under way).
  void ReadAhead(int frame) {
    if (pending_.valid()) return;
    pending_frame_ = frame;
    pending_ = std::async(std::launch::async, [this, frame] { return Read(frame); });
  }

  // The input of `frame`: the one read ahead when it is that frame (its errors are thrown here),
  // else read now. The cameras skipped go to *skipped.
  FrameInput Take(int frame, std::vector<std::string>* skipped) {
    if (pending_.valid() && pending_frame_ == frame) {
      Frame read = pending_.get();
      *skipped = std::move(read.skipped);
      return std::move(read.input);
    }
    pending_ = {};  // Waits for a read of another frame, and drops it.
    Frame read = Read(frame);
    *skipped = std::move(read.skipped);
    return std::move(read.input);
  }

 private:
  struct Frame {
    FrameInput input;
    std::vector<std::string> skipped;
  };
  Frame Read(int frame) {
    Frame read;
    read.input = internal::ReadFrameInput(capture_, frame, skip_unreadable_, &read.skipped);
    return read;
  }

  Capture* capture_;
  bool skip_unreadable_;
  int pending_frame_ = -1;
  std::future<Frame> pending_;
};

}  // namespace

int RunRefine(const Config& configured) {
  Capture capture = internal::OpenConfiguredCapture(configured);
  const FrameRange frames =
      ShardOf(internal::ConfiguredFrames(configured, capture), configured.runtime.shard);
  const Config config = internal::WithSceneLengths(configured, capture, "refine");
  const std::string out = internal::PrepareOutputFolder(config, capture);
  const int stale = internal::PrepareRunSubfolders(out);
  if (stale > 0) std::cerr << "finecap refine: removed " << stale << " files a killed run left\n";
  const internal::StatsLog stats_log(out, capture.frame_names(), config.output.mesh_format);
  stats_log.Rebuild();
  if (frames.size() == 0) {
    std::cout << "Shard " << config.runtime.shard.ToString() << " holds none of the "
              << internal::ConfiguredFrames(config, capture).size() << " configured frames\n";
    return 0;
  }

  const SequenceModel model(capture.ReadCoarseMesh(0), capture.vertex_mask(), config.refine,
                            capture.mesh_path(0));
  const ReferenceColors colors = internal::LoadOrComputeReferenceColors(
      config, model, &capture, out + "/reference_colors.txt");
  const Regions regions = SplitByTexture(model, capture);
  PrintProblemSize(config, model, colors, &capture, frames.begin, frames.size());

  internal::Progress progress(frames.size());
  FrameReader reader(&capture, config.capture.skip_unreadable_cameras);
  double sum_coarse2 = 0.0, sum_refined2 = 0.0;
  int measured = 0;
  for (int frame = frames.begin; frame < frames.end; ++frame) {
    const std::string& name = capture.frame_name(frame);
    const internal::FrameFiles files = internal::FrameFilesIn(out, name, config.output.mesh_format);
    if (internal::FrameDone(files)) {
      progress.FrameDone(name, true, "");
      continue;
    }
    const auto start = std::chrono::steady_clock::now();
    std::vector<std::string> skipped;
    FrameInput input = reader.Take(frame, &skipped);
    const std::vector<CalibratedImage> held_out = internal::TakeHeldOutViews(config, &input);
    for (int next = frame + 1; next < frames.end; ++next) {
      if (internal::FrameDone(
              internal::FrameFilesIn(out, capture.frame_name(next), config.output.mesh_format))) {
        continue;
      }
      reader.ReadAhead(next);
      break;
    }
    const Eigen::VectorXd warm_start = WarmStart(out, capture, frame, config, model);
    FrameResult result = warm_start.size() > 0
                             ? RefineFrameFrom(model, colors, input, config.refine, warm_start)
                             : RefineFrame(model, colors, input, config.refine);
    if (result.num_surface_gaussians == 0) {
      std::cerr << "finecap refine: warning: frame " << name
                << ": no camera sees any vertex to refine (the mesh is behind every camera or "
                   "out of view); the input surface is written\n";
    }

    FrameStats stats = MakeFrameStats(name, config.refine, result);
    stats.skipped_cameras = skipped;
    ScoreInHeldOutViews(config, model, input, held_out, &result, &stats);
    AddGroundTruthErrors(capture, model, input.coarse, frame, regions, result, &stats);
    const Eigen::VectorXd quality = result.k.array().isFinite().select(result.k, 0.0);
    WriteMesh(files.mesh, result.refined, {result.normals, {}, quality},
              config.output.mesh_format == "obj" ? MeshFormat::kObj : MeshFormat::kPly);
    WriteDisplacement(files.displacement, result.k);
    WriteTextFileAtomically(files.trace, SolverTraceCsv(result.summary.trace));
    stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    // Last: the record marks the frame done.
    const std::string record = ToJson(stats);
    WriteTextFileAtomically(files.stats, record + "\n");
    stats_log.Append(record);

    std::ostringstream detail;
    detail.precision(3);
    detail << "E " << stats.energy_start << " -> " << stats.energy_end << ", " << stats.iterations
           << " iterations";
    if (std::isfinite(stats.heldout_ncc_input)) {
      detail << ", held-out NCC " << stats.heldout_ncc_input << " -> " << stats.heldout_ncc_refined;
    }
    detail << (stats.worse ? ", WORSE" : "") << (stats.kept_input ? " (input kept)" : "");
    if (std::isfinite(stats.rms_refined_mm)) {
      detail << ", RMS vs truth " << stats.rms_coarse_mm << " -> " << stats.rms_refined_mm << " mm";
      sum_coarse2 += stats.rms_coarse_mm * stats.rms_coarse_mm;
      sum_refined2 += stats.rms_refined_mm * stats.rms_refined_mm;
      ++measured;
    }
    progress.FrameDone(name, false, detail.str());
  }
  stats_log.Rebuild();
  std::cout << "Refined meshes: " << out << "/meshes/, displacements: " << out
            << "/k/, statistics: " << out << "/stats.jsonl\n";
  if (measured > 0) {
    const double coarse = std::sqrt(sum_coarse2 / measured);
    const double refined = std::sqrt(sum_refined2 / measured);
    std::cout.precision(3);
    std::cout << "Error against the ground truth (textured region, RMS over the frames run now): "
              << "input " << coarse << " mm, refined " << refined << " mm, detail recovered "
              << 100.0 * (1.0 - refined / coarse) << " %\n";
  }
  return 0;
}

}  // namespace finecap
