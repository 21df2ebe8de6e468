#include "energy/terms/prior/input_prior.h"

#include <cmath>

#include <gtest/gtest.h>

#include "energy_fixture.h"
#include "finecap/solvers/solver.h"
#include "finecap/util/error.h"

namespace finecap {
namespace {

// Every residual of the similarity at k, in block order.
std::vector<double> AllResiduals(DataTerm* term, const Eigen::VectorXd& k) {
  term->PrepareResiduals(k, false);
  std::vector<double> all;
  for (int b = 0; b < static_cast<int>(term->residual_blocks().size()); ++b) {
    std::vector<double> residuals(term->residual_blocks()[b].num_residuals);
    term->BlockResiduals(b, residuals.data(), nullptr);
    all.insert(all.end(), residuals.begin(), residuals.end());
  }
  return all;
}

EnergyOptions SurfaceColorOptions(double confidence_prior) {
  EnergyOptions options;
  options.k_max = 0.01;
  options.confidence_prior = confidence_prior;
  return options;
}

TEST(DataCurvatureTest, IsTheSumOfSquaredResidualSlopes) {
  EnergyScene scene = MakeEnergyScene({0.0, 0.5}, 3, 5);
  FrameEnergy energy(scene.surface, scene.cameras, scene.neighbourhoods, SurfaceColorOptions(0));
  const Eigen::VectorXd k = RandomK(energy.num_parameters(), 0.002, 6);
  const Eigen::VectorXd curvature = DataCurvature(&energy.data_term(0), k);
  const double h = 1e-7;
  for (int s = 0; s < k.size(); ++s) {
    Eigen::VectorXd plus = k, minus = k;
    plus[s] += h;
    minus[s] -= h;
    const std::vector<double> r_plus = AllResiduals(&energy.data_term(0), plus);
    const std::vector<double> r_minus = AllResiduals(&energy.data_term(0), minus);
    double expected = 0.0;
    for (size_t r = 0; r < r_plus.size(); ++r) {
      const double slope = (r_plus[r] - r_minus[r]) / (2.0 * h);
      expected += slope * slope;
    }
    EXPECT_NEAR(curvature[s], expected, 1e-5 * expected + 1e-9) << "Gaussian " << s;
  }
}

// A 20 x 20 grid: columns 0-9 one plain colour, columns 10-19 stripes of alternating colours,
// except for a 6 x 6 plain patch inside the stripes and one odd colour inside the plain half.
struct ClothScene {
  SurfaceGaussians surface;
  VertexNeighbourhoods neighbourhoods;
  static constexpr int kSize = 20;
  static int Id(int row, int col) { return row * kSize + col; }
  static constexpr int kOdd = 10 * kSize + 3;
};

ClothScene MakeClothScene() {
  ClothScene scene;
  const Mesh mesh = GridMesh(ClothScene::kSize, ClothScene::kSize, 0.01);
  ReferenceColors colors;
  colors.color_space = ColorSpace::kChromaticity;
  const Eigen::Vector3f plain(0.40f, 0.35f, 0.25f);
  for (int row = 0; row < ClothScene::kSize; ++row) {
    for (int col = 0; col < ClothScene::kSize; ++col) {
      const bool patch = row >= 3 && row < 9 && col >= 12 && col < 18;
      Eigen::Vector3f color = plain;
      if (col >= 10 && !patch) {
        color = col % 2 ? Eigen::Vector3f(0.6f, 0.2f, 0.2f) : Eigen::Vector3f(0.2f, 0.3f, 0.5f);
      }
      colors.colors.push_back(color);
      colors.valid.push_back(1);
    }
  }
  colors.colors[ClothScene::kOdd] = Eigen::Vector3f(0.1f, 0.8f, 0.1f);
  std::vector<int> ids(mesh.num_vertices());
  for (int v = 0; v < mesh.num_vertices(); ++v) ids[v] = v;
  scene.surface = MakeSurfaceGaussians(mesh.vertices, ComputeVertexNormals(mesh), ids, colors);
  scene.neighbourhoods = BuildVertexNeighbourhoods(mesh, 2);
  return scene;
}

Regularizer MakeRegularizer(const ClothScene& scene) {
  return Regularizer(scene.neighbourhoods, scene.surface.vertex_ids, 2, 1000.0);
}

TEST(ColorVariationTest, ZeroOnPlainClothEvenBesideAnOddColourAndLargeOnStripes) {
  const ClothScene scene = MakeClothScene();
  const Eigen::VectorXd variation = ColorVariation(scene.surface, MakeRegularizer(scene));
  EXPECT_EQ(variation[ClothScene::kOdd], 0.0);
  EXPECT_EQ(variation[ClothScene::kOdd + 1], 0.0);
  EXPECT_EQ(variation[ClothScene::Id(2, 2)], 0.0);
  // Half the neighbours of a stripe vertex have the other colour: the median distance from
  // the median colour is that of one stripe colour to the other, or half of it per channel.
  EXPECT_GT(variation[ClothScene::Id(15, 17)], 0.01);
}

TEST(PlainClothTest, HoldsWidePlainRegionsAndLeavesNarrowPatchesToTheRegulariser) {
  const ClothScene scene = MakeClothScene();
  const Regularizer regularizer = MakeRegularizer(scene);
  EnergyOptions options;
  options.confidence_opening = 2;
  const Eigen::VectorXd plain = PlainCloth(scene.surface, regularizer, options);
  EXPECT_GT(plain[ClothScene::Id(10, 2)], 0.99);
  EXPECT_GT(plain[ClothScene::kOdd], 0.99);
  EXPECT_LT(plain[ClothScene::Id(15, 17)], 0.01);
  EXPECT_LT(plain[ClothScene::Id(6, 15)], 0.01) << "the 6 x 6 patch is narrower than the opening";

  options.confidence_opening = 0;
  const Eigen::VectorXd unopened = PlainCloth(scene.surface, regularizer, options);
  EXPECT_GT(unopened[ClothScene::Id(6, 15)], 0.99) << "without the opening the patch is plain";
}

TEST(PriorCurvatureTest, AddsTheUniformPullAndTheScaledConfidencePull) {
  EnergyOptions options;
  options.w_prior = 2.0;
  options.reg_unit = RegUnit::kMillimetres;
  options.confidence_prior = 10.0;
  const Eigen::VectorXd data = (Eigen::VectorXd(5) << 4.0, 0.0, 1.0, 3.0, 2.0).finished();
  const Eigen::VectorXd confidence = (Eigen::VectorXd(5) << 0.0, 1.0, 0.5, 1.0, 0.0).finished();
  int measured = 0;
  const auto typical = [&] {
    ++measured;
    return MedianOfPositive(data);
  };
  const Eigen::VectorXd prior = PriorCurvature(typical, confidence, 5, options);
  // Median of the positive data curvatures {1, 2, 3, 4}: the upper middle one, 3; the pull goes
  // with the square of the doubt, 1 - c.
  EXPECT_EQ(measured, 1);
  const double uniform = 2.0 * 2.0 * 1e6;
  const double doubt_squared[5] = {1.0, 0.0, 0.25, 0.0, 1.0};
  for (int s = 0; s < 5; ++s) {
    EXPECT_DOUBLE_EQ(prior[s], uniform + 10.0 * 3.0 * doubt_squared[s]);
  }

  options.confidence_prior = 0.0;
  EXPECT_EQ(PriorCurvature(typical, {}, 3, options), Eigen::VectorXd::Constant(3, uniform));
  EXPECT_EQ(measured, 1);  // Without a confidence pull the data is not measured.
}

// On plain cloth the pull is on everywhere: the scalar energy, its gradient and the
// least-squares cost the Ceres solver minimises must all include it, and agree; with the input as
// given off the subdivided surface (an approximating subdivision) the pull is towards it.
TEST(InputPriorEnergyTest, ScalarGradientAndLeastSquaresFormAgree) {
  for (const bool off_the_input : {false, true}) {
    SCOPED_TRACE(off_the_input ? "input as given off k = 0" : "input as given at k = 0");
    EnergyScene scene = MakeEnergyScene({0.0, 0.6}, 2, 9);
    for (Eigen::Vector3f& color : scene.surface.colors) color = Eigen::Vector3f(0.4f, 0.3f, 0.3f);
    if (off_the_input) {
      const Eigen::VectorXd offsets = RandomK(scene.surface.size(), 0.002, 11);
      scene.surface.input_offset.assign(offsets.data(), offsets.data() + offsets.size());
    }
    FrameEnergy energy(scene.surface, scene.cameras, scene.neighbourhoods, SurfaceColorOptions(50));
    EXPECT_GT(energy.pull_curvature().minCoeff(), 0.0);
    EXPECT_EQ(energy.pull_target().norm() > 0.0, off_the_input);

    const Eigen::VectorXd k = RandomK(energy.num_parameters(), 0.004, 10);
    Eigen::VectorXd gradient;
    double similarity = 0.0, quadratic = 0.0;
    const double e = energy.Evaluate(k, &gradient, &similarity, &quadratic);
    const Eigen::VectorXd from_target = k - energy.pull_target();
    const double prior = 0.5 * from_target.dot(energy.pull_curvature().cwiseProduct(from_target));
    const double smoothness = energy.options().w_reg * energy.regularizer().Evaluate(k, nullptr);
    EXPECT_GT(smoothness, 0.0);
    EXPECT_NEAR(quadratic, smoothness + prior, 1e-12 * quadratic);
    EXPECT_NEAR(e, similarity - quadratic, 1e-12 * quadratic);
    EXPECT_NEAR(LeastSquaresCost(&energy, k), -e, 1e-9 * std::abs(e));

    const Eigen::VectorXd numeric = NumericGradient(
        [&](const Eigen::VectorXd& x) { return energy.Evaluate(x, nullptr); }, k, 1e-7);
    EXPECT_LT((gradient - numeric).norm(), 1e-5 * gradient.norm());
  }
}

// Pulls on one unknown are one quadratic: the first is taken as it is, a later one adds its
// curvature and blends the targets by the curvatures; no curvature or no target adds nothing.
TEST(PullsTest, TwoPullsOnOneUnknownAreOneQuadratic) {
  Pulls pulls(3);
  EXPECT_EQ(pulls.Evaluate(Eigen::VectorXd::Zero(3)), 0.0);
  pulls.Add(Eigen::Vector3d(2.0, 0.0, 1.0), Eigen::Vector3d(0.1, 0.2, 0.3));
  EXPECT_EQ(pulls.curvature(), Eigen::Vector3d(2.0, 0.0, 1.0));
  EXPECT_EQ(pulls.target(), Eigen::Vector3d(0.1, 0.0, 0.3));  // No pull, no target.
  pulls.Add(3.0, Eigen::Vector3d(0.6, 0.4, std::nan("")));
  EXPECT_EQ(pulls.curvature(), Eigen::Vector3d(5.0, 3.0, 1.0));
  EXPECT_NEAR(pulls.target()[0], (2.0 * 0.1 + 3.0 * 0.6) / 5.0, 1e-15);
  EXPECT_EQ(pulls.target()[1], 0.4);
  EXPECT_EQ(pulls.target()[2], 0.3);
  // Against the two quadratics summed: equal up to a constant, the same at every k.
  const auto separate = [](const Eigen::Vector3d& k) {
    return 0.5 * (2.0 * std::pow(k[0] - 0.1, 2) + 3.0 * std::pow(k[0] - 0.6, 2) +
                  3.0 * std::pow(k[1] - 0.4, 2) + std::pow(k[2] - 0.3, 2));
  };
  const Eigen::Vector3d a(0.0, 0.1, -0.2), b(0.5, -0.3, 0.7);
  EXPECT_NEAR(separate(a) - pulls.Evaluate(a), separate(b) - pulls.Evaluate(b), 1e-14);
  pulls.Add(-1.0, Eigen::Vector3d::Zero());  // A negative curvature is no pull.
  EXPECT_EQ(pulls.curvature(), Eigen::Vector3d(5.0, 3.0, 1.0));
  EXPECT_THROW(pulls.Add(1.0, Eigen::VectorXd::Zero(4)), Error);
}

}  // namespace
}  // namespace finecap
