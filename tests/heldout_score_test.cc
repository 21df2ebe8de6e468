// The held-out score (heldout_score.h) on synthetic views, and held-out cameras in finecap refine
// and eval: never used by the refinement, scored in the stats and metrics, bad names refused.
#include "finecap/measure/heldout_score.h"

#include <cmath>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>
#include <opencv2/imgcodecs.hpp>

#include "eval/mesh_viewer.h"
#include "finecap/commands/commands.h"
#include "finecap/config/config.h"
#include "finecap/refine/frame_stats.h"
#include "finecap/synth/synth.h"
#include "finecap/util/error.h"
#include "finecap/util/threads.h"
#include "test_util.h"
#include "tiny_synth.h"

namespace finecap {
namespace {

namespace fs = std::filesystem;
using testing_util::ExpectErrorMentions;
using testing_util::FileBytes;
using testing_util::MakeTempDir;
using testing_util::OneWorkerThread;

// A skirt with folds from frame 0, seen by 8 cameras at 1.6 m that resolve them (~4 mm per
// pixel; the folds shift the texture by a few pixels between neighbouring views).
SynthOptions FoldedSkirtOptions() {
  SynthOptions options = testing_util::TinySynthOptions();
  options.num_frames = 1;
  options.skirt.around = 32;
  options.skirt.down = 16;
  options.texture.width = 512;
  options.texture.height = 256;
  options.cameras.count = 8;
  options.cameras.width = 200;
  options.cameras.height = 200;
  options.cameras.focal = 400.0;
  options.cameras.distance = 1.6;
  options.render.supersampling = 2;
  return options;
}

TEST(HeldOutScoreTest, TheTrueSurfaceScoresHigherThanTheCoarseOne) {
  const SyntheticCapture capture(FoldedSkirtOptions());
  const SyntheticFrame frame = capture.Frame(0);
  std::vector<CalibratedImage> training, held_out;
  for (int c = 0; c < 8; ++c) {
    CalibratedImage view{capture.true_cameras()[c], capture.Image(frame, 0, c)};
    (c % 4 == 0 ? held_out : training).push_back(view);
  }
  const HeldOutScore score =
      ScoreHeldOutViews(training, held_out, {&frame.coarse, &frame.truth}, HeldOutOptions());
  ASSERT_EQ(score.views.size(), 2u);
  for (const HeldOutViewScore& view : score.views) {
    EXPECT_EQ(view.training.size(), 4u);
    EXPECT_GT(view.ncc_pixels, 1000);
    EXPECT_GT(view.surfaces[1].ncc, view.surfaces[0].ncc + 0.05) << view.camera;
    EXPECT_LT(view.surfaces[1].mad, view.surfaces[0].mad) << view.camera;
  }
  // Rendered without noise from the true surface, the warped views nearly match.
  EXPECT_GT(score.mean[1].ncc, 0.8);
  EXPECT_DOUBLE_EQ(score.mean[1].ncc,
                   0.5 * (score.views[0].surfaces[1].ncc + score.views[1].surfaces[1].ncc));
}

TEST(HeldOutScoreTest, OccludedPointsAndFlatWindowsAreNotScored) {
  const SyntheticCapture capture(FoldedSkirtOptions());
  const SyntheticFrame frame = capture.Frame(0);
  const CalibratedImage held_out{capture.true_cameras()[0], capture.Image(frame, 0, 0)};
  // The opposite camera sees the skirt's far side only: every point the held-out view sees on
  // the near side is hidden from it, so (almost) nothing is warped in.
  const CalibratedImage opposite{capture.true_cameras()[4], capture.Image(frame, 0, 4)};
  HeldOutOptions options;
  options.neighbours = 1;
  const HeldOutScore hidden = ScoreHeldOutViews({opposite}, {held_out}, {&frame.truth}, options);
  const CalibratedImage neighbour{capture.true_cameras()[1], capture.Image(frame, 0, 1)};
  const HeldOutScore seen = ScoreHeldOutViews({neighbour}, {held_out}, {&frame.truth}, options);
  // Through the open hem the far camera sees a little of the inside: a small share at most.
  EXPECT_LT(hidden.views[0].common_pixels, seen.views[0].common_pixels / 10);
  // A held-out image without any structure has no window to correlate.
  CalibratedImage flat = held_out;
  flat.image = cv::Mat(held_out.image.size(), CV_8UC3, cv::Scalar(90, 90, 90));
  const HeldOutScore none = ScoreHeldOutViews({neighbour}, {flat}, {&frame.truth}, options);
  EXPECT_EQ(none.views[0].ncc_pixels, 0);
  EXPECT_TRUE(std::isnan(none.mean[0].ncc));
  EXPECT_TRUE(std::isfinite(none.mean[0].mad));
}

TEST(HeldOutScoreTest, NearestCamerasAreOrderedByCentreDistance) {
  std::vector<Camera> cameras(4);
  for (int c = 0; c < 4; ++c) cameras[c].t = Eigen::Vector3d(-c, 0.0, 0.0);  // Centre (c, 0, 0).
  Camera target;
  target.t = Eigen::Vector3d(-2.2, 0.0, 0.0);
  EXPECT_EQ(NearestCameras(target, cameras, 3), (std::vector<int>{2, 3, 1}));
  EXPECT_EQ(NearestCameras(target, cameras, 10).size(), 4u);
}

TEST(HeldOutScoreTest, RefusesBadOptionsAndImages) {
  HeldOutOptions options;
  options.window = 6;
  ExpectErrorMentions([&] { options.Check(); }, {"HeldOutOptions::window"});
  const SyntheticCapture capture(FoldedSkirtOptions());
  const SyntheticFrame frame = capture.Frame(0);
  CalibratedImage view{capture.true_cameras()[0], capture.Image(frame, 0, 0)};
  CalibratedImage small = view;
  small.image = cv::Mat(10, 10, CV_8UC3);
  ExpectErrorMentions([&] { ScoreHeldOutViews({small}, {view}, {&frame.truth}, HeldOutOptions()); },
                      {"camera " + view.camera.name, "size"});
  ExpectErrorMentions([&] { ScoreHeldOutViews({}, {view}, {&frame.truth}, HeldOutOptions()); },
                      {"no training view"});
}

// 4 cameras of 96 x 96 around a tiny skirt; the last one is held out.
SynthOptions HeldOutRunOptions() {
  SynthOptions options = testing_util::TinyRefinableSynthOptions(1);
  options.cameras.count = 4;
  return options;
}

Config HeldOutRunConfig(const std::string& capture, const std::string& out) {
  Config config = testing_util::TinyRunConfig(capture, out, 5);
  config.validation.cameras = {"cam03"};
  config.eval.flow = "none";
  return config;
}

FrameStats FirstRecord(const std::string& out) {
  return ParseFrameStats(FileBytes(out + "/frames/000000.json"), out);
}

TEST(HeldOutRefineTest, HeldOutCamerasAreScoredButNeverUsed) {
  const OneWorkerThread one_thread;  // Byte-equal results from run to run.
  const std::string root = MakeTempDir("heldout_refine");
  const std::string capture = root + "/capture";
  GenerateSyntheticCapture(HeldOutRunOptions(), capture);
  ASSERT_TRUE(fs::exists(capture + "/images/cam03"));
  ASSERT_EQ(RunRefine(HeldOutRunConfig(capture, root + "/a")), 0);

  // The same capture with the held-out camera's image replaced by noise.
  const std::string corrupted = root + "/corrupted";
  fs::copy(capture, corrupted, fs::copy_options::recursive);
  cv::Mat noise(96, 96, CV_8UC3);
  cv::randu(noise, 0, 255);
  ASSERT_TRUE(cv::imwrite(corrupted + "/images/cam03/000000.png", noise));
  ASSERT_EQ(RunRefine(HeldOutRunConfig(corrupted, root + "/b")), 0);

  // Reference colours, displacements and energies do not change...
  EXPECT_EQ(FileBytes(root + "/a/reference_colors.txt"),
            FileBytes(root + "/b/reference_colors.txt"));
  EXPECT_EQ(FileBytes(root + "/a/k/000000.txt"), FileBytes(root + "/b/k/000000.txt"));
  const FrameStats a = FirstRecord(root + "/a"), b = FirstRecord(root + "/b");
  EXPECT_EQ(a.energy_end, b.energy_end);
  // ... but the held-out score, measured in that camera, does.
  ASSERT_TRUE(std::isfinite(a.heldout_ncc_input));
  ASSERT_TRUE(std::isfinite(a.heldout_ncc_refined));
  ASSERT_TRUE(std::isfinite(b.heldout_ncc_input));
  EXPECT_NE(a.heldout_ncc_input, b.heldout_ncc_input);
  EXPECT_GT(b.heldout_mad_input, a.heldout_mad_input);
  EXPECT_GT(a.seconds_heldout, 0.0);
  EXPECT_EQ(a.worse, a.heldout_ncc_refined < a.heldout_ncc_input || a.energy_end < a.energy_start);

  // Without held-out cameras the energy sees one camera more.
  ASSERT_EQ(RunRefine(testing_util::TinyRunConfig(capture, root + "/c", 5)), 0);
  EXPECT_NE(FileBytes(root + "/a/reference_colors.txt"),
            FileBytes(root + "/c/reference_colors.txt"));
  EXPECT_TRUE(std::isnan(FirstRecord(root + "/c").heldout_ncc_input));
  EXPECT_EQ(FirstRecord(root + "/c").seconds_heldout, 0.0);
}

TEST(HeldOutRefineTest, AWorseHeldOutScoreKeepsTheInputWhenAsked) {
  const OneWorkerThread one_thread;
  const std::string root = MakeTempDir("heldout_keep");
  const std::string capture = root + "/capture";
  // No folds: the input is the true surface, and anything that moves it makes it worse.
  SynthOptions options = HeldOutRunOptions();
  options.folds.clear();
  options.cameras.count = 6;
  GenerateSyntheticCapture(options, capture);
  // No iteration (the energy cannot get worse), then 4 cm added along every normal by the bias
  // compensation of wide Gaussians: only the held-out view can tell.
  Config config = HeldOutRunConfig(capture, root + "/run");
  config.validation.cameras = {"cam05"};
  config.refine.solver.max_iterations = 0;
  config.refine.sigma_hat = 0.04;
  config.refine.bias_compensation = true;
  Config keep = config;
  keep.output.dir = root + "/keep";
  keep.refine.keep_input_if_worse = true;
  ASSERT_EQ(RunRefine(config), 0);
  ASSERT_EQ(RunRefine(keep), 0);

  const FrameStats flagged = FirstRecord(root + "/run");
  EXPECT_EQ(flagged.energy_end, flagged.energy_start);
  EXPECT_LT(flagged.heldout_ncc_refined, flagged.heldout_ncc_input);
  EXPECT_TRUE(flagged.worse);
  EXPECT_FALSE(flagged.kept_input);
  const FrameStats kept = FirstRecord(root + "/keep");
  EXPECT_TRUE(kept.worse);
  EXPECT_TRUE(kept.kept_input);
  EXPECT_EQ(kept.heldout_ncc_refined, flagged.heldout_ncc_refined);  // As solved.
  const std::string k = FileBytes(root + "/keep/k/000000.txt");
  const size_t first_value = k.find('\n') + 1;
  ASSERT_GT(k.size(), first_value);
  EXPECT_EQ(k.find_first_of("123456789", first_value), std::string::npos)
      << "every refined displacement is 0 when the input is kept";
  EXPECT_NE(FileBytes(root + "/run/k/000000.txt").find_first_of("123456789", first_value),
            std::string::npos);
}

TEST(HeldOutRefineTest, EvalWritesHeldOutFiguresAndPictures) {
  const std::string root = MakeTempDir("heldout_eval");
  const std::string capture = root + "/capture";
  GenerateSyntheticCapture(HeldOutRunOptions(), capture);
  const Config config = HeldOutRunConfig(capture, root + "/run");
  ASSERT_EQ(RunRefine(config), 0);
  ASSERT_EQ(RunEval(config), 0);
  const YAML::Node metrics = YAML::LoadFile(root + "/run/eval/metrics.json");
  EXPECT_TRUE(std::isfinite(metrics["heldout_ncc_input"].as<double>()));
  EXPECT_TRUE(std::isfinite(metrics["heldout_ncc_refined"].as<double>()));
  EXPECT_TRUE(std::isfinite(metrics["heldout_mad_refined"].as<double>()));
  const YAML::Node views = metrics["frames"][0]["heldout"]["views"];
  ASSERT_EQ(views.size(), 1u);
  EXPECT_EQ(views[0]["camera"].as<std::string>(), "cam03");
  EXPECT_EQ(views[0]["training"].size(), 3u);
  // The stats record and eval measure the same surfaces the same way.
  const FrameStats stats = FirstRecord(root + "/run");
  EXPECT_NEAR(views[0]["ncc_input"].as<double>(), stats.heldout_ncc_input, 1e-6);
  EXPECT_NEAR(views[0]["ncc_subdivided"].as<double>(), stats.heldout_ncc_subdivided, 1e-6);
  EXPECT_NEAR(metrics["heldout_mad_subdivided"].as<double>(), stats.heldout_mad_subdivided, 1e-6);
  // The input is the coarse mesh as given, a surface of its own beside its subdivision.
  EXPECT_TRUE(std::isfinite(stats.heldout_ncc_subdivided));
  EXPECT_NE(stats.heldout_ncc_subdivided, stats.heldout_ncc_input);
  const cv::Mat picture = cv::imread(root + "/run/eval/heldout_000000_cam03.png");
  ASSERT_FALSE(picture.empty());
  EXPECT_GT(picture.cols, 4 * picture.rows / 2);  // Five panels side by side.
  const std::string report = FileBytes(root + "/run/eval/report.html");
  EXPECT_NE(report.find("Held-out cameras"), std::string::npos);
  // The comparison panels: the photo, what each mesh predicts there, their NCC maps.
  EXPECT_NE(report.find("data-panels=\"held-out frame 000000, cam03\""), std::string::npos);
  for (const std::string panel :
       {"photo (held out)", "predicted by the input", "predicted by the refined mesh",
        "NCC of the input", "NCC of the refined mesh"}) {
    EXPECT_NE(report.find("data-panel=\"" + panel + "\""), std::string::npos) << panel;
  }
  EXPECT_NE(report.find("RMS subdivided mm"), std::string::npos);
  if (FindThreeJs()) {
    EXPECT_NE(report.find("data-panel=\"truth\""), std::string::npos);
  }

  // Without ground truth: no truth panel, no tables of n/a, the held-out comparisons still there.
  fs::remove_all(capture + "/gt");
  ASSERT_EQ(RunEval(config), 0);
  const std::string without = FileBytes(root + "/run/eval/report.html");
  EXPECT_NE(without.find("No ground truth"), std::string::npos);
  EXPECT_EQ(without.find("RMS subdivided mm"), std::string::npos);
  EXPECT_EQ(without.find("data-panel=\"truth\""), std::string::npos);
  EXPECT_NE(without.find("data-panel=\"NCC of the refined mesh\""), std::string::npos);
}

TEST(HeldOutRefineTest, RefusesUnknownAndAllHeldOutCameras) {
  const std::string root = MakeTempDir("heldout_bad");
  const std::string capture = root + "/capture";
  GenerateSyntheticCapture(HeldOutRunOptions(), capture);
  Config unknown = HeldOutRunConfig(capture, root + "/unknown");
  unknown.validation.cameras = {"cam01", "cam09"};
  ExpectErrorMentions([&] { RunRefine(unknown); }, {"validation.cameras", "'cam09'", "cam00"});
  EXPECT_FALSE(fs::exists(root + "/unknown"));
  Config all = HeldOutRunConfig(capture, root + "/all");
  all.validation.cameras = {"cam00", "cam01", "cam02", "cam03"};
  ExpectErrorMentions([&] { RunRefine(all); }, {"validation.cameras", "every camera"});
  EXPECT_FALSE(fs::exists(root + "/all"));
  ExpectErrorMentions([&] { RunEval(all); }, {"validation.cameras", "every camera"});
}

TEST(HeldOutConfigTest, KeysReadAndRefuse) {
  const Config config = LoadConfig(
      "", {{"validation.cameras", "[cam1, cam2]", "--set"}, {"validation.window", "9", "--set"}});
  EXPECT_EQ(config.validation.cameras, (std::vector<std::string>{"cam1", "cam2"}));
  EXPECT_EQ(config.validation.score.window, 9);
  EXPECT_EQ(LoadConfig("", {{"validation.cameras", "cam4", "--set"}}).validation.cameras,
            std::vector<std::string>{"cam4"});
  ExpectErrorMentions(
      [] {
        LoadConfig("", {{"validation.window", "8", "--set"}});
      },
      {"validation.window", "odd"});
  ExpectErrorMentions(
      [] {
        LoadConfig("", {{"validation.cameras", "[a, [b]]", "--set"}});
      },
      {"validation.cameras"});
}

}  // namespace
}  // namespace finecap
