// Speed of the image model: building the image Gaussians of a frame (8 cameras, 1004 x 1004) and
// querying them once per surface Gaussian, as the energy does.
#include <cmath>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <benchmark/benchmark.h>
#include <omp.h>
#include <opencv2/imgproc.hpp>

#include "finecap/geometry/color.h"
#include "finecap/model/image_gaussians.h"

namespace finecap {
namespace {

constexpr int kImageSide = 1004;
constexpr int kCameras = 8;

// A cloth-like texture: smooth colour noise, a plaid of two stripe families with a random period
// and phase, and a little sensor noise.
cv::Mat MakeTexturedImage(unsigned seed) {
  cv::RNG rng(seed);
  cv::Mat coarse(8, 8, CV_32FC3);
  rng.fill(coarse, cv::RNG::UNIFORM, cv::Scalar::all(40), cv::Scalar::all(215));
  cv::Mat smooth;
  cv::resize(coarse, smooth, cv::Size(kImageSide, kImageSide), 0, 0, cv::INTER_CUBIC);

  const double period_x = rng.uniform(24.0, 60.0), period_y = rng.uniform(24.0, 60.0);
  const cv::Vec3f stripe_x(rng.uniform(-60.f, 60.f), rng.uniform(-60.f, 60.f), 30.f);
  const cv::Vec3f stripe_y(20.f, rng.uniform(-60.f, 60.f), rng.uniform(-60.f, 60.f));
  for (int y = 0; y < kImageSide; ++y) {
    cv::Vec3f* row = smooth.ptr<cv::Vec3f>(y);
    const bool in_y_stripe = std::fmod(y, period_y) < 0.3 * period_y;
    for (int x = 0; x < kImageSide; ++x) {
      if (std::fmod(x, period_x) < 0.3 * period_x) row[x] += stripe_x;
      if (in_y_stripe) row[x] += stripe_y;
    }
  }
  cv::Mat noise(smooth.size(), CV_32FC3);
  rng.fill(noise, cv::RNG::NORMAL, cv::Scalar::all(0), cv::Scalar::all(1.5));
  smooth += noise;
  cv::Mat image;
  smooth.convertTo(image, CV_8UC3);
  return image;
}

const std::vector<cv::Mat>& FrameImages() {
  static const std::vector<cv::Mat> images = [] {
    std::vector<cv::Mat> made;
    for (int c = 0; c < kCameras; ++c) made.push_back(MakeTexturedImage(100 + c));
    return made;
  }();
  return images;
}

std::vector<std::string> CameraNames() {
  std::vector<std::string> names;
  for (int c = 0; c < kCameras; ++c) names.push_back("cam" + std::to_string(c));
  return names;
}

ImageGaussianOptions LeafSizeOptions(int min_leaf_size) {
  ImageGaussianOptions options;
  options.min_leaf_size = min_leaf_size;
  return options;
}

// The whole frame: 8 images converted to HSV and cut into Gaussians, on range(0) threads, with
// smallest leaves of range(1) pixels (1: finecap refine's default; 4: the paper's depth 8).
void BM_BuildFrameImageGaussians(benchmark::State& state) {
  const std::vector<cv::Mat>& images = FrameImages();
  const std::vector<std::string> names = CameraNames();
  const ImageGaussianOptions options = LeafSizeOptions(static_cast<int>(state.range(1)));
  const int previous_threads = omp_get_max_threads();
  omp_set_num_threads(static_cast<int>(state.range(0)));
  size_t leaves = 0;
  for (auto _ : state) {
    const std::vector<ImageGaussians> frame = BuildFrameImageGaussians(images, {}, options, names);
    leaves = 0;
    for (const ImageGaussians& gaussians : frame) leaves += gaussians.size();
    benchmark::DoNotOptimize(leaves);
  }
  omp_set_num_threads(previous_threads);
  state.counters["leaves_per_image"] = static_cast<double>(leaves) / kCameras;
  state.counters["images_per_s"] =
      benchmark::Counter(double(kCameras) * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_BuildFrameImageGaussians)
    ->ArgNames({"threads", "leaf"})
    ->ArgsProduct({{1, omp_get_max_threads()}, {1, 4}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

const ColorSpace kSpaces[] = {ColorSpace::kHsv, ColorSpace::kNormalizedRgb, ColorSpace::kLab};

// One image, one thread, by colour space and smallest leaf; the conversion alone for comparison.
void BM_BuildImageGaussians(benchmark::State& state) {
  ImageGaussianOptions options = LeafSizeOptions(static_cast<int>(state.range(1)));
  options.color_space = kSpaces[state.range(0)];
  state.SetLabel(ColorSpaceName(options.color_space));
  for (auto _ : state) {
    benchmark::DoNotOptimize(BuildImageGaussians(FrameImages()[0], cv::Mat(), options, "cam0"));
  }
}
BENCHMARK(BM_BuildImageGaussians)
    ->ArgNames({"space", "leaf"})
    ->ArgsProduct({{0, 1, 2}, {1, 4}})
    ->Unit(benchmark::kMillisecond);

void BM_ConvertImage(benchmark::State& state) {
  const ColorSpace space = kSpaces[state.range(0)];
  state.SetLabel(ColorSpaceName(space));
  for (auto _ : state) benchmark::DoNotOptimize(ConvertImage(FrameImages()[0], space, "cam0"));
}
BENCHMARK(BM_ConvertImage)->DenseRange(0, 2)->Unit(benchmark::kMillisecond);

// One frame's worth of queries for one camera: 80k surface Gaussians of sigma ~2.8 px (7 mm at
// ~3 m, f ~1200 px) spread over the central half of the image, reaching 3 sigma of the pair.
void BM_FindReaching(benchmark::State& state) {
  const ImageGaussians gaussians =
      BuildImageGaussians(FrameImages()[0], cv::Mat(), ImageGaussianOptions(), "cam0");
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> coordinate(0.25 * kImageSide, 0.75 * kImageSide);
  std::vector<Eigen::Vector2d> points(80000);
  for (Eigen::Vector2d& p : points) p = Eigen::Vector2d(coordinate(rng), coordinate(rng));
  std::vector<int> found;
  size_t total_found = 0;
  for (auto _ : state) {
    total_found = 0;
    for (const Eigen::Vector2d& p : points) {
      gaussians.FindReaching(p, 2.8, 3.0, &found);
      total_found += found.size();
    }
    benchmark::DoNotOptimize(total_found);
  }
  state.counters["found_per_query"] = double(total_found) / points.size();
  state.SetItemsProcessed(state.iterations() * points.size());
}
BENCHMARK(BM_FindReaching)->Unit(benchmark::kMillisecond);

// The queries of BuildCameraPairs: the same surface Gaussians, each moving along its normal over a
// segment of up to 16 px in any direction (the projection of +-k_max), among the 1 px leaves of
// finecap refine's default.
void BM_FindReachingSegment(benchmark::State& state) {
  const ImageGaussians gaussians =
      BuildImageGaussians(FrameImages()[0], cv::Mat(), LeafSizeOptions(1), "cam0");
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> coordinate(0.25 * kImageSide, 0.75 * kImageSide);
  std::uniform_real_distribution<double> angle(0.0, 2.0 * M_PI), length(0.0, 16.0);
  std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> segments(80000);
  for (auto& [start, end] : segments) {
    start = Eigen::Vector2d(coordinate(rng), coordinate(rng));
    const double a = angle(rng);
    end = start + length(rng) * Eigen::Vector2d(std::cos(a), std::sin(a));
  }
  std::vector<int> found;
  size_t total_found = 0;
  for (auto _ : state) {
    total_found = 0;
    for (const auto& [start, end] : segments) {
      gaussians.FindReachingSegment(start, end, 2.8, 3.0, &found);
      total_found += found.size();
    }
    benchmark::DoNotOptimize(total_found);
  }
  state.counters["found_per_query"] = double(total_found) / segments.size();
  state.SetItemsProcessed(state.iterations() * segments.size());
}
BENCHMARK(BM_FindReachingSegment)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace finecap

BENCHMARK_MAIN();
