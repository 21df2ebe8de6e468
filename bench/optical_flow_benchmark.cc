// Cost of one optical flow of the eval's flow figure: a 1004 x 1004 image (the synthetic
// captures' size) against a copy shifted by about a pixel, per method and DIS preset.
#include <string>

#include <benchmark/benchmark.h>
#include <opencv2/imgproc.hpp>

#include "finecap/eval/optical_flow.h"

namespace finecap {
namespace {

cv::Mat SmoothNoise(int size) {
  cv::Mat noise(size, size, CV_8UC3);
  cv::randu(noise, cv::Scalar::all(0), cv::Scalar::all(255));
  cv::GaussianBlur(noise, noise, cv::Size(0, 0), 1.5);
  return noise;
}

void RunFlow(benchmark::State& state, const OpticalFlowOptions& options) {
  const cv::Mat image = SmoothNoise(1004);
  cv::Mat shifted;
  const cv::Mat move = (cv::Mat_<double>(2, 3) << 1, 0, 1.3, 0, 1, -0.7);
  cv::warpAffine(image, shifted, move, image.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
  for (auto _ : state) {
    benchmark::DoNotOptimize(ComputeOpticalFlow(image, shifted, options, "benchmark").data);
  }
}

void BM_DisFlow(benchmark::State& state, const std::string& preset) {
  OpticalFlowOptions options;
  StringToEnum(preset, &options.dis_preset);
  RunFlow(state, options);
}
BENCHMARK_CAPTURE(BM_DisFlow, ultrafast, "ultrafast")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_DisFlow, fast, "fast")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_DisFlow, medium, "medium")->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_DeepFlow(benchmark::State& state) {
  OpticalFlowOptions options;
  options.method = FlowMethod::kDeepFlow;
  RunFlow(state, options);
}
BENCHMARK(BM_DeepFlow)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);

}  // namespace
}  // namespace finecap

BENCHMARK_MAIN();
