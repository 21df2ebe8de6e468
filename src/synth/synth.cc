// The synthetic capture: subject, folds, rig and images put together, and written to disk.
#include "finecap/synth/synth.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <random>
#include <sstream>

#include <Eigen/Geometry>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>

#include "finecap/geometry/mesh_ray_caster.h"
#include "finecap/geometry/mesh_smoothing.h"
#include "finecap/io/camera_io.h"
#include "finecap/io/mesh_io.h"
#include "finecap/util/atomic_file.h"
#include "finecap/util/error.h"
#include "synth/synth_internal.h"
#include "util/io_util.h"

namespace finecap {
namespace {

using synth_internal::Subject;

// Independent, well-mixed seeds for the separate random streams (SplitMix64's finaliser).
std::uint64_t MixSeed(std::uint64_t seed, std::uint64_t stream) {
  std::uint64_t z = seed + 0x9e3779b97f4a7c15ull * (stream + 1);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}
enum SeedStream : std::uint64_t {
  kTextureStream = 1,
  kMisalignmentStream,
  kCalibrationStream,
  kBackgroundStream,  // The first of one stream per camera.
};

std::string FrameName(int frame) {
  char name[16];
  std::snprintf(name, sizeof(name), "%06d", frame);
  return name;
}

// Camera at `center` looking at `target` with world +y up in the image.
Camera LookAt(const std::string& name, const RigOptions& rig, const Eigen::Vector3d& center,
              const Eigen::Vector3d& target) {
  Camera camera;
  camera.name = name;
  camera.width = rig.width;
  camera.height = rig.height;
  camera.K << rig.focal, 0.0, 0.5 * (rig.width - 1), 0.0, rig.focal, 0.5 * (rig.height - 1), 0.0,
      0.0, 1.0;
  const Eigen::Vector3d z = (target - center).normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitY()).normalized();
  camera.R.row(0) = x;
  camera.R.row(1) = z.cross(x);
  camera.R.row(2) = z;
  camera.t = -camera.R * center;
  std::copy(rig.distortion.begin(), rig.distortion.end(), camera.distortion.begin());
  return camera;
}

std::vector<Camera> MakeRing(const RigOptions& rig, const Eigen::Vector3d& target) {
  std::vector<Camera> cameras;
  for (int c = 0; c < rig.count; ++c) {
    const double angle = 2.0 * M_PI * c / rig.count;
    const Eigen::Vector3d center = target + Eigen::Vector3d(rig.distance * std::cos(angle),
                                                            rig.heights[c % rig.heights.size()],
                                                            rig.distance * std::sin(angle));
    char name[16];
    std::snprintf(name, sizeof(name), "cam%02d", c);
    cameras.push_back(LookAt(name, rig, center, target));
  }
  return cameras;
}

// What a calibration would have measured: the true camera turned, moved and rescaled a little.
Camera Miscalibrate(const Camera& truth, const RigOptions& rig, std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  const Eigen::Vector3d rotation =
      rig.rotation_noise * M_PI / 180.0 * Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
  const Eigen::Vector3d shift =
      rig.translation_noise * Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
  const double scale = 1.0 + rig.focal_noise * normal(rng);
  Camera camera = truth;
  if (rotation.norm() > 0.0) {
    camera.R =
        Eigen::AngleAxisd(rotation.norm(), rotation.normalized()).toRotationMatrix() * truth.R;
  }
  camera.t = -camera.R * (truth.Center() + shift);
  camera.K(0, 0) *= scale;
  camera.K(1, 1) *= scale;
  return camera;
}

// A smooth random 3D displacement per point: three plane waves of `wavelength` in random
// directions, each moving points along its own random direction; peak at most `amplitude`.
Eigen::Matrix3Xd SmoothRandomField(const Eigen::Matrix3Xd& points, double amplitude,
                                   double wavelength, std::mt19937_64& rng) {
  constexpr int kWaves = 3;
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> angle(0.0, 2.0 * M_PI);
  Eigen::Matrix3Xd field = Eigen::Matrix3Xd::Zero(3, points.cols());
  for (int w = 0; w < kWaves; ++w) {
    const Eigen::Vector3d wave =
        Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized() * 2.0 * M_PI /
        wavelength;
    const Eigen::Vector3d direction =
        Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized() * amplitude / kWaves;
    const double phase = angle(rng);
    for (int i = 0; i < points.cols(); ++i) {
      field.col(i) += std::sin(wave.dot(points.col(i)) + phase) * direction;
    }
  }
  return field;
}

// Signed distance from each coarse vertex along its area-weighted normal to `truth`.
Eigen::VectorXd CastAlongNormals(const Mesh& coarse, const Mesh& truth, double max_distance) {
  const MeshRayCaster caster(truth);
  const Eigen::Matrix3Xd normals = ComputeVertexNormals(coarse);
  Eigen::VectorXd k(coarse.num_vertices());
#pragma omp parallel for schedule(dynamic, 64)
  for (int v = 0; v < coarse.num_vertices(); ++v) {
    const std::optional<double> hit =
        normals.col(v).squaredNorm() > 0.0
            ? caster.NearestHit(coarse.vertices.col(v), normals.col(v), max_distance)
            : std::nullopt;
    k(v) = hit ? *hit : std::numeric_limits<double>::quiet_NaN();
  }
  return k;
}

// The coarse input of a frame before misalignment (see CoarseInput). Exact: the true surface at
// the coarse vertices, which are vertices of the true mesh displaced by their fold along their
// smooth normal; smoothed: that, smoothed over the coarse mesh.
Eigen::Matrix3Xd CoarseInputVertices(const SynthOptions& options, const Subject& subject,
                                     const synth_internal::SmoothFrame& smooth,
                                     const Eigen::VectorXd& folds_at_coarse) {
  if (options.coarse == CoarseInput::kUnfolded) return smooth.coarse_vertices;
  Mesh detailed;
  detailed.faces = subject.coarse_faces;
  detailed.vertices = smooth.coarse_vertices + smooth.coarse_normals * folds_at_coarse.asDiagonal();
  if (options.coarse == CoarseInput::kExact) return detailed.vertices;
  return TaubinSmooth(detailed, options.smoothing);
}

// For a camera with lens distortion: where each pixel of the distorted image lies in an
// undistorted render of the same camera, drawn on a canvas enlarged by `pad` pixels per side so
// that barrel distortion never reaches past its edge.
struct DistortionMap {
  int pad = 0;
  cv::Mat map_x;
  cv::Mat map_y;
};

DistortionMap MakeDistortionMap(const Camera& camera) {
  std::vector<cv::Point2f> distorted;
  distorted.reserve(static_cast<size_t>(camera.width) * camera.height);
  for (int y = 0; y < camera.height; ++y) {
    for (int x = 0; x < camera.width; ++x) distorted.emplace_back(x, y);
  }
  cv::Mat K;
  cv::eigen2cv(camera.K, K);
  const std::vector<double> coefficients(camera.distortion.begin(), camera.distortion.end());
  std::vector<cv::Point2f> undistorted;
  cv::undistortPoints(distorted, undistorted, K, coefficients, cv::noArray(), K,
                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 40, 1e-10));
  float overshoot = 0.0f;
  for (const cv::Point2f& p : undistorted) {
    overshoot =
        std::max({overshoot, -p.x, -p.y, p.x - (camera.width - 1), p.y - (camera.height - 1)});
  }
  DistortionMap map;
  map.pad = std::min(camera.width, static_cast<int>(std::ceil(overshoot)) + 2);
  map.map_x.create(camera.height, camera.width, CV_32F);
  map.map_y.create(camera.height, camera.width, CV_32F);
  for (int y = 0; y < camera.height; ++y) {
    for (int x = 0; x < camera.width; ++x) {
      const cv::Point2f& p = undistorted[static_cast<size_t>(y) * camera.width + x];
      map.map_x.at<float>(y, x) = p.x + map.pad;
      map.map_y.at<float>(y, x) = p.y + map.pad;
    }
  }
  return map;
}

// A camera's own background wall: random colours at two scales (blotches of about a sixth of
// the image and a texture of ~6 px), so that it is textured where the silhouette meets it and
// differs from every other camera's.
cv::Mat MakeCameraBackground(int width, int height, std::uint64_t seed) {
  cv::RNG rng(seed);
  const auto noise = [&](int cell, double low, double high) {
    cv::Mat coarse(std::max(2, height / cell), std::max(2, width / cell), CV_32FC3), fine;
    rng.fill(coarse, cv::RNG::UNIFORM, cv::Scalar::all(low), cv::Scalar::all(high));
    cv::resize(coarse, fine, cv::Size(width, height), 0, 0, cv::INTER_CUBIC);
    return fine;
  };
  const cv::Mat wall = noise(160, 40.0, 200.0) + noise(6, -50.0, 50.0);
  cv::Mat background;
  wall.convertTo(background, CV_8UC3);
  return background;
}

// What `lens` records of `mesh`: rendered straight, or, with lens distortion (`distortion`
// its map), rendered undistorted on the map's enlarged canvas and distorted.
cv::Mat Record(const Camera& lens, const DistortionMap* distortion, const Mesh& mesh,
               const SurfaceAppearance& appearance, const RenderOptions& render) {
  if (distortion == nullptr) return RenderColor(lens, mesh, appearance, render);
  Camera canvas = lens.Undistorted();
  canvas.width += 2 * distortion->pad;
  canvas.height += 2 * distortion->pad;
  canvas.K(0, 2) += distortion->pad;
  canvas.K(1, 2) += distortion->pad;
  const cv::Mat undistorted = RenderColor(canvas, mesh, appearance, render);
  const Eigen::Vector3d background = 255.0 * render.background;
  cv::Mat image;
  cv::remap(undistorted, image, distortion->map_x, distortion->map_y, cv::INTER_LINEAR,
            cv::BORDER_CONSTANT, cv::Scalar(background.z(), background.y(), background.x()));
  return image;
}

// The part of each pixel of what `lens` records that `mesh` covers, 0-255 (CV_8UC1): the mesh
// recorded in white on black, anti-aliased as the images are.
cv::Mat RecordCoverage(const Camera& lens, const DistortionMap* distortion, const Mesh& mesh,
                       const RenderOptions& render) {
  RenderOptions flat = render;
  flat.shade = false;
  flat.background = Eigen::Vector3d::Zero();
  SurfaceAppearance white;
  white.vertex_colors = Eigen::Matrix3Xd::Ones(3, mesh.num_vertices());
  cv::Mat channels[3];
  cv::split(Record(lens, distortion, mesh, white, flat), channels);
  return channels[0];
}

// Replaces the plain background `plain` (BGR, 0-255) of `image` by `wall`, pixel by pixel in
// proportion to the part of the pixel the subject leaves uncovered.
void PutOnWall(const cv::Mat& coverage, const cv::Mat& wall, const cv::Scalar& plain,
               cv::Mat* image) {
  cv::Mat uncovered, change, result;
  coverage.convertTo(uncovered, CV_32F, -1.0 / 255.0, 1.0);
  wall.convertTo(change, CV_32FC3);
  change -= plain;
  cv::Mat uncovered3;
  cv::merge(std::vector<cv::Mat>(3, uncovered), uncovered3);
  image->convertTo(result, CV_32FC3);
  result += change.mul(uncovered3);
  result.convertTo(*image, CV_8UC3);
}

void RequireEmptyFolder(const std::string& out_dir) {
  namespace fs = std::filesystem;
  Require(!out_dir.empty(), "synth output", "no output folder given");
  if (!fs::exists(out_dir)) return;
  Require(fs::is_directory(out_dir), out_dir, "exists and is not a folder");
  Require(fs::is_empty(out_dir), out_dir,
          "is not empty: refusing to write into it so that nothing there is overwritten; "
          "choose a new or empty folder");
}

std::string DisplacementText(const Eigen::VectorXd& k) {
  std::ostringstream text;
  text.precision(9);
  for (int v = 0; v < k.size(); ++v) {
    if (std::isnan(k(v))) {
      text << "nan\n";
    } else {
      text << k(v) << "\n";
    }
  }
  return text.str();
}

std::string IdsText(const std::vector<int>& ids) {
  std::string text;
  for (int id : ids) text += std::to_string(id) + "\n";
  return text;
}

}  // namespace

struct SyntheticCapture::Impl {
  SynthOptions options;
  std::unique_ptr<Subject> subject;
  SurfaceAppearance appearance;
  std::vector<Camera> true_cameras;
  std::vector<Camera> calibrated_cameras;
  std::vector<DistortionMap> distortion_maps;  // Per camera; empty when there is no distortion.
  std::vector<int> textureless;
  // Per coarse vertex, the same world offset in every frame.
  Eigen::Matrix3Xd misalignment;
};

SyntheticCapture::SyntheticCapture(const SynthOptions& options) : impl_(std::make_unique<Impl>()) {
  options.Check();
  Impl& impl = *impl_;
  impl.options = options;
  if (options.single_wavelength > 0.0) {
    for (FoldComponent& fold : impl.options.folds) fold.wavelength = options.single_wavelength;
  }
  impl.subject = options.subject == SynthSubject::kSkirt
                     ? synth_internal::MakeSkirt(options.skirt, options.truth_refinement)
                     : synth_internal::MakeMeshSubject(options.mesh_path, options.num_frames,
                                                       options.truth_refinement);
  const Subject& subject = *impl.subject;
  impl.appearance.corner_uvs = subject.fine_corner_uvs;
  impl.appearance.texture = synth_internal::MakeClothTexture(options.texture, subject.circumference,
                                                             subject.surface_height,
                                                             MixSeed(options.seed, kTextureStream));
  for (int v = 0; v < subject.coarse_v.size(); ++v) {
    if (options.texture.textureless_end > options.texture.textureless_begin &&
        subject.coarse_v(v) >= options.texture.textureless_begin &&
        subject.coarse_v(v) <= options.texture.textureless_end) {
      impl.textureless.push_back(v);
    }
  }
  impl.true_cameras = MakeRing(options.cameras, subject.center);
  std::mt19937_64 calibration_rng(MixSeed(options.seed, kCalibrationStream));
  for (const Camera& camera : impl.true_cameras) {
    impl.calibrated_cameras.push_back(Miscalibrate(camera, options.cameras, calibration_rng));
    if (camera.HasDistortion()) impl.distortion_maps.push_back(MakeDistortionMap(camera));
  }
  std::mt19937_64 misalignment_rng(MixSeed(options.seed, kMisalignmentStream));
  impl.misalignment = SmoothRandomField(subject.Smooth(0).coarse_vertices, options.misalignment,
                                        options.misalignment_wavelength, misalignment_rng);
}

SyntheticCapture::~SyntheticCapture() = default;

int SyntheticCapture::num_frames() const { return impl_->options.num_frames; }
const std::vector<Camera>& SyntheticCapture::true_cameras() const { return impl_->true_cameras; }
const std::vector<Camera>& SyntheticCapture::calibrated_cameras() const {
  return impl_->calibrated_cameras;
}
const std::vector<int>& SyntheticCapture::textureless_vertices() const {
  return impl_->textureless;
}
const SurfaceAppearance& SyntheticCapture::appearance() const { return impl_->appearance; }

SyntheticFrame SyntheticCapture::Frame(int index) const {
  Require(index >= 0 && index < num_frames(), "synthetic capture",
          "frame " + std::to_string(index) + " does not exist");
  const Impl& impl = *impl_;
  const Subject& subject = *impl.subject;
  const synth_internal::SmoothFrame smooth = subject.Smooth(index);
  const auto fold = [&](const synth_internal::MaterialCoordinates& at) {
    return synth_internal::FoldDisplacement(impl.options.folds, impl.options.fold_ramp_frames,
                                            subject.mean_radius, at, index);
  };
  SyntheticFrame frame;
  frame.truth.faces = subject.fine_faces;
  frame.truth.vertices =
      smooth.fine_vertices + smooth.fine_normals * fold(subject.fine_material).asDiagonal();
  frame.folds_at_coarse = fold(subject.coarse_material);
  frame.coarse.faces = subject.coarse_faces;
  frame.coarse.vertices =
      CoarseInputVertices(impl.options, subject, smooth, frame.folds_at_coarse) + impl.misalignment;
  frame.smooth_normals = smooth.coarse_normals;
  frame.true_k = CastAlongNormals(frame.coarse, frame.truth, impl.options.max_displacement);
  return frame;
}

cv::Mat SyntheticCapture::Image(const SyntheticFrame& frame, int index, int camera,
                                cv::Mat* mask) const {
  const Impl& impl = *impl_;
  Require(camera >= 0 && camera < static_cast<int>(impl.true_cameras.size()), "synthetic capture",
          "camera " + std::to_string(camera) + " does not exist");
  RenderOptions render = impl.options.render;
  const std::uint64_t noise_seed =
      MixSeed(impl.options.seed ^ MixSeed(render.noise_seed, 0),
              1000 + static_cast<std::uint64_t>(index) * impl.true_cameras.size() + camera);
  render.noise_sigma = 0.0;  // Noise is added at the sensor, after the lens.
  const Camera& lens = impl.true_cameras[camera];
  const DistortionMap* distortion = lens.HasDistortion() ? &impl.distortion_maps[camera] : nullptr;
  cv::Mat image = Record(lens, distortion, frame.truth, impl.appearance, render);
  const bool on_wall = impl.options.background == SynthBackground::kPerCamera;
  if (on_wall || mask != nullptr) {
    const cv::Mat coverage = RecordCoverage(lens, distortion, frame.truth, render);
    if (on_wall) {
      const Eigen::Vector3d plain = 255.0 * render.background;
      PutOnWall(coverage,
                MakeCameraBackground(lens.width, lens.height,
                                     MixSeed(impl.options.seed, kBackgroundStream + camera)),
                cv::Scalar(plain.z(), plain.y(), plain.x()), &image);
    }
    if (mask != nullptr) *mask = coverage >= 128;
  }
  AddSensorNoise(impl.options.render.noise_sigma, noise_seed, &image);
  return image;
}

void GenerateSyntheticCapture(const SynthOptions& options, const std::string& out_dir) {
  namespace fs = std::filesystem;
  options.Check();
  RequireEmptyFolder(out_dir);
  const SyntheticCapture capture(options);
  const fs::path root(out_dir);
  for (const Camera& camera : capture.true_cameras()) {
    fs::create_directories(root / "images" / camera.name);
    if (options.write_masks) fs::create_directories(root / "masks" / camera.name);
  }
  fs::create_directories(root / "meshes");
  fs::create_directories(root / "gt");
  WriteCamerasYaml(capture.calibrated_cameras(), (root / "cameras.yaml").string());
  WriteTextFileAtomically((root / "gt" / "textureless.txt").string(),
                          IdsText(capture.textureless_vertices()));
  for (int index = 0; index < capture.num_frames(); ++index) {
    const std::string name = FrameName(index);
    const SyntheticFrame frame = capture.Frame(index);
    WriteMesh((root / "meshes" / (name + ".ply")).string(), frame.coarse);
    WriteMesh((root / "gt" / (name + ".ply")).string(), frame.truth);
    WriteTextFileAtomically((root / "gt" / (name + "_k.txt")).string(),
                            DisplacementText(frame.true_k));
    for (int c = 0; c < static_cast<int>(capture.true_cameras().size()); ++c) {
      const std::string camera = capture.true_cameras()[c].name;
      cv::Mat mask;
      internal::WritePng((root / "images" / camera / (name + ".png")).string(),
                         capture.Image(frame, index, c, options.write_masks ? &mask : nullptr));
      if (options.write_masks) {
        internal::WritePng((root / "masks" / camera / (name + ".png")).string(), mask);
      }
    }
  }
}

}  // namespace finecap
