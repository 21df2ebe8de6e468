#include "finecap/refine/refine.h"

#include <cmath>

#include <gtest/gtest.h>

#include "finecap/io/capture.h"
#include "finecap/refine/frame_reader.h"
#include "test_util.h"
#include "tiny_synth.h"

namespace finecap {
namespace {

class RefineFrameTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    directory_ = new std::string(testing_util::MakeTempDir("refine_frame"));
    GenerateSyntheticCapture(testing_util::TinyRefinableSynthOptions(2), *directory_);
  }
  static void TearDownTestSuite() { delete directory_; }

  static std::string* directory_;
};

std::string* RefineFrameTest::directory_ = nullptr;

// The residuals of an energy's first data term (the detail stage's patches).
long DataResiduals(const FrameEnergy& energy) {
  long count = 0;
  for (const auto& block : energy.data_term(0).residual_blocks()) count += block.num_residuals;
  return count;
}

// A surface found `fraction` of the size of `mesh`'s bounding box out on every other surface
// Gaussian and as far in on the rest: one that faces no camera as the surface does.
Eigen::VectorXd CrumpledSurface(int num_parameters, const Mesh& mesh, double fraction) {
  const double amplitude =
      fraction * (mesh.vertices.rowwise().maxCoeff() - mesh.vertices.rowwise().minCoeff()).norm();
  Eigen::VectorXd found = Eigen::VectorXd::Constant(num_parameters, amplitude);
  for (Eigen::Index s = 1; s < found.size(); s += 2) found[s] = -amplitude;
  return found;
}

// With a schedule, the figures of the frame still refer to the configured energy: it starts
// where a single-level solve starts and ends at the energy of the k it returns. One consensus
// pass and no detail stage: a further pass, and the detail stage, shape the patches like the
// surface found, so their energy depends on the solve that came before them.
TEST_F(RefineFrameTest, CoarseToFineReportsTheConfiguredEnergy) {
  Capture capture = Capture::Open(*directory_);
  RefineOptions options;
  options.visibility.max_view_angle_deg = 60.0;
  options.energy.consensus.passes = 1;
  options.energy.consensus.sample_spacing = 0.0;
  const FrameInput input = ReadFrameInput(&capture, 1);
  const SequenceModel model(input.coarse, {}, options, "test");
  const ReferenceColors colors = ComputeSequenceColors(model, ReadFrameInput(&capture, 0), options);

  const FrameResult single = RefineFrame(model, colors, input, options);
  options.coarse_to_fine.levels = 2;
  const FrameResult scheduled = RefineFrame(model, colors, input, options);

  ASSERT_GT(scheduled.num_surface_gaussians, 0);
  // To rounding: the single level's figure is the solver's own sum of the blocks' costs, the
  // schedule's is EvaluateEnergyAndCost's, and the two sum a patch's residuals in other orders.
  EXPECT_NEAR(scheduled.summary.energy_start, single.summary.energy_start,
              1e-12 * std::abs(single.summary.energy_start));
  options.coarse_to_fine.levels = 1;
  PreparedFrame configured = PrepareFrame(model, colors, input, options);
  // The consensus similarity's tables hold what its energy needs of the image models.
  EXPECT_TRUE(configured.images.empty());
  EXPECT_GT(configured.num_image_gaussians, 0);
  EXPECT_NEAR(configured.energy->Evaluate(scheduled.k_solved, nullptr),
              scheduled.summary.energy_end, 1e-9 * std::abs(scheduled.summary.energy_end));
  EXPECT_GT(scheduled.summary.energy_end, scheduled.summary.energy_start);
  // The coarse level's iterations are counted too: at least one solve on each level.
  EXPECT_GE(scheduled.summary.iterations, 2);
}

// With energy.consensus.shared_appearance a frame hands on the appearance of its refined surface
// at its samples, and the next frame given it solves to another surface than without it. A
// frame whose input is put back by another measure (KeepInputSurface) hands on none: what it
// showed was not the surface it writes.
TEST_F(RefineFrameTest, AFrameHandsOnTheAppearanceOfTheSurfaceItWrites) {
  Capture capture = Capture::Open(*directory_);
  RefineOptions options;
  options.solver.max_iterations = 3;
  options.energy.consensus.shared_appearance = true;
  const FrameInput first = ReadFrameInput(&capture, 0);
  FrameInput second = ReadFrameInput(&capture, 1);
  const SequenceModel model(first.coarse, {}, options, "test");
  const ReferenceColors colors = ComputeSequenceColors(model, first, options);

  FrameResult result = RefineFrame(model, colors, first, options);
  ASSERT_GT(result.appearance.cols(), model.num_fine_vertices());
  EXPECT_GT(result.appearance.array().isFinite().count(), result.appearance.size() / 2);
  const FrameResult alone = RefineFrame(model, colors, second, options);
  second.frame_before_appearance = result.appearance;
  const FrameResult shared = RefineFrame(model, colors, second, options);
  EXPECT_GT((shared.k - alone.k).array().isFinite().select(shared.k - alone.k, 0.0).norm(), 0.0);
  // Without the option the appearance is neither made nor read.
  options.energy.consensus.shared_appearance = false;
  const FrameResult off = RefineFrame(model, colors, second, options);
  EXPECT_EQ(off.appearance.cols(), 0);
  EXPECT_EQ((off.k - alone.k).array().isFinite().select(off.k - alone.k, 0.0).norm(), 0.0);

  KeepInputSurface(model.Subdivide(first.coarse), &result);
  EXPECT_TRUE(result.kept_input);
  EXPECT_EQ(result.appearance.cols(), 0);
}

// The detail stage reads each patch in the cameras that see the surface the first stage found
// within VisibilityOptions::sample_view_angle_deg: a wider angle than the first stage's gives it
// more comparisons. A found surface of the wrong size is refused.
TEST_F(RefineFrameTest, TheDetailStageReadsTheCamerasWithinItsOwnAngle) {
  Capture capture = Capture::Open(*directory_);
  const RefineOptions defaults;
  const FrameInput input = ReadFrameInput(&capture, 0);
  const SequenceModel model(input.coarse, {}, defaults, "test");
  const ReferenceColors colors = ComputeSequenceColors(model, input, defaults);
  // The detail stage's residuals with the surface found crumpled by `fraction` of the scene's
  // size (CrumpledSurface; 0: the input surface).
  const auto detail_residuals = [&](double angle, double fraction = 0.0) {
    RefineOptions options = defaults;
    options.visibility.sample_view_angle_deg = angle;
    PreparedFrame frame = PrepareFrame(model, colors, input, options);
    const Eigen::VectorXd found =
        CrumpledSurface(frame.energy->num_parameters(), input.coarse, fraction);
    PrepareDetailEnergy(model, input, options, found, &frame);
    return DataResiduals(*frame.energy);
  };
  EXPECT_GT(detail_residuals(80.0), detail_residuals(defaults.visibility.max_view_angle_deg));
  // A found surface crumpled by noise faces no camera as the surface does; its patches are still
  // read in the views that see the input most frontally (as many as at 1 degree and no noise:
  // those views alone).
  EXPECT_GE(detail_residuals(defaults.visibility.sample_view_angle_deg, 0.05),
            detail_residuals(1.0));

  PreparedFrame frame = PrepareFrame(model, colors, input, defaults);
  const Eigen::VectorXd too_short = Eigen::VectorXd::Zero(frame.energy->num_parameters() - 1);
  EXPECT_THROW(PrepareDetailEnergy(model, input, defaults, too_short, &frame), Error);
}

// With refine.views_follow_surface each pass of the detail stage after the first is prepared at
// the surface the pass before found, from that pass's own energy: the energy so prepared is the
// one prepared at that surface from the surface Gaussians' stage, and differs from the pass
// before's where the surface found turns patches towards other cameras.
TEST_F(RefineFrameTest, TheDetailStagesNextPassIsPreparedAtTheSurfaceFound) {
  Capture capture = Capture::Open(*directory_);
  const RefineOptions options;
  const FrameInput input = ReadFrameInput(&capture, 0);
  const SequenceModel model(input.coarse, {}, options, "test");
  const ReferenceColors colors = ComputeSequenceColors(model, input, options);
  PreparedFrame passes = PrepareFrame(model, colors, input, options);
  const int n = passes.energy->num_parameters();
  const Eigen::VectorXd found = CrumpledSurface(n, input.coarse, 0.05);
  PrepareDetailEnergy(model, input, options, Eigen::VectorXd::Zero(n), &passes);
  const long first_pass = DataResiduals(*passes.energy);
  PrepareDetailEnergy(model, input, options, found, &passes);

  PreparedFrame at_once = PrepareFrame(model, colors, input, options);
  PrepareDetailEnergy(model, input, options, found, &at_once);
  ASSERT_EQ(passes.energy->num_parameters(), n);
  EXPECT_EQ(DataResiduals(*passes.energy), DataResiduals(*at_once.energy));
  EXPECT_NE(DataResiduals(*passes.energy), first_pass);
  const Eigen::VectorXd k = 0.1 * found;
  EXPECT_NEAR(passes.energy->Evaluate(k, nullptr), at_once.energy->Evaluate(k, nullptr),
              1e-12 * std::abs(at_once.energy->Evaluate(k, nullptr)));
}

// With energy.consensus.surface_weight the detail stage compares the refined mesh itself beside
// the patches in its last pass: its energy has the second term then, the solve ends above where
// it started, and the surface differs from the patches' alone, with two passes as with one (whose
// only pass is the last).
class RefinedMeshTermTest : public RefineFrameTest, public testing::WithParamInterface<int> {};

TEST_P(RefinedMeshTermTest, JoinsTheDetailStagesLastPass) {
  Capture capture = Capture::Open(*directory_);
  RefineOptions options;
  options.solver.max_iterations = 5;
  options.energy.consensus.passes = GetParam();
  options.energy.consensus.surface_weight = 0.0;
  const FrameInput input = ReadFrameInput(&capture, 0);
  const SequenceModel model(input.coarse, {}, options, "test");
  const ReferenceColors colors = ComputeSequenceColors(model, input, options);
  const FrameResult patches = RefineFrame(model, colors, input, options);
  options.energy.consensus.surface_weight = 1.0;
  const FrameResult both = RefineFrame(model, colors, input, options);
  EXPECT_GT(both.summary.energy_end, both.summary.energy_start);
  EXPECT_FALSE(both.worse);
  const Eigen::VectorXd difference = both.k - patches.k;
  EXPECT_EQ(difference.array().isNaN().count(), patches.k.array().isNaN().count());
  EXPECT_GT(difference.array().isFinite().select(difference, 0.0).norm(), 0.0);

  PreparedFrame frame = PrepareFrame(model, colors, input, options);
  PrepareDetailEnergy(model, input, options, both.k_solved, &frame);
  ASSERT_EQ(frame.energy->num_data_terms(), 1);
  frame.energy->StartLastPass();
  ASSERT_EQ(frame.energy->num_data_terms(), 2);
  EXPECT_GT(frame.energy->data_term(1).residual_blocks().front().parameters.size(), 1u);
}

INSTANTIATE_TEST_SUITE_P(Passes, RefinedMeshTermTest, testing::Values(1, 2));

// The plane sweep sets the range a frame is solved in from what it finds: a range far narrower
// than the input's error limits many Gaussians and widens, one far wider than it holds almost
// every Gaussian's best displacement in its inner half and narrows, never below sigma_hat. With
// both rules off the frame keeps the range it was given.
TEST_F(RefineFrameTest, TheSweepWidensANarrowRangeAndNarrowsAWideOne) {
  Capture capture = Capture::Open(*directory_);
  RefineOptions options;
  options.solver.max_iterations = 1;
  options.energy.consensus.sample_spacing = 0.0;
  const FrameInput input = ReadFrameInput(&capture, 0);
  const SequenceModel model(input.coarse, {}, options, "test");
  const ReferenceColors colors = ComputeSequenceColors(model, input, options);
  const auto range_solved_in = [&](double k_max, double widen_share, double narrow_share) {
    RefineOptions ranged = options;
    ranged.energy.k_max = k_max;
    ranged.sweep.widen_share = widen_share;
    ranged.sweep.narrow_share = narrow_share;
    return RefineFrame(model, colors, input, ranged).k_max;
  };
  const double narrow = 0.05 * options.sigma_hat, wide = 64.0 * options.sigma_hat;
  const SweepOptions defaults;
  EXPECT_GT(range_solved_in(narrow, defaults.widen_share, defaults.narrow_share), narrow);
  const double narrowed = range_solved_in(wide, defaults.widen_share, defaults.narrow_share);
  EXPECT_LT(narrowed, wide);
  EXPECT_GE(narrowed, options.sigma_hat);
  EXPECT_EQ(range_solved_in(narrow, 0.0, 0.0), narrow);
  EXPECT_EQ(range_solved_in(wide, 0.0, 0.0), wide);
}

// A frame modelled ahead (ModelFrameImages) gives its own models to every stage that asks with the
// same options, keeps those of the cameras left after the held-out ones are set aside, and is
// modelled afresh under other options; the frame it solves to is the one it solves to unmodelled.
TEST_F(RefineFrameTest, ImagesModelledAheadServeTheSameOptionsOnly) {
  Capture capture = Capture::Open(*directory_);
  RefineOptions options;
  FrameInput input = ReadFrameInput(&capture, 1);
  const FrameInput unmodelled = input;
  ModelFrameImages(options.image, &input);
  ASSERT_EQ(input.image_models.size(), input.images.size());
  // Marks the models, so that a copy of them can be told from a fresh build.
  std::vector<ImageGaussian> marked = {{1.0f, 2.0f, 0.5f, {0.1f, 0.2f, 0.3f}}};
  const int num_marked = 1;
  input.image_models[0] = ImageGaussians(16, 16, options.image.color_space, marked, "test");
  EXPECT_EQ(FrameImageModels(input, options.image)[0].size(), num_marked);

  ImageGaussianOptions other = options.image;
  other.min_leaf_size = 2 * options.image.min_leaf_size;
  EXPECT_GT(FrameImageModels(input, other)[0].size(), num_marked);

  const std::string held_out = input.cameras[1].name;
  TakeHeldOutViews({held_out}, &input);
  ASSERT_EQ(input.image_models.size(), input.images.size());
  EXPECT_EQ(input.image_models[0].size(), num_marked);

  FrameInput fresh = unmodelled;
  ModelFrameImages(options.image, &fresh);
  const SequenceModel model(fresh.coarse, {}, options, "test");
  const ReferenceColors colors = ComputeSequenceColors(model, unmodelled, options);
  const Eigen::ArrayXd ahead = RefineFrame(model, colors, fresh, options).k.array();
  const Eigen::ArrayXd now = RefineFrame(model, colors, unmodelled, options).k.array();
  ASSERT_EQ(ahead.size(), now.size());
  EXPECT_TRUE((ahead == now || (ahead.isNaN() && now.isNaN())).all());
}

// A frame prepared ahead (PrepareFrameAhead: the energy and the plane sweep's start, with the
// input's image models taken) solves to exactly the frame that RefineFrame prepares itself, from
// the sweep and from a given start alike; with a schedule, the sweep is left to the coarsest
// level.
TEST_F(RefineFrameTest, AFramePreparedAheadSolvesAsOnePreparedInPlace) {
  Capture capture = Capture::Open(*directory_);
  RefineOptions options;
  const FrameInput input = ReadFrameInput(&capture, 1);
  const SequenceModel model(input.coarse, {}, options, "test");
  const ReferenceColors colors = ComputeSequenceColors(model, ReadFrameInput(&capture, 0), options);
  const auto same = [](const Eigen::ArrayXd& a, const Eigen::ArrayXd& b) {
    return a.size() == b.size() && (a == b || (a.isNaN() && b.isNaN())).all();
  };

  FrameInput read = input;
  PreparedFrame ahead = PrepareFrameAhead(model, colors, &read, options);
  EXPECT_TRUE(read.image_models.empty());
  ASSERT_EQ(ahead.sweep_start.size(), ahead.energy->num_parameters());
  ASSERT_GT(ahead.sweep_start.size(), 0);
  const FrameResult in_place = RefineFrame(model, colors, input, options);
  const FrameResult prepared = RefineFrame(model, colors, read, options, nullptr, std::move(ahead));
  EXPECT_TRUE(prepared.prepared_ahead);
  EXPECT_FALSE(in_place.prepared_ahead);
  EXPECT_TRUE(same(prepared.k.array(), in_place.k.array()));

  const Eigen::VectorXd start = Eigen::VectorXd::Constant(model.num_fine_vertices(), 0.001);
  read = input;
  EXPECT_TRUE(same(RefineFrameFrom(model, colors, read, options, start,
                                   PrepareFrameAhead(model, colors, &read, options))
                       .k.array(),
                   RefineFrameFrom(model, colors, input, options, start).k.array()));

  options.coarse_to_fine.levels = 2;
  read = input;
  EXPECT_EQ(PrepareFrameAhead(model, colors, &read, options).sweep_start.size(), 0);
}

// Every entry point checks its options, so that a library caller's bad value is refused naming
// the field instead of selecting a default.
TEST_F(RefineFrameTest, EntryPointsRefuseBadOptionsNamingTheField) {
  Capture capture = Capture::Open(*directory_);
  const RefineOptions options;
  const FrameInput input = ReadFrameInput(&capture, 1);
  const SequenceModel model(input.coarse, {}, options, "test");
  const ReferenceColors colors = ComputeSequenceColors(model, ReadFrameInput(&capture, 0), options);

  RefineOptions bad = options;
  bad.sigma_hat = -0.007;
  testing_util::ExpectErrorMentions([&] { RefineFrame(model, colors, input, bad); },
                                    {"RefineOptions::sigma_hat", "[1e-05, 1]"});
  const Eigen::VectorXd start = Eigen::VectorXd::Zero(model.num_fine_vertices());
  testing_util::ExpectErrorMentions([&] { RefineFrameFrom(model, colors, input, bad, start); },
                                    {"RefineOptions::sigma_hat"});
  testing_util::ExpectErrorMentions([&] { PrepareFrame(model, colors, input, bad); },
                                    {"RefineOptions::sigma_hat"});
  testing_util::ExpectErrorMentions([&] { SequenceModel(input.coarse, {}, bad, "test"); },
                                    {"RefineOptions::sigma_hat"});

  bad = options;
  bad.reference_colors = static_cast<ReferenceColorSource>(7);
  testing_util::ExpectErrorMentions(
      [&] { ComputeSequenceColors(model, ReadFrameInput(&capture, 0), bad); },
      {"RefineOptions::reference_colors", "not a valid choice"});
  bad = options;
  bad.sweep.samples = 2;
  testing_util::ExpectErrorMentions([&] { RefineFrame(model, colors, input, bad); },
                                    {"SweepOptions::samples", "0 (off)"});
}

TEST(CoarseToFineOptionsTest, RefusesLevelsAndScalesOutOfRange) {
  CoarseToFineOptions options;
  options.levels = 0;
  testing_util::ExpectErrorMentions([&] { options.Check(); },
                                    {"CoarseToFineOptions::levels", "[1, 5]"});
  options.levels = 2;
  options.scale = 1.0;
  testing_util::ExpectErrorMentions([&] { options.Check(); },
                                    {"CoarseToFineOptions::scale", "[1.0001, 4]"});
}

// A patch covers the same surface at every subdivision level: its rings double with each level
// past the first, up to the widest patch.
TEST(PatchRingsTest, CountEdgesOfTheInputSubdividedOnce) {
  RefineOptions options;
  const auto rings_at = [&](int patch_rings, int levels) {
    options.energy.consensus.patch_rings = patch_rings;
    options.subdivision_levels = levels;
    return PatchRingsAt(options);
  };
  EXPECT_EQ(rings_at(1, 0), 1);
  EXPECT_EQ(rings_at(1, 1), 1);
  EXPECT_EQ(rings_at(1, 2), 2);
  EXPECT_EQ(rings_at(1, 3), 4);
  EXPECT_EQ(rings_at(2, 1), 2);
  EXPECT_EQ(rings_at(2, 3), ConsensusOptions::kMaxPatchRings);
}

}  // namespace
}  // namespace finecap
