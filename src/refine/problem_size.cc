#include "finecap/refine/problem_size.h"

#include "energy/consensus_similarity.h"

#include <algorithm>

#include "finecap/energy/frame_energy.h"
#include "finecap/model/gaussian_pairs.h"

namespace finecap {
namespace {

// At most this many surface Gaussians per camera have their pairs counted, evenly spread: enough
// for a count within a few per cent (synth_skirt: 3.2 M pairs counted within 1 %), in a tenth of
// the time of counting them all, which the forecast once did on every camera of the first frame.
constexpr int kSampledSurfaceGaussians = 1000;

// The peak resident memory of a run, fitted to nine refinements on 2 cores (bench/
// memory_forecast.sh; the demo, synth_skirt and the temple with several sigma_hat, k_max,
// subdivision levels and view-angle caps; 0.35 M to 85 M pairs, 115 MB to 890 MB), every one
// within 4 % of its measured peak. The image Gaussians' own share is too small to measure.
constexpr double kBaseMegabytes = 88.0;  // The process: code, libraries, thread stacks, allocator.
// The 8-bit images and the buffers of one at a time.
constexpr double kBytesPerPixel = 5.5;
// The next frame's 8-bit images, read while this one is solved (runs of more than one frame).
constexpr double kBytesPerPixelReadAhead = 3.0;
// The consensus similarity's patch residuals, Jacobians and member rows, per surface Gaussian and
// camera that sees it.
constexpr double kConsensusBytesPerObservation = 400.0;
// The image Gaussian's id and the pair's colour weight; the consensus similarity's pairs carry no
// weight (every one is 1).
constexpr double kBytesPerPair = 8.0;
constexpr double kBytesPerConsensusPair = 4.0;
// Residual blocks, neighbourhoods, the regulariser and the solver's sparse matrices, which grow
// with the surface Gaussians (not with the cameras that see them): with conjugate gradients
// (Ceres' CGNR, the default), and with the sparse Cholesky factorisation, whose normal equations
// and factor add the rest.
constexpr double kBytesPerSurfaceGaussian = 1400.0;
constexpr double kBytesPerSurfaceGaussianCholesky = 3900.0;

// Seconds of one frame: the pairs dominate large problems (the colour tables and pair lists run
// over them), the solver's work per Gaussian small ones. Refitted to the first frames of
// bench/memory_forecast.sh's three captures (synth_demo 0.2 s, synth_skirt 0.5 s, the temple
// 2.9 s on the idle machine): within a factor of 2 of each.
constexpr double kSecondsPerPair = 0.16e-6;
constexpr double kSecondsPerSurfaceGaussian = 0.02e-3;

}  // namespace

ProblemSize EstimateProblemSize(const SequenceModel& model, const ReferenceColors& colors,
                                const FrameInput& frame, const RefineOptions& options,
                                int num_frames) {
  ProblemSize size;
  const Mesh fine = model.Subdivide(frame.coarse);
  const Eigen::Matrix3Xd normals = ComputeVertexNormals(fine);
  const auto visible = ComputeFrameVisibility(fine, normals, frame.cameras, options.visibility);
  size.num_fine_vertices = fine.num_vertices();
  size.num_refined_vertices = static_cast<int>(model.refined_vertices().size());
  for (int v : model.refined_vertices()) {
    bool seen = false;
    for (const auto& camera : visible) seen = seen || camera[v];
    size.num_unseen_refined_vertices += seen ? 0 : 1;
  }
  for (const auto& camera : visible) {
    size.visible_per_camera.push_back(
        static_cast<int>(std::count(camera.begin(), camera.end(), 1)));
  }

  const std::vector<ImageGaussians> images = FrameImageModels(frame, options.image);
  const SurfaceGaussians surface =
      MakeSurfaceGaussians(fine.vertices, normals, model.refined_vertices(), colors);
  size.num_surface_gaussians = surface.size();
  const PairOptions pair_options = EnergyPairOptions(options.energy);
  for (size_t c = 0; c < frame.cameras.size(); ++c) {
    std::vector<unsigned char> seen;
    for (int v : surface.vertex_ids) seen.push_back(visible[c][v]);
    const long observations = std::count(seen.begin(), seen.end(), 1);
    const int stride = static_cast<int>(std::max<long>(
        1, (observations + kSampledSurfaceGaussians - 1) / kSampledSurfaceGaussians));
    size.num_pairs +=
        CountCameraPairs(frame.cameras[c], images[c], surface, seen, pair_options, stride);
    size.num_observations += observations;
    size.num_image_gaussians += images[c].size();
    size.num_pixels += double(frame.cameras[c].width) * frame.cameras[c].height;
  }

  double bytes =
      size.num_pixels * (kBytesPerPixel + (num_frames > 1 ? kBytesPerPixelReadAhead : 0.0)) +
      size.num_pairs * (options.energy.similarity == SimilarityType::kConsensus
                            ? kBytesPerConsensusPair
                            : kBytesPerPair) +
      size.num_surface_gaussians * (options.solver.type == SolverType::kCeres &&
                                            options.solver.linear_solver != LinearSolverType::kCgnr
                                        ? kBytesPerSurfaceGaussianCholesky
                                        : kBytesPerSurfaceGaussian);
  if (options.energy.similarity == SimilarityType::kConsensus) {
    // Its colour tables (value and derivative, 3 floats each, per node), the residuals and
    // Jacobians of the patches (3 channels of about 7 members, two doubles each) per observation,
    // and the sweep's cost matrix and its smoothing copy; with more frames to come, the tables of
    // the next, which the sequence prepares while this one is solved (PrepareFrameAhead).
    const int nodes = ConsensusSimilarity::NumTableNodes(options.sigma_hat, options.energy.k_max);
    const int tables = num_frames > 1 ? 2 : 1;
    bytes += size.num_observations * (tables * nodes * 24.0 + kConsensusBytesPerObservation) +
             size.num_surface_gaussians * options.sweep.samples * 16.0;
  }
  size.peak_memory_mb = kBaseMegabytes + bytes / 1e6;
  size.seconds_per_frame =
      size.num_pairs * kSecondsPerPair + size.num_surface_gaussians * kSecondsPerSurfaceGaussian;
  return size;
}

}  // namespace finecap
