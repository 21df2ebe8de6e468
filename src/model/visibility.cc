#include "finecap/model/visibility.h"

#include <algorithm>
#include <cmath>
#include <functional>

#include "finecap/util/error.h"
#include "util/option_checks.h"

namespace finecap {

const OptionFields<VisibilityOptions>& VisibilityOptions::Fields() {
  static const OptionFields<VisibilityOptions> fields = [] {
    OptionFields<VisibilityOptions> f;
    f.AddDouble("depth_tolerance", &VisibilityOptions::depth_tolerance,
                "A vertex more than this behind the rendered input surface is occluded, m", 0.0,
                10.0);
    f.AddDouble("max_view_angle_deg", &VisibilityOptions::max_view_angle_deg,
                "Largest angle between a normal and the direction to a camera that sees it.", 1.0,
                90.0);
    f.AddDouble("fallback_view_angle_deg", &VisibilityOptions::fallback_view_angle_deg,
                "A vertex that fewer cameras see within max_view_angle_deg than the similarity "
                "compares takes the most frontal up to this angle, with less confidence; equal to "
                "max_view_angle_deg: none.",
                1.0, 90.0);
    f.AddDouble("max_pair_angle_deg", &VisibilityOptions::max_pair_angle_deg,
                "Widest angle between two cameras' directions to a vertex at which their "
                "agreement still counts fully towards its confidence (the narrowest pair of the "
                "cameras that see it).",
                1.0, 180.0);
    f.AddDouble("fallback_pair_angle_deg", &VisibilityOptions::fallback_pair_angle_deg,
                "Angle between two cameras' directions to a vertex at which their agreement no "
                "longer counts towards its confidence (falling from max_pair_angle_deg); equal to "
                "it: a sharp cut; both 180: any pair counts.",
                1.0, 180.0);
    f.AddDouble("sample_view_angle_deg", &VisibilityOptions::sample_view_angle_deg,
                "Largest angle between a normal of the surface the surface Gaussians found and "
                "the direction to a camera whose pixels the detail stage reads "
                "(energy.consensus.sample_spacing above 0).",
                1.0, 90.0);
    f.AddDouble("border_margin", &VisibilityOptions::border_margin,
                "Vertices projecting closer than this to the image border are not used, px.", 0.0,
                1000.0);
    return f;
  }();
  return fields;
}

void VisibilityOptions::Check() const {
  Fields().CheckValues(*this, "VisibilityOptions::");
  // The fallback widens the cone of the views that max_view_angle_deg admits, never narrows it.
  internal::RequireFieldRange(fallback_view_angle_deg, max_view_angle_deg,
                              Fields().Field("fallback_view_angle_deg").max,
                              "VisibilityOptions::fallback_view_angle_deg");
  internal::RequireFieldRange(fallback_pair_angle_deg, max_pair_angle_deg,
                              Fields().Field("fallback_pair_angle_deg").max,
                              "VisibilityOptions::fallback_pair_angle_deg");
}

namespace {

// The nearest rendered depth among the four pixels around a sub-pixel position: a point that
// lies on the surface is then never declared occluded by its own triangle's rasterisation.
float NearestRenderedDepth(const cv::Mat& depth_map, const Eigen::Vector2d& pixel) {
  const int x0 = static_cast<int>(std::floor(pixel.x()));
  const int y0 = static_cast<int>(std::floor(pixel.y()));
  float nearest = std::numeric_limits<float>::infinity();
  for (int y = std::max(0, y0); y <= std::min(depth_map.rows - 1, y0 + 1); ++y) {
    for (int x = std::max(0, x0); x <= std::min(depth_map.cols - 1, x0 + 1); ++x) {
      nearest = std::min(nearest, depth_map.at<float>(y, x));
    }
  }
  return nearest;
}

}  // namespace

std::vector<unsigned char> ComputeVisibility(const Camera& camera, const cv::Mat& depth_map,
                                             const Eigen::Matrix3Xd& points,
                                             const Eigen::Matrix3Xd& normals,
                                             const VisibilityOptions& options) {
  Require(depth_map.type() == CV_32F && depth_map.cols == camera.width &&
              depth_map.rows == camera.height,
          camera.name, "the depth map must be CV_32F of the camera's size");
  const double min_cosine = std::cos(options.max_view_angle_deg * M_PI / 180.0);
  const Eigen::Vector3d center = camera.Center();
  const int n = static_cast<int>(points.cols());
  std::vector<unsigned char> visible(n, 0);
#pragma omp parallel for schedule(static)
  for (int p = 0; p < n; ++p) {
    const Eigen::Vector3d point = points.col(p);
    const double depth = camera.Depth(point);
    if (!(depth > 0.0)) continue;
    const Eigen::Vector3d to_camera = (center - point).normalized();
    if (normals.col(p).dot(to_camera) < min_cosine) continue;
    const Eigen::Vector2d pixel = camera.Project(point);
    const double margin = options.border_margin;
    if (pixel.x() < margin || pixel.y() < margin || pixel.x() > camera.width - 1 - margin ||
        pixel.y() > camera.height - 1 - margin) {
      continue;
    }
    visible[p] = depth <= NearestRenderedDepth(depth_map, pixel) + options.depth_tolerance;
  }
  return visible;
}

namespace {

double CosineOf(double degrees) { return std::cos(degrees * M_PI / 180.0); }

// The cosines of the angles at which the cameras that `visible` marks see point p, largest
// first, with the cameras.
std::vector<std::pair<double, int>> ViewsOf(const std::vector<Camera>& cameras,
                                            const Eigen::Vector3d& point,
                                            const Eigen::Vector3d& normal,
                                            const std::vector<std::vector<unsigned char>>& visible,
                                            int p) {
  std::vector<std::pair<double, int>> views;
  for (int c = 0; c < static_cast<int>(cameras.size()); ++c) {
    if (!visible[c][p]) continue;
    views.emplace_back(cameras[c].ViewCosine(point, normal), c);
  }
  std::sort(views.begin(), views.end(), std::greater<>());
  return views;
}

// Clears, for each point, the views past its `keep` most frontal whose cosine is below
// `min_cosine`.
void DropSteepViews(const char* caller, const std::vector<Camera>& cameras,
                    const Eigen::Matrix3Xd& points, const Eigen::Matrix3Xd& normals, int keep,
                    double min_cosine, std::vector<std::vector<unsigned char>>* visible) {
  Require(visible->size() == cameras.size(), caller, "one flag list per camera");
  const int n = static_cast<int>(points.cols());
#pragma omp parallel for schedule(static)
  for (int p = 0; p < n; ++p) {
    const auto views = ViewsOf(cameras, points.col(p), normals.col(p), *visible, p);
    for (int i = 0; i < static_cast<int>(views.size()); ++i) {
      if (views[i].first < min_cosine && i >= keep) (*visible)[views[i].second][p] = 0;
    }
  }
}

// How much the narrowest pair of `views` (at least two) counts, in [0, 1]: 1 when two of them are
// within `full` (a cosine) of each other as seen from `point`, falling linearly in the cosine to 0
// at `none`.
double PairConfidence(const std::vector<Camera>& cameras, const Eigen::Vector3d& point,
                      const std::vector<std::pair<double, int>>& views, double full, double none) {
  std::vector<Eigen::Vector3d> directions;
  for (const auto& view : views) {
    directions.push_back((cameras[view.second].Center() - point).normalized());
  }
  double narrowest = -1.0;  // The largest cosine between two directions.
  for (size_t i = 0; i < directions.size(); ++i) {
    for (size_t j = i + 1; j < directions.size(); ++j) {
      narrowest = std::max(narrowest, directions[i].dot(directions[j]));
    }
  }
  if (narrowest >= full) return 1.0;
  return full > none ? std::max(0.0, (narrowest - none) / (full - none)) : 0.0;
}

}  // namespace

void KeepFrontalViews(const std::vector<Camera>& cameras, const Eigen::Matrix3Xd& points,
                      const Eigen::Matrix3Xd& normals, int wanted, const VisibilityOptions& options,
                      std::vector<std::vector<unsigned char>>* visible) {
  DropSteepViews("KeepFrontalViews", cameras, points, normals, wanted,
                 CosineOf(options.max_view_angle_deg), visible);
}

void KeepMostFrontalViews(const std::vector<Camera>& cameras, const Eigen::Matrix3Xd& points,
                          const Eigen::Matrix3Xd& normals, int count,
                          std::vector<std::vector<unsigned char>>* visible) {
  // No view's cosine reaches 2: every view past the first `count` goes.
  DropSteepViews("KeepMostFrontalViews", cameras, points, normals, count, 2.0, visible);
}

std::vector<float> ViewConfidence(const std::vector<Camera>& cameras,
                                  const Eigen::Matrix3Xd& points, const Eigen::Matrix3Xd& normals,
                                  int wanted, const VisibilityOptions& options,
                                  const std::vector<std::vector<unsigned char>>& visible) {
  Require(wanted >= 1 && visible.size() == cameras.size(), "ViewConfidence",
          "at least one wanted camera and one flag list per camera");
  const double full = CosineOf(options.max_view_angle_deg);
  const double none = CosineOf(options.fallback_view_angle_deg);
  const double pair_full = CosineOf(options.max_pair_angle_deg);
  const double pair_none = CosineOf(options.fallback_pair_angle_deg);
  const int n = static_cast<int>(points.cols());
  std::vector<float> confidence(n, 0.0f);
#pragma omp parallel for schedule(static)
  for (int p = 0; p < n; ++p) {
    const auto views = ViewsOf(cameras, points.col(p), normals.col(p), visible, p);
    if (static_cast<int>(views.size()) < wanted) continue;
    const double cosine = views[wanted - 1].first;
    if (cosine >= full) {
      confidence[p] = 1.0f;
    } else if (full > none) {  // Without a fallback (the two angles equal) a steeper view is 0.
      confidence[p] = static_cast<float>(std::max(0.0, (cosine - none) / (full - none)));
    }
    if (wanted >= 2) {
      confidence[p] *=
          static_cast<float>(PairConfidence(cameras, points.col(p), views, pair_full, pair_none));
    }
  }
  return confidence;
}

}  // namespace finecap
