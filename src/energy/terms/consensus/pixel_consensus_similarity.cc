#include "energy/terms/consensus/pixel_consensus_similarity.h"

#include <algorithm>
#include <cmath>

#include <opencv2/core.hpp>

#include "finecap/geometry/bilinear.h"
#include "finecap/geometry/spatial_order.h"
#include "finecap/util/error.h"

namespace finecap {
namespace {

// A patch needs its own sample and at least this many more to have a shape worth comparing.
constexpr int kMinPatchSamples = 4;

// The pixel of the homogeneous pixel `at_zero` + k `direction` (a sample's projection moved by k
// along its normal: a straight line), and its k-derivative.
inline void PixelOnRay(const Eigen::Vector3d& at_zero, const Eigen::Vector3d& direction, double k,
                       double* x, double* y, double* dx, double* dy) {
  const Eigen::Vector3d h = at_zero + k * direction;
  const double inverse_depth = 1.0 / h.z();
  *x = h.x() * inverse_depth;
  *y = h.y() * inverse_depth;
  *dx = (direction.x() - *x * direction.z()) * inverse_depth;
  *dy = (direction.y() - *y * direction.z()) * inverse_depth;
}

// The homogeneous pixel of camera `projection` of a sample at `base` moved by `k` along `normal`,
// and its k-derivative.
inline void ProjectSample(const Eigen::Matrix<double, 3, 4>& projection,
                          const Eigen::Vector3d& base, const Eigen::Vector3d& normal, double k,
                          double* x, double* y, double* dx, double* dy) {
  const Eigen::Vector3d direction = projection.leftCols<3>() * normal;
  const Eigen::Vector3d at_zero = projection.leftCols<3>() * base + projection.col(3);
  PixelOnRay(at_zero, direction, k, x, y, dx, dy);
}

Eigen::Matrix<double, 3, 4> ProjectionOf(const Camera& camera) {
  Eigen::Matrix<double, 3, 4> projection;
  projection << camera.K * camera.R, camera.K * camera.t;
  return projection;
}

}  // namespace

double SampleRayTableBytes(double num_reads, double max_table_bytes) {
  const double bytes = num_reads * sizeof(Eigen::Vector3d) * 2;
  return bytes <= max_table_bytes ? bytes : 0.0;
}

Eigen::Matrix3Xd SeenAppearance(const SurfaceSamples& samples,
                                const std::vector<CameraInput>& cameras,
                                const Eigen::VectorXd& shape) {
  Require(shape.size() == samples.size(), "SeenAppearance", "one shape entry per sample expected");
  std::vector<Eigen::Matrix<double, 3, 4>> projections;
  for (const CameraInput& camera : cameras) projections.push_back(ProjectionOf(camera.camera));
  Eigen::Matrix3Xd appearance(3, samples.size());
#pragma omp parallel for schedule(dynamic, 1024)
  for (int j = 0; j < samples.size(); ++j) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    int seen = 0;
    for (size_t c = 0; c < cameras.size(); ++c) {
      const CameraInput& camera = cameras[c];
      if (camera.samples_visible[j] == 0) continue;
      if (!camera.samples_on_foreground.empty() && camera.samples_on_foreground[j] == 0) continue;
      double x, y, dx, dy;
      ProjectSample(projections[c], samples.base.col(j), samples.normals.col(j), shape[j], &x, &y,
                    &dx, &dy);
      double color[3];
      ReadBilinear(camera.pixels, x, y, dx, dy, color, nullptr);
      sum += Eigen::Vector3d(color[0], color[1], color[2]);
      ++seen;
    }
    appearance.col(j) = seen > 0 ? (sum / seen).eval() : Eigen::Vector3d::Constant(std::nan(""));
  }
  return appearance;
}

PixelConsensusSimilarity::PixelConsensusSimilarity(const SurfaceSamples& samples,
                                                   const std::vector<CameraInput>& cameras,
                                                   const ConsensusOptions& options,
                                                   double max_ray_table_bytes)
    : PatchAgreementTerm(options, static_cast<int>(cameras.size())),
      samples_(samples),
      cameras_(cameras),
      appearance_view_(static_cast<int>(cameras.size())) {
  Require(samples.appearance.cols() == 0 || samples.appearance.cols() == samples.size(),
          "pixel consensus similarity", "the appearance must have one colour per sample, or none");
  for (const CameraInput& camera : cameras) {
    projections_.push_back(ProjectionOf(camera.camera));
    Require(camera.pixels.type() == CV_32FC3 && camera.pixels.cols >= 2 && camera.pixels.rows >= 2,
            camera.camera.name, "the samples need the camera's image, converted (CV_32FC3)");
    Require(camera.samples_visible.size() == static_cast<size_t>(samples.size()),
            camera.camera.name, "visibility must have one flag per surface sample");
    Require(camera.view_cosines.empty() || camera.view_cosines.size() == samples.patches.size(),
            camera.camera.name, "view cosines must have one entry per surface Gaussian, or none");
    Require(camera.samples_on_foreground.empty() ||
                camera.samples_on_foreground.size() == static_cast<size_t>(samples.size()),
            camera.camera.name, "the foreground must have one flag per surface sample, or none");
  }
  // Patches added in the order of their centres in space, so that the blocks a thread evaluates
  // one after the other read the same rows of the images and mostly the same samples: the reads
  // then come from the caches, not memory.
  const int num_patches = static_cast<int>(samples.patches.size());
  Eigen::Matrix3Xd centres(3, num_patches);
  for (int s = 0; s < num_patches; ++s) {
    centres.col(s) = samples.patches[s].empty() ? Eigen::Vector3d::Constant(std::nan(""))
                                                : samples.base.col(samples.patches[s][0]).eval();
  }
  for (int s : SpatialOrder(centres)) {
    const std::vector<int>& patch = samples.patches[s];
    if (static_cast<int>(patch.size()) < kMinPatchSamples) continue;
    std::vector<int> seen_by, members;
    ComparablePart(patch, &seen_by, &members);
    if (seen_by.empty()) continue;
    if (AppearanceKnown(members)) seen_by.push_back(appearance_view_);
    if (static_cast<int>(seen_by.size()) < options_.min_cameras) continue;
    AddPatch(s, members, seen_by, CameraWeightsOf(s, seen_by));
  }
  shape_ = Eigen::VectorXd::Zero(samples.size());
  parameter_shape_ = Eigen::VectorXd::Zero(samples.patches.size());
  ProjectReads(max_ray_table_bytes);
  WeighPatches();
}

void PixelConsensusSimilarity::ComparablePart(const std::vector<int>& patch,
                                              std::vector<int>* seen_by,
                                              std::vector<int>* members) const {
  // Occlusion takes a camera from the whole patch: a hidden sample would compare what lies in
  // front of it. A mask only takes pixels out, and along a silhouette it cuts the patches at the
  // subject's edge in every camera, so a cut patch is compared on its samples that lie on the
  // foreground of every camera comparing it. Cameras with most of the patch on their foreground
  // are taken first; one that would leave too few samples for a shape (kMinPatchSamples) is left
  // out.
  const int size = static_cast<int>(patch.size());
  std::vector<std::pair<int, int>> candidates;  // (samples off the foreground, camera)
  for (int c = 0; c < static_cast<int>(cameras_.size()); ++c) {
    const CameraInput& camera = cameras_[c];
    const auto unseen = [&](int j) { return camera.samples_visible[j] == 0; };
    if (std::any_of(patch.begin(), patch.end(), unseen)) continue;
    const auto off = [&](int j) {
      return !camera.samples_on_foreground.empty() && camera.samples_on_foreground[j] == 0;
    };
    candidates.push_back({static_cast<int>(std::count_if(patch.begin(), patch.end(), off)), c});
  }
  std::stable_sort(candidates.begin(), candidates.end());
  std::vector<unsigned char> kept(patch.size(), 1);
  int num_kept = size;
  for (const auto& [num_off, c] : candidates) {
    const std::vector<unsigned char>& foreground = cameras_[c].samples_on_foreground;
    const auto cut = [&](int m) { return !foreground.empty() && foreground[patch[m]] == 0; };
    int remaining = num_kept;
    for (int m = 0; m < size; ++m) remaining -= kept[m] != 0 && cut(m);
    if (remaining < kMinPatchSamples) continue;
    for (int m = 0; m < size; ++m) kept[m] = kept[m] != 0 && !cut(m);
    num_kept = remaining;
    seen_by->push_back(c);
  }
  std::sort(seen_by->begin(), seen_by->end());
  for (int m = 0; m < size; ++m) {
    if (kept[m] != 0) members->push_back(patch[m]);
  }
}

std::vector<double> PixelConsensusSimilarity::CameraWeightsOf(
    int patch, const std::vector<int>& seen_by) const {
  if (options_.view_cosine_power == 0.0) return {};
  const int own = samples_.patches[patch][0];
  std::vector<double> weights;
  for (int c : seen_by) {
    // The appearance is the surface seen head-on, as the frame before's cameras averaged it.
    double cosine = 1.0;
    if (c != appearance_view_) {
      const CameraInput& camera = cameras_[c];
      cosine = !camera.view_cosines.empty()
                   ? camera.view_cosines[patch]
                   : camera.camera.ViewCosine(samples_.base.col(own), samples_.normals.col(own));
    }
    weights.push_back(internal::ViewWeight(cosine, options_.view_cosine_power));
  }
  return weights;
}

bool PixelConsensusSimilarity::AppearanceKnown(const std::vector<int>& members) const {
  if (!options_.shared_appearance || samples_.appearance.cols() == 0) return false;
  return std::all_of(members.begin(), members.end(),
                     [&](int j) { return samples_.appearance.col(j).allFinite(); });
}

void PixelConsensusSimilarity::ProjectReads(double max_table_bytes) {
  const int num_blocks = static_cast<int>(blocks_.size());
  read_begin_.assign(1, 0);
  for (int b = 0; b < num_blocks; ++b) {
    read_begin_.push_back(read_begin_.back() + static_cast<long>(PatchSize(b)) * NumCameras(b));
  }
  rays_.clear();
  if (SampleRayTableBytes(static_cast<double>(read_begin_.back()), max_table_bytes) == 0.0) return;
  rays_.resize(read_begin_.back());
#pragma omp parallel for schedule(dynamic, 64)
  for (int b = 0; b < num_blocks; ++b) {
    const int n = PatchSize(b), num_cameras = NumCameras(b);
    const int* members = Members(b);
    for (int a = 0; a < num_cameras; ++a) {
      const int c = Cameras(b)[a];
      if (c == appearance_view_) continue;
      for (int m = 0; m < n; ++m) rays_[read_begin_[b] + a * n + m] = RayOf(c, members[m]);
    }
  }
}

PixelConsensusSimilarity::SampleRay PixelConsensusSimilarity::RayOf(int camera, int sample) const {
  const Eigen::Matrix<double, 3, 4>& projection = projections_[camera];
  return {projection.leftCols<3>() * samples_.base.col(sample) + projection.col(3),
          projection.leftCols<3>() * samples_.normals.col(sample)};
}

void PixelConsensusSimilarity::PatchColors(int b, double k, double* colors,
                                           double* derivatives) const {
  const int n = PatchSize(b);
  const int* members = Members(b);
  const double centre_shape = parameter_shape_[blocks_[b].parameters[0]];
  thread_local std::vector<double> member_k;
  member_k.resize(n);
  for (int m = 0; m < n; ++m) member_k[m] = k + shape_[members[m]] - centre_shape;
  ReadPatch(b, member_k.data(), colors, derivatives);
}

void PixelConsensusSimilarity::ReadPatch(int b, const double* member_k, double* colors,
                                         double* derivatives) const {
  const int n = PatchSize(b), num_cameras = NumCameras(b);
  const int* members = Members(b);
  thread_local std::vector<BilinearCell> cells;
  cells.resize(n);
  for (int a = 0; a < num_cameras; ++a) {
    const int c = Cameras(b)[a];
    if (c == appearance_view_) {
      // The appearance stays where the frame that showed it put it: it does not move with k.
      for (int m = 0; m < n; ++m) {
        const int i = a * n + m;
        for (int channel = 0; channel < 3; ++channel) {
          colors[3 * i + channel] = samples_.appearance(channel, members[m]);
          if (derivatives != nullptr) derivatives[3 * i + channel] = 0.0;
        }
      }
      continue;
    }
    // The sample's homogeneous pixel h(k) = P (base + k normal) is a straight line, so that the
    // pixel h_xy / h_z and its k-derivative (h'_xy - pixel h'_z) / h_z need no more than it.
    // Every member's cell first and its pixels asked of memory, then the reads: the image is
    // mostly not in the nearest caches, and the reads' waits then overlap.
    const SampleRay* rays = rays_.empty() ? nullptr : &rays_[read_begin_[b] + a * n];
    const cv::Mat& image = cameras_[c].pixels;
    const long row_step = RowStep(image);
    for (int m = 0; m < n; ++m) {
      double x, y, dx, dy;
      SampleRay projected;
      const SampleRay& ray = rays != nullptr ? rays[m] : (projected = RayOf(c, members[m]));
      PixelOnRay(ray.at_zero, ray.direction, member_k[m], &x, &y, &dx, &dy);
      cells[m] = CellAt(image, x, y, dx, dy);
      __builtin_prefetch(cells[m].top);
      __builtin_prefetch(cells[m].top + row_step);
    }
    for (int m = 0; m < n; ++m) {
      const int i = a * n + m;
      ReadCell(cells[m], row_step, colors + 3 * i,
               derivatives != nullptr ? derivatives + 3 * i : nullptr);
    }
  }
}

void PixelConsensusSimilarity::SetPatchShape(const Eigen::VectorXd& shape) {
  Require(shape.size() == static_cast<Eigen::Index>(samples_.patches.size()),
          "pixel consensus similarity", "one patch shape entry per surface Gaussian expected");
  parameter_shape_ = shape;
  shape_ = samples_.weights * shape;
}

}  // namespace finecap
