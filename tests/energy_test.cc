#include <random>

#include <gtest/gtest.h>

#include "energy/terms/consensus/consensus_similarity.h"
#include "energy/terms/paper/paper_similarity.h"
#include "energy/terms/surface_color/surface_color_similarity.h"
#include "energy_fixture.h"
#include "finecap/energy/frame_energy.h"
#include "model/surface_projection.h"

namespace finecap {
namespace {

EnergyOptions Options(const std::string& similarity, const std::string& overlap) {
  EnergyOptions options;
  EXPECT_TRUE(StringToEnum(similarity, &options.similarity)) << similarity;
  EXPECT_TRUE(StringToEnum(overlap, &options.overlap)) << overlap;
  options.k_max = 0.01;
  return options;
}

class EnergyDerivativeTest : public ::testing::TestWithParam<EnergyForm> {};

// dE/dk of the full energy (similarity and regulariser) against central differences, for
// cameras from straight on to grazing (80 degrees).
TEST_P(EnergyDerivativeTest, GradientMatchesCentralDifferences) {
  const auto [similarity, overlap] = GetParam();
  const EnergyScene scene = MakeEnergyScene({0.0, 0.5, 1.0, 1.4}, 3, 5);
  const FrameEnergy energy(scene.surface, scene.cameras, scene.neighbourhoods,
                           Options(similarity, overlap));
  ASSERT_GT(energy.num_pairs(), 100);
  for (unsigned trial = 0; trial < 3; ++trial) {
    const Eigen::VectorXd k = RandomK(energy.num_parameters(), 0.004, trial);
    Eigen::VectorXd analytic;
    energy.Evaluate(k, &analytic);
    const Eigen::VectorXd numeric = NumericGradient(
        [&](const Eigen::VectorXd& x) { return energy.Evaluate(x, nullptr); }, k, 1e-7);
    // The paper's min() has kinks; coordinates whose difference quotient straddles one are rare
    // and are the only ones allowed to disagree.
    int disagreeing = 0;
    for (int s = 0; s < k.size(); ++s) {
      const double error = std::abs(analytic[s] - numeric[s]);
      disagreeing += error > 1e-6 * std::max(numeric.cwiseAbs().maxCoeff(), 1e-12);
    }
    EXPECT_LE(disagreeing, similarity == "paper" ? 1 : 0) << "trial " << trial;
  }
}

INSTANTIATE_TEST_SUITE_P(AllForms, EnergyDerivativeTest, AllEnergyForms(), EnergyFormName);

// Every least-squares residual's Jacobian against central differences of the residuals.
TEST_P(EnergyDerivativeTest, ResidualJacobiansMatchCentralDifferences) {
  const auto [similarity, overlap] = GetParam();
  EnergyScene scene = MakeEnergyScene({0.0, 0.7, 1.3}, 3, 9);
  FrameEnergy energy(scene.surface, scene.cameras, scene.neighbourhoods,
                     Options(similarity, overlap));
  DataTerm& term = energy.data_term(0);
  const Eigen::VectorXd k = RandomK(energy.num_parameters(), 0.003, 17);
  const double h = 1e-7;
  term.PrepareResiduals(k, true);
  int checked = 0, disagreeing = 0;
  for (int b = 0; b < static_cast<int>(term.residual_blocks().size()); ++b) {
    const auto& block = term.residual_blocks()[b];
    const int R = block.num_residuals, P = static_cast<int>(block.parameters.size());
    std::vector<double> residuals(R), jacobian(R * P);
    term.BlockResiduals(b, residuals.data(), jacobian.data());
    for (int p = 0; p < P; ++p) {
      std::vector<double> plus(R), minus(R);
      Eigen::VectorXd shifted = k;
      shifted[block.parameters[p]] += h;
      term.PrepareResiduals(shifted, false);
      term.BlockResiduals(b, plus.data(), nullptr);
      shifted[block.parameters[p]] -= 2 * h;
      term.PrepareResiduals(shifted, false);
      term.BlockResiduals(b, minus.data(), nullptr);
      for (int r = 0; r < R; ++r) {
        const double numeric = (plus[r] - minus[r]) / (2 * h);
        const double error = std::abs(numeric - jacobian[r * P + p]);
        disagreeing += error > 1e-6 * std::max(std::abs(numeric), 1.0);
        ++checked;
      }
    }
    term.PrepareResiduals(k, true);
    if (b > 150) break;  // Enough blocks; each costs a full preparation per parameter.
  }
  EXPECT_GT(checked, 140);
  EXPECT_LE(disagreeing, similarity == "paper" ? 2 : 0);
}

// The least-squares residuals and the scalar similarity describe the same residual, for each
// similarity whose scalar is a sum of squares.
class ScalarAndResidualsTest : public ::testing::TestWithParam<std::string> {};

TEST_P(ScalarAndResidualsTest, ScalarIsMinusHalfTheSumOfSquaredResiduals) {
  EnergyScene scene = MakeEnergyScene({0.0, 0.6, -0.4}, 2, 3);
  FrameEnergy energy(scene.surface, scene.cameras, scene.neighbourhoods,
                     Options(GetParam(), "printed"));
  const Eigen::VectorXd k = RandomK(energy.num_parameters(), 0.005, 4);
  DataTerm& term = energy.data_term(0);
  ASSERT_GT(term.residual_blocks().size(), 10u);
  term.PrepareResiduals(k, false);
  double sum = 0.0;
  for (int b = 0; b < static_cast<int>(term.residual_blocks().size()); ++b) {
    std::vector<double> residuals(term.residual_blocks()[b].num_residuals);
    term.BlockResiduals(b, residuals.data(), nullptr);
    for (double r : residuals) sum += r * r;
  }
  EXPECT_GT(sum, 0.0);
  EXPECT_NEAR(term.Evaluate(k, nullptr), -0.5 * sum, 1e-12 * sum);
}

// BlockCosts gives each block's sum of squares, at a k the same for every Gaussian (the sweep's
// samples, where consensus reads each row's colour once) as at any other.
TEST_P(ScalarAndResidualsTest, BlockCostsAreEachBlocksSumOfSquares) {
  EnergyScene scene = MakeEnergyScene({0.0, 0.6, -0.4}, 2, 3);
  FrameEnergy energy(scene.surface, scene.cameras, scene.neighbourhoods,
                     Options(GetParam(), "printed"));
  DataTerm& term = energy.data_term(0);
  const int num_blocks = static_cast<int>(term.residual_blocks().size());
  ASSERT_GT(num_blocks, 10);
  for (const Eigen::VectorXd& k :
       {Eigen::VectorXd(Eigen::VectorXd::Constant(energy.num_parameters(), 0.003)),
        RandomK(energy.num_parameters(), 0.005, 4)}) {
    std::vector<double> costs;
    term.BlockCosts(k, &costs);
    ASSERT_EQ(costs.size(), static_cast<size_t>(num_blocks));
    term.PrepareResiduals(k, false);
    double total = 0.0;
    for (int b = 0; b < num_blocks; ++b) {
      std::vector<double> residuals(term.residual_blocks()[b].num_residuals);
      term.BlockResiduals(b, residuals.data(), nullptr);
      double sum = 0.0;
      for (double r : residuals) sum += r * r;
      EXPECT_NEAR(costs[b], sum, 1e-12 * (1.0 + sum)) << "block " << b;
      total += sum;
    }
    EXPECT_GT(total, 0.0);
  }
}

INSTANTIATE_TEST_SUITE_P(SumOfSquares, ScalarAndResidualsTest,
                         ::testing::Values("surface_color", "consensus"));

// The plane sweep's costs for every similarity: UniformBlockCosts at each displacement is
// BlockCosts there, to the bit (for consensus, several displacements at a time against one).
TEST(DataTermTest, UniformBlockCostsAreBlockCostsAtEachDisplacement) {
  EnergyScene scene = MakeEnergyScene({0.0, 0.6, -0.4}, 2, 3);
  for (const std::string similarity : {"paper", "surface_color", "consensus"}) {
    FrameEnergy energy(scene.surface, scene.cameras, scene.neighbourhoods,
                       Options(similarity, "printed"));
    DataTerm& term = energy.data_term(0);
    const int n = energy.num_parameters();
    const Eigen::VectorXd displacements = Eigen::VectorXd::LinSpaced(9, -0.01, 0.01);
    Eigen::MatrixXd costs;
    ASSERT_NE(term.sweep_costs(), nullptr) << similarity;
    term.sweep_costs()->UniformBlockCosts(n, displacements, &costs);
    ASSERT_EQ(costs.rows(), static_cast<Eigen::Index>(term.residual_blocks().size()));
    ASSERT_EQ(costs.cols(), displacements.size());
    for (int j = 0; j < displacements.size(); ++j) {
      std::vector<double> block_costs;
      term.BlockCosts(Eigen::VectorXd::Constant(n, displacements[j]), &block_costs);
      for (int b = 0; b < costs.rows(); ++b) {
        EXPECT_EQ(costs(b, j), block_costs[b]) << similarity << " block " << b << " sample " << j;
      }
    }
    EXPECT_GT(costs.sum(), 0.0) << similarity;
  }
}

struct UniformCostsCase {
  bool gain_per_channel;
  double contrast_floor;
  double robust_fraction;
};

std::ostream& operator<<(std::ostream& os, const UniformCostsCase& variant) {
  return os << "gain_per_channel " << variant.gain_per_channel << ", contrast_floor "
            << variant.contrast_floor << ", robust_fraction " << variant.robust_fraction;
}

class ConsensusUniformCostsTest : public ::testing::TestWithParam<UniformCostsCase> {};

// The consensus similarity reduces each block to its cost at the sweep's uniform displacements
// without writing its residuals, several displacements at a time. Each cost must be the one the
// residual path gives, to rounding: that of SummaryAt (which BlockCosts takes when k is not
// uniform; a block depends on its centre's k alone), and the sum of squares of the residuals
// PrepareResiduals writes (the robust loss applied to each). With a patch shape set, the costs come
// from the residual path itself.
TEST_P(ConsensusUniformCostsTest, CostsAreThoseOfTheResidualPath) {
  const UniformCostsCase variant = GetParam();
  EnergyScene scene = MakeEnergyScene({0.0, 0.6, -0.4}, 2, 3);
  EnergyOptions options = Options("consensus", "printed");
  options.consensus.gain_per_channel = variant.gain_per_channel;
  options.consensus.contrast_floor = variant.contrast_floor;
  options.consensus.robust_fraction = variant.robust_fraction;
  FrameEnergy energy(scene.surface, scene.cameras, scene.neighbourhoods, options);
  auto& consensus = dynamic_cast<ConsensusSimilarity&>(energy.data_term(0));
  const auto& blocks = consensus.residual_blocks();
  ASSERT_GT(blocks.size(), 10u);
  const int n = energy.num_parameters();
  // Eleven: a batch of eight and three alone; on the tables' nodes, between them and beyond.
  const Eigen::VectorXd displacements =
      Eigen::VectorXd::LinSpaced(11, -1.2 * options.k_max, 1.1 * options.k_max);
  for (const bool shaped : {false, true}) {
    consensus.SetPatchShape(shaped ? RandomK(n, 0.003, 5) : Eigen::VectorXd::Zero(n));
    Eigen::MatrixXd costs;
    consensus.UniformBlockCosts(n, displacements, &costs);
    ASSERT_EQ(costs.rows(), static_cast<Eigen::Index>(blocks.size()));
    ASSERT_EQ(costs.cols(), displacements.size());
    double total = 0.0;
    for (int j = 0; j < displacements.size(); ++j) {
      Eigen::VectorXd k = Eigen::VectorXd::Constant(n, displacements[j]);
      const int moved = blocks[0].parameters[0];
      k[moved] += 1e-4;
      std::vector<double> summary_costs;
      consensus.BlockCosts(k, &summary_costs);
      consensus.PrepareResiduals(Eigen::VectorXd::Constant(n, displacements[j]), false);
      for (int b = 0; b < static_cast<int>(blocks.size()); ++b) {
        if (blocks[b].parameters[0] != moved) {
          EXPECT_NEAR(costs(b, j), summary_costs[b], 1e-12 * (1.0 + summary_costs[b]))
              << "block " << b << " sample " << j;
        }
        std::vector<double> residuals(blocks[b].num_residuals);
        consensus.BlockResiduals(b, residuals.data(), nullptr);
        double sum = 0.0;
        for (double r : residuals) sum += r * r;
        EXPECT_NEAR(costs(b, j), sum, 1e-12 * (1.0 + sum)) << "block " << b << " sample " << j;
        total += sum;
      }
    }
    EXPECT_GT(total, 0.0) << "shaped " << shaped;
  }
}

INSTANTIATE_TEST_SUITE_P(
    NormalisationsAndLosses, ConsensusUniformCostsTest,
    ::testing::Values(UniformCostsCase{true, 0.005, 0.5}, UniformCostsCase{false, 0.005, 0.5},
                      UniformCostsCase{true, 1e-6, 0.0}, UniformCostsCase{false, 1e-6, 0.0},
                      UniformCostsCase{true, 0.5, 0.5}, UniformCostsCase{false, 0.5, 0.0}));

// A camera's gain and offset (per channel, as exposure and white balance) change each block's
// weight but not the direction of its residual vector: the disagreement the solver sees is the
// same up to a factor per block, so its optimum does not move.
TEST(ConsensusSimilarityTest, IgnoresEachCamerasGainAndOffset) {
  EnergyScene scene = MakeEnergyScene({0.0, 0.6, -0.4}, 3, 8);
  EnergyOptions options = Options("consensus", "printed");
  options.consensus.contrast_floor = 1e-6;
  const Eigen::VectorXd k = RandomK(scene.surface.size(), 0.004, 2);
  const auto residuals_of = [&](const EnergyScene& s) {
    FrameEnergy energy(s.surface, s.cameras, s.neighbourhoods, options);
    DataTerm& term = energy.data_term(0);
    term.PrepareResiduals(k, false);
    std::vector<std::vector<double>> all;
    for (int b = 0; b < static_cast<int>(term.residual_blocks().size()); ++b) {
      all.emplace_back(term.residual_blocks()[b].num_residuals);
      term.BlockResiduals(b, all.back().data(), nullptr);
    }
    return all;
  };
  const auto plain = residuals_of(scene);
  // Camera 1 twice as bright in red, 0.7 times in blue, with offsets.
  std::vector<ImageGaussian> gaussians;
  for (int i = 0; i < scene.images[1]->size(); ++i) {
    ImageGaussian g = (*scene.images[1])[i];
    g.color[0] = 2.0f * g.color[0] + 0.1f;
    g.color[1] = g.color[1] - 0.2f;
    g.color[2] = 0.7f * g.color[2];
    gaussians.push_back(g);
  }
  EnergyScene changed = std::move(scene);
  changed.images[1] = std::make_unique<ImageGaussians>(
      changed.cameras[1].camera.width, changed.cameras[1].camera.height, ColorSpace::kNormalizedRgb,
      gaussians, "test");
  changed.cameras[1].image = changed.images[1].get();
  const auto adjusted = residuals_of(changed);
  ASSERT_EQ(plain.size(), adjusted.size());
  ASSERT_GT(plain.size(), 10u);
  for (size_t b = 0; b < plain.size(); ++b) {
    // Per channel, the residuals of a block scale by one factor (the weight's change).
    for (int channel = 0; channel < 3; ++channel) {
      double dot = 0.0, plain_norm = 0.0, adjusted_norm = 0.0;
      for (size_t r = channel; r < plain[b].size(); r += 3) {
        dot += plain[b][r] * adjusted[b][r];
        plain_norm += plain[b][r] * plain[b][r];
        adjusted_norm += adjusted[b][r] * adjusted[b][r];
      }
      if (plain_norm < 1e-20) continue;
      EXPECT_NEAR(dot / std::sqrt(plain_norm * adjusted_norm), 1.0, 1e-6)
          << "block " << b << " channel " << channel;
    }
  }
}

// The colour tables hold, at each node, the overlap-weighted colour and its slope that
// ImageColorOfPairs computes directly over the image Gaussians in reach, in every overlap form.
TEST(ConsensusSimilarityTest, TablesHoldTheImageColourAtTheirNodes) {
  for (const std::string form : {"printed", "exact", "patch"}) {
    EnergyScene scene = MakeEnergyScene({0.0, 0.6, -0.4}, 2, 6);
    const EnergyOptions options = Options("consensus", form);
    FrameEnergy energy(scene.surface, scene.cameras, scene.neighbourhoods, options);
    const auto& consensus = dynamic_cast<const ConsensusSimilarity&>(energy.data_term(0));
    const int num_nodes =
        ConsensusSimilarity::NumTableNodes(scene.surface.sigma_hat, options.k_max);
    const double step = 2.0 * options.k_max / (num_nodes - 1);
    int compared = 0;
    for (int c = 0; c < static_cast<int>(energy.views().size()); ++c) {
      // The energy released its pair lists and let go of the image Gaussians once the tables
      // were built: the same lists again, over the camera's image Gaussians.
      EnergyView view = energy.views()[c];
      EXPECT_EQ(view.image, nullptr);
      view.image = scene.cameras[c].image;
      view.pairs = BuildCameraPairs(view.camera, *view.image, energy.surface(),
                                    scene.cameras[c].visible, EnergyPairOptions(options));
      ASSERT_EQ(view.pairs.surface_ids, energy.views()[c].pairs.surface_ids);
      for (int row = 0; row < static_cast<int>(view.pairs.surface_ids.size()); row += 7) {
        const Eigen::Vector3d own =
            energy.surface().colors[view.pairs.surface_ids[row]].cast<double>();
        // Inner nodes: at the table's ends the derivative is that of the clamped colour, zero.
        for (int node = 1; node + 1 < num_nodes; ++node) {
          const double k = -options.k_max + node * step;
          Eigen::Vector3d direct_slope, tabulated_slope;
          const Eigen::Vector3d direct =
              ImageColorOfPairs(view, energy.surface(), row, k, options.overlap, own, &direct_slope,
                                options.reach_sigmas);
          const Eigen::Vector3d tabulated = consensus.Interpolate(c, row, k, &tabulated_slope);
          EXPECT_LT((tabulated - direct).norm(), 1e-6 * (1.0 + direct.norm())) << form;
          EXPECT_LT((tabulated_slope - direct_slope).norm(), 1e-5 * (1.0 + direct_slope.norm()))
              << form;
          ++compared;
        }
      }
    }
    EXPECT_GT(compared, 20) << form;
  }
}

// A plain surface (every image Gaussian the same colour) gives the consensus nothing to agree
// on: no weight, no residual, no pull anywhere.
// The consensus similarity reads only its tables once built, so the energy keeps no image
// Gaussian ids of its pairs, but counts them, and no image Gaussians; a similarity that reads its
// pairs keeps both.
TEST(FrameEnergyTest, ReleasesThePairListsOfASimilarityThatDoesNotReadThem) {
  EnergyScene scene = MakeEnergyScene({0.0, 0.6, -0.4}, 2, 6);
  for (const std::string similarity : {"consensus", "surface_color"}) {
    const EnergyOptions options = Options(similarity, "exact");
    const FrameEnergy energy(scene.surface, scene.cameras, scene.neighbourhoods, options);
    long pairs = 0, kept = 0;
    for (size_t c = 0; c < energy.views().size(); ++c) {
      pairs += BuildCameraPairs(scene.cameras[c].camera, *scene.cameras[c].image, energy.surface(),
                                scene.cameras[c].visible, EnergyPairOptions(options))
                   .num_pairs();
      kept += energy.views()[c].pairs.num_pairs();
      // Nor does it refer to the image Gaussians, which may then go (PreparedFrame::images).
      EXPECT_EQ(energy.views()[c].image,
                similarity == "consensus" ? nullptr : scene.cameras[c].image)
          << similarity;
    }
    EXPECT_GT(pairs, 0) << similarity;
    EXPECT_EQ(energy.num_pairs(), pairs) << similarity;
    EXPECT_EQ(kept, similarity == "consensus" ? 0 : pairs) << similarity;
  }
}

TEST(ConsensusSimilarityTest, PlainSurfaceCarriesNoWeight) {
  EnergyScene scene = MakeEnergyScene({0.0, 0.6}, 3, 5);
  for (auto& image : scene.images) {
    std::vector<ImageGaussian> gaussians;
    for (int i = 0; i < image->size(); ++i) {
      ImageGaussian g = (*image)[i];
      g.color[0] = 0.4f, g.color[1] = 0.5f, g.color[2] = 0.6f;
      gaussians.push_back(g);
    }
    image = std::make_unique<ImageGaussians>(image->width(), image->height(),
                                             ColorSpace::kNormalizedRgb, gaussians, "test");
  }
  for (size_t c = 0; c < scene.cameras.size(); ++c) scene.cameras[c].image = scene.images[c].get();
  FrameEnergy energy(scene.surface, scene.cameras, scene.neighbourhoods,
                     Options("consensus", "printed"));
  Eigen::VectorXd gradient;
  const double value =
      energy.data_term(0).Evaluate(RandomK(scene.surface.size(), 0.004, 1), &gradient);
  EXPECT_NEAR(value, 0.0, 1e-20);
  EXPECT_LT(gradient.cwiseAbs().maxCoeff(), 1e-12);
}

// Near the min() clamp: scale one camera's image Gaussians so that the overlap sums sit just
// below E_ii, where the gradient is still defined and must match.
TEST(PaperSimilarityTest, GradientNearTheClampMatches) {
  EnergyScene scene = MakeEnergyScene({0.0}, 4, 21);
  FrameEnergy energy(scene.surface, scene.cameras, scene.neighbourhoods, Options("paper", "exact"));
  const Eigen::VectorXd k = Eigen::VectorXd::Zero(energy.num_parameters());
  Eigen::VectorXd analytic;
  const double value = energy.data_term(0).Evaluate(k, &analytic);
  const Eigen::VectorXd numeric = NumericGradient(
      [&](const Eigen::VectorXd& x) { return energy.data_term(0).Evaluate(x, nullptr); }, k, 1e-8);
  EXPECT_GT(value, 0.0);
  EXPECT_LT((analytic - numeric).norm(), 1e-5 * numeric.norm() + 1e-9);
}

TEST(RegularizerTest, MatchesThePapersDoubleSumAndItsGradient) {
  const Mesh mesh = GridMesh(5, 5, 0.01);
  const VertexNeighbourhoods neighbourhoods = BuildVertexNeighbourhoods(mesh, 3);
  // Surface Gaussians on every vertex but 12 (the centre), which stays at k = 0.
  std::vector<int> ids;
  for (int v = 0; v < 25; ++v) {
    if (v != 12) ids.push_back(v);
  }
  const Regularizer regularizer(neighbourhoods, ids, 3, 1000.0);
  const Eigen::VectorXd k = RandomK(24, 0.003, 8);
  Eigen::VectorXd full = Eigen::VectorXd::Zero(25);
  for (int s = 0; s < 24; ++s) full[ids[s]] = k[s];
  double expected = 0.0;
  for (int v = 0; v < 25; ++v) {
    for (int e = neighbourhoods.offsets[v]; e < neighbourhoods.offsets[v + 1]; ++e) {
      const double difference = 1000.0 * (full[v] - full[neighbourhoods.neighbours[e]]);
      expected += Wendland(neighbourhoods.edge_distances[e], 3) * difference * difference;
    }
  }
  Eigen::VectorXd analytic;
  EXPECT_NEAR(regularizer.Evaluate(k, &analytic), expected, 1e-9 * expected);
  const Eigen::VectorXd numeric = NumericGradient(
      [&](const Eigen::VectorXd& x) { return regularizer.Evaluate(x, nullptr); }, k, 1e-7);
  EXPECT_LT((analytic - numeric).norm(), 1e-6 * numeric.norm());
}

// Averaging keeps what is smooth over the neighbourhood (a plane of k) and damps what changes from
// one vertex to the next (a checkerboard), and a neighbour fixed at k = 0 does not pull it down.
TEST(RegularizerTest, AveragingOverNeighboursKeepsAPlaneAndDampsACheckerboard) {
  const Mesh mesh = GridMesh(9, 9, 0.01);
  // Cut-off 2 edges, as by default: the one-ring carries the weight (T(2) = 0).
  const VertexNeighbourhoods neighbourhoods = BuildVertexNeighbourhoods(mesh, 2);
  std::vector<int> ids;
  for (int v = 1; v < 81; ++v) ids.push_back(v);  // Vertex 0, a corner, stays fixed.

  const Regularizer regularizer(neighbourhoods, ids, 2, 1000.0);
  Eigen::MatrixXd values(ids.size(), 2);
  for (size_t s = 0; s < ids.size(); ++s) {
    const int x = ids[s] % 9, y = ids[s] / 9;
    values(s, 0) = 0.001 * x - 0.002 * y + 0.003;
    values(s, 1) = (x + y) % 2 == 0 ? 0.001 : -0.001;
  }
  Eigen::MatrixXd averaged = values;
  regularizer.AverageOverNeighbours(2, &averaged);
  for (size_t s = 0; s < ids.size(); ++s) {
    const int x = ids[s] % 9, y = ids[s] / 9;
    // Two rounds reach two edges: further from the border (and the fixed corner) every one-ring
    // involved is symmetric about its vertex.
    if (x >= 3 && x <= 5 && y >= 3 && y <= 5) {
      EXPECT_NEAR(averaged(s, 0), values(s, 0), 1e-12) << "vertex " << ids[s];
    }
  }
  EXPECT_LT(averaged.col(1).norm(), 0.5 * values.col(1).norm());
  Eigen::MatrixXd unchanged = values;
  regularizer.AverageOverNeighbours(0, &unchanged);
  EXPECT_EQ(unchanged, values);
}

}  // namespace
}  // namespace finecap

namespace finecap {
namespace {

// One image Gaussian exactly as wide as the projected surface Gaussians: a single pair explains
// it almost fully (sum just below E_ii, the clamp not yet active) and two pairs more than fully
// (clamped: no derivative may pass).
class PaperClampTest : public ::testing::Test {
 protected:
  PaperClampTest() {
    camera_ = LookAtOrigin(1.0, 0.0, 500.0, 200);
    mesh_ = GridMesh(2, 2, 0.01, 0.0);
    normals_ = ComputeVertexNormals(mesh_);
    ReferenceColors colors;
    colors.color_space = ColorSpace::kNormalizedRgb;
    colors.sigma_hat = 0.004;
    colors.colors.assign(4, Eigen::Vector3f(0.5f, 0.4f, 0.3f));
    colors.valid.assign(4, 1);
    surface_all_ = MakeSurfaceGaussians(mesh_.vertices, normals_, {0, 1, 2, 3}, colors);
    const ProjectedGaussian projected = ProjectSurfaceGaussian(
        camera_, surface_all_.base.col(0), surface_all_.normals.col(0), 0.0, 0.004);
    ImageGaussian g;
    g.x = static_cast<float>(projected.mean.x() + 0.3);
    g.y = static_cast<float>(projected.mean.y());
    g.sigma = static_cast<float>(projected.sigma);
    g.color[0] = 0.5f, g.color[1] = 0.4f, g.color[2] = 0.3f;
    image_ = std::make_unique<ImageGaussians>(200, 200, ColorSpace::kNormalizedRgb,
                                              std::vector<ImageGaussian>{g}, "test");
  }

  // The paper's similarity and its analytic and numeric gradients, with surface Gaussians `ids`.
  double Check(const std::vector<int>& ids, double* worst_error, double* gradient_norm) {
    ReferenceColors colors;
    colors.color_space = ColorSpace::kNormalizedRgb;
    colors.sigma_hat = 0.004;
    colors.colors.assign(4, Eigen::Vector3f(0.5f, 0.4f, 0.3f));
    colors.valid.assign(4, 1);
    const SurfaceGaussians surface = MakeSurfaceGaussians(mesh_.vertices, normals_, ids, colors);
    std::vector<EnergyView> views(1);
    views[0].camera = camera_;
    views[0].image = image_.get();
    PairOptions pair_options;
    pair_options.k_max = 0.005;
    views[0].pairs = BuildCameraPairs(camera_, *image_, surface,
                                      std::vector<unsigned char>(surface.size(), 1), pair_options);
    const PaperSimilarity similarity(surface, views, OverlapForm::kPrinted);
    const Eigen::VectorXd k = Eigen::VectorXd::Zero(surface.size());
    Eigen::VectorXd analytic;
    const double value = similarity.Evaluate(k, &analytic);
    const Eigen::VectorXd numeric = NumericGradient(
        [&](const Eigen::VectorXd& x) { return similarity.Evaluate(x, nullptr); }, k, 1e-9);
    *worst_error = (analytic - numeric).cwiseAbs().maxCoeff();
    *gradient_norm = analytic.norm();
    return value;
  }

  Camera camera_;
  Mesh mesh_;
  Eigen::Matrix3Xd normals_;
  SurfaceGaussians surface_all_;
  std::unique_ptr<ImageGaussians> image_;
};

TEST_F(PaperClampTest, JustBelowTheClampTheGradientMatches) {
  double error = 0.0, norm = 0.0;
  const double explained = Check({0}, &error, &norm);
  EXPECT_GT(explained, 0.95);  // sum / E_ii: just below the clamp at 1.
  EXPECT_LT(explained, 1.0);
  EXPECT_GT(norm, 0.0);
  EXPECT_LT(error, 1e-6 * norm);
}

TEST_F(PaperClampTest, AboveTheClampNoDerivativePasses) {
  double error = 0.0, norm = 0.0;
  const double explained = Check({0, 1, 2, 3}, &error, &norm);
  EXPECT_DOUBLE_EQ(explained, 1.0);
  EXPECT_EQ(norm, 0.0);
  EXPECT_LT(error, 1e-9);
}

}  // namespace
}  // namespace finecap
