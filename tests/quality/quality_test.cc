// Quality tests (ctest label `quality`): the figures the README and docs/measurements.md report,
// asserted, so that a change that loses quality fails the suite instead of passing because its
// figures are finite. Each runs the built `finecap` binary as a user would (synth, refine, probe)
// on a capture small enough for about a minute on 2 cores, and reads the figures refine writes.
//
// Every bound is today's figure of the same setup (measured 2026-12-04, docs/measurements.md)
// minus a stated margin: they guard against regressions, they are not benchmarks. A margin is a
// few times the run-to-run spread of its figure (thread scheduling changes the order of sums,
// and the held-out score's pixels change with the surfaces), and well below what a regression
// such as a 100 times stronger regulariser or the plane sweep switched off costs.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <ostream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "run_finecap.h"
#include "test_util.h"

namespace finecap {
namespace {

namespace fs = std::filesystem;

// The frames every synthetic test refines (0, 1 and 2: the folds are there from frame 0, so the
// reference frame has to find them too) and the frames synth generates for them.
constexpr char kFrames[] = "0:3";
constexpr char kSynthFrames[] = "synth.num_frames=3";

using testing_util::RunFinecap;
using testing_util::RunResult;

std::string Config(const std::string& name) {
  return std::string(FINECAP_SOURCE_DIR) + "/configs/" + name;
}

// ../shared/captures next to the repository (as CI has it), or the folder FINECAP_CAPTURES names
// (a worktree elsewhere); as tests/temple_test.cc finds them.
std::string CapturesDir() {
  const char* captures = std::getenv("FINECAP_CAPTURES");
  return captures != nullptr && *captures != '\0' ? std::string(captures)
                                                  : FINECAP_SOURCE_DIR "/../shared/captures";
}

// One record of stats.jsonl per refined frame, in frame order (the file is JSON lines, which
// yaml-cpp reads as flow maps).
std::vector<YAML::Node> ReadStats(const std::string& run) {
  std::ifstream file(run + "/stats.jsonl");
  std::vector<YAML::Node> records;
  for (std::string line; std::getline(file, line);) {
    if (!line.empty()) records.push_back(YAML::Load(line));
  }
  std::sort(records.begin(), records.end(), [](const YAML::Node& a, const YAML::Node& b) {
    return a["frame"].as<std::string>() < b["frame"].as<std::string>();
  });
  return records;
}

// The synthetic capture of `config` (frames 0-2 of it, at its full size: 8 cameras of 1004 x
// 1004 take a few seconds a frame; `synth_settings` more of synth's keys), made in a new folder
// under `capture`; the folder.
std::string Synth(const std::string& name, const std::string& config,
                  const std::string& synth_settings = "") {
  const std::string root = testing_util::MakeTempDir("quality_" + name);
  const RunResult synth =
      RunFinecap("synth --config " + Config(config) + " --out " + root + "/capture --set " +
                 kSynthFrames + (synth_settings.empty() ? "" : "," + synth_settings));
  EXPECT_EQ(synth.exit_code, 0) << synth.output;
  return root;
}

// The capture Synth made in `root` refined into `root`/`run` with the defaults and `settings`
// (refine's --set); its records.
std::vector<YAML::Node> Refine(const std::string& name, const std::string& root,
                               const std::string& run = "run", const std::string& settings = "") {
  const RunResult refine =
      RunFinecap("refine --capture " + root + "/capture --out " + root + "/" + run + " --frames " +
                 kFrames + (settings.empty() ? "" : " --set " + settings));
  EXPECT_EQ(refine.exit_code, 0) << refine.output;
  std::vector<YAML::Node> records = ReadStats(root + "/" + run);
  EXPECT_EQ(records.size(), 3u) << refine.output;
  // The figures, for re-measuring the bounds (ctest -V, or the test binary itself).
  for (const YAML::Node& record : records) {
    std::printf("%s %s frame %s: %.3f mm as given, %.3f mm refined\n", name.c_str(), run.c_str(),
                record["frame"].as<std::string>().c_str(), record["rms_coarse_mm"].as<double>(),
                record["rms_refined_mm"].as<double>());
  }
  return records;
}

// Synth's capture refined with the defaults; its records.
std::vector<YAML::Node> SynthAndRefine(const std::string& name, const std::string& config,
                                       const std::string& synth_settings = "") {
  return Refine(name, Synth(name, config, synth_settings));
}

// 1 - refined / as given of one record: the share of the input's error refinement took away.
double Gain(const YAML::Node& record) {
  return 1.0 - record["rms_refined_mm"].as<double>() / record["rms_coarse_mm"].as<double>();
}

// The same over frames, RMS errors pooled as bench/synthetic_captures.sh pools them.
double PooledGain(const std::vector<YAML::Node>& records) {
  double given = 0.0, refined = 0.0;
  for (const YAML::Node& record : records) {
    given += std::pow(record["rms_coarse_mm"].as<double>(), 2);
    refined += std::pow(record["rms_refined_mm"].as<double>(), 2);
  }
  return 1.0 - std::sqrt(refined / given);
}

// synth_skirt (configs/synth_skirt.yaml): folds of 4-9 mm in every frame, frame 0 included, and
// coarse meshes without them. Today: 79.5 % of the input's RMS error recovered over frames 0-2
// (8.372 mm as given, 1.716 mm refined), each frame at least 78.6 %.
TEST(QualityTest, SkirtWithFoldsInFrameZeroRecoversTheDetail) {
  const std::vector<YAML::Node> records = SynthAndRefine("skirt", "synth_skirt.yaml");
  ASSERT_EQ(records.size(), 3u);
  // Margin 5 points: runs differ by well under one.
  EXPECT_GT(PooledGain(records), 0.745);
  for (const YAML::Node& record : records) {
    SCOPED_TRACE(record["frame"].as<std::string>());
    EXPECT_GT(Gain(record), 0.735);
    // Eight cameras see all of it well: today every vertex is refined with confidence.
    EXPECT_GE(record["confident_share"].as<double>(), 0.9);
  }
}

// The same skirt on sparse rigs (bench/camera_counts.sh): with 3 cameras 120 degrees apart no
// point has two cameras within 60 degrees, and a refinement must leave what it cannot see well
// as it was, also where its subdivision moved the input (the smoothed skirt: Loop's surface is
// 5.02 mm from the truth, the input as given 4.93 mm); with 4 it must find detail. Today
// (2026-12-05): skirt 3 cameras +1.0 % pooled, the worst frame +0.7 %, 15 % of the vertices
// refined with confidence; 4 cameras 14.9 %, the worst frame 14.6 %, 52 % with confidence; the
// smoothed skirt 3 cameras +1.0 %, the worst frame +0.3 %. Before the fallback views and the
// confidence pull all three ended worse than their input (-0.0 %, -7.0 %, -1.9 %). The printed
// skirt on 4 cameras (2026-12-07): 6.1 % pooled, the worst frame +4.8 %; before its ambiguous
// two-view starts went back to the input (SweepOptions::min_uniqueness) -6.9 %, the worst -7.7 %.
// Three cameras have no pair nearer than 120 degrees, where two views' agreement is no evidence
// (VisibilityOptions::max_pair_angle_deg; 2026-12-08): no vertex is refined with confidence, and
// the printed skirt on 3 cameras ends +0.2 % in every frame (before: -0.3 % pooled, -0.7 % in
// frame 0), the plain skirt +0.6 %, the smoothed one +2.5 %.
TEST(QualityTest, SparseRigsEndNoWorseThanTheirInput) {
  struct Rig {
    const char* name;
    const char* config;
    int cameras;
    double min_gain;  // Per frame.
    double max_confident_share;
    const char* synth_settings;  // Beside the camera count.
  };
  for (const Rig& rig :
       {Rig{"skirt_3", "synth_skirt.yaml", 3, 0.0, 0.05, ""},
        Rig{"skirt_4", "synth_skirt.yaml", 4, 0.096, 0.7, ""},  // Margin 5 points.
        Rig{"smoothed_3", "synth_skirt_smoothed.yaml", 3, 0.0, 0.05, ""},
        Rig{"printed_3", "synth_skirt.yaml", 3, 0.0, 0.05, ",synth.texture.pattern=print"},
        Rig{"printed_4", "synth_skirt.yaml", 4, 0.0, 0.7, ",synth.texture.pattern=print"}}) {
    SCOPED_TRACE(std::string(rig.name) + " cameras");
    const std::vector<YAML::Node> records =
        SynthAndRefine(rig.name, rig.config,
                       "synth.cameras.count=" + std::to_string(rig.cameras) + rig.synth_settings);
    ASSERT_EQ(records.size(), 3u);
    for (const YAML::Node& record : records) {
      SCOPED_TRACE(record["frame"].as<std::string>());
      EXPECT_GT(Gain(record), rig.min_gain);
      EXPECT_LT(record["confident_share"].as<double>(), rig.max_confident_share);
    }
  }
}

// The demo (scripts/demo.sh): configs/synth_demo.yaml (8 cameras of 512 x 512, folds in every
// frame) refined with configs/demo.yaml, which keeps every default. Today 79.3 % recovered over its
// 3 frames (8.225 mm as given, 1.700 mm refined), each frame at least 78.6 %; the demo promises at
// least 40 %.
TEST(QualityTest, DemoRecoversTheDetailWithTheDefaults) {
  const std::string root = testing_util::MakeTempDir("quality_demo");
  const RunResult synth =
      RunFinecap("synth --config " + Config("synth_demo.yaml") + " --out " + root + "/capture");
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  const RunResult refine = RunFinecap("refine --config " + Config("demo.yaml") + " --capture " +
                                      root + "/capture --out " + root + "/run");
  ASSERT_EQ(refine.exit_code, 0) << refine.output;
  const std::vector<YAML::Node> records = ReadStats(root + "/run");
  ASSERT_EQ(records.size(), 3u) << refine.output;
  for (const YAML::Node& record : records) {
    SCOPED_TRACE(record["frame"].as<std::string>());
    EXPECT_EQ(record["similarity"].as<std::string>(), "consensus");
    // Margin 5 points, as for synth_skirt.
    EXPECT_GT(Gain(record), 0.735);
  }
  EXPECT_GT(PooledGain(records), 0.743);
}

// synth_skirt_smoothed (configs/synth_skirt_smoothed.yaml): the coarse meshes are the truth
// Taubin-smoothed. Every frame must end below its input as given; today each gains at least
// 77.7 % (78.3 % pooled, 4.936 -> 1.073 mm).
TEST(QualityTest, SmoothedInputEndsBelowItsInputInEveryFrame) {
  const std::vector<YAML::Node> records = SynthAndRefine("smoothed", "synth_skirt_smoothed.yaml");
  ASSERT_EQ(records.size(), 3u);
  for (const YAML::Node& record : records) {
    SCOPED_TRACE(record["frame"].as<std::string>());
    // Margin 5 points, as for synth_skirt.
    EXPECT_GT(Gain(record), 0.727);
  }
  EXPECT_GT(PooledGain(records), 0.733);
}

// The detail stage's second pass prepared at the surface its first found
// (refine.views_follow_surface): on the smoothed skirt, whose input's folds are shallow, the views
// of the surface with the detail recover more of it than those of the surface Gaussians' surface.
// Today (2026-12-06) 82.5 % pooled against 81.4 %.
TEST(QualityTest, ViewsFoundAtTheDetailedSurfaceRecoverMore) {
  const std::string root = Synth("views", "synth_skirt_smoothed.yaml");
  const std::vector<YAML::Node> following = Refine("views", root);
  const std::vector<YAML::Node> fixed =
      Refine("views", root, "fixed_views", "refine.views_follow_surface=false");
  ASSERT_EQ(following.size(), 3u);
  ASSERT_EQ(fixed.size(), 3u);
  // Margin half the gain.
  EXPECT_GT(PooledGain(following), PooledGain(fixed) + 0.005);
}

// synth_skirt_exact (configs/synth_skirt_exact.yaml): the coarse vertices lie on the truth, the
// honest best case of an input. No frame may end worse than its input as given; today (measured
// 2026-12-05) the worst frame gains 47.2 % (47.7 % pooled, 1.279 -> 0.669 mm).
TEST(QualityTest, ExactInputEndsNoWorseInAnyFrame) {
  const std::vector<YAML::Node> records = SynthAndRefine("exact", "synth_skirt_exact.yaml");
  ASSERT_EQ(records.size(), 3u);
  // Margin 2.5 points, tighter than elsewhere: this input leaves the least to gain, so a loss
  // shows first here, and its search range shows here alone. Solved in the automatic 24 mm
  // instead of the 6 mm the plane sweep narrows it to (refine.sweep.narrow_share), it gains
  // 43.8 % (worst frame 43.3 %).
  for (const YAML::Node& record : records) {
    SCOPED_TRACE(record["frame"].as<std::string>());
    EXPECT_GT(Gain(record), 0.45);
  }
  EXPECT_GT(PooledGain(records), 0.45);
}

// synth_noisy (configs/synth_noisy.yaml): the skirt with a calibration off by half a pixel to a
// pixel in every camera, sensor noise and lens distortion. The detail stage's alignment of the
// cameras (refine.camera_alignment) takes it from 53.4 % (8.405 -> 3.917 mm, frames 0-2, as given)
// to 66.4 % (2.825 mm) today, each frame at least 65 %; without it every frame would fail.
TEST(QualityTest, CalibrationErrorIsAlignedAway) {
  const std::vector<YAML::Node> records = SynthAndRefine("noisy", "synth_noisy.yaml");
  ASSERT_EQ(records.size(), 3u);
  for (const YAML::Node& record : records) {
    SCOPED_TRACE(record["frame"].as<std::string>());
    // Margin 4 points: the alignment's own gain is 13.
    EXPECT_GT(Gain(record), 0.61);
    EXPECT_LT(record["camera_shift_px"].as<double>(), 2.0);
    EXPECT_GT(record["camera_shift_px"].as<double>(), 0.2);
  }
  EXPECT_GT(PooledGain(records), 0.62);
}

// A real capture refined with views held out (the capture's own `validation.cameras`), as
// bench/temple_heldout.sh and bench/sceaux_heldout.sh run it; the frame's record. Skipped where
// the capture is missing (CI has ../shared/captures, and fails on a skipped test).
YAML::Node HeldOutRecord(const std::string& name, const std::string& capture,
                         const std::string& config) {
  const std::string root = testing_util::MakeTempDir("quality_" + name);
  const RunResult refine =
      RunFinecap("refine --config " + config + " --capture " + capture + " --out " + root + "/run");
  EXPECT_EQ(refine.exit_code, 0) << refine.output;
  const std::vector<YAML::Node> records = ReadStats(root + "/run");
  EXPECT_EQ(records.size(), 1u) << refine.output;
  if (records.empty()) return YAML::Node();
  std::printf("%s held-out NCC: %.4f as given, %.4f refined\n", name.c_str(),
              records[0]["heldout_ncc_input"].as<double>(),
              records[0]["heldout_ncc_refined"].as<double>());
  return records[0];
}

// The Middlebury temple (16 photos of 640 x 480, a visual hull as the input; configs/temple.yaml
// holds 4 views out), whole: one frame of it takes about 13 s. Today the held-out NCC goes from
// 0.4150 (the hull as given) to 0.6507, a gain of 0.236.
TEST(QualityTest, TempleGainsInTheHeldOutViews) {
  const std::string capture = CapturesDir() + "/middlebury_temple";
  if (!fs::exists(capture + "/cameras.yaml")) {
    GTEST_SKIP() << "the Middlebury temple capture is not at " << capture;
  }
  const YAML::Node record = HeldOutRecord("temple", capture, Config("temple.yaml"));
  ASSERT_TRUE(record.IsMap());
  const double input = record["heldout_ncc_input"].as<double>();
  const double refined = record["heldout_ncc_refined"].as<double>();
  // Margin 0.03 of NCC: the runs of one day differ by under 0.01.
  EXPECT_GT(refined - input, 0.206) << input << " -> " << refined;
}

// Sceaux (8 photos and the mesh of a full photogrammetry pipeline, an input that is good already;
// its heldout.yaml holds 2 views out), whole: about 10-20 s. Today the held-out NCC goes from
// 0.8102 to 0.8360, a gain of 0.026.
TEST(QualityTest, SceauxGainsInTheHeldOutViews) {
  const std::string capture = CapturesDir() + "/openmvs_sceaux";
  if (!fs::exists(capture + "/cameras.yaml") || !fs::exists(capture + "/heldout.yaml")) {
    GTEST_SKIP() << "the Sceaux capture (cameras.yaml and heldout.yaml) is not at " << capture;
  }
  const YAML::Node record = HeldOutRecord("sceaux", capture, capture + "/heldout.yaml");
  ASSERT_TRUE(record.IsMap());
  const double input = record["heldout_ncc_input"].as<double>();
  const double refined = record["heldout_ncc_refined"].as<double>();
  // Margin 0.008 of NCC: a third of the gain; the before/after of the detail stage differed by
  // 0.0125.
  EXPECT_GT(refined - input, 0.018) << input << " -> " << refined;
}

// The figure printed as "`key`: value" on a line of its own in `output`; NaN (and a failure)
// without one.
double PrintedFigure(const std::string& output, const std::string& key) {
  const std::string line_start = "\n" + key + ": ";
  const size_t at = output.find(line_start);
  if (at == std::string::npos) {
    ADD_FAILURE() << "no " << key << " in\n" << output;
    return std::numeric_limits<double>::quiet_NaN();
  }
  return std::stod(output.substr(at + line_start.size()));
}

struct ProbeCase {
  std::string name;
  std::string config;  // configs/<config>; empty: the defaults (the consensus similarity).
  // Today's distance of the optimum from alpha = 1, of the similarity alone and of the whole
  // energy (similarity and regulariser); a negative one is not asserted.
  double similarity_distance;
  double energy_distance;
};

// The probe's alpha step: the parabola through the peak places the optimum between steps, and a
// change that moves it by less than a step is within what an unrelated change may do.
constexpr double kProbeMargin = 0.1;

// Names the case by its similarity in the test's name (instead of the struct's bytes).
void PrintTo(const ProbeCase& probe, std::ostream* os) { *os << probe.name; }

class QualityProbeTest : public testing::TestWithParam<ProbeCase> {};

// finecap probe on frame 0 of synth_skirt (8 cameras of 1004 x 1004, folds of 4-9 mm): the
// configured energy along k = alpha * k_true. An energy that describes the images well peaks at
// alpha = 1, the truth; one that prefers flatter surfaces peaks below it. Each similarity's
// optimum may come no further from 1 than today's plus kProbeMargin.
TEST_P(QualityProbeTest, OptimumNoFurtherFromTheTruthThanToday) {
  const ProbeCase& probe = GetParam();
  const std::string root = testing_util::MakeTempDir("quality_probe_" + probe.name);
  const RunResult synth = RunFinecap("synth --config " + Config("synth_skirt.yaml") + " --out " +
                                     root + "/capture --set synth.num_frames=1");
  ASSERT_EQ(synth.exit_code, 0) << synth.output;
  const RunResult run =
      RunFinecap("probe " + (probe.config.empty() ? "" : "--config " + Config(probe.config) + " ") +
                 "--capture " + root + "/capture --frame 0 --out " + root + "/probe");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  std::printf("%s", run.output.c_str());
  const double similarity = PrintedFigure(run.output, "similarity_alpha_optimum");
  EXPECT_LE(std::abs(similarity - 1.0), probe.similarity_distance + kProbeMargin) << similarity;
  if (probe.energy_distance >= 0.0) {
    const double energy = PrintedFigure(run.output, "alpha_optimum");
    EXPECT_LE(std::abs(energy - 1.0), probe.energy_distance + kProbeMargin) << energy;
  }
}

// Today's optima (similarity, energy): consensus 0.823, 0.809; surface_color 0.948, 0.911; paper
// 0.696, 0.000. The paper's energy (w_reg = 1, as printed) peaks at the input, alpha = 0: its
// regulariser outweighs the similarity everywhere, so only its similarity is guarded.
INSTANTIATE_TEST_SUITE_P(
    Similarities, QualityProbeTest,
    testing::Values(ProbeCase{"consensus", "", 0.177, 0.191},
                    ProbeCase{"surface_color", "surface_color.yaml", 0.052, 0.089},
                    ProbeCase{"paper", "paper.yaml", 0.304, -1.0}),
    [](const testing::TestParamInfo<ProbeCase>& info) { return info.param.name; });

}  // namespace
}  // namespace finecap
