// Foreground masks end to end: synth writes the subject's silhouettes, a capture reads them with
// the images, and what the images hold outside them changes neither the refined surface nor the
// held-out score.
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "finecap/geometry/render.h"
#include "finecap/io/capture.h"
#include "finecap/measure/heldout_score.h"
#include "finecap/refine/frame_reader.h"
#include "finecap/refine/refine.h"
#include "finecap/synth/synth.h"
#include "test_util.h"
#include "tiny_synth.h"

namespace finecap {
namespace {

// Six cameras that see a folded skirt in front of a wall of their own, with masks.
SynthOptions MaskedSynthOptions() {
  SynthOptions options = testing_util::TinyRefinableSynthOptions(2);
  options.background = SynthBackground::kPerCamera;
  options.write_masks = true;
  return options;
}

// `image` with every pixel outside `mask` replaced by noise of `seed`.
cv::Mat Repainted(const cv::Mat& image, const cv::Mat& mask, int seed) {
  cv::Mat repainted(image.size(), image.type());
  cv::RNG(seed).fill(repainted, cv::RNG::UNIFORM, cv::Scalar::all(0), cv::Scalar::all(256));
  image.copyTo(repainted, mask);
  return repainted;
}

FrameInput RepaintedInput(const FrameInput& input) {
  FrameInput repainted = input;
  for (size_t c = 0; c < input.images.size(); ++c) {
    repainted.images[c] = Repainted(input.images[c], input.masks[c], static_cast<int>(c) + 7);
  }
  return repainted;
}

FrameInput WithoutMasks(FrameInput input) {
  input.masks.clear();
  return input;
}

bool BitwiseEqual(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return a.size() == b.size() &&
         std::memcmp(a.data(), b.data(), sizeof(double) * static_cast<size_t>(a.size())) == 0;
}

class MaskedCaptureTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    directory_ = new std::string(testing_util::MakeTempDir("masked_capture"));
    GenerateSyntheticCapture(MaskedSynthOptions(), *directory_);
  }
  static void TearDownTestSuite() { delete directory_; }

  // The refined k of frame 1, its surface coloured by frame 0, with the default refinement
  // (the consensus similarity and its per-pixel detail stage).
  static Eigen::VectorXd Refined(const FrameInput& reference, const FrameInput& input) {
    RefineOptions options;
    options.visibility.max_view_angle_deg = 60.0;
    const SequenceModel model(input.coarse, {}, options, "test");
    const ReferenceColors colors = ComputeSequenceColors(model, reference, options);
    return RefineFrame(model, colors, input, options).k;
  }

  static std::string* directory_;
};

std::string* MaskedCaptureTest::directory_ = nullptr;

TEST_F(MaskedCaptureTest, SynthMasksAreTheRenderedSilhouette) {
  Capture capture = Capture::Open(*directory_);
  ASSERT_TRUE(capture.has_masks());
  const SyntheticCapture synth(MaskedSynthOptions());
  const SyntheticFrame frame = synth.Frame(1);
  for (int c = 0; c < capture.num_cameras(); ++c) {
    const cv::Mat mask = capture.ReadMask(c, 1);
    ASSERT_EQ(mask.type(), CV_8UC1);
    // One sample per pixel: the silhouette is the pixels whose centre sees the surface.
    const cv::Mat covered = RenderDepth(synth.true_cameras()[c], frame.truth).triangle_ids >= 0;
    EXPECT_EQ(cv::countNonZero(mask != covered), 0) << c;
    EXPECT_GT(cv::countNonZero(mask), 500) << c;
    EXPECT_GT(cv::countNonZero(mask == 0), 500) << c;
    // The wall behind the subject is textured, and no two cameras' walls agree.
    const cv::Mat image = capture.ReadImage(c, 1), other = capture.ReadImage((c + 1) % 6, 1);
    cv::Scalar mean, deviation;
    cv::meanStdDev(image, mean, deviation, mask == 0);
    EXPECT_GT(deviation[0], 10.0) << c;
    cv::Mat difference;
    cv::absdiff(image, other, difference);
    EXPECT_GT(cv::mean(difference, (mask == 0) & (capture.ReadMask((c + 1) % 6, 1) == 0))[0], 10.0)
        << c;
  }
}

// Outside the masks the images may hold anything: the refined surface is the same to the bit.
// Without the masks the same change moves it.
TEST_F(MaskedCaptureTest, PixelsOutsideTheMasksDoNotChangeTheRefinement) {
  Capture capture = Capture::Open(*directory_);
  const FrameInput reference = ReadFrameInput(&capture, 0);
  const FrameInput input = ReadFrameInput(&capture, 1);
  ASSERT_EQ(input.masks.size(), input.images.size());
  const Eigen::VectorXd masked = Refined(reference, input);
  ASSERT_GT((masked.array() == masked.array()).count(), 0);  // Some vertices refined.
  EXPECT_TRUE(BitwiseEqual(Refined(RepaintedInput(reference), RepaintedInput(input)), masked));
  const Eigen::VectorXd unmasked = Refined(WithoutMasks(reference), WithoutMasks(input));
  EXPECT_FALSE(BitwiseEqual(
      Refined(WithoutMasks(RepaintedInput(reference)), WithoutMasks(RepaintedInput(input))),
      unmasked));
}

// The detail stage's next pass is prepared from the energy of the pass before
// (refine.views_follow_surface), which hands on its samples as the masks cut them: the energy is
// the one prepared at once, and not the one prepared without the masks.
TEST_F(MaskedCaptureTest, TheDetailStagesNextPassKeepsWhatTheMasksCut) {
  Capture capture = Capture::Open(*directory_);
  const FrameInput input = ReadFrameInput(&capture, 1);
  RefineOptions options;
  options.visibility.max_view_angle_deg = 60.0;
  const SequenceModel model(input.coarse, {}, options, "test");
  const ReferenceColors colors = ComputeSequenceColors(model, input, options);
  // The detail stage's energy at k after `preparations` preparations at the input surface.
  const auto detail_energy = [&](const FrameInput& frame_input, int preparations) {
    PreparedFrame frame = PrepareFrame(model, colors, frame_input, options);
    const Eigen::VectorXd input_surface = Eigen::VectorXd::Zero(frame.energy->num_parameters());
    for (int p = 0; p < preparations; ++p) {
      PrepareDetailEnergy(model, frame_input, options, input_surface, &frame);
    }
    return frame.energy->Evaluate(Eigen::VectorXd::Constant(input_surface.size(), 1e-3), nullptr);
  };
  // The threads sum in any order: equal within a few ulps.
  const double at_once = detail_energy(input, 1);
  EXPECT_NEAR(detail_energy(input, 2), at_once, 1e-12 * std::abs(at_once));
  EXPECT_GT(std::abs(detail_energy(WithoutMasks(input), 1) - at_once), 1e-3 * std::abs(at_once));
}

// The held-out score measures the subject alone: repainting the background of every view changes
// nothing with masks, and changes the score without them.
TEST_F(MaskedCaptureTest, HeldOutScoreIgnoresPixelsOutsideTheMasks) {
  Capture capture = Capture::Open(*directory_);
  FrameInput input = ReadFrameInput(&capture, 1);
  const std::vector<CalibratedImage> held_out = TakeHeldOutViews({"cam00", "cam03"}, &input);
  const std::vector<CalibratedImage> training = CalibratedImagesOf(input);
  const auto repainted = [](std::vector<CalibratedImage> views) {
    for (size_t v = 0; v < views.size(); ++v) {
      views[v].image = Repainted(views[v].image, views[v].mask, static_cast<int>(v) + 3);
    }
    return views;
  };
  const auto unmasked = [](std::vector<CalibratedImage> views) {
    for (CalibratedImage& view : views) view.mask = cv::Mat();
    return views;
  };
  const std::vector<const Mesh*> surfaces = {&input.coarse};
  const HeldOutScore masked = ScoreHeldOutViews(training, held_out, surfaces, HeldOutOptions());
  const HeldOutScore masked_repainted =
      ScoreHeldOutViews(repainted(training), repainted(held_out), surfaces, HeldOutOptions());
  const HeldOutScore plain =
      ScoreHeldOutViews(unmasked(training), unmasked(held_out), surfaces, HeldOutOptions());
  const HeldOutScore plain_repainted = ScoreHeldOutViews(
      unmasked(repainted(training)), unmasked(repainted(held_out)), surfaces, HeldOutOptions());
  ASSERT_EQ(masked.views.size(), 2u);
  for (size_t v = 0; v < masked.views.size(); ++v) {
    EXPECT_GT(masked.views[v].common_pixels, 100) << v;
    EXPECT_LT(masked.views[v].common_pixels, plain.views[v].common_pixels) << v;
    EXPECT_EQ(masked_repainted.views[v].common_pixels, masked.views[v].common_pixels) << v;
  }
  EXPECT_EQ(masked_repainted.mean[0].mad, masked.mean[0].mad);
  EXPECT_NE(plain_repainted.mean[0].mad, plain.mean[0].mad);

  std::vector<CalibratedImage> badly_masked = held_out;
  badly_masked[1].mask = cv::Mat::ones(10, 10, CV_8UC1);
  testing_util::ExpectErrorMentions(
      [&] { ScoreHeldOutViews(training, badly_masked, surfaces, HeldOutOptions()); },
      {"held-out camera cam03", "the mask is not CV_8UC1 of the image's size"});
}

}  // namespace
}  // namespace finecap
