#include "finecap/measure/heldout_score.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>

#include <Eigen/LU>
#include <opencv2/imgproc.hpp>

#include "finecap/geometry/render.h"
#include "finecap/util/error.h"

namespace finecap {

const OptionFields<HeldOutOptions>& HeldOutOptions::Fields() {
  static const OptionFields<HeldOutOptions> fields = [] {
    OptionFields<HeldOutOptions> f;
    f.AddInt("neighbours", &HeldOutOptions::neighbours,
             "Training views warped into each held-out view, the nearest by camera centre.", 1,
             1000);
    f.AddInt("window", &HeldOutOptions::window, "Side of the windows of the held-out NCC, pixels.",
             3, 31);
    f.AddDouble("min_std", &HeldOutOptions::min_std,
                "Held-out NCC windows whose grey levels vary less than this (standard deviation, "
                "0-255) are not scored.",
                0.0, 255.0);
    f.AddDouble("depth_tolerance_px", &HeldOutOptions::depth_tolerance_px,
                "A point counts as seen by a training view within this many pixel footprints "
                "behind its depth map there.",
                0.01, 1000.0);
    return f;
  }();
  return fields;
}

void HeldOutOptions::Check() const {
  Fields().CheckValues(*this, "HeldOutOptions::");
  // A window has a centre pixel.
  Require(window % 2 == 1, "HeldOutOptions::window",
          "is " + std::to_string(window) + " but must be odd");
}

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

void CheckView(const CalibratedImage& view, const std::string& role) {
  const std::string where = role + " camera " + view.camera.name;
  Require(view.image.type() == CV_8UC3 && view.image.cols == view.camera.width &&
              view.image.rows == view.camera.height,
          where, "the image is not 8-bit BGR of the camera's size");
  Require(
      view.mask.empty() || (view.mask.type() == CV_8UC1 && view.mask.size() == view.image.size()),
      where, "the mask is not CV_8UC1 of the image's size");
}

cv::Mat GreyLevels(const cv::Mat& bgr) {
  cv::Mat grey, levels;
  cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
  grey.convertTo(levels, CV_32F);
  return levels;
}

// Bilinear sample of a CV_32F image at (u, v), which lies within [0, cols-1] x [0, rows-1].
float SampleGrey(const cv::Mat& image, double u, double v) {
  const int x0 = std::min(static_cast<int>(u), std::max(0, image.cols - 2));
  const int y0 = std::min(static_cast<int>(v), std::max(0, image.rows - 2));
  const int x1 = std::min(x0 + 1, image.cols - 1), y1 = std::min(y0 + 1, image.rows - 1);
  const double a = u - x0, b = v - y0;
  return static_cast<float>((1 - b) *
                                ((1 - a) * image.at<float>(y0, x0) + a * image.at<float>(y0, x1)) +
                            b * ((1 - a) * image.at<float>(y1, x0) + a * image.at<float>(y1, x1)));
}

cv::Vec3b SampleColor(const cv::Mat& image, double u, double v) {
  const int x0 = std::min(static_cast<int>(u), std::max(0, image.cols - 2));
  const int y0 = std::min(static_cast<int>(v), std::max(0, image.rows - 2));
  const int x1 = std::min(x0 + 1, image.cols - 1), y1 = std::min(y0 + 1, image.rows - 1);
  const double a = u - x0, b = v - y0;
  cv::Vec3b color;
  for (int ch = 0; ch < 3; ++ch) {
    const double value =
        (1 - b) *
            ((1 - a) * image.at<cv::Vec3b>(y0, x0)[ch] + a * image.at<cv::Vec3b>(y0, x1)[ch]) +
        b * ((1 - a) * image.at<cv::Vec3b>(y1, x0)[ch] + a * image.at<cv::Vec3b>(y1, x1)[ch]);
    color[ch] = cv::saturate_cast<unsigned char>(value);
  }
  return color;
}

// Whether every pixel a bilinear read at (u, v), inside the image, blends is on the foreground
// of `mask`: what is read there then owes nothing to the background.
bool ReadsForegroundOnly(const cv::Mat& mask, double u, double v) {
  const int x0 = static_cast<int>(u), y0 = static_cast<int>(v);
  const int x1 = std::min(x0 + 1, mask.cols - 1), y1 = std::min(y0 + 1, mask.rows - 1);
  return mask.at<unsigned char>(y0, x0) != 0 && mask.at<unsigned char>(y0, x1) != 0 &&
         mask.at<unsigned char>(y1, x0) != 0 && mask.at<unsigned char>(y1, x1) != 0;
}

// One training view warped into a held-out view through one surface.
struct Warp {
  cv::Mat grey;   // CV_32F, 0 where not reached.
  cv::Mat color;  // CV_8UC3, black where not reached (only when asked for).
  cv::Mat valid;  // CV_8U, 255 where the surface point is seen by the training view.
};

Warp WarpThroughSurface(const Camera& target, const DepthMap& target_depth,
                        const CalibratedImage& source, const cv::Mat& source_grey,
                        const DepthMap& source_depth, const HeldOutOptions& options,
                        bool with_color) {
  Warp warp;
  warp.grey = cv::Mat::zeros(target.height, target.width, CV_32F);
  warp.valid = cv::Mat::zeros(target.height, target.width, CV_8U);
  if (with_color) warp.color = cv::Mat::zeros(target.height, target.width, CV_8UC3);
  const Eigen::Matrix3d target_inverse_k = target.K.inverse();
  const Eigen::Matrix3d rotation_back = target.R.transpose();
  const Camera& camera = source.camera;
  const double tolerance = options.depth_tolerance_px / camera.focal();
#pragma omp parallel for schedule(static)
  for (int y = 0; y < target.height; ++y) {
    for (int x = 0; x < target.width; ++x) {
      const float z = target_depth.depth.at<float>(y, x);
      if (!std::isfinite(z)) continue;
      const Eigen::Vector3d in_target = z * (target_inverse_k * Eigen::Vector3d(x, y, 1.0));
      const Eigen::Vector3d world = rotation_back * (in_target - target.t);
      const Eigen::Vector3d in_source = camera.R * world + camera.t;
      if (!(in_source.z() > 0.0)) continue;
      const Eigen::Vector3d pixel = camera.K * (in_source / in_source.z());
      const double u = pixel.x(), v = pixel.y();
      if (!(u >= 0.0 && v >= 0.0 && u <= camera.width - 1 && v <= camera.height - 1)) continue;
      const int nearest_x = static_cast<int>(std::lround(u));
      const int nearest_y = static_cast<int>(std::lround(v));
      const float seen = source_depth.depth.at<float>(nearest_y, nearest_x);
      if (!std::isfinite(seen) || in_source.z() > seen + tolerance * in_source.z()) continue;
      if (!source.mask.empty() && !ReadsForegroundOnly(source.mask, u, v)) continue;
      warp.valid.at<unsigned char>(y, x) = 255;
      warp.grey.at<float>(y, x) = SampleGrey(source_grey, u, v);
      if (with_color) warp.color.at<cv::Vec3b>(y, x) = SampleColor(source.image, u, v);
    }
  }
  return warp;
}

// Window sums of `image` (CV_32F or CV_64F), unnormalised, as CV_64F.
cv::Mat WindowSums(const cv::Mat& image, int window) {
  cv::Mat sums;
  cv::boxFilter(image, sums, CV_64F, cv::Size(window, window), cv::Point(-1, -1), false,
                cv::BORDER_CONSTANT);
  return sums;
}

// The held-out image's part of the NCC of one pair: its window statistics over the common pixels,
// and which pixels are scored (whole window common, enough variation).
struct HeldOutWindows {
  cv::Mat masked;  // The held-out grey levels, 0 outside the common pixels (CV_64F).
  cv::Mat mean, variance;
  cv::Mat scored;  // CV_8U.
  cv::Mat count;   // Window pixel counts (CV_64F).
};

HeldOutWindows MakeHeldOutWindows(const cv::Mat& grey, const cv::Mat& common,
                                  const HeldOutOptions& options) {
  HeldOutWindows windows;
  cv::Mat mask;
  common.convertTo(mask, CV_64F, 1.0 / 255.0);
  grey.convertTo(windows.masked, CV_64F);
  windows.masked = windows.masked.mul(mask);
  windows.count = WindowSums(mask, options.window);
  const cv::Mat safe_count = cv::max(windows.count, 1.0);
  windows.mean = WindowSums(windows.masked, options.window) / safe_count;
  windows.variance = WindowSums(windows.masked.mul(windows.masked), options.window) / safe_count -
                     windows.mean.mul(windows.mean);
  const double full = double(options.window) * options.window;
  windows.scored = (windows.count > full - 0.5) & (common > 0) &
                   (windows.variance >= options.min_std * options.min_std);
  return windows;
}

// NCC of the held-out windows with one warped image over the scored pixels (CV_32F, NaN
// elsewhere).
cv::Mat NccMap(const HeldOutWindows& windows, const cv::Mat& warped_grey, const cv::Mat& common,
               int window) {
  cv::Mat mask, warped;
  common.convertTo(mask, CV_64F, 1.0 / 255.0);
  warped_grey.convertTo(warped, CV_64F);
  warped = warped.mul(mask);
  const cv::Mat safe_count = cv::max(windows.count, 1.0);
  const cv::Mat mean = WindowSums(warped, window) / safe_count;
  const cv::Mat variance = WindowSums(warped.mul(warped), window) / safe_count - mean.mul(mean);
  const cv::Mat covariance =
      WindowSums(warped.mul(windows.masked), window) / safe_count - mean.mul(windows.mean);
  cv::Mat ncc(common.size(), CV_32F, cv::Scalar(kNaN));
  for (int y = 0; y < ncc.rows; ++y) {
    for (int x = 0; x < ncc.cols; ++x) {
      if (!windows.scored.at<unsigned char>(y, x)) continue;
      const double product = windows.variance.at<double>(y, x) * variance.at<double>(y, x);
      // A warped window without variation correlates with nothing.
      const double value = product > 1e-9 ? covariance.at<double>(y, x) / std::sqrt(product) : 0.0;
      ncc.at<float>(y, x) = static_cast<float>(std::clamp(value, -1.0, 1.0));
    }
  }
  return ncc;
}

// Rows of the held-out view whose NCC is computed at once. The window statistics are images of
// doubles, and over a whole full-size photo (2832 x 2128: 48 MB each) every one of the dozens a
// pair makes would exceed the largest block the heap holds (util/process.h), be mapped on its own
// and faulted in page by page; a band of 128 rows (and the window's half above and below it) keeps
// them in the heap and in the caches, and lets the bands run in parallel.
constexpr int kBandRows = 128;

// NccMap of every warped image of `warps`, band by band. A band's statistics are those of the
// whole view at its rows (the window never reaches beyond the rows read for it) up to the
// rounding of the box filter's running sums.
std::vector<cv::Mat> NccMaps(const cv::Mat& grey, const std::vector<Warp>& warps,
                             const cv::Mat& common, const HeldOutOptions& options) {
  std::vector<cv::Mat> maps;
  for (size_t s = 0; s < warps.size(); ++s) {
    maps.emplace_back(common.size(), CV_32F, cv::Scalar(kNaN));
  }
  const int rows = common.rows, halo = options.window / 2;
  const int num_bands = (rows + kBandRows - 1) / kBandRows;
#pragma omp parallel for schedule(dynamic)
  for (int band = 0; band < num_bands; ++band) {
    const int begin = band * kBandRows, end = std::min(rows, begin + kBandRows);
    const cv::Range read(std::max(0, begin - halo), std::min(rows, end + halo));
    const cv::Range kept(begin - read.start, end - read.start);
    const cv::Mat band_common = common.rowRange(read);
    const HeldOutWindows windows = MakeHeldOutWindows(grey.rowRange(read), band_common, options);
    for (size_t s = 0; s < warps.size(); ++s) {
      NccMap(windows, warps[s].grey.rowRange(read), band_common, options.window)
          .rowRange(kept)
          .copyTo(maps[s].rowRange(begin, end));
    }
  }
  return maps;
}

// 255 where a CV_32F map is finite (OpenCV's comparisons do not single out NaN).
cv::Mat FiniteMask(const cv::Mat& values) {
  cv::Mat mask(values.size(), CV_8U);
  for (int y = 0; y < values.rows; ++y) {
    for (int x = 0; x < values.cols; ++x) {
      mask.at<unsigned char>(y, x) = std::isfinite(values.at<float>(y, x)) ? 255 : 0;
    }
  }
  return mask;
}

// Mean of the finite values of a CV_32F map and their count.
std::pair<double, long> FiniteMean(const cv::Mat& values) {
  double sum = 0.0;
  long count = 0;
  for (int y = 0; y < values.rows; ++y) {
    for (int x = 0; x < values.cols; ++x) {
      const float value = values.at<float>(y, x);
      if (std::isfinite(value)) {
        sum += value;
        ++count;
      }
    }
  }
  return {count > 0 ? sum / count : kNaN, count};
}

double MeanAbsoluteDifference(const cv::Mat& a, const cv::Mat& b, const cv::Mat& common,
                              long* count) {
  *count = cv::countNonZero(common);
  if (*count == 0) return kNaN;
  cv::Mat difference;
  cv::absdiff(a, b, difference);
  return cv::mean(difference, common)[0];
}

// Mean of the finite entries; NaN when there is none.
double FiniteAverage(const std::vector<double>& values) {
  double sum = 0.0;
  int count = 0;
  for (double value : values) {
    if (std::isfinite(value)) {
      sum += value;
      ++count;
    }
  }
  return count > 0 ? sum / count : kNaN;
}

// Depth maps of the training views, rendered once per (view, surface) when first needed.
class TrainingDepths {
 public:
  TrainingDepths(const std::vector<CalibratedImage>& training,
                 const std::vector<const Mesh*>& surfaces)
      : training_(training), surfaces_(surfaces) {}

  const DepthMap& Get(int view, int surface) {
    auto [it, inserted] = depths_.try_emplace({view, surface});
    if (inserted) it->second = RenderDepth(training_[view].camera, *surfaces_[surface]);
    return it->second;
  }

 private:
  const std::vector<CalibratedImage>& training_;
  const std::vector<const Mesh*>& surfaces_;
  std::map<std::pair<int, int>, DepthMap> depths_;
};

// The mean of NCC maps over training views, per pixel where any scored it (NaN elsewhere).
class NccMapMean {
 public:
  void Add(const cv::Mat& map) {
    if (sum_.empty()) {
      sum_ = cv::Mat::zeros(map.size(), CV_32F);
      count_ = cv::Mat::zeros(map.size(), CV_32F);
    }
    const cv::Mat finite = FiniteMask(map);
    cv::Mat values = map.clone(), ones;
    values.setTo(0.0f, ~finite);
    finite.convertTo(ones, CV_32F, 1.0 / 255.0);
    sum_ += values;
    count_ += ones;
  }

  cv::Mat Mean(const cv::Size& size) const {
    cv::Mat mean(size, CV_32F, cv::Scalar(kNaN));
    if (sum_.empty()) return mean;
    const cv::Mat quotient = sum_ / cv::max(count_, 1.0f);
    quotient.copyTo(mean, count_ > 0.5f);
    return mean;
  }

 private:
  cv::Mat sum_, count_;
};

// The surfaces compared in one held-out view with one training view.
struct PairScore {
  std::vector<SurfaceScore> surfaces;
  long ncc_pixels = 0, common_pixels = 0;
  std::vector<cv::Mat> ncc_maps;  // Per surface.
  std::vector<cv::Mat> colors;    // Per surface, when asked for.
};

// What one held-out view shows, prepared once for all its training views.
struct HeldOutTarget {
  const CalibratedImage* view;
  cv::Mat grey;
  std::vector<DepthMap> depths;  // Per surface.
  cv::Mat covered;               // Pixels every surface covers.
};

PairScore ScorePair(const HeldOutTarget& target, const CalibratedImage& training,
                    const cv::Mat& training_grey, int training_index, int num_surfaces,
                    const HeldOutOptions& options, bool with_color,
                    TrainingDepths* training_depths) {
  std::vector<Warp> warps;
  cv::Mat common = target.covered.clone();
  for (int s = 0; s < num_surfaces; ++s) {
    warps.push_back(WarpThroughSurface(target.view->camera, target.depths[s], training,
                                       training_grey, training_depths->Get(training_index, s),
                                       options, with_color));
    common &= warps.back().valid;
  }
  PairScore pair;
  pair.ncc_maps = NccMaps(target.grey, warps, common, options);
  for (int s = 0; s < num_surfaces; ++s) {
    const auto [ncc, ncc_pixels] = FiniteMean(pair.ncc_maps[s]);
    const double mad =
        MeanAbsoluteDifference(target.grey, warps[s].grey, common, &pair.common_pixels);
    pair.surfaces.push_back({ncc, mad});
    pair.ncc_pixels = ncc_pixels;  // The same pixels for every surface.
    if (with_color) pair.colors.push_back(warps[s].color);
  }
  return pair;
}

// Scores one held-out view; fills `maps` when given.
HeldOutViewScore ScoreView(const CalibratedImage& held_out,
                           const std::vector<CalibratedImage>& training,
                           const std::vector<cv::Mat>& training_grey,
                           const std::vector<const Mesh*>& surfaces, const HeldOutOptions& options,
                           TrainingDepths* training_depths, HeldOutViewMaps* maps) {
  const int num_surfaces = static_cast<int>(surfaces.size());
  HeldOutTarget target{&held_out,
                       GreyLevels(held_out.image),
                       {},
                       cv::Mat(held_out.image.size(), CV_8U, cv::Scalar(255))};
  for (const Mesh* surface : surfaces) {
    target.depths.push_back(RenderDepth(held_out.camera, *surface));
    target.covered &= target.depths.back().triangle_ids >= 0;
  }
  if (!held_out.mask.empty()) target.covered &= held_out.mask != 0;
  std::vector<Camera> training_cameras;
  for (const CalibratedImage& view : training) training_cameras.push_back(view.camera);
  HeldOutViewScore score;
  score.camera = held_out.camera.name;
  std::vector<std::vector<double>> ncc(num_surfaces), mad(num_surfaces);
  std::vector<NccMapMean> map_means(num_surfaces);
  for (int t : NearestCameras(held_out.camera, training_cameras, options.neighbours)) {
    const bool with_color = maps != nullptr && score.training.empty();
    const PairScore pair = ScorePair(target, training[t], training_grey[t], t, num_surfaces,
                                     options, with_color, training_depths);
    score.training.push_back(training[t].camera.name);
    score.ncc_pixels += pair.ncc_pixels;
    score.common_pixels += pair.common_pixels;
    for (int s = 0; s < num_surfaces; ++s) {
      ncc[s].push_back(pair.surfaces[s].ncc);
      mad[s].push_back(pair.surfaces[s].mad);
      if (maps != nullptr) map_means[s].Add(pair.ncc_maps[s]);
    }
    if (with_color) maps->warped = pair.colors;
  }
  for (int s = 0; s < num_surfaces; ++s) {
    score.surfaces.push_back({FiniteAverage(ncc[s]), FiniteAverage(mad[s])});
    if (maps != nullptr) maps->ncc.push_back(map_means[s].Mean(held_out.image.size()));
  }
  if (maps != nullptr && maps->warped.empty()) {
    maps->warped.assign(num_surfaces, cv::Mat::zeros(held_out.image.size(), CV_8UC3));
  }
  return score;
}

}  // namespace

std::vector<int> NearestCameras(const Camera& target, const std::vector<Camera>& cameras,
                                int count) {
  std::vector<int> order(cameras.size());
  std::iota(order.begin(), order.end(), 0);
  const Eigen::Vector3d centre = target.Center();
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return (cameras[a].Center() - centre).squaredNorm() <
           (cameras[b].Center() - centre).squaredNorm();
  });
  order.resize(std::min<size_t>(order.size(), std::max(0, count)));
  return order;
}

HeldOutScore ScoreHeldOutViews(const std::vector<CalibratedImage>& training,
                               const std::vector<CalibratedImage>& held_out,
                               const std::vector<const Mesh*>& surfaces,
                               const HeldOutOptions& options, std::vector<HeldOutViewMaps>* maps) {
  options.Check();
  Require(!training.empty(), "held-out score", "no training view to warp in");
  Require(!surfaces.empty(), "held-out score", "no surface to score");
  for (const CalibratedImage& view : training) CheckView(view, "training");
  for (const CalibratedImage& view : held_out) CheckView(view, "held-out");
  std::vector<cv::Mat> training_grey;
  for (const CalibratedImage& view : training) training_grey.push_back(GreyLevels(view.image));
  TrainingDepths training_depths(training, surfaces);
  HeldOutScore score;
  if (maps != nullptr) maps->assign(held_out.size(), HeldOutViewMaps());
  for (size_t h = 0; h < held_out.size(); ++h) {
    score.views.push_back(ScoreView(held_out[h], training, training_grey, surfaces, options,
                                    &training_depths, maps ? &(*maps)[h] : nullptr));
  }
  for (size_t s = 0; s < surfaces.size(); ++s) {
    std::vector<double> ncc, mad;
    for (const HeldOutViewScore& view : score.views) {
      ncc.push_back(view.surfaces[s].ncc);
      mad.push_back(view.surfaces[s].mad);
    }
    score.mean.push_back({FiniteAverage(ncc), FiniteAverage(mad)});
  }
  return score;
}

}  // namespace finecap
