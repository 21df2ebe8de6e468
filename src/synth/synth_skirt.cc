// The built-in subject: a flared tube swaying like a skirt, on a regular (theta, s) grid.
#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Geometry>

#include "synth/synth_internal.h"

namespace finecap {
namespace synth_internal {
namespace {

class Skirt : public Subject {
 public:
  Skirt(const SkirtOptions& options, int refinement)
      : options_(options),
        refinement_(refinement),
        fine_around_(options.around * refinement),
        fine_down_((options.down - 1) * refinement + 1) {
    TabulateMeridianLength();
    coarse_faces = GridFaces(options.around, options.down);
    fine_faces = GridFaces(fine_around_, fine_down_);
    fine_material = GridMaterial(fine_around_, fine_down_);
    coarse_material = GridMaterial(options.around, options.down);
    coarse_v = coarse_material.down / meridian_length_.back();
    fine_corner_uvs = GridCornerUvs();
    mean_radius = 0.5 * (options.waist_radius + options.hem_radius);
    circumference = 2.0 * M_PI * mean_radius;
    surface_height = meridian_length_.back();
    center = Eigen::Vector3d(0.0, options.waist_height - 0.5 * options.length, 0.0);
  }

  SmoothFrame Smooth(int frame) const override {
    SmoothFrame smooth;
    smooth.fine_vertices.resize(3, fine_around_ * fine_down_);
    smooth.fine_normals.resize(3, fine_around_ * fine_down_);
#pragma omp parallel for
    for (int j = 0; j < fine_down_; ++j) {
      for (int i = 0; i < fine_around_; ++i) {
        const double theta = 2.0 * M_PI * i / fine_around_;
        const double s = static_cast<double>(j) / (fine_down_ - 1);
        smooth.fine_vertices.col(j * fine_around_ + i) = Point(theta, s, frame);
        smooth.fine_normals.col(j * fine_around_ + i) = Normal(theta, s, frame);
      }
    }
    // Coarse vertex (i, j) is fine vertex (i * refinement, j * refinement).
    const int count = options_.around * options_.down;
    smooth.coarse_vertices.resize(3, count);
    smooth.coarse_normals.resize(3, count);
    for (int j = 0; j < options_.down; ++j) {
      for (int i = 0; i < options_.around; ++i) {
        const int fine = j * refinement_ * fine_around_ + i * refinement_;
        smooth.coarse_vertices.col(j * options_.around + i) = smooth.fine_vertices.col(fine);
        smooth.coarse_normals.col(j * options_.around + i) = smooth.fine_normals.col(fine);
      }
    }
    return smooth;
  }

 private:
  double RestRadius(double s) const {
    return options_.waist_radius +
           (options_.hem_radius - options_.waist_radius) * std::pow(s, options_.flare_exponent);
  }

  // The smooth surface at parameter (theta, s), s = 0 at the waist and 1 at the hem. The motion
  // grows towards the hem, as a skirt hanging from a waistband moves.
  Eigen::Vector3d Point(double theta, double s, int frame) const {
    const double cycle = 2.0 * M_PI * frame / options_.period;
    const double twist = options_.swing * M_PI / 180.0 * s * std::sin(cycle + 1.0);
    const double turned = theta + twist;
    const double radius =
        RestRadius(s) * (1.0 + options_.flare_wobble * s * s * std::cos(2.0 * theta - cycle));
    const double sway = options_.sway * s * s;
    return Eigen::Vector3d(sway * std::sin(cycle) + radius * std::cos(turned),
                           options_.waist_height - options_.length * s,
                           0.4 * sway * std::sin(2.0 * cycle) + radius * std::sin(turned));
  }

  // Outward unit normal from central differences of the parametrisation.
  Eigen::Vector3d Normal(double theta, double s, int frame) const {
    constexpr double kStep = 1e-5;
    const Eigen::Vector3d along_theta =
        Point(theta + kStep, s, frame) - Point(theta - kStep, s, frame);
    // One-sided at the waist and hem: the flare s^p is not defined for s < 0.
    const Eigen::Vector3d along_s = Point(theta, std::min(1.0, s + kStep), frame) -
                                    Point(theta, std::max(0.0, s - kStep), frame);
    return along_theta.cross(along_s).normalized();
  }

  // Arc length of the rest meridian from the waist, tabulated at kSamples + 1 values of s, so
  // that the material's "down" coordinate and the texture's v are true distances on the cloth.
  void TabulateMeridianLength() {
    constexpr int kSamples = 4096;
    meridian_length_.assign(kSamples + 1, 0.0);
    for (int k = 1; k <= kSamples; ++k) {
      const double s0 = static_cast<double>(k - 1) / kSamples;
      const double s1 = static_cast<double>(k) / kSamples;
      meridian_length_[k] = meridian_length_[k - 1] + std::hypot(options_.length * (s1 - s0),
                                                                 RestRadius(s1) - RestRadius(s0));
    }
  }

  double MeridianLength(double s) const {
    const double position = s * (meridian_length_.size() - 1);
    const int k =
        std::min(static_cast<int>(position), static_cast<int>(meridian_length_.size()) - 2);
    const double a = position - k;
    return (1.0 - a) * meridian_length_[k] + a * meridian_length_[k + 1];
  }

  // Quads (i, j) - (i + 1, j) - (i + 1, j + 1) - (i, j + 1), split in two triangles that are
  // counter-clockwise seen from outside; the tube closes around theta.
  static Eigen::Matrix3Xi GridFaces(int around, int down) {
    Eigen::Matrix3Xi faces(3, 2 * around * (down - 1));
    int f = 0;
    for (int j = 0; j + 1 < down; ++j) {
      for (int i = 0; i < around; ++i) {
        const int a = j * around + i;
        const int b = j * around + (i + 1) % around;
        const int c = b + around;
        const int d = a + around;
        faces.col(f++) << a, b, c;
        faces.col(f++) << a, c, d;
      }
    }
    return faces;
  }

  MaterialCoordinates GridMaterial(int around, int down) const {
    MaterialCoordinates material;
    material.theta.resize(around * down);
    material.down.resize(around * down);
    for (int j = 0; j < down; ++j) {
      for (int i = 0; i < around; ++i) {
        material.theta(j * around + i) = 2.0 * M_PI * i / around;
        material.down(j * around + i) = MeridianLength(static_cast<double>(j) / (down - 1));
      }
    }
    return material;
  }

  // u = i / around (1, not 0, on the far side of the seam), v = arc length / total length.
  Eigen::Matrix2Xd GridCornerUvs() const {
    Eigen::Matrix2Xd uvs(2, 3 * fine_faces.cols());
    for (int f = 0; f < fine_faces.cols(); ++f) {
      const int first_column = fine_faces(0, f) % fine_around_;
      for (int c = 0; c < 3; ++c) {
        const int vertex = fine_faces(c, f);
        int column = vertex % fine_around_;
        if (column < first_column) column += fine_around_;  // Across the seam.
        uvs.col(3 * f + c) = Eigen::Vector2d(static_cast<double>(column) / fine_around_,
                                             fine_material.down(vertex) / meridian_length_.back());
      }
    }
    return uvs;
  }

  SkirtOptions options_;
  int refinement_;
  int fine_around_;
  int fine_down_;
  std::vector<double> meridian_length_;
};

}  // namespace

std::unique_ptr<Subject> MakeSkirt(const SkirtOptions& options, int refinement) {
  return std::make_unique<Skirt>(options, refinement);
}

}  // namespace synth_internal
}  // namespace finecap
