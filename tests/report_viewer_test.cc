// The report seen in a browser: finecap eval's report.html of a tiny refined run with ground truth
// and a held-out camera, opened in headless Chromium by scripts/check-report.sh, must show a
// shaded mesh in every panel of the 3D view (input, refined coloured by its error, truth, refined
// coloured by its confidence) and the
// held-out comparison panels (the photo, what each mesh predicts there, their NCC maps), none
// blank. Skipped with a message where three.js is not installed or Chromium cannot be installed
// or started.
#include <sys/wait.h>

#include <cstdlib>
#include <string>

#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "eval/mesh_viewer.h"
#include "finecap/commands/commands.h"
#include "finecap/config/config.h"
#include "finecap/eval/html_report.h"
#include "finecap/synth/synth.h"
#include "test_util.h"
#include "tiny_synth.h"

namespace finecap {
namespace {

constexpr int kChromiumUnavailable = 77;  // scripts/check-report.sh's exit code.

TEST(ReportViewerTest, ChromiumShowsTruthAndHeldOutComparisons) {
  if (!FindThreeJs()) GTEST_SKIP() << "three.js not installed (Debian's libjs-three)";
  const std::string root = testing_util::MakeTempDir("report_viewer");
  GenerateSyntheticCapture(testing_util::TinyRefinableSynthOptions(2), root + "/capture");
  Config config;
  config.capture.dir = root + "/capture";
  config.output.dir = root + "/out";
  config.runtime.threads = 1;
  config.refine.solver.max_iterations = 5;
  config.refine.solver.num_threads = 1;
  config.eval.flow = "none";
  config.validation.cameras = {"cam02"};
  ASSERT_EQ(RunRefine(config), 0);
  ASSERT_EQ(RunEval(config), 0);
  const std::string command = "bash " FINECAP_SOURCE_DIR "/scripts/check-report.sh " + root +
                              "/out/eval/report.html " + root + "/shot.png > " + root +
                              "/check.log 2>&1";
  const int status = std::system(command.c_str());
  ASSERT_TRUE(WIFEXITED(status)) << command;
  const std::string log = testing_util::FileBytes(root + "/check.log");
  if (WEXITSTATUS(status) == kChromiumUnavailable) GTEST_SKIP() << log;
  EXPECT_EQ(WEXITSTATUS(status), 0) << log;
  EXPECT_NE(log.find("check-report: 3D view: input "), std::string::npos) << log;
  EXPECT_NE(log.find("; refined,_coloured_by_its_error "), std::string::npos) << log;
  EXPECT_NE(log.find("; truth "), std::string::npos) << log;
  EXPECT_NE(log.find("; refined,_coloured_by_confidence "), std::string::npos) << log;
  // Both frames' comparison rows, each with its five pictures.
  for (const std::string frame : {"000000", "000001"}) {
    SCOPED_TRACE(frame);
    const size_t row = log.find("check-report: panels held-out frame " + frame + ", cam02: ");
    ASSERT_NE(row, std::string::npos) << log;
    const std::string line = log.substr(row, log.find('\n', row) - row);
    for (const std::string panel :
         {"photo (held out) ", "predicted by the input ", "predicted by the refined mesh ",
          "NCC of the input ", "NCC of the refined mesh "}) {
      EXPECT_NE(line.find(panel), std::string::npos) << line;
    }
  }
}

// The check itself fails on a blank comparison panel (a picture of one colour), naming it.
TEST(ReportViewerTest, CheckFailsOnABlankPanel) {
  const std::string root = testing_util::MakeTempDir("report_blank_panel");
  cv::Mat texture(32, 32, CV_8UC3);
  cv::randu(texture, cv::Scalar::all(0), cv::Scalar::all(255));
  HtmlReport report("blank panel");
  report.AddSection("Held-out cameras");
  report.AddPanelRow(
      "held-out frame 000000, cam01",
      {{"photo (held out)", texture},
       {"predicted by the refined mesh", cv::Mat(32, 32, CV_8UC3, cv::Scalar(9, 9, 9))}});
  report.Write(root + "/report.html");
  const std::string command = "bash " FINECAP_SOURCE_DIR "/scripts/check-report.sh " + root +
                              "/report.html " + root + "/shot.png > " + root + "/check.log 2>&1";
  const int status = std::system(command.c_str());
  ASSERT_TRUE(WIFEXITED(status)) << command;
  const std::string log = testing_util::FileBytes(root + "/check.log");
  if (WEXITSTATUS(status) == kChromiumUnavailable) GTEST_SKIP() << log;
  EXPECT_EQ(WEXITSTATUS(status), 1) << log;
  EXPECT_NE(log.find("panel 'predicted by the refined mesh' of 'held-out frame 000000, cam01' is "
                     "blank (1 colours)"),
            std::string::npos)
      << log;
  EXPECT_EQ(log.find("panel 'photo (held out)'"), std::string::npos) << log;
}

}  // namespace
}  // namespace finecap
