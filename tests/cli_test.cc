// The command line as a user meets it: subcommands listed, bad input refused with one message
// naming the file and the problem, a non-zero exit, and no output written.
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "run_finecap.h"
#include "test_util.h"

namespace {

namespace fs = std::filesystem;

using finecap::testing_util::RunFinecap;
using finecap::testing_util::RunResult;

// The same, run from `working` with `environment` ("NAME=value ...") set.
RunResult RunFinecapIn(const fs::path& working, const std::string& environment,
                       const std::string& arguments) {
  return RunFinecap(arguments, "cd '" + working.string() + "' && " + environment + " ");
}

// Unique per process: the plain and the sanitized suites may run at the same time.
fs::path FreshFolder(const std::string& name) {
  return finecap::testing_util::MakeTempDir("cli_" + name);
}

TEST(CliTest, HelpListsTheSubcommands) {
  const RunResult result = RunFinecap("--help");
  EXPECT_EQ(result.exit_code, 0);
  for (const char* subcommand : {"synth", "refine", "probe", "info"}) {
    EXPECT_NE(result.output.find(std::string("  ") + subcommand + "\n"), std::string::npos)
        << subcommand;
  }
  EXPECT_NE(result.output.find("energy.similarity"), std::string::npos);
}

// libgomp prints the policy it took as it loads (OMP_DISPLAY_ENV): the executable's own
// choice, workers that sleep (no spinning), unless the caller chose one.
TEST(CliTest, OpenMpWorkersSleepUnlessTheCallerChoseAPolicy) {
  const RunResult own = RunFinecap("--help", "OMP_DISPLAY_ENV=verbose ");
  EXPECT_EQ(own.exit_code, 0);
  EXPECT_NE(own.output.find("GOMP_SPINCOUNT = '0'"), std::string::npos)
      << own.output.substr(0, 2000);
  const RunResult callers = RunFinecap("--help", "OMP_DISPLAY_ENV=verbose OMP_WAIT_POLICY=active ");
  EXPECT_NE(callers.output.find("OMP_WAIT_POLICY = 'ACTIVE'"), std::string::npos);
  EXPECT_EQ(callers.output.find("GOMP_SPINCOUNT = '0'"), std::string::npos);
}

TEST(CliTest, MissingCaptureFolderIsNamedAndNothingIsWritten) {
  const fs::path folder = FreshFolder("missing");
  const fs::path out = folder / "out";
  const RunResult result =
      RunFinecap("refine --capture " + (folder / "nowhere").string() + " --out " + out.string());
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.output.find((folder / "nowhere").string()), std::string::npos) << result.output;
  EXPECT_FALSE(fs::exists(out));
}

TEST(CliTest, MalformedCamerasYamlIsNamed) {
  const fs::path capture = FreshFolder("malformed");
  fs::create_directories(capture / "meshes");
  std::ofstream(capture / "cameras.yaml") << "cameras: [ {name: cam0, width: 10\n";
  const RunResult result = RunFinecap("refine --capture " + capture.string() + " --out " +
                                      (capture / ".." / "out_m").string());
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.output.find("cameras.yaml"), std::string::npos) << result.output;
  EXPECT_FALSE(fs::exists(capture / ".." / "out_m"));
}

TEST(CliTest, UnknownConfigKeyNamesFileAndKey) {
  const fs::path folder = FreshFolder("config");
  const fs::path config = folder / "bad.yaml";
  std::ofstream(config) << "energy:\n  simlarity: paper\n";
  const RunResult result = RunFinecap("refine --config " + config.string());
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.output.find("bad.yaml: key 'energy.simlarity': unknown key"), std::string::npos)
      << result.output;
}

// A 3-camera synthetic capture of 96 x 96 pixels, one frame, made by `finecap synth`.
fs::path TinyCapture(const std::string& name, int cameras = 3) {
  const fs::path capture = FreshFolder(name) / "capture";
  const RunResult result =
      RunFinecap("synth --out " + capture.string() +
                 " --set synth.num_frames=1,synth.skirt.around=16,synth.skirt.down=8,"
                 "synth.texture.width=256,synth.texture.height=128,synth.cameras.count=" +
                 std::to_string(cameras) +
                 ",synth.cameras.width=96,synth.cameras.height=96,synth.cameras.focal=300,"
                 "synth.render.supersampling=1");
  EXPECT_EQ(result.exit_code, 0) << result.output;
  return capture;
}

int CountFiles(const fs::path& folder) {
  int files = 0;
  for (const auto& entry : fs::recursive_directory_iterator(folder))
    files += entry.is_regular_file();
  return files;
}

// The number after `label` in `text`, or -1.
long NumberAfter(const std::string& text, const std::string& label) {
  const size_t at = text.find(label);
  return at == std::string::npos ? -1 : std::stol(text.substr(at + label.size()));
}

TEST(CliTest, InfoPrintsTheCaptureAndWritesNothing) {
  const fs::path capture = TinyCapture("info");
  const int files = CountFiles(capture);
  const fs::path out = capture / ".." / "out";
  const RunResult result =
      RunFinecap("info --capture " + capture.string() + " --out " + out.string());
  EXPECT_EQ(result.exit_code, 0) << result.output;
  EXPECT_FALSE(fs::exists(out));
  EXPECT_EQ(CountFiles(capture), files);
  for (const char* item :
       {"cameras: 3, read from cameras.yaml", "cam00: 96x96", "cam02: 96x96", "frames: 1",
        "mesh: 128 vertices", "after 1 subdivision level", "scene: extent", "pixel footprint",
        "model.sigma_hat", "energy.k_max", "visibility.depth_tolerance", "(auto)",
        "vertices refined:", "pairs of Gaussians", "forecast per frame: peak memory"}) {
    EXPECT_NE(result.output.find(item), std::string::npos) << item << "\n" << result.output;
  }
  EXPECT_GT(NumberAfter(result.output, "forecast per frame: peak memory "), 0) << result.output;
  // A length set on the command line is used and said to be set.
  const RunResult set =
      RunFinecap("info --capture " + capture.string() + " --set model.sigma_hat=0.0123");
  EXPECT_NE(set.output.find("model.sigma_hat 12.3 mm (set)"), std::string::npos) << set.output;
}

// How many times libgomp loaded in a run with OMP_DISPLAY_ENV (once per process), and the wait
// policy it showed last.
std::pair<int, std::string> WaitPolicies(const RunResult& result) {
  const std::string key = "OMP_WAIT_POLICY = '";
  int count = 0;
  std::string last;
  for (size_t at = result.output.find(key); at != std::string::npos;
       at = result.output.find(key, at + 1)) {
    ++count;
    const size_t begin = at + key.size();
    last = result.output.substr(begin, result.output.find('\'', begin) - begin);
  }
  return {count, last};
}

// finecap's OpenMP workers sleep, unless the caller chose a policy, and libgomp loads once.
TEST(CliTest, SleepingWorkersUnlessAPolicyIsSet) {
  const RunResult plain = RunFinecap("--help", "OMP_DISPLAY_ENV=true ");
  EXPECT_EQ(WaitPolicies(plain), std::make_pair(1, std::string("PASSIVE"))) << plain.output;
  const RunResult chosen = RunFinecap("--help", "OMP_DISPLAY_ENV=true OMP_WAIT_POLICY=active ");
  EXPECT_EQ(WaitPolicies(chosen), std::make_pair(1, std::string("ACTIVE"))) << chosen.output;
}

TEST(CliTest, InfoForecastsTheMemoryRefinePrints) {
  const fs::path capture = TinyCapture("info_forecast");
  const RunResult info = RunFinecap("info --capture " + capture.string());
  const fs::path out = capture / ".." / "out";
  const RunResult refine = RunFinecap("refine --capture " + capture.string() + " --out " +
                                      out.string() + " --set solver.max_iterations=1");
  ASSERT_EQ(refine.exit_code, 0) << refine.output;
  const long forecast = NumberAfter(info.output, "forecast per frame: peak memory ");
  EXPECT_GT(forecast, 0) << info.output;
  EXPECT_EQ(NumberAfter(refine.output, "expected peak memory "), forecast) << refine.output;
}

// A run whose memory forecast exceeds runtime.max_memory_mb is refused before it starts: one
// message with the forecast and what to lower, exit 1, no output folder. Within the limit it runs.
TEST(CliTest, RefineRefusesARunForecastAboveTheMemoryLimit) {
  const fs::path capture = TinyCapture("memory_limit");
  const fs::path out = capture / ".." / "out";
  const RunResult refused = RunFinecap("refine --capture " + capture.string() + " --out " +
                                       out.string() + " --set runtime.max_memory_mb=1");
  EXPECT_EQ(refused.exit_code, 1) << refused.output;
  for (const char* part : {"finecap: error: runtime.max_memory_mb: the forecast peak memory of "
                           "this run, ",
                           "MB, exceeds the 1 MB it is allowed", "model.subdivision_levels",
                           "the size of the images", "or raise runtime.max_memory_mb"}) {
    EXPECT_NE(refused.output.find(part), std::string::npos) << part << "\n" << refused.output;
  }
  EXPECT_EQ(refused.output.find("expected peak memory"), std::string::npos) << refused.output;
  EXPECT_FALSE(fs::exists(out));

  const RunResult within =
      RunFinecap("refine --capture " + capture.string() + " --out " + out.string() +
                 " --set runtime.max_memory_mb=100000,solver.max_iterations=1");
  EXPECT_EQ(within.exit_code, 0) << within.output;
  EXPECT_TRUE(fs::exists(out / "stats.jsonl"));
}

// A limit between the forecast and the forecast at the widest search range the plane sweep may
// take runs, with a warning that names the range, the figures and what to lower.
TEST(CliTest, RefineWarnsWhenTheWidestSearchRangeMightNotFit) {
  const fs::path capture = TinyCapture("widest_range");
  // Without the detail stage, whose peak the tiny capture's widest range would not pass.
  const std::string first_stage_only = "energy.consensus.sample_spacing=0";
  const RunResult info =
      RunFinecap("info --capture " + capture.string() + " --set " + first_stage_only);
  ASSERT_EQ(info.exit_code, 0) << info.output;
  const long forecast = NumberAfter(info.output, "forecast per frame: peak memory ");
  const long widest = NumberAfter(info.output, "(up to ");
  ASSERT_GT(widest, forecast + 2) << info.output;
  const std::string limit = std::to_string((forecast + widest) / 2);
  const RunResult refine = RunFinecap(
      "refine --capture " + capture.string() + " --out " + (capture / ".." / "out").string() +
      " --set " + first_stage_only + ",solver.max_iterations=1,runtime.max_memory_mb=" + limit);
  EXPECT_EQ(refine.exit_code, 0) << refine.output;
  for (const std::string& part :
       {std::string("warning: a frame whose plane sweep widens its search range to "),
        "would need about " + std::to_string(widest) + " MB, more than the " + limit + " MB",
        std::string("refine.sweep.max_widenings")}) {
    EXPECT_NE(refine.output.find(part), std::string::npos) << part << "\n" << refine.output;
  }
}

// Refine's summary states the share of vertices refined with confidence, and says so when a
// capture cannot be refined usefully: three cameras 120 degrees apart never give a point a third
// camera within the fallback view angle, so asking for three leaves no vertex with confidence. The
// run still succeeds.
TEST(CliTest, RefineSaysHowMuchItRefinedWithConfidence) {
  const fs::path capture = TinyCapture("confidence");
  const std::string out = (FreshFolder("confidence") / "out").string();
  const RunResult usual = RunFinecap("refine --capture " + capture.string() + " --out " + out +
                                     "_usual --set solver.max_iterations=2");
  EXPECT_EQ(usual.exit_code, 0) << usual.output;
  EXPECT_NE(usual.output.find("Refined with confidence: "), std::string::npos) << usual.output;

  const RunResult starved =
      RunFinecap("refine --capture " + capture.string() + " --out " + out +
                 "_starved --set solver.max_iterations=2,energy.consensus.min_cameras=3");
  EXPECT_EQ(starved.exit_code, 0) << starved.output;
  EXPECT_NE(starved.output.find("Refined with confidence: 0 %"), std::string::npos)
      << starved.output;
  EXPECT_NE(starved.output.find("Too few views for this capture to be refined usefully"),
            std::string::npos)
      << starved.output;
}

TEST(CliTest, InfoWarnsAboutVerticesNoCameraSees) {
  const fs::path capture = TinyCapture("info_unseen");
  const RunResult result =
      RunFinecap("info --capture " + capture.string() +
                 " --set visibility.max_view_angle_deg=1,visibility.fallback_view_angle_deg=2");
  EXPECT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("warning: "), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("seen by no camera within visibility.fallback_view_angle_deg 2"),
            std::string::npos)
      << result.output;
}

// Before a run, info says how much of the surface its cameras let be refined with confidence,
// and warns when that is less than half: three cameras on a ring, 120 degrees apart, see no point
// from two directions near enough to each other; eight, 45 degrees apart, see every one.
TEST(CliTest, InfoWarnsWhenTheCamerasAreTooFewToRefineUsefully) {
  const std::string warning = "warning: too few views for this capture to be refined usefully";
  const RunResult three = RunFinecap("info --capture " + TinyCapture("info_three").string());
  EXPECT_EQ(three.exit_code, 0) << three.output;
  EXPECT_NE(three.output.find(", 0 seen well enough by enough cameras"), std::string::npos)
      << three.output;
  EXPECT_NE(three.output.find(warning), std::string::npos) << three.output;

  const RunResult eight = RunFinecap("info --capture " + TinyCapture("info_eight", 8).string());
  EXPECT_EQ(eight.exit_code, 0) << eight.output;
  const long refined = NumberAfter(eight.output, "vertices refined: ");
  EXPECT_GT(refined, 0) << eight.output;
  EXPECT_EQ(NumberAfter(eight.output, "seen by no camera, "), refined) << eight.output;
  EXPECT_EQ(eight.output.find(warning), std::string::npos) << eight.output;
}

// Without --out the probe writes into a new folder under $TMPDIR, and nothing into the folder it
// is run from.
TEST(CliTest, ProbeWithoutOutWritesNothingIntoTheCurrentDirectory) {
  const fs::path capture = TinyCapture("probe");
  const fs::path working = capture.parent_path() / "working";
  const fs::path temp = capture.parent_path() / "tmp";
  fs::create_directories(working);
  fs::create_directories(temp);
  const RunResult result =
      RunFinecapIn(working, "TMPDIR=" + temp.string(),
                   "probe --capture " + capture.string() + " --set runtime.threads=1");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_TRUE(fs::is_empty(working));
  const std::string prefix = "plot: " + (temp / "finecap-probe-").string();
  const size_t plot = result.output.find(prefix);
  ASSERT_NE(plot, std::string::npos) << result.output;
  const std::string plot_path =
      result.output.substr(plot + 6, result.output.find('\n', plot) - plot - 6);
  EXPECT_TRUE(fs::is_regular_file(plot_path)) << plot_path;
  EXPECT_TRUE(fs::is_regular_file(fs::path(plot_path).parent_path() / "reference_colors.txt"));
}

TEST(CliTest, UnknownSubcommandAndBadOverrideAreRefused) {
  EXPECT_EQ(RunFinecap("refin").exit_code, 2);
  const RunResult result = RunFinecap("refine --set solver.max_iterations=many");
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.output.find("solver.max_iterations"), std::string::npos) << result.output;
}

}  // namespace
