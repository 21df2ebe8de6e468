// The lengths that follow from the scene: what MeasureSceneScale measures, and that
// ResolveSceneScaleDefaults scales with the scene and leaves set lengths alone.
#include "refine/scene_scale.h"

#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>

#include "energy_fixture.h"
#include "finecap/config/config.h"
#include "finecap/io/capture.h"
#include "test_meshes.h"

namespace finecap {
namespace {

// A 21 x 21 grid of spacing `spacing` centred on the origin in the z = 0 plane.
Mesh CentredGrid(double spacing) {
  Mesh mesh = testing_meshes::GridMesh(21, 21);
  mesh.vertices.row(0).array() -= 10.0;
  mesh.vertices.row(1).array() -= 10.0;
  mesh.vertices *= spacing;
  return mesh;
}

// Mean edge length of the grid: 2 * 21 * 20 sides of `spacing`, 20 * 20 diagonals.
double GridMeanEdge(double spacing) {
  const double sides = 2.0 * 21 * 20, diagonals = 20.0 * 20;
  return spacing * (sides + diagonals * std::sqrt(2.0)) / (sides + diagonals);
}

TEST(SceneScale, MeasuresEdgeLengthAndPixelFootprint) {
  // 1 cm spacing seen face-on from 2 m with a focal length of 1000 px: 2 mm per pixel.
  const Camera camera = LookAtOrigin(2.0, 0.0, 1000.0, 400);
  const SceneScale scale = MeasureSceneScale(CentredGrid(0.01), {camera});
  EXPECT_NEAR(scale.mean_edge_length, GridMeanEdge(0.01), 1e-12);
  EXPECT_NEAR(scale.pixel_footprint, 0.002, 1e-12);
  EXPECT_NEAR(scale.diagonal, 0.2 * std::sqrt(2.0), 1e-12);
  // 3 footprints (6 mm) are less than the mean edge (11.7 mm): the edges set the length.
  EXPECT_DOUBLE_EQ(scale.length, scale.mean_edge_length);

  // From 10 m a pixel covers 1 cm, and the Gaussians must stay wide enough to be seen.
  const SceneScale far =
      MeasureSceneScale(CentredGrid(0.01), {LookAtOrigin(10.0, 0.0, 1000.0, 400)});
  EXPECT_NEAR(far.pixel_footprint, 0.01, 1e-12);
  EXPECT_NEAR(far.length, kFootprintsPerSceneLength * 0.01, 1e-12);

  // A camera with the mesh behind it measures no footprint.
  Camera away = camera;
  away.t.z() -= 5.0;
  const SceneScale unseen = MeasureSceneScale(CentredGrid(0.01), {away});
  EXPECT_EQ(unseen.pixel_footprint, 0.0);
  EXPECT_DOUBLE_EQ(unseen.length, unseen.mean_edge_length);
}

// The similarities that compare single Gaussians blur more than consensus, which compares patches.
TEST(SceneScale, SigmaHatFollowsTheSimilarity) {
  const Mesh grid = CentredGrid(0.01);
  const Camera camera = LookAtOrigin(2.0, 0.0, 1000.0, 400);
  const double s = GridMeanEdge(0.01);
  const SceneLengthFactors factors;
  for (const std::string similarity : {"consensus", "surface_color", "paper"}) {
    RefineOptions options;
    options.subdivision_levels = 0;
    ASSERT_TRUE(StringToEnum(similarity, &options.energy.similarity)) << similarity;
    ResolveSceneScaleDefaults(grid, {camera}, "grid.ply", &options);
    const double factor =
        similarity == "consensus" ? factors.sigma_hat : factors.single_gaussian_sigma_hat;
    EXPECT_NEAR(options.sigma_hat, factor * s, 1e-12) << similarity;
  }
  EXPECT_LT(factors.sigma_hat, factors.single_gaussian_sigma_hat);
}

TEST(SceneScale, LengthsFollowTheSceneUnlessSet) {
  RefineOptions options;
  options.subdivision_levels = 0;
  const Mesh grid = CentredGrid(0.01);
  const Camera camera = LookAtOrigin(2.0, 0.0, 1000.0, 400);
  const SceneScaleDefaults defaults =
      ResolveSceneScaleDefaults(grid, {camera}, "grid.ply", &options);
  const double s = GridMeanEdge(0.01);
  const SceneLengthFactors factors;
  EXPECT_NEAR(options.sigma_hat, factors.sigma_hat * s, 1e-12);
  EXPECT_NEAR(options.energy.k_max, factors.k_max * s, 1e-12);
  EXPECT_NEAR(options.visibility.depth_tolerance, factors.depth_tolerance * s, 1e-12);
  EXPECT_NEAR(options.solver.initial_step, factors.initial_step * s, 1e-12);
  EXPECT_NEAR(options.solver.max_step, factors.max_step * s, 1e-12);
  ASSERT_EQ(defaults.lengths.size(), 5u);
  for (const ChosenLength& length : defaults.lengths)
    EXPECT_TRUE(length.from_scene) << length.field;
  EXPECT_NO_THROW(options.Check());

  // Resolving again changes nothing.
  const RefineOptions once = options;
  ResolveSceneScaleDefaults(grid, {camera}, "grid.ply", &options);
  EXPECT_EQ(options.sigma_hat, once.sigma_hat);
  EXPECT_EQ(options.energy.k_max, once.energy.k_max);

  // The same scene a tenth of the size (mesh and camera): every length a tenth.
  RefineOptions small;
  small.subdivision_levels = 0;
  Camera near = camera;
  near.t *= 0.1;
  Mesh small_grid = grid;
  small_grid.vertices *= 0.1;
  ResolveSceneScaleDefaults(small_grid, {near}, "grid.ply", &small);
  EXPECT_NEAR(small.sigma_hat, 0.1 * options.sigma_hat, 1e-12);
  EXPECT_NEAR(small.energy.k_max, 0.1 * options.energy.k_max, 1e-12);
  EXPECT_NEAR(small.visibility.depth_tolerance, 0.1 * options.visibility.depth_tolerance, 1e-12);

  // A length that is set stays, and is reported as set.
  RefineOptions set;
  set.subdivision_levels = 0;
  set.sigma_hat = 0.004;
  set.scene_lengths.sigma_hat = false;
  const SceneScaleDefaults chosen = ResolveSceneScaleDefaults(grid, {camera}, "grid.ply", &set);
  EXPECT_EQ(set.sigma_hat, 0.004);
  EXPECT_FALSE(chosen.lengths[0].from_scene);
  EXPECT_EQ(chosen.lengths[0].field, "RefineOptions::sigma_hat");
  EXPECT_NEAR(set.energy.k_max, options.energy.k_max, 1e-12);
  const std::string text = DescribeSceneScaleDefaults(chosen);
  EXPECT_NE(text.find("RefineOptions::sigma_hat 4 mm (set)"), std::string::npos) << text;
  EXPECT_NE(text.find("EnergyOptions::k_max"), std::string::npos) << text;
  // The command line reads the same line in config keys.
  const std::string keys = InConfigTerms(text);
  EXPECT_NE(keys.find("model.sigma_hat 4 mm (set)"), std::string::npos) << keys;
  EXPECT_NE(keys.find("energy.k_max"), std::string::npos) << keys;
  EXPECT_EQ(keys.find("Options::"), std::string::npos) << keys;
  EXPECT_NE(text.find("(auto)"), std::string::npos) << text;
}

TEST(SceneScale, SubdivisionShortensTheEdgesTheLengthsFollow) {
  RefineOptions coarse, fine;
  coarse.subdivision_levels = 0;
  fine.subdivision_levels = 1;
  const Camera camera = LookAtOrigin(2.0, 0.0, 1000.0, 400);
  ResolveSceneScaleDefaults(CentredGrid(0.04), {camera}, "grid.ply", &coarse);
  ResolveSceneScaleDefaults(CentredGrid(0.04), {camera}, "grid.ply", &fine);
  // Loop subdivision halves the edges of a planar grid (its boundary stays straight).
  EXPECT_NEAR(fine.sigma_hat, 0.5 * coarse.sigma_hat, 0.02 * coarse.sigma_hat);
}

// The Middlebury temple (../shared/captures, a 10 cm object filmed from 0.6 m) gets lengths
// proportionate to it, about a tenth of a person's.
TEST(SceneScale, ASmallRealObjectGetsProportionateLengths) {
  const std::string dir = FINECAP_SOURCE_DIR "/../shared/captures/middlebury_temple";
  if (!std::filesystem::exists(dir)) {
    GTEST_SKIP() << "the Middlebury temple capture is not at " << dir;
  }
  const Capture capture = Capture::Open(dir);
  RefineOptions options;
  const SceneScaleDefaults defaults = ResolveSceneScaleDefaults(capture, 0, &options);
  // 640 x 480 pixels of focal 1520 at 0.55-0.65 m: about 0.4 mm per pixel.
  EXPECT_NEAR(defaults.scale.pixel_footprint, 0.0004, 0.00005);
  EXPECT_GT(defaults.scale.diagonal, 0.15);
  EXPECT_LT(defaults.scale.diagonal, 0.25);
  EXPECT_GT(options.sigma_hat, 0.0004);
  EXPECT_LT(options.sigma_hat, 0.0012);
  EXPECT_LT(options.energy.k_max, 0.006);  // 2 % of its diagonal, against 24 mm for a person.
  // A surface Gaussian is still wider than the finest image Gaussians (sigma 1 pixel, half of
  // the 2-pixel leaves), so that the image model resolves it.
  EXPECT_GT(options.sigma_hat / defaults.scale.pixel_footprint, 1.25);
}

}  // namespace
}  // namespace finecap
