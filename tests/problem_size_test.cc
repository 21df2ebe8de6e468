// What a frame's refinement will take, known before the work: the pair count is that of the
// pair lists the energy builds, and the forecast follows the problem's size.
#include "finecap/refine/problem_size.h"

#include <gtest/gtest.h>

#include "energy_fixture.h"
#include "finecap/energy/frame_energy.h"
#include "finecap/io/capture.h"
#include "finecap/model/gaussian_pairs.h"
#include "finecap/synth/synth.h"
#include "finecap/util/error.h"
#include "refine/scene_scale.h"
#include "test_util.h"
#include "tiny_synth.h"

namespace finecap {
namespace {

TEST(CountCameraPairs, CountsThePairsBuildCameraPairsMakes) {
  const EnergyScene scene = MakeEnergyScene({0.0, 0.4}, 12, 7);
  for (const double cutoff : {0.0, 0.05}) {
    PairOptions options;
    options.k_max = 0.01;
    options.color_cutoff = cutoff;
    for (const CameraInput& camera : scene.cameras) {
      const CameraPairs pairs =
          BuildCameraPairs(camera.camera, *camera.image, scene.surface, camera.visible, options);
      ASSERT_GT(pairs.num_pairs(), 0);
      EXPECT_EQ(
          CountCameraPairs(camera.camera, *camera.image, scene.surface, camera.visible, options, 1),
          pairs.num_pairs());
      // Every 3rd surface Gaussian, scaled: close, not exact.
      EXPECT_NEAR(
          CountCameraPairs(camera.camera, *camera.image, scene.surface, camera.visible, options, 3),
          pairs.num_pairs(), 0.2 * pairs.num_pairs());
    }
  }
}

class ProblemSizeTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string dir = testing_util::MakeTempDir("problem_size") + "/capture";
    GenerateSyntheticCapture(testing_util::TinyRefinableSynthOptions(1), dir);
    Capture capture = Capture::Open(dir);
    input_.coarse = capture.ReadCoarseMesh(0);
    input_.cameras = capture.cameras();
    for (int c = 0; c < capture.num_cameras(); ++c)
      input_.images.push_back(capture.ReadImage(c, 0));
    ResolveSceneScaleDefaults(input_.coarse, input_.cameras, "tiny", &options_);
  }

  ProblemSize Estimate(const RefineOptions& options, PreparedFrame* prepared) const {
    const SequenceModel model(input_.coarse, {}, options, "tiny");
    const ReferenceColors colors = ComputeSequenceColors(model, input_, options);
    *prepared = PrepareFrame(model, colors, input_, options);
    return EstimateProblemSize(model, colors, input_, options);
  }

  FrameInput input_;
  RefineOptions options_;
};

TEST_F(ProblemSizeTest, SizesAreThoseOfThePreparedFrame) {
  PreparedFrame prepared;
  const ProblemSize size = Estimate(options_, &prepared);
  EXPECT_EQ(size.num_fine_vertices, prepared.fine.num_vertices());
  EXPECT_EQ(size.num_refined_vertices, prepared.fine.num_vertices());
  EXPECT_EQ(size.num_surface_gaussians, prepared.energy->num_parameters());
  EXPECT_EQ(size.num_image_gaussians, prepared.num_image_gaussians);
  // Fewer than 3000 surface Gaussians per camera: every one is counted.
  EXPECT_EQ(size.num_pairs, prepared.energy->num_pairs());
  ASSERT_EQ(size.visible_per_camera.size(), input_.cameras.size());
  for (int seen : size.visible_per_camera) EXPECT_GT(seen, 0);
  EXPECT_EQ(size.num_pixels, input_.cameras.size() * 96.0 * 96.0);
  EXPECT_GT(size.peak_memory_mb, 0.0);
  EXPECT_GT(size.seconds_per_frame, 0.0);
}

// Without the detail stage a frame's memory peaks in its first stage, whose pairs and colour
// tables grow with the range.
TEST_F(ProblemSizeTest, MoreReachMeansMorePairsAndMoreMemory) {
  RefineOptions first_stage_only = options_;
  first_stage_only.energy.consensus.sample_spacing = 0.0;
  PreparedFrame prepared;
  const ProblemSize size = Estimate(first_stage_only, &prepared);
  RefineOptions wider = first_stage_only;
  wider.energy.k_max *= 3.0;
  const ProblemSize wide = Estimate(wider, &prepared);
  EXPECT_GT(wide.num_pairs, size.num_pairs);
  EXPECT_GT(wide.peak_memory_mb, size.peak_memory_mb);
  EXPECT_GT(wide.seconds_per_frame, size.seconds_per_frame);
}

// The first stage's energy is freed before the detail stage is built, so a frame peaks in the
// larger of the two, not in their sum: the tiny capture's detail stage (169 samples a patch)
// outweighs its first stage, and a wider range, with more pairs and more time, leaves its peak
// where it was; without the detail stage the same range adds to it.
TEST_F(ProblemSizeTest, WithTheDetailStageTheLargerStageIsThePeak) {
  PreparedFrame prepared;
  const ProblemSize size = Estimate(options_, &prepared);
  RefineOptions wider = options_;
  wider.energy.k_max *= 3.0;
  const ProblemSize wide = Estimate(wider, &prepared);
  ASSERT_GT(size.num_surface_samples, 0.0);
  EXPECT_GT(wide.num_pairs, size.num_pairs);
  EXPECT_GT(wide.seconds_per_frame, size.seconds_per_frame);
  EXPECT_DOUBLE_EQ(wide.peak_memory_mb, size.peak_memory_mb);
}

// The plane sweep may double k_max up to max_widenings times: the widest range is forecast as a
// run configured with it from the start would be, and equals the configured one where the sweep
// does not widen. Without the detail stage, whose peak the tiny capture's range does not reach,
// the wider range takes more memory.
TEST_F(ProblemSizeTest, TheWidestRangeTheSweepMayTakeIsForecast) {
  for (const double spacing : {options_.energy.consensus.sample_spacing, 0.0}) {
    RefineOptions options = options_;
    options.energy.consensus.sample_spacing = spacing;
    PreparedFrame prepared;
    const ProblemSize size = Estimate(options, &prepared);
    const double widest = std::min(options.energy.k_max * (1 << options.sweep.max_widenings),
                                   EnergyOptions::kLargestKMax);
    ASSERT_GT(widest, options.energy.k_max);
    EXPECT_DOUBLE_EQ(size.widest_k_max, widest);
    if (spacing == 0.0) {
      EXPECT_GT(size.widest_peak_memory_mb, size.peak_memory_mb);
    } else {
      EXPECT_GE(size.widest_peak_memory_mb, size.peak_memory_mb);
    }

    RefineOptions configured_widest = options;
    configured_widest.energy.k_max = widest;
    configured_widest.sweep.widen_share = 0.0;
    const ProblemSize as_configured = Estimate(configured_widest, &prepared);
    EXPECT_NEAR(size.widest_peak_memory_mb, as_configured.peak_memory_mb,
                1e-9 * as_configured.peak_memory_mb);
    EXPECT_DOUBLE_EQ(as_configured.widest_k_max, widest);
    EXPECT_DOUBLE_EQ(as_configured.widest_peak_memory_mb, as_configured.peak_memory_mb);
  }
}

TEST_F(ProblemSizeTest, VerticesNoCameraSeesAreCounted) {
  RefineOptions narrow = options_;
  narrow.visibility.max_view_angle_deg = 1.0;
  narrow.visibility.fallback_view_angle_deg = 1.0;
  PreparedFrame prepared;
  const ProblemSize size = Estimate(narrow, &prepared);
  EXPECT_GT(size.num_unseen_refined_vertices, 0);
  EXPECT_EQ(size.num_surface_gaussians + size.num_unseen_refined_vertices,
            size.num_refined_vertices);
}

// A rig with lens distortion has its images undistorted as they are read, by maps held for the
// run: every camera's pixels count, and the forecast grows with them; a rig without has none.
TEST(UndistortedPixelsTest, CountsTheCamerasWithDistortion) {
  SynthOptions options = testing_util::TinyRefinableSynthOptions(1);
  const std::string plain = testing_util::MakeTempDir("undistorted") + "/capture";
  GenerateSyntheticCapture(options, plain);
  EXPECT_EQ(UndistortedPixels(Capture::Open(plain)), 0.0);
  options.cameras.distortion = {-0.1, 0.02, 0.0, 0.0, 0.0};
  const std::string distorted = testing_util::MakeTempDir("undistorted") + "/capture";
  GenerateSyntheticCapture(options, distorted);
  EXPECT_EQ(UndistortedPixels(Capture::Open(distorted)),
            options.cameras.count * double(options.cameras.width) * options.cameras.height);
}

TEST_F(ProblemSizeTest, UndistortedImagesTakeMoreMemory) {
  const RefineOptions options = options_;
  const SequenceModel model(input_.coarse, {}, options, "tiny");
  const ReferenceColors colors = ComputeSequenceColors(model, input_, options);
  const ProblemSize plain = EstimateProblemSize(model, colors, input_, options, 1, 0.0);
  const ProblemSize undistorted = EstimateProblemSize(model, colors, input_, options, 1, 1e6);
  EXPECT_GT(undistorted.peak_memory_mb, plain.peak_memory_mb + 1.0);
  EXPECT_EQ(undistorted.num_pairs, plain.num_pairs);
}

// A forecast above the run's own limit or above what the system has is refused with the figure,
// the limit and what to lower; one within both is not.
TEST(MemoryLimitTest, TheRunsOwnLimitWhenBelowWhatIsAvailable) {
  const AvailableMemory available{4000.0, "/proc/meminfo"};
  EXPECT_EQ(MemoryLimitMb(0, available), 4000.0);
  EXPECT_EQ(MemoryLimitMb(1000, available), 1000.0);
  EXPECT_EQ(MemoryLimitMb(9000, available), 4000.0);
}

TEST(RequireMemoryForTest, RefusesAForecastAboveEitherLimit) {
  ProblemSize size;
  size.peak_memory_mb = 812.4;
  size.num_pixels = 4 * 96.0 * 96.0;
  size.visible_per_camera = {1, 1, 1, 1};
  RefineOptions options;
  const AvailableMemory plenty{64000.0, "/proc/meminfo"};
  EXPECT_NO_THROW(RequireMemoryFor(size, 3, options, 0, plenty));
  EXPECT_NO_THROW(RequireMemoryFor(size, 3, options, 900, plenty));
  testing_util::ExpectErrorMentions([&] { RequireMemoryFor(size, 3, options, 500, plenty); },
                                    {"SequenceOptions::max_memory_mb", "812 MB", "500 MB",
                                     "RefineOptions::subdivision_levels (now 1",
                                     "0.04 Mpixel a frame over 4 cameras", "frames held at once"});
  // One frame: nothing is prepared ahead, so the frames held are not named.
  try {
    RequireMemoryFor(size, 1, options, 500, plenty);
    ADD_FAILURE() << "expected an Error";
  } catch (const Error& error) {
    EXPECT_EQ(std::string(error.what()).find("frames held"), std::string::npos) << error.what();
  }
  // The system's figure, named by its file, when it is the smaller.
  const AvailableMemory scarce{600.0, "/sys/fs/cgroup/memory.max"};
  testing_util::ExpectErrorMentions([&] { RequireMemoryFor(size, 1, options, 700, scarce); },
                                    {"/sys/fs/cgroup/memory.max", "812 MB", "600 MB available"});
}

}  // namespace
}  // namespace finecap
