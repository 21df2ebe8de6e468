// One evaluation of the energy and its gradient on a synth_skirt frame (10k surface Gaussians,
// 8 cameras of 1004 x 1004), for both similarities, on one thread and on all threads, and the
// block summaries Ceres' evaluation callback prepares instead at the same point; the preparation
// of a frame (subdivision, visibility, image Gaussians, pair lists) and of its detail stage; one
// solve of it; and reading a frame's input (the coarse mesh and every camera's image, decoded and
// undistorted).
//
//   build/energy_benchmark [--benchmark_repetitions=5]
//
// The capture is generated once into a temporary folder (about ten seconds).
#include <omp.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <memory>

#include <benchmark/benchmark.h>

#include "finecap/config/config.h"
#include "finecap/io/capture.h"
#include "finecap/refine/frame_reader.h"
#include "finecap/refine/refine.h"
#include "finecap/solvers/solver.h"
#include "finecap/solvers/sweep.h"

namespace finecap {
namespace {

struct SkirtFrame {
  std::string dir;  // The capture, removed at exit.
  std::unique_ptr<SequenceModel> model;
  ReferenceColors colors;
  FrameInput input;
};

// Frame 3 of synth_skirt (its folds fully grown), colours from frame 0.
const SkirtFrame& Skirt() {
  static const SkirtFrame* frame = [] {
    Config config = LoadConfig(FINECAP_SOURCE_DIR "/configs/synth_skirt.yaml",
                               {{"synth.num_frames", "4", "benchmark"}});
    const std::string dir = (std::filesystem::temp_directory_path() /
                             ("finecap_bench_skirt_" + std::to_string(getpid())))
                                .string();
    GenerateSyntheticCapture(config.synth, dir);
    Capture capture = Capture::Open(dir);
    auto* skirt = new SkirtFrame;
    skirt->dir = dir;
    skirt->model = std::make_unique<SequenceModel>(capture.ReadCoarseMesh(0), capture.vertex_mask(),
                                                   config.refine, dir);
    skirt->colors =
        ComputeSequenceColors(*skirt->model, ReadFrameInput(&capture, 0), config.refine);
    skirt->input = ReadFrameInput(&capture, 3);
    static const std::string removed_at_exit = dir;
    std::atexit([] { std::filesystem::remove_all(removed_at_exit); });
    return skirt;
  }();
  return *frame;
}

RefineOptions Options(const std::string& similarity) {
  RefineOptions options;
  StringToEnum(similarity, &options.energy.similarity);
  return options;
}

void BM_EnergyAndGradient(benchmark::State& state, const std::string& similarity) {
  const SkirtFrame& skirt = Skirt();
  const int threads = state.range(0) > 0 ? static_cast<int>(state.range(0)) : omp_get_num_procs();
  PreparedFrame frame = PrepareFrame(*skirt.model, skirt.colors, skirt.input, Options(similarity));
  const Eigen::VectorXd k = Eigen::VectorXd::Constant(frame.energy->num_parameters(), 0.001);
  Eigen::VectorXd gradient;
  omp_set_num_threads(threads);
  for (auto _ : state) benchmark::DoNotOptimize(frame.energy->Evaluate(k, &gradient));
  omp_set_num_threads(omp_get_num_procs());
  state.counters["threads"] = threads;
  state.counters["surface_gaussians"] = frame.energy->num_parameters();
  state.counters["pairs"] = static_cast<double>(frame.energy->num_pairs());
}
BENCHMARK_CAPTURE(BM_EnergyAndGradient, consensus, std::string("consensus"))
    ->Arg(1)
    ->Arg(0)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_EnergyAndGradient, surface_color, std::string("surface_color"))
    ->Arg(1)
    ->Arg(0)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_EnergyAndGradient, paper, std::string("paper"))
    ->Arg(1)
    ->Arg(0)
    ->Unit(benchmark::kMillisecond);

// The plane-sweep start of a prepared frame (the default similarity): the data cost of every
// surface Gaussian at each of refine.sweep.samples displacements, smoothed over its neighbours.
void BM_SweepInitialization(benchmark::State& state) {
  const SkirtFrame& skirt = Skirt();
  const RefineOptions options;
  PreparedFrame frame = PrepareFrame(*skirt.model, skirt.colors, skirt.input, options);
  for (auto _ : state) {
    benchmark::DoNotOptimize(SweepInitialization(frame.energy.get(), options.sweep).data());
  }
}
BENCHMARK(BM_SweepInitialization)->Unit(benchmark::kMillisecond);

// One evaluation with its gradient on one thread where the solve starts (the plane sweep's k):
// the tables read at a spread of displacements, not all at one.
void BM_EnergyAndGradientAtSweep(benchmark::State& state) {
  const SkirtFrame& skirt = Skirt();
  const RefineOptions options;
  PreparedFrame frame = PrepareFrame(*skirt.model, skirt.colors, skirt.input, options);
  const Eigen::VectorXd k = SweepInitialization(frame.energy.get(), options.sweep);
  Eigen::VectorXd gradient;
  omp_set_num_threads(1);
  for (auto _ : state) benchmark::DoNotOptimize(frame.energy->Evaluate(k, &gradient));
  omp_set_num_threads(omp_get_num_procs());
}
BENCHMARK(BM_EnergyAndGradientAtSweep)->Unit(benchmark::kMillisecond);

// The same point, prepared as Ceres' evaluation callback prepares it: each block's |r|^2, J^T r and
// J^T J (BlockSummaries::PrepareBlockSummaries), on one thread.
void BM_BlockSummariesAtSweep(benchmark::State& state) {
  const SkirtFrame& skirt = Skirt();
  const RefineOptions options;
  PreparedFrame frame = PrepareFrame(*skirt.model, skirt.colors, skirt.input, options);
  const Eigen::VectorXd k = SweepInitialization(frame.energy.get(), options.sweep);
  omp_set_num_threads(1);
  for (auto _ : state) frame.energy->data_term(0).block_summaries()->PrepareBlockSummaries(k);
  omp_set_num_threads(omp_get_num_procs());
}
BENCHMARK(BM_BlockSummariesAtSweep)->Unit(benchmark::kMillisecond);

// The detail stage's block summaries (PrepareDetailEnergy: the images read at their own
// resolution at samples about a pixel apart) where it starts, the surface Gaussians' plane sweep
// standing in for their solve; on one thread and on all threads.
void BM_DetailBlockSummaries(benchmark::State& state) {
  const SkirtFrame& skirt = Skirt();
  const int threads = state.range(0) > 0 ? static_cast<int>(state.range(0)) : omp_get_num_procs();
  const RefineOptions options;
  PreparedFrame frame = PrepareFrame(*skirt.model, skirt.colors, skirt.input, options);
  const Eigen::VectorXd k = SweepInitialization(frame.energy.get(), options.sweep);
  PrepareDetailEnergy(*skirt.model, skirt.input, options, k, &frame);
  omp_set_num_threads(threads);
  for (auto _ : state) frame.energy->data_term(0).block_summaries()->PrepareBlockSummaries(k);
  omp_set_num_threads(omp_get_num_procs());
  state.counters["threads"] = threads;
  state.counters["blocks"] =
      static_cast<double>(frame.energy->data_term(0).residual_blocks().size());
}
BENCHMARK(BM_DetailBlockSummaries)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond);

// The detail stage's preparation (PrepareDetailEnergy) at the surface the plane sweep found:
// visibility, samples, images, the cameras' alignment (refine.camera_alignment.max_rounds: the
// first argument; 0 without) and the energy. With a second argument of 0, as its first pass is
// prepared, from the surface Gaussians' stage (prepared anew, untimed, before each); with 1, as
// each next pass is (refine.views_follow_surface), from the pass before, whose samples and
// images it takes over.
void BM_PrepareDetailEnergy(benchmark::State& state) {
  const SkirtFrame& skirt = Skirt();
  RefineOptions options;
  options.camera_alignment.max_rounds = static_cast<int>(state.range(0));
  const bool from_pass_before = state.range(1) != 0;
  PreparedFrame frame = PrepareFrame(*skirt.model, skirt.colors, skirt.input, options);
  const Eigen::VectorXd k = SweepInitialization(frame.energy.get(), options.sweep);
  if (from_pass_before) PrepareDetailEnergy(*skirt.model, skirt.input, options, k, &frame);
  for (auto _ : state) {
    if (!from_pass_before) {
      state.PauseTiming();
      frame = PrepareFrame(*skirt.model, skirt.colors, skirt.input, options);
      state.ResumeTiming();
    }
    PrepareDetailEnergy(*skirt.model, skirt.input, options, k, &frame);
  }
  state.counters["camera_shift_px"] = frame.camera_shift;
}
BENCHMARK(BM_PrepareDetailEnergy)
    ->Args({0, 0})
    ->Args({10, 0})
    ->Args({0, 1})
    ->Args({10, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The detail stage's second term (energy.consensus.surface_weight: the refined mesh itself, each
// sample moved with its face's corners): its reduced rows with their Jacobians where the stage
// starts, as BM_DetailBlockSummaries; through the patches that cover the faces (the default) or,
// with a second argument of 1, through every patch.
void BM_DetailSurfaceRows(benchmark::State& state) {
  const SkirtFrame& skirt = Skirt();
  const int threads = state.range(0) > 0 ? static_cast<int>(state.range(0)) : omp_get_num_procs();
  RefineOptions options;
  options.energy.consensus.surface_weight = 1.0;
  if (state.range(1) == 1) options.energy.consensus.surface_patches = SurfacePatches::kAll;
  PreparedFrame frame = PrepareFrame(*skirt.model, skirt.colors, skirt.input, options);
  const Eigen::VectorXd k = SweepInitialization(frame.energy.get(), options.sweep);
  PrepareDetailEnergy(*skirt.model, skirt.input, options, k, &frame);
  frame.energy->StartLastPass();
  DataTerm& surface = frame.energy->data_term(1);
  omp_set_num_threads(threads);
  for (auto _ : state) surface.PrepareResiduals(k, /*with_jacobians=*/true);
  omp_set_num_threads(omp_get_num_procs());
  state.counters["threads"] = threads;
  state.counters["blocks"] = static_cast<double>(surface.residual_blocks().size());
}
BENCHMARK(BM_DetailSurfaceRows)
    ->Args({1, 0})
    ->Args({0, 0})
    ->Args({1, 1})
    ->Unit(benchmark::kMillisecond);

// One solve of a prepared frame with Ceres and the linear solver named, from the plane sweep's
// start, as the first of a frame's passes: the solver's own work around the evaluations, beside
// BM_EnergyAndGradient's evaluation alone. Real time: the solve runs on all threads.
void BM_Solve(benchmark::State& state, const std::string& linear_solver) {
  const SkirtFrame& skirt = Skirt();
  RefineOptions options;
  StringToEnum(linear_solver, &options.solver.linear_solver);
  PreparedFrame frame = PrepareFrame(*skirt.model, skirt.colors, skirt.input, options);
  const Eigen::VectorXd start = SweepInitialization(frame.energy.get(), options.sweep);
  int evaluations = 0;
  for (auto _ : state) {
    Eigen::VectorXd k = start;
    evaluations = Solve(frame.energy.get(), options.solver, &k).evaluations;
    benchmark::DoNotOptimize(k.data());
  }
  state.counters["evaluations"] = evaluations;
}
BENCHMARK_CAPTURE(BM_Solve, cgnr, std::string("cgnr"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Solve, sparse_normal_cholesky, std::string("sparse_normal_cholesky"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_PrepareFrame(benchmark::State& state) {
  const SkirtFrame& skirt = Skirt();
  const RefineOptions options;
  for (auto _ : state) {
    PreparedFrame frame = PrepareFrame(*skirt.model, skirt.colors, skirt.input, options);
    benchmark::DoNotOptimize(frame.energy.get());
  }
}
BENCHMARK(BM_PrepareFrame)->Unit(benchmark::kMillisecond);

// What the frame loop's reader does for every frame: the part of a frame's time that is not
// compute on the model.
void BM_ReadFrame(benchmark::State& state) {
  Capture capture = Capture::Open(Skirt().dir);
  for (auto _ : state) {
    FrameInput input = ReadFrameInput(&capture, 3);
    benchmark::DoNotOptimize(input.images.data());
  }
  state.counters["cameras"] = capture.num_cameras();
}
BENCHMARK(BM_ReadFrame)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace finecap

BENCHMARK_MAIN();
