#include "finecap/model/gaussian_overlap.h"

#include <random>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "model/surface_projection.h"

namespace finecap {
namespace {

// A camera looking down +z from 2.5 m with a random tilt.
Camera RandomCamera(std::mt19937* rng) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  Camera camera;
  camera.width = camera.height = 1004;
  camera.K << 900.0 + 300.0 * unit(*rng), 0.0, 502.0, 0.0, 900.0 + 300.0 * unit(*rng), 498.0, 0.0,
      0.0, 1.0;
  camera.R =
      Eigen::AngleAxisd(0.3 * unit(*rng), Eigen::Vector3d(unit(*rng), unit(*rng), 1.0).normalized())
          .toRotationMatrix();
  camera.t = Eigen::Vector3d(0.1 * unit(*rng), 0.1 * unit(*rng), 2.5 + unit(*rng));
  return camera;
}

// Numerically integrates the product of two unnormalised Gaussians on a fine pixel grid.
double IntegrateProduct(const Eigen::Vector2d& m1, double s1, const Eigen::Vector2d& m2,
                        double s2) {
  const double step = 0.05;
  double total = 0.0;
  for (double x = -40.0; x <= 40.0; x += step) {
    for (double y = -40.0; y <= 40.0; y += step) {
      const Eigen::Vector2d p(x, y);
      total += std::exp(-(p - m1).squaredNorm() / (2 * s1 * s1) -
                        (p - m2).squaredNorm() / (2 * s2 * s2));
    }
  }
  return total * step * step;
}

TEST(GaussianOverlapTest, ExactFormIsTheIntegralOfTheProduct) {
  ProjectedGaussian surface;
  surface.mean = Eigen::Vector2d(1.0, -2.0);
  surface.sigma = 2.5;
  const Eigen::Vector2d image_mean(3.0, 0.5);
  const double image_sigma = 4.0;
  const double numeric = IntegrateProduct(surface.mean, surface.sigma, image_mean, image_sigma);
  EXPECT_NEAR(GaussianOverlap(OverlapForm::kExact, surface, image_mean, image_sigma), numeric,
              1e-6 * numeric);
  // The printed form has half the exponent's divisor: smaller as soon as the means differ.
  EXPECT_LT(GaussianOverlap(OverlapForm::kPrinted, surface, image_mean, image_sigma), numeric);
}

TEST(GaussianOverlapTest, SelfOverlapMatchesBothForms) {
  ProjectedGaussian surface;
  surface.mean = Eigen::Vector2d(7.0, 8.0);
  surface.sigma = 3.0;
  for (OverlapForm form : {OverlapForm::kPrinted, OverlapForm::kExact}) {
    EXPECT_NEAR(GaussianOverlap(form, surface, surface.mean, 3.0), SelfOverlap(3.0), 1e-12);
  }
}

// d(overlap)/dk through the projection, against central differences of the full chain.
TEST(GaussianOverlapTest, DerivativeMatchesCentralDifferences) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  int checked = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const Camera camera = RandomCamera(&rng);
    const Eigen::Vector3d base(0.2 * unit(rng), 0.2 * unit(rng), 0.3 * unit(rng));
    // Include grazing normals: nearly perpendicular to the viewing ray.
    Eigen::Vector3d normal(unit(rng), unit(rng), trial % 4 == 0 ? 0.05 * unit(rng) : unit(rng));
    normal.normalize();
    const double sigma_hat = 0.004 + 0.006 * std::abs(unit(rng));
    const double k = 0.01 * unit(rng);
    const ProjectedGaussian at_k = ProjectSurfaceGaussian(camera, base, normal, k, sigma_hat);
    const Eigen::Vector2d image_mean =
        at_k.mean + Eigen::Vector2d(unit(rng), unit(rng)) * 3.0 * at_k.sigma;
    const double image_sigma = 0.5 + 8.0 * std::abs(unit(rng));
    for (OverlapForm form : {OverlapForm::kPrinted, OverlapForm::kExact}) {
      const auto overlap = [&](double kk) {
        return GaussianOverlap(form, ProjectSurfaceGaussian(camera, base, normal, kk, sigma_hat),
                               image_mean, image_sigma);
      };
      double analytic = 0.0;
      GaussianOverlap(form, at_k, image_mean, image_sigma, &analytic);
      const double h = 1e-7;
      const double numeric = (overlap(k + h) - overlap(k - h)) / (2.0 * h);
      const double scale = std::max(std::abs(numeric), 1e-3 * overlap(k) / 0.01);
      EXPECT_LT(std::abs(analytic - numeric), 1e-6 * scale)
          << "trial " << trial << " analytic " << analytic << " numeric " << numeric;
      ++checked;
    }
  }
  EXPECT_EQ(checked, 400);
}

TEST(GaussianOverlapTest, PrintedDerivativeEqualsThePapersEquation) {
  // The paper's dE_is/dk_s: 4 pi Q [ [PN]_z (-1 + s2/S - |d|^2 s2/S^2) / z + d.dm/S ],
  // Q = s2 i2 / S exp(-|d|^2/S), evaluated here from its own ingredients.
  std::mt19937 rng(3);
  const Camera camera = RandomCamera(&rng);
  const Eigen::Vector3d base(0.05, -0.1, 0.2),
      normal = Eigen::Vector3d(0.3, -0.2, -0.9).normalized();
  const double sigma_hat = 0.007, k = 0.004, image_sigma = 2.0;
  const ProjectedGaussian s = ProjectSurfaceGaussian(camera, base, normal, k, sigma_hat);
  const Eigen::Vector2d image_mean = s.mean + Eigen::Vector2d(1.5, -0.7);
  const double z = camera.Depth(base + k * normal), dz_dk = camera.R.row(2).dot(normal);
  const double s2 = s.sigma * s.sigma, i2 = image_sigma * image_sigma, S = s2 + i2;
  const Eigen::Vector2d d = image_mean - s.mean;
  const double Q = s2 * i2 / S * std::exp(-d.squaredNorm() / S);
  const double paper =
      4.0 * M_PI * Q *
      (dz_dk * (-1.0 + s2 / S - d.squaredNorm() * s2 / (S * S)) / z + d.dot(s.dmean_dk) / S);
  double ours = 0.0;
  GaussianOverlap(OverlapForm::kPrinted, s, image_mean, image_sigma, &ours);
  EXPECT_NEAR(ours, paper, 1e-10 * std::abs(paper));
}

TEST(GaussianOverlapTest, WendlandIsOneAtZeroAndVanishesSmoothlyAtTheCutoff) {
  EXPECT_DOUBLE_EQ(Wendland(0.0, 0.05), 1.0);
  EXPECT_DOUBLE_EQ(Wendland(0.05, 0.05), 0.0);
  EXPECT_DOUBLE_EQ(Wendland(0.07, 0.05), 0.0);
  EXPECT_NEAR(Wendland(0.025, 0.05), std::pow(0.5, 4) * 3.0, 1e-15);
  // C^2 at the cut-off: the value just inside is O(h^3).
  EXPECT_LT(Wendland(0.05 - 1e-4, 0.05), 1e-7);
}

}  // namespace
}  // namespace finecap
