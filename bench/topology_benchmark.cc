// Building the topology structures of a 10k-vertex skirt-like tube: they are built once per
// sequence, but must stay in the milliseconds so that a run never waits on them.
#include <benchmark/benchmark.h>

#include "../tests/test_meshes.h"
#include "finecap/geometry/mesh_diagnostics.h"
#include "finecap/geometry/neighbourhood.h"
#include "finecap/geometry/subdivision.h"

namespace finecap {
namespace {

// 100 segments x 100 rings = 10,000 vertices, 19,800 triangles.
const Mesh& Tube() {
  static const Mesh tube = testing_meshes::TubeMesh(100, 100, 0.3, 0.6);
  return tube;
}

void BM_VertexNeighbourhoods(benchmark::State& state) {
  const int max_edge_distance = static_cast<int>(state.range(0));
  for (auto _ : state) {
    benchmark::DoNotOptimize(BuildVertexNeighbourhoods(Tube(), max_edge_distance));
  }
}
BENCHMARK(BM_VertexNeighbourhoods)->Arg(1)->Arg(2)->Arg(3)->Unit(benchmark::kMillisecond);

void BM_LoopSubdivisionStencil(benchmark::State& state) {
  const int levels = static_cast<int>(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(BuildLoopSubdivision(Tube(), levels));
}
BENCHMARK(BM_LoopSubdivisionStencil)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);

void BM_ButterflySubdivisionStencil(benchmark::State& state) {
  const int levels = static_cast<int>(state.range(0));
  for (auto _ : state) benchmark::DoNotOptimize(BuildButterflySubdivision(Tube(), levels));
}
BENCHMARK(BM_ButterflySubdivisionStencil)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);

// The per-frame cost once the stencil exists: one sparse product.
void BM_ApplySubdivision(benchmark::State& state) {
  const SubdivisionStencil stencil = BuildLoopSubdivision(Tube(), 1);
  for (auto _ : state) benchmark::DoNotOptimize(ApplySubdivision(stencil, Tube().vertices));
}
BENCHMARK(BM_ApplySubdivision)->Unit(benchmark::kMillisecond);

void BM_DiagnoseMesh(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(DiagnoseMesh(Tube()));
}
BENCHMARK(BM_DiagnoseMesh)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace finecap

BENCHMARK_MAIN();
