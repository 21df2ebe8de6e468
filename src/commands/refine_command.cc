// finecap refine: every configured frame of a capture, refined and written to output.dir.
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "commands/command_util.h"
#include "finecap/atomic_file.h"
#include "finecap/commands.h"
#include "finecap/error.h"
#include "finecap/frame_stats.h"
#include "finecap/mesh_io.h"
#include "finecap/metrics.h"
#include "finecap/scene_scale.h"
#include "finecap/solver_trace.h"

namespace finecap {
namespace {

namespace fs = std::filesystem;

// Where the results of one frame go.
struct FramePaths {
  std::string mesh, displacement, stats, trace;
};

FramePaths OutputPaths(const std::string& out, const std::string& frame, const Config& config) {
  return {out + "/meshes/" + frame + "." + config.output.mesh_format, out + "/k/" + frame + ".txt",
          out + "/frames/" + frame + ".json", out + "/traces/" + frame + ".csv"};
}

void WriteDisplacement(const std::string& path, const Eigen::VectorXd& k) {
  std::ostringstream text;
  text << "# displacement along the normal of each vertex of the refined mesh, metres; nan where "
          "not refined\n";
  text.precision(9);
  for (int v = 0; v < k.size(); ++v) text << k[v] << "\n";
  WriteTextFileAtomically(path, text.str());
}

// Rewrites stats.jsonl from the per-frame records of every frame done so far, in frame order.
void WriteStatsLines(const std::string& out, const Capture& capture, const Config& config) {
  std::string lines;
  for (const std::string& frame : capture.frame_names()) {
    std::ifstream record(OutputPaths(out, frame, config).stats);
    std::string line;
    if (record && std::getline(record, line)) lines += line + "\n";
  }
  WriteTextFileAtomically(out + "/stats.jsonl", lines);
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

void PrintProblemSize(const Capture& capture, const SequenceModel& model, int frames) {
  const Camera& camera = capture.cameras().front();
  const double pixels = double(camera.width) * camera.height * capture.num_cameras();
  // Images (8-bit and converted float), image Gaussians (~1 per 16 pixels), pair lists
  // (~40 pairs per visible surface Gaussian and camera, ~half the cameras see a vertex).
  const double megabytes =
      (pixels * (3 + 12 + 24.0 / 16) +
       model.refined_vertices().size() * capture.num_cameras() * 0.5 * 40 * 8.0) /
      1e6;
  std::cerr << "finecap refine: " << frames << " frames, " << capture.num_cameras()
            << " cameras of " << camera.width << "x" << camera.height << ", "
            << model.refined_vertices().size() << " surface Gaussians (of "
            << model.num_fine_vertices() << " vertices after subdivision); expected peak memory "
            << static_cast<long>(megabytes + 100) << " MB\n";
}

}  // namespace

int RunRefine(const Config& config) {
  Capture capture = internal::OpenConfiguredCapture(config);
  const FrameRange frames = internal::ConfiguredFrames(config, capture);
  RequirePlausibleSceneScale(capture.ReadCoarseMesh(0), config.refine.sigma_hat,
                             capture.mesh_path(0));
  const std::string out = internal::PrepareOutputFolder(config, capture);
  for (const char* folder : {"meshes", "k", "frames", "traces"})
    fs::create_directories(out + "/" + folder);

  const SequenceModel model(capture.ReadCoarseMesh(0), capture.vertex_mask(), config.refine,
                            capture.mesh_path(0));
  const ReferenceColors colors = internal::LoadOrComputeReferenceColors(
      config, model, &capture, out + "/reference_colors.txt");
  const Regions regions = SplitByTexture(model, capture);
  PrintProblemSize(capture, model, frames.size());

  internal::Progress progress(frames.size());
  Eigen::VectorXd previous_k;
  double sum_coarse2 = 0.0, sum_refined2 = 0.0;
  int measured = 0;
  for (int frame = frames.begin; frame < frames.end; ++frame) {
    const std::string& name = capture.frame_name(frame);
    const FramePaths paths = OutputPaths(out, name, config);
    if (fs::exists(paths.mesh) && fs::exists(paths.stats)) {
      progress.FrameDone(name, true, "");
      continue;
    }
    const auto start = std::chrono::steady_clock::now();
    std::vector<std::string> skipped;
    const FrameInput input =
        internal::ReadFrameInput(&capture, frame, config.capture.skip_unreadable_cameras, &skipped);
    const bool warm = config.refine.warm_start && previous_k.size() > 0;
    FrameResult result =
        RefineFrame(model, colors, input, config.refine, warm ? &previous_k : nullptr);
    previous_k = result.k_solved;
    if (result.num_surface_gaussians == 0) {
      std::cerr << "finecap refine: warning: frame " << name
                << ": no camera sees any vertex to refine (the mesh is behind every camera or "
                   "out of view); the input surface is written\n";
    }

    FrameStats stats = MakeFrameStats(name, config.refine, result);
    stats.skipped_cameras = skipped;
    AddGroundTruthErrors(capture, model, input.coarse, frame, regions, result, &stats);
    const Eigen::VectorXd quality = result.k.array().isFinite().select(result.k, 0.0);
    WriteMesh(paths.mesh, result.refined, {result.normals, {}, quality},
              config.output.mesh_format == "obj" ? MeshFormat::kObj : MeshFormat::kPly);
    WriteDisplacement(paths.displacement, result.k);
    WriteTextFileAtomically(paths.trace, SolverTraceCsv(result.summary.trace));
    stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    WriteTextFileAtomically(paths.stats, ToJson(stats) + "\n");
    WriteStatsLines(out, capture, config);

    std::ostringstream detail;
    detail.precision(3);
    detail << "E " << stats.energy_start << " -> " << stats.energy_end << ", " << stats.iterations
           << " iterations" << (stats.worse ? ", WORSE" : "");
    if (std::isfinite(stats.rms_refined_mm)) {
      detail << ", RMS vs truth " << stats.rms_coarse_mm << " -> " << stats.rms_refined_mm << " mm";
      sum_coarse2 += stats.rms_coarse_mm * stats.rms_coarse_mm;
      sum_refined2 += stats.rms_refined_mm * stats.rms_refined_mm;
      ++measured;
    }
    progress.FrameDone(name, false, detail.str());
  }
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
