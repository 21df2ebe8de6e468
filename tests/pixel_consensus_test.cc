// The consensus similarity read at surface samples (pixel_consensus_similarity.h) and the samples
// themselves (surface_sampling.h).
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "energy/terms/consensus/pixel_consensus_similarity.h"
#include "energy/terms/consensus/surface_consensus_similarity.h"
#include "energy_fixture.h"
#include "finecap/energy/frame_energy.h"
#include "finecap/geometry/mesh_edges.h"
#include "finecap/geometry/subdivision.h"
#include "finecap/util/error.h"
#include "refine/camera_alignment.h"
#include "refine/surface_sampling.h"

namespace finecap {
namespace {

// A texture fixed to the world's xy plane: smooth at the scale of a few millimetres, so that
// every camera sees it in sharp detail.
Eigen::Vector3f WorldTexture(double x, double y) {
  const double a = std::sin(900.0 * x + 2.0) * std::cos(700.0 * y - 1.0);
  const double b = std::sin(1300.0 * (x + y)) * std::sin(500.0 * x - 800.0 * y + 0.5);
  return Eigen::Vector3f(static_cast<float>(0.5 + 0.25 * a), static_cast<float>(0.5 + 0.2 * b),
                         static_cast<float>(0.5 + 0.1 * (a - b)));
}

// What `camera` sees of the textured plane z = z_plane, in the similarity's colour space.
cv::Mat RenderPlane(const Camera& camera, double z_plane) {
  cv::Mat image(camera.height, camera.width, CV_32FC3);
  const Eigen::Vector3d centre = -camera.R.transpose() * camera.t;
  const Eigen::Matrix3d inverse_k = camera.K.inverse();
  for (int y = 0; y < camera.height; ++y) {
    for (int x = 0; x < camera.width; ++x) {
      const Eigen::Vector3d ray = camera.R.transpose() * (inverse_k * Eigen::Vector3d(x, y, 1.0));
      const double t = (z_plane - centre.z()) / ray.z();
      const Eigen::Vector3d point = centre + t * ray;
      const Eigen::Vector3f color = WorldTexture(point.x(), point.y());
      image.at<cv::Vec3f>(y, x) = cv::Vec3f(color[0], color[1], color[2]);
    }
  }
  return image;
}

// A flat grid 1 m in front of three cameras, its faces split into 4 x 4 for the samples, the
// cameras' images showing the textured plane `truth_offset` metres along the grid's normal.
struct SampledScene {
  Mesh mesh;
  SurfaceGaussians surface;
  VertexNeighbourhoods neighbourhoods;
  SurfaceSamples samples;
  std::vector<CameraInput> cameras;
};

SampledScene MakeSampledScene(double truth_offset, int segments = 4) {
  SampledScene scene;
  scene.mesh = GridMesh(7, 7, 0.01, /*curvature=*/0.0);
  const Eigen::Matrix3Xd normals = ComputeVertexNormals(scene.mesh);
  ReferenceColors colors;
  colors.color_space = ColorSpace::kNormalizedRgb;
  colors.colors.assign(scene.mesh.num_vertices(), Eigen::Vector3f(0.5f, 0.5f, 0.5f));
  colors.valid.assign(scene.mesh.num_vertices(), 1);
  std::vector<int> ids(scene.mesh.num_vertices());
  for (int v = 0; v < scene.mesh.num_vertices(); ++v) ids[v] = v;
  scene.surface = MakeSurfaceGaussians(scene.mesh.vertices, normals, ids, colors);
  scene.neighbourhoods = BuildVertexNeighbourhoods(scene.mesh, 2);
  scene.samples = SampleSurface(scene.mesh, normals, scene.surface, scene.neighbourhoods,
                                /*patch_rings=*/1, segments);
  // The grid's normals point to -z, at the cameras: k moves the surface to z = -k.
  const double z_plane = -truth_offset;
  for (double tilt : {0.0, 0.35, -0.3}) {
    CameraInput input;
    input.camera = LookAtOrigin(1.0, tilt, 4000.0, 400);
    input.visible.assign(scene.surface.size(), 1);
    input.samples_visible.assign(scene.samples.size(), 1);
    input.pixels = RenderPlane(input.camera, z_plane);
    cv::GaussianBlur(input.pixels, input.pixels, cv::Size(0, 0), 0.7);
    scene.cameras.push_back(std::move(input));
  }
  return scene;
}

// The k, the same for every surface Gaussian, within 3 mm of the grid in steps of 0.1 mm, at
// which `energy`'s similarity is highest.
double BestUniformDisplacement(const FrameEnergy& energy) {
  double best_k = 0.0, best = -std::numeric_limits<double>::infinity();
  for (double k = -0.003; k <= 0.003; k += 0.0001) {
    const double value = energy.data_term(0).Evaluate(
        Eigen::VectorXd::Constant(energy.num_parameters(), k), nullptr);
    if (value > best) {
      best = value;
      best_k = k;
    }
  }
  return best_k;
}

EnergyOptions SampledOptions() {
  EnergyOptions options;
  options.similarity = SimilarityType::kConsensus;
  options.k_max = 0.004;
  options.consensus.sample_spacing = 1.0;
  return options;
}

TEST(SurfaceSamplingTest, SamplesKeepTheVerticesAndBlendTheirCorners) {
  const SampledScene scene = MakeSampledScene(0.0);
  const int n = scene.mesh.num_vertices();
  ASSERT_GT(scene.samples.size(), 10 * n);
  for (int v = 0; v < n; ++v) {
    EXPECT_EQ((scene.samples.base.col(v) - scene.mesh.vertices.col(v)).norm(), 0.0);
    ASSERT_FALSE(scene.samples.patches[v].empty());
    EXPECT_EQ(scene.samples.patches[v].front(), v);
  }
  // Every sample lies on the flat grid and is a convex blend of at most three corners.
  for (int j = 0; j < scene.samples.size(); ++j) {
    double sum = 0.0;
    int corners = 0;
    for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(scene.samples.weights, j);
         it; ++it) {
      EXPECT_GT(it.value(), 0.0);
      sum += it.value();
      ++corners;
    }
    EXPECT_NEAR(sum, 1.0, 1e-12);
    EXPECT_LE(corners, 3);
    EXPECT_NEAR(scene.samples.base(2, j), 0.0, 1e-15);
  }
  // An interior vertex's patch: the samples of its six faces, split 4 a side (4 sample steps
  // per edge), that have a weight on it: the hexagon of radius 4 without its rim, 1 + 3 * 3 * 4.
  const int interior = 3 * 7 + 3;
  EXPECT_EQ(scene.samples.patches[interior].size(), 37u);
}

// Any count a side: each edge's inside points once, shared by its faces, each face's inside
// points once, every point at its barycentric grid position.
TEST(SurfaceSamplingTest, FacesSplitIntoAnyNumberOfSegments) {
  const Mesh grid = GridMesh(4, 3, 0.01, /*curvature=*/0.0);
  const MeshEdges edges = BuildMeshEdges(grid.faces);
  for (int n : {1, 3, 5}) {
    const Eigen::SparseMatrix<double> split = SplitFaces(grid, n);
    const long expected = grid.num_vertices() + long(edges.num_edges()) * (n - 1) +
                          long(grid.num_faces()) * (n - 1) * (n - 2) / 2;
    ASSERT_EQ(split.rows(), expected) << n << " segments";
    const Eigen::Matrix3Xd points = grid.vertices * split.transpose();
    // No two points at the same place: a shared edge's points are not repeated.
    for (int a = 0; a < points.cols(); ++a) {
      for (int b = a + 1; b < points.cols(); ++b) {
        ASSERT_GT((points.col(a) - points.col(b)).norm(), 1e-9) << n << " segments";
      }
    }
    // The point nearest each face's centroid is its centre when n is a multiple of 3.
    if (n % 3 != 0) continue;
    for (int f = 0; f < grid.num_faces(); ++f) {
      const Eigen::Vector3d centroid =
          (grid.vertices(Eigen::all, grid.faces.col(f))).rowwise().mean();
      const double nearest = (points.colwise() - centroid).colwise().norm().minCoeff();
      EXPECT_LT(nearest, 1e-12) << "face " << f;
    }
  }
}

// Powers of two give the points of as many levels of linear subdivision.
TEST(SurfaceSamplingTest, PowersOfTwoGiveTheLinearSubdivisionsPoints) {
  const Mesh grid = GridMesh(4, 3, 0.01, /*curvature=*/0.0);
  const Eigen::Matrix3Xd split = grid.vertices * SplitFaces(grid, 4).transpose();
  const Mesh subdivided = ApplySubdivision(BuildLinearSubdivision(grid, 2), grid.vertices);
  ASSERT_EQ(split.cols(), subdivided.num_vertices());
  for (int v = 0; v < subdivided.num_vertices(); ++v) {
    const double nearest =
        (split.colwise() - subdivided.vertices.col(v)).colwise().norm().minCoeff();
    EXPECT_LT(nearest, 1e-12) << "subdivided vertex " << v;
  }
}

TEST(SurfaceSamplingTest, WiderPatchesTakeTheNeighboursFacesToo) {
  SampledScene scene = MakeSampledScene(0.0);
  const Eigen::Matrix3Xd normals = ComputeVertexNormals(scene.mesh);
  const SurfaceSamples wide =
      SampleSurface(scene.mesh, normals, scene.surface, scene.neighbourhoods, /*patch_rings=*/2, 4);
  const int interior = 3 * 7 + 3;
  EXPECT_GT(wide.patches[interior].size(), 3 * scene.samples.patches[interior].size());
  std::vector<int> sorted = wide.patches[interior];
  std::sort(sorted.begin(), sorted.end());
  EXPECT_EQ(std::adjacent_find(sorted.begin(), sorted.end()), sorted.end()) << "a sample twice";
}

TEST(SurfaceSamplingTest, ASampleIsSeenWhereEveryCornerItIsBlendedFromIs) {
  const SampledScene scene = MakeSampledScene(0.0);
  std::vector<unsigned char> surface_visible(scene.surface.size(), 1);
  const int hidden = 3 * 7 + 3;
  surface_visible[hidden] = 0;
  const std::vector<unsigned char> visible = SampleVisibility(scene.samples, surface_visible);
  ASSERT_EQ(visible.size(), static_cast<size_t>(scene.samples.size()));
  for (int j = 0; j < scene.samples.size(); ++j) {
    EXPECT_EQ(visible[j] == 0, scene.samples.weights.coeff(j, hidden) > 0.0) << "sample " << j;
  }
}

// A camera whose principal point is off by half a pixel is brought back in line with the others;
// cameras already in line stay where they are.
TEST(CameraAlignmentTest, ACameraOffByHalfAPixelIsBroughtBackInLine) {
  const Eigen::Vector2d error(0.4, -0.3);
  for (bool misaligned : {false, true}) {
    SampledScene scene = MakeSampledScene(0.0);
    // The images show the plane as the cameras really are; camera 1's calibration says otherwise.
    if (misaligned) {
      scene.cameras[1].camera.K(0, 2) += error.x();
      scene.cameras[1].camera.K(1, 2) += error.y();
    }
    const std::vector<Eigen::Vector2d> shifts =
        AlignCameras(scene.samples.base, /*max_rounds=*/30, &scene.cameras);
    ASSERT_EQ(shifts.size(), 3u);
    // Only the cameras' shifts relative to each other are what the images say.
    const Eigen::Vector2d relative = shifts[1] - 0.5 * (shifts[0] + shifts[2]);
    const Eigen::Vector2d expected = misaligned ? Eigen::Vector2d(-error) : Eigen::Vector2d::Zero();
    EXPECT_LT((relative - expected).norm(), 0.05)
        << (misaligned ? "misaligned" : "aligned") << ": " << relative.transpose();
    EXPECT_LT((shifts[0] - shifts[2]).norm(), 0.05)
        << shifts[0].transpose() << " against " << shifts[2].transpose();
  }
}

// dE/dk against central differences. The bilinear interpolant has kinks at pixel borders, so a
// difference quotient may straddle one: a few coordinates may disagree, not more.
TEST(PixelConsensusTest, GradientMatchesCentralDifferences) {
  const SampledScene scene = MakeSampledScene(0.0015);
  const FrameEnergy energy(scene.surface, scene.cameras, scene.neighbourhoods, SampledOptions(),
                           scene.samples);
  ASSERT_GT(energy.data_term(0).residual_blocks().size(), 20u);
  int disagreeing = 0, checked = 0;
  for (unsigned trial = 0; trial < 3; ++trial) {
    const Eigen::VectorXd k = RandomK(energy.num_parameters(), 0.002, trial);
    Eigen::VectorXd analytic;
    energy.Evaluate(k, &analytic);
    const Eigen::VectorXd numeric = NumericGradient(
        [&](const Eigen::VectorXd& x) { return energy.Evaluate(x, nullptr); }, k, 1e-8);
    for (int s = 0; s < k.size(); ++s) {
      const double error = std::abs(analytic[s] - numeric[s]);
      disagreeing += error > 1e-4 * std::max(numeric.cwiseAbs().maxCoeff(), 1e-12);
      ++checked;
    }
  }
  EXPECT_LE(disagreeing, checked / 50);
}

TEST(PixelConsensusTest, ResidualJacobiansMatchCentralDifferences) {
  const SampledScene scene = MakeSampledScene(0.001);
  FrameEnergy energy(scene.surface, scene.cameras, scene.neighbourhoods, SampledOptions(),
                     scene.samples);
  DataTerm& term = energy.data_term(0);
  const Eigen::VectorXd k = RandomK(energy.num_parameters(), 0.002, 3);
  const double h = 1e-8;
  int checked = 0, disagreeing = 0;
  for (int b = 0; b < static_cast<int>(term.residual_blocks().size()); b += 3) {
    const auto& block = term.residual_blocks()[b];
    ASSERT_EQ(block.parameters.size(), 1u);
    const int R = block.num_residuals;
    std::vector<double> residuals(R), jacobian(R), plus(R), minus(R);
    term.PrepareResiduals(k, true);
    term.BlockResiduals(b, residuals.data(), jacobian.data());
    Eigen::VectorXd shifted = k;
    shifted[block.parameters[0]] += h;
    term.PrepareResiduals(shifted, false);
    term.BlockResiduals(b, plus.data(), nullptr);
    shifted[block.parameters[0]] -= 2 * h;
    term.PrepareResiduals(shifted, false);
    term.BlockResiduals(b, minus.data(), nullptr);
    const double scale =
        Eigen::Map<const Eigen::VectorXd>(jacobian.data(), R).cwiseAbs().maxCoeff();
    for (int r = 0; r < R; ++r) {
      const double numeric = (plus[r] - minus[r]) / (2 * h);
      disagreeing += std::abs(numeric - jacobian[r]) > 1e-4 * std::max(scale, 1e-12);
      ++checked;
    }
  }
  EXPECT_GT(checked, 1000);
  EXPECT_LE(disagreeing, checked / 100);
}

// Without the table of its reads' rays (too many reads for the memory it may take) every read
// projects its sample itself, with the same arithmetic: the same values and derivatives, to the
// bit.
TEST(PixelConsensusTest, ReadsWithoutTheirTableGiveTheSameBits) {
  EXPECT_EQ(SampleRayTableBytes(100.0, 4800.0), 4800.0);
  EXPECT_EQ(SampleRayTableBytes(101.0, 4800.0), 0.0);
  const SampledScene scene = MakeSampledScene(0.001);
  const ConsensusOptions options = SampledOptions().consensus;
  PixelConsensusSimilarity tabled(scene.samples, scene.cameras, options);
  PixelConsensusSimilarity untabled(scene.samples, scene.cameras, options,
                                    /*max_ray_table_bytes=*/0.0);
  ASSERT_GT(tabled.residual_blocks().size(), 20u);
  const Eigen::VectorXd k = RandomK(scene.surface.size(), 0.002, 5);
  Eigen::VectorXd tabled_gradient, untabled_gradient;
  EXPECT_EQ(tabled.Evaluate(k, &tabled_gradient), untabled.Evaluate(k, &untabled_gradient));
  EXPECT_EQ(tabled_gradient, untabled_gradient);
  EXPECT_NE(tabled_gradient.cwiseAbs().maxCoeff(), 0.0);
}

TEST(PixelConsensusTest, ScalarIsMinusHalfTheSumOfTheBlockCosts) {
  const SampledScene scene = MakeSampledScene(0.001);
  FrameEnergy energy(scene.surface, scene.cameras, scene.neighbourhoods, SampledOptions(),
                     scene.samples);
  DataTerm& term = energy.data_term(0);
  const Eigen::VectorXd k = RandomK(energy.num_parameters(), 0.002, 8);
  std::vector<double> costs;
  term.BlockCosts(k, &costs);
  BlockSummaries* summaries = term.block_summaries();
  ASSERT_NE(summaries, nullptr);
  summaries->PrepareBlockSummaries(k);
  double sum = 0.0;
  for (size_t b = 0; b < costs.size(); ++b) {
    EXPECT_NEAR(summaries->BlockSummaryOf(static_cast<int>(b)).squared_norm, costs[b],
                1e-12 * std::max(costs[b], 1.0));
    sum += costs[b];
  }
  EXPECT_GT(sum, 0.0);
  EXPECT_NEAR(term.Evaluate(k, nullptr), -0.5 * sum, 1e-12 * sum);
}

// A block's summary (SummaryAt, what the solvers read) must be the summary of the residuals
// PrepareResiduals writes (sum of squares, <r, dr/dk>, |dr/dk|^2), with and without the robust
// loss, with one gain per camera or one per channel.
class SummaryOfResidualsTest : public testing::TestWithParam<std::tuple<double, bool>> {};

TEST_P(SummaryOfResidualsTest, SummariesAreThoseOfTheResidualsThemselves) {
  const auto [robust_fraction, gain_per_channel] = GetParam();
  const SampledScene scene = MakeSampledScene(0.001);
  ConsensusOptions options = SampledOptions().consensus;
  options.robust_fraction = robust_fraction;
  options.gain_per_channel = gain_per_channel;
  PixelConsensusSimilarity term(scene.samples, scene.cameras, options);
  const int num_blocks = static_cast<int>(term.residual_blocks().size());
  ASSERT_GT(num_blocks, 20);
  const Eigen::VectorXd k = RandomK(scene.surface.size(), 0.002, 11);
  term.PrepareBlockSummaries(k);
  term.PrepareResiduals(k, true);
  double largest_gradient = 0.0;
  for (int b = 0; b < num_blocks; ++b) {
    const int m = term.residual_blocks()[b].num_residuals;
    std::vector<double> residuals(m), jacobian(m);
    term.BlockResiduals(b, residuals.data(), jacobian.data());
    const BlockSummary expected =
        SummarisedDataTerm::Summarise(residuals.data(), jacobian.data(), m);
    const BlockSummary summary = term.BlockSummaryOf(b);
    const auto tolerance = [](double value) { return 1e-10 * std::max(std::abs(value), 1.0); };
    EXPECT_NEAR(summary.squared_norm, expected.squared_norm, tolerance(expected.squared_norm))
        << "block " << b;
    EXPECT_NEAR(summary.gradient, expected.gradient, tolerance(expected.gradient)) << "block " << b;
    EXPECT_NEAR(summary.curvature, expected.curvature, tolerance(expected.curvature))
        << "block " << b;
    largest_gradient = std::max(largest_gradient, std::abs(expected.gradient));
  }
  EXPECT_GT(largest_gradient, 0.0);
}

INSTANTIATE_TEST_SUITE_P(PixelConsensusTest, SummaryOfResidualsTest,
                         testing::Combine(testing::Values(0.0, 0.5), testing::Bool()));

// Camera weights make the cameras' mean a weighted one and count each camera's squared
// residuals its weight's times: two cameras of weights 1 and 3, one member of one channel.
TEST(AgainstCameraMeanTest, WeightsTheMeanAndTheSquaredResiduals) {
  // One member (three channels) in each of two cameras: z = 1 in the first, 5 in the second.
  double values[6] = {1.0, 1.0, 1.0, 5.0, 5.0, 5.0};
  const double weights[2] = {1.0, 3.0};
  internal::AgainstCameraMean(1, 2, Eigen::Vector3d::Ones(), values, weights);
  const double mean = (1.0 * 1.0 + 3.0 * 5.0) / 4.0;  // 4
  EXPECT_DOUBLE_EQ(values[0], 1.0 - mean);
  EXPECT_DOUBLE_EQ(values[3], std::sqrt(3.0) * (5.0 - mean));
  // Without weights, the plain mean.
  double plain[6] = {1.0, 1.0, 1.0, 5.0, 5.0, 5.0};
  internal::AgainstCameraMean(1, 2, Eigen::Vector3d::Ones(), plain);
  EXPECT_DOUBLE_EQ(plain[0], -2.0);
  EXPECT_DOUBLE_EQ(plain[3], 2.0);
}

// The cameras' weights follow their view cosines: given the same cosine in every camera they all
// count alike, as without weights; given the scene's own, a steeper camera counts less and the
// summaries change.
TEST(PixelConsensusTest, CamerasCountByTheCosinesOfTheirViews) {
  SampledScene scene = MakeSampledScene(0.001);
  ConsensusOptions options = SampledOptions().consensus;
  const Eigen::VectorXd k = RandomK(scene.surface.size(), 0.002, 13);
  const auto summaries = [&](const ConsensusOptions& o) {
    PixelConsensusSimilarity term(scene.samples, scene.cameras, o);
    term.PrepareBlockSummaries(k);
    std::vector<double> costs;
    for (int b = 0; b < static_cast<int>(term.residual_blocks().size()); ++b) {
      costs.push_back(term.BlockSummaryOf(b).squared_norm);
    }
    return costs;
  };
  ConsensusOptions alike = options;
  alike.view_cosine_power = 0.0;
  const std::vector<double> unweighted = summaries(alike);
  const std::vector<double> weighted = summaries(options);
  ASSERT_EQ(weighted.size(), unweighted.size());
  ASSERT_GT(weighted.size(), 20u);
  double largest_change = 0.0;
  for (size_t b = 0; b < weighted.size(); ++b) {
    largest_change = std::max(
        largest_change, std::abs(weighted[b] - unweighted[b]) / std::max(unweighted[b], 1e-300));
  }
  EXPECT_GT(largest_change, 1e-3);
  for (CameraInput& camera : scene.cameras) {
    camera.view_cosines.assign(scene.surface.size(), 0.5);
  }
  const std::vector<double> equal_cosines = summaries(options);
  for (size_t b = 0; b < weighted.size(); ++b) {
    EXPECT_NEAR(equal_cosines[b], unweighted[b], 1e-12 * std::max(unweighted[b], 1.0))
        << "block " << b;
  }
  scene.cameras[0].view_cosines.resize(3);
  EXPECT_THROW(summaries(options), Error);
}

// The samples see the texture at the images' resolution: with every k the same, the similarity
// is best where the textured plane truly is, within a small fraction of the vertex spacing.
TEST(PixelConsensusTest, UniformDisplacementIsBestAtTheTruePlane) {
  for (double truth : {-0.0012, 0.0, 0.0017}) {
    const SampledScene scene = MakeSampledScene(truth);
    FrameEnergy energy(scene.surface, scene.cameras, scene.neighbourhoods, SampledOptions(),
                       scene.samples);
    EXPECT_NEAR(BestUniformDisplacement(energy), truth, 0.00015) << "truth " << truth;
  }
}

// A patch shaped like the surface found before (the term's PassHook, through the energy) reads
// each sample at the blend of that shape.
TEST(PixelConsensusTest, PatchShapeMovesTheSamplesByTheBlendedShape) {
  const SampledScene scene = MakeSampledScene(0.0);
  FrameEnergy energy(scene.surface, scene.cameras, scene.neighbourhoods, SampledOptions(),
                     scene.samples);
  DataTerm& term = energy.data_term(0);
  ASSERT_NE(term.pass_hook(), nullptr);
  ASSERT_TRUE(energy.HasPassHooks());
  const int n = energy.num_parameters();
  // A shape that is the same everywhere is no shape: every sample moves with its patch's k.
  const Eigen::VectorXd k = RandomK(n, 0.001, 4);
  const double unshaped = term.Evaluate(k, nullptr);
  energy.EndOfPass(Eigen::VectorXd::Constant(n, 0.0007));
  EXPECT_NEAR(term.Evaluate(k, nullptr), unshaped, 1e-12 * std::abs(unshaped));
  // A tilted shape changes what the patches read.
  Eigen::VectorXd tilted(n);
  for (int s = 0; s < n; ++s) tilted[s] = 0.1 * scene.mesh.vertices(0, s);
  energy.EndOfPass(tilted);
  EXPECT_GT(std::abs(term.Evaluate(k, nullptr) - unshaped), 1e-6 * std::abs(unshaped));
  EXPECT_THROW(energy.EndOfPass(Eigen::VectorXd::Zero(n + 1)), Error);
}

// A foreground mask cuts the patches along a silhouette; it does not drop them. Here the first
// camera's foreground holds only the grid's half x < 0: each patch across the cut is still
// compared by all three cameras, on its samples in that half, and a patch beyond it by the other
// two, whole. The cut patches keep the similarity exact and best at the true plane.
TEST(PixelConsensusTest, AMaskCutsPatchesAlongItsEdgeInsteadOfDroppingThem) {
  const double truth = 0.0011;
  SampledScene scene = MakeSampledScene(truth);
  const FrameEnergy whole(scene.surface, scene.cameras, scene.neighbourhoods, SampledOptions(),
                          scene.samples);
  auto& foreground = scene.cameras[0].samples_on_foreground;
  foreground.assign(scene.samples.size(), 0);
  for (int j = 0; j < scene.samples.size(); ++j) foreground[j] = scene.samples.base(0, j) < 0.0;
  const FrameEnergy cut(scene.surface, scene.cameras, scene.neighbourhoods, SampledOptions(),
                        scene.samples);
  const auto& whole_blocks = whole.data_term(0).residual_blocks();
  const auto& cut_blocks = cut.data_term(0).residual_blocks();
  ASSERT_EQ(cut_blocks.size(), whole_blocks.size());
  int shrunk = 0, two_cameras = 0;
  for (size_t b = 0; b < cut_blocks.size(); ++b) {
    ASSERT_EQ(cut_blocks[b].parameters, whole_blocks[b].parameters);
    const int whole_residuals = whole_blocks[b].num_residuals;
    const int cut_residuals = cut_blocks[b].num_residuals;
    EXPECT_LE(cut_residuals, whole_residuals);
    two_cameras += 3 * cut_residuals == 2 * whole_residuals;
    shrunk += cut_residuals < whole_residuals && 3 * cut_residuals != 2 * whole_residuals;
  }
  EXPECT_GT(shrunk, 0);
  EXPECT_GT(two_cameras, 0);

  const Eigen::VectorXd k = RandomK(cut.num_parameters(), 0.002, 5);
  Eigen::VectorXd analytic;
  cut.Evaluate(k, &analytic);
  const Eigen::VectorXd numeric =
      NumericGradient([&](const Eigen::VectorXd& x) { return cut.Evaluate(x, nullptr); }, k, 1e-8);
  EXPECT_LE((analytic - numeric).cwiseAbs().maxCoeff(), 1e-4 * numeric.cwiseAbs().maxCoeff());

  EXPECT_NEAR(BestUniformDisplacement(cut), truth, 0.00015);

  // A foreground of the wrong size is refused.
  foreground.pop_back();
  EXPECT_THROW(FrameEnergy(scene.surface, scene.cameras, scene.neighbourhoods, SampledOptions(),
                           scene.samples),
               Error);
}

// The appearance a frame's surface shows at its samples (SeenAppearance): at the true surface
// every camera reads the texture there, so their mean is the texture; at a wrong surface they
// read points of the plane apart from it and from each other. A sample no camera sees has none.
TEST(PixelConsensusTest, SeenAppearanceIsTheTextureAtTheSurfaceFound) {
  const double truth = 0.0013;
  SampledScene scene = MakeSampledScene(truth);
  for (CameraInput& camera : scene.cameras) camera.samples_visible[5] = 0;
  const FrameEnergy energy(scene.surface, scene.cameras, scene.neighbourhoods, SampledOptions(),
                           scene.samples);
  const auto error_at = [&](double k) {
    const Eigen::Matrix3Xd appearance =
        energy.SampleAppearance(Eigen::VectorXd::Constant(energy.num_parameters(), k));
    EXPECT_EQ(appearance.cols(), scene.samples.size());
    EXPECT_TRUE(appearance.col(5).array().isNaN().all());
    double sum = 0.0;
    int count = 0;
    for (int j = 0; j < scene.samples.size(); ++j) {
      if (j == 5) continue;
      // The grid's normals point to -z: the surface displaced by k lies at z = -k, where the
      // sample's x and y do not change.
      const Eigen::Vector3f texture =
          WorldTexture(scene.samples.base(0, j), scene.samples.base(1, j));
      sum += (appearance.col(j) - texture.cast<double>()).norm();
      ++count;
    }
    return sum / count;
  };
  const double at_truth = error_at(truth), off = error_at(truth + 0.002);
  EXPECT_LT(at_truth, 0.02);
  EXPECT_GT(off, 4.0 * at_truth);
}

// The appearance of the frame before is one more view of each patch (shared_appearance): a patch
// two cameras see gets a third comparison, and a patch one camera sees, which the cameras alone
// leave out (min_cameras), is compared with it, at its best where the surface truly is. Without
// the option, or without an appearance, nothing changes.
TEST(PixelConsensusTest, TheAppearanceIsOneMoreViewOfEachPatch) {
  const double truth = 0.0009;
  SampledScene scene = MakeSampledScene(truth);
  EnergyOptions options = SampledOptions();
  options.consensus.shared_appearance = true;
  {
    const FrameEnergy seen(scene.surface, scene.cameras, scene.neighbourhoods, options,
                           scene.samples);
    scene.samples.appearance =
        seen.SampleAppearance(Eigen::VectorXd::Constant(seen.num_parameters(), truth));
  }
  const FrameEnergy plain(scene.surface, scene.cameras, scene.neighbourhoods, SampledOptions(),
                          scene.samples);
  const FrameEnergy shared(scene.surface, scene.cameras, scene.neighbourhoods, options,
                           scene.samples);
  const auto& plain_blocks = plain.data_term(0).residual_blocks();
  const auto& shared_blocks = shared.data_term(0).residual_blocks();
  ASSERT_EQ(shared_blocks.size(), plain_blocks.size());
  for (size_t b = 0; b < plain_blocks.size(); ++b) {
    // Three cameras and the appearance: four views of the patch's samples.
    EXPECT_EQ(3 * shared_blocks[b].num_residuals, 4 * plain_blocks[b].num_residuals);
  }
  EXPECT_NEAR(BestUniformDisplacement(shared), truth, 0.00015);

  // One camera, tilted so that k moves its reads: alone it compares nothing; with the appearance
  // every patch is compared, and the surface found is the true one.
  scene.cameras.erase(scene.cameras.begin(), scene.cameras.begin() + 1);
  scene.cameras.pop_back();
  const FrameEnergy one_camera(scene.surface, scene.cameras, scene.neighbourhoods, SampledOptions(),
                               scene.samples);
  EXPECT_TRUE(one_camera.data_term(0).residual_blocks().empty());
  const FrameEnergy one_and_appearance(scene.surface, scene.cameras, scene.neighbourhoods, options,
                                       scene.samples);
  EXPECT_EQ(one_and_appearance.data_term(0).residual_blocks().size(), plain_blocks.size());
  EXPECT_NEAR(BestUniformDisplacement(one_and_appearance), truth, 0.00015);
  Eigen::VectorXd analytic;
  const Eigen::VectorXd k = RandomK(one_and_appearance.num_parameters(), 0.002, 6);
  one_and_appearance.Evaluate(k, &analytic);
  const Eigen::VectorXd numeric = NumericGradient(
      [&](const Eigen::VectorXd& x) { return one_and_appearance.Evaluate(x, nullptr); }, k, 1e-8);
  EXPECT_LE((analytic - numeric).cwiseAbs().maxCoeff(), 1e-3 * numeric.cwiseAbs().maxCoeff());

  // Where a sample of a patch has no appearance the patch is compared by its cameras alone.
  scene.samples.appearance.col(scene.samples.patches[0][0]).setConstant(std::nan(""));
  const FrameEnergy partly(scene.surface, scene.cameras, scene.neighbourhoods, options,
                           scene.samples);
  EXPECT_EQ(partly.data_term(0).residual_blocks().size(), plain_blocks.size() - 1);

  // An appearance of the wrong size is refused.
  scene.samples.appearance.conservativeResize(3, scene.samples.size() - 1);
  EXPECT_THROW(
      FrameEnergy(scene.surface, scene.cameras, scene.neighbourhoods, options, scene.samples),
      Error);
}

// The second term of the detail stage (surface_consensus_similarity.h): the same patches read
// with every sample where the blend of its face's corners puts it.
struct SurfaceTermScene {
  explicit SurfaceTermScene(double truth_offset, double weight = 1.0, bool pooled_gain = false,
                            SurfacePatches through = SurfacePatches::kFaceCover,
                            double view_cosine_power = 1.0)
      : scene(MakeSampledScene(truth_offset)),
        options(Weighted(weight, pooled_gain, through, view_cosine_power)),
        patches(scene.samples, scene.cameras, options),
        surface(patches, scene.samples, options) {}
  static ConsensusOptions Weighted(double weight, bool pooled_gain, SurfacePatches through,
                                   double view_cosine_power = 1.0) {
    ConsensusOptions options = SampledOptions().consensus;
    options.surface_weight = weight;
    options.surface_patches = through;
    options.gain_per_channel = !pooled_gain;
    options.view_cosine_power = view_cosine_power;
    return options;
  }
  SampledScene scene;
  ConsensusOptions options;
  PixelConsensusSimilarity patches;
  SurfaceConsensusSimilarity surface;
};

// From the solver's last pass on: the passes before it only shape the patches of the next.
TEST(SurfaceConsensusTest, TheDetailStageSumsItWithThePatchesInTheLastPassWhenItHasAWeight) {
  const SampledScene scene = MakeSampledScene(0.001);
  EnergyOptions options = SampledOptions();
  options.consensus.surface_weight = 1.0;
  FrameEnergy both(scene.surface, scene.cameras, scene.neighbourhoods, options, scene.samples);
  ASSERT_EQ(both.num_data_terms(), 1);
  both.StartLastPass();
  ASSERT_EQ(both.num_data_terms(), 2);
  EXPECT_EQ(both.data_term(0).residual_blocks()[0].parameters.size(), 1u);
  size_t widest = 0;
  for (const auto& block : both.data_term(1).residual_blocks()) {
    widest = std::max(widest, block.parameters.size());
  }
  EXPECT_EQ(widest, 7u);  // An inner vertex of the grid and its six neighbours.
  options.consensus.surface_weight = 0.0;
  FrameEnergy patches(scene.surface, scene.cameras, scene.neighbourhoods, options, scene.samples);
  patches.StartLastPass();
  EXPECT_EQ(patches.num_data_terms(), 1);
}

// A block depends on its vertex and the corners of its faces: every unknown a sample of the
// patch is blended from, and those only; with every patch or with a set that covers the faces.
class SurfaceBlocksTest : public testing::TestWithParam<SurfacePatches> {};

TEST_P(SurfaceBlocksTest, ABlockDependsOnTheCornersOfItsSamples) {
  const SurfaceTermScene t(0.001, 1.0, false, GetParam());
  const auto& blocks = t.surface.residual_blocks();
  if (GetParam() == SurfacePatches::kAll) {
    ASSERT_EQ(blocks.size(), t.patches.residual_blocks().size());
  }
  for (size_t b = 0; b < blocks.size(); ++b) {
    const int patch = t.surface.PatchOf(static_cast<int>(b));
    std::vector<int> corners;
    const int* members = t.patches.Members(patch);
    for (int j = 0; j < t.patches.PatchSize(patch); ++j) {
      for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(t.scene.samples.weights,
                                                                          members[j]);
           it; ++it) {
        corners.push_back(static_cast<int>(it.col()));
      }
    }
    std::sort(corners.begin(), corners.end());
    corners.erase(std::unique(corners.begin(), corners.end()), corners.end());
    EXPECT_EQ(blocks[b].parameters, corners) << "block " << b;
    EXPECT_EQ(blocks[b].num_residuals, static_cast<int>(corners.size()) + 1);
    // The patch's own vertex is one of them.
    EXPECT_TRUE(std::binary_search(corners.begin(), corners.end(),
                                   t.patches.residual_blocks()[patch].parameters[0]));
  }
}

INSTANTIATE_TEST_SUITE_P(SurfaceConsensusTest, SurfaceBlocksTest,
                         testing::Values(SurfacePatches::kFaceCover, SurfacePatches::kAll),
                         [](const testing::TestParamInfo<SurfacePatches>& info) {
                           return info.param == SurfacePatches::kAll ? "All" : "FaceCover";
                         });

// The covering set compares every sample between vertices that a patch holds through a patch,
// each patch once: with samples inside the faces (4 a side) one corner of each face, about a
// third of the patches on a regular grid; with the faces split in two, where the edges' midpoints
// are the only samples between vertices, one end of each edge, about two thirds.
class FaceCoverTest : public testing::TestWithParam<int> {};

TEST_P(FaceCoverTest, ComparesEverySampleBetweenVerticesInAFewPatches) {
  const int segments = GetParam();
  const SampledScene scene = MakeSampledScene(0.001, segments);
  const ConsensusOptions options =
      SurfaceTermScene::Weighted(1.0, false, SurfacePatches::kFaceCover);
  const PixelConsensusSimilarity patches(scene.samples, scene.cameras, options);
  const SurfaceConsensusSimilarity surface(patches, scene.samples, options);
  const int num_patches = static_cast<int>(patches.residual_blocks().size());
  const int num_blocks = static_cast<int>(surface.residual_blocks().size());
  const int between = segments == 2 ? 2 : 3;
  std::vector<char> in_a_patch(scene.samples.size(), 0), compared(in_a_patch.size(), 0);
  for (int b = 0; b < num_patches; ++b) {
    for (int j = 0; j < patches.PatchSize(b); ++j) in_a_patch[patches.Members(b)[j]] = 1;
  }
  for (int b = 0; b < num_blocks; ++b) {
    const int patch = surface.PatchOf(b);
    if (b > 0) {
      EXPECT_GT(patch, surface.PatchOf(b - 1));  // Each once, in the patches' order.
    }
    for (int j = 0; j < patches.PatchSize(patch); ++j) compared[patches.Members(patch)[j]] = 1;
  }
  int checked = 0;
  for (int j = 0; j < scene.samples.size(); ++j) {
    if (in_a_patch[j] == 0 || scene.samples.weights.row(j).nonZeros() != between) continue;
    ++checked;
    EXPECT_EQ(compared[j], 1) << "sample " << j;
  }
  EXPECT_GT(checked, 50);
  const double share = static_cast<double>(num_blocks) / num_patches;
  if (segments == 2) {
    EXPECT_GT(share, 0.55);
    EXPECT_LT(share, 0.8);
  } else {
    EXPECT_GT(share, 0.25);
    EXPECT_LT(share, 0.45);
  }
}

INSTANTIATE_TEST_SUITE_P(SurfaceConsensusTest, FaceCoverTest, testing::Values(2, 4),
                         [](const testing::TestParamInfo<int>& info) {
                           return info.param == 2 ? "EdgesOnly" : "InsideTheFaces";
                         });

TEST(SurfaceConsensusTest, GradientMatchesCentralDifferences) {
  const SurfaceTermScene t(0.0015);
  int disagreeing = 0, checked = 0;
  for (unsigned trial = 0; trial < 3; ++trial) {
    const Eigen::VectorXd k = RandomK(t.scene.surface.size(), 0.002, trial);
    Eigen::VectorXd analytic;
    t.surface.Evaluate(k, &analytic);
    const Eigen::VectorXd numeric = NumericGradient(
        [&](const Eigen::VectorXd& x) { return t.surface.Evaluate(x, nullptr); }, k, 1e-8);
    ASSERT_GT(numeric.cwiseAbs().maxCoeff(), 0.0);
    for (int s = 0; s < k.size(); ++s) {
      disagreeing += std::abs(analytic[s] - numeric[s]) > 1e-4 * numeric.cwiseAbs().maxCoeff();
      ++checked;
    }
  }
  EXPECT_LE(disagreeing, checked / 50);
}

TEST(SurfaceConsensusTest, ResidualJacobiansMatchCentralDifferences) {
  const SurfaceTermScene t(0.001, /*weight=*/2.0);
  const Eigen::VectorXd k = RandomK(t.scene.surface.size(), 0.002, 3);
  const double h = 1e-8;
  int checked = 0, disagreeing = 0;
  for (int b = 0; b < static_cast<int>(t.surface.residual_blocks().size()); b += 5) {
    const std::vector<int>& unknowns = t.surface.residual_blocks()[b].parameters;
    Eigen::VectorXd residuals, plus, minus;
    Eigen::MatrixXd jacobian;
    t.surface.ResidualsOfBlock(b, k, &residuals, &jacobian);
    ASSERT_EQ(jacobian.cols(), static_cast<Eigen::Index>(unknowns.size()));
    const double scale = std::max(jacobian.cwiseAbs().maxCoeff(), 1e-12);
    for (size_t i = 0; i < unknowns.size(); ++i) {
      Eigen::VectorXd shifted = k;
      shifted[unknowns[i]] += h;
      t.surface.ResidualsOfBlock(b, shifted, &plus, nullptr);
      shifted[unknowns[i]] -= 2 * h;
      t.surface.ResidualsOfBlock(b, shifted, &minus, nullptr);
      for (Eigen::Index r = 0; r < residuals.size(); ++r) {
        const double numeric = (plus[r] - minus[r]) / (2 * h);
        disagreeing += std::abs(numeric - jacobian(r, i)) > 1e-4 * scale;
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 1000);
  EXPECT_LE(disagreeing, checked / 100);
}

// What a solver takes of a block, its rows and their Jacobian, has the block's cost, gradient
// J^T r and Gauss-Newton matrix J^T J (summed over its members and cameras, not from its
// Jacobian: with one gain per camera and channel, and one per camera); and the term's value is
// minus half the sum of the costs.
class SurfaceRowsTest : public testing::TestWithParam<bool> {};

TEST_P(SurfaceRowsTest, ReducedRowsKeepTheBlocksCostGradientAndCurvature) {
  SurfaceTermScene t(0.001, /*weight=*/2.0, /*pooled_gain=*/GetParam());
  const Eigen::VectorXd k = RandomK(t.scene.surface.size(), 0.002, 6);
  t.surface.PrepareResiduals(k, true);
  double sum = 0.0;
  for (int b = 0; b < static_cast<int>(t.surface.residual_blocks().size()); ++b) {
    const int p = static_cast<int>(t.surface.residual_blocks()[b].parameters.size());
    const int num_rows = t.surface.residual_blocks()[b].num_residuals;
    Eigen::VectorXd rows(num_rows);
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> reduced(num_rows, p);
    t.surface.BlockResiduals(b, rows.data(), reduced.data());
    Eigen::VectorXd residuals;
    Eigen::MatrixXd jacobian;
    t.surface.ResidualsOfBlock(b, k, &residuals, &jacobian);
    const double cost = residuals.squaredNorm();
    const Eigen::MatrixXd curvature = jacobian.transpose() * jacobian;
    const double tolerance = 1e-9 * std::max(curvature.cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_NEAR(rows.squaredNorm(), cost, 1e-9 * std::max(cost, 1e-12)) << "block " << b;
    const Eigen::VectorXd gradient = jacobian.transpose() * residuals;
    EXPECT_LE((reduced.transpose() * rows - gradient).cwiseAbs().maxCoeff(),
              1e-7 * std::max(gradient.cwiseAbs().maxCoeff(), 1e-12))
        << "block " << b;
    EXPECT_LE((reduced.transpose() * reduced - curvature).cwiseAbs().maxCoeff(), tolerance)
        << "block " << b;
    sum += cost;
  }
  EXPECT_GT(sum, 0.0);
  EXPECT_NEAR(t.surface.Evaluate(k, nullptr), -0.5 * sum, 1e-9 * sum);
  std::vector<double> costs;
  t.surface.BlockCosts(k, &costs);
  EXPECT_NEAR(std::accumulate(costs.begin(), costs.end(), 0.0), sum, 1e-9 * sum);
}

INSTANTIATE_TEST_SUITE_P(SurfaceConsensusTest, SurfaceRowsTest, testing::Bool(),
                         [](const testing::TestParamInfo<bool>& info) {
                           return info.param ? "PooledGain" : "GainPerChannel";
                         });

// With every k the same the refined mesh is the input surface moved as a whole, as each patch
// is: the two terms agree block by block, the surface term times its weight.
// The term weighs a patch's cameras alike (ConsensusOptions::view_cosine_power weighs the
// patches' only), so the two agree where the patches' cameras count alike too.
TEST(SurfaceConsensusTest, WithEveryKTheSameItIsThePatchTermTimesItsWeight) {
  SurfaceTermScene t(0.0012, /*weight=*/3.0, /*pooled_gain=*/false, SurfacePatches::kFaceCover,
                     /*view_cosine_power=*/0.0);
  const Eigen::VectorXd k = Eigen::VectorXd::Constant(t.scene.surface.size(), 0.0007);
  std::vector<double> patch_costs, surface_costs;
  t.patches.BlockCosts(k, &patch_costs);
  t.surface.BlockCosts(k, &surface_costs);
  ASSERT_FALSE(surface_costs.empty());
  for (size_t b = 0; b < surface_costs.size(); ++b) {
    const double patch_cost = patch_costs[t.surface.PatchOf(static_cast<int>(b))];
    EXPECT_NEAR(surface_costs[b], 3.0 * patch_cost, 1e-9 * std::max(patch_cost, 1e-12))
        << "block " << b;
  }
}

// The mesh on the textured plane compares better than the same mesh tilted or roughened.
TEST(SurfaceConsensusTest, TheTruthScoresBetterThanATiltOrNoise) {
  const SurfaceTermScene t(0.0);
  // The cameras see the plane z = 0; the grid's normals point to -z, so k = 0 is the truth.
  const Eigen::VectorXd truth = Eigen::VectorXd::Zero(t.scene.surface.size());
  const double at_truth = t.surface.Evaluate(truth, nullptr);
  Eigen::VectorXd tilted(t.scene.surface.size());
  for (int s = 0; s < tilted.size(); ++s) tilted[s] = 0.05 * t.scene.surface.base(0, s);
  EXPECT_LT(t.surface.Evaluate(tilted, nullptr), at_truth);
  const Eigen::VectorXd step = RandomK(t.scene.surface.size(), 0.0005, 2);
  EXPECT_LT(t.surface.Evaluate(step, nullptr), at_truth);
}

}  // namespace
}  // namespace finecap
