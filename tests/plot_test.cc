#include "finecap/util/plot.h"

#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "test_util.h"

namespace finecap {
namespace {

namespace fs = std::filesystem;
using testing_util::ExpectErrorMentions;
using testing_util::FilesIn;
using testing_util::MakeTempDir;

PlotSeries Line(const std::string& name, double slope) {
  PlotSeries series{name, {}, {}};
  for (int i = 0; i < 20; ++i) {
    series.x.push_back(i);
    series.y.push_back(1.0 + slope * i);
  }
  return series;
}

PlotOptions SmallPlot() {
  PlotOptions options;
  options.title = "Error per frame";
  options.x_label = "frame";
  options.y_label = "RMS error (m)";
  options.width = 320;
  options.height = 240;
  return options;
}

TEST(Plot, DetectsAPngTerminal) {
  const std::string terminal = PngTerminal();
  EXPECT_TRUE(terminal == "pngcairo" || terminal == "png") << terminal;
  EXPECT_EQ(PngTerminal(), terminal);
}

TEST(Plot, WritesAPngOfTheRequestedSize) {
  const std::string dir = MakeTempDir("plot_size");
  const std::string path = dir + "/error.png";
  WriteLinePlot(path, {Line("refined", 0.5), Line("coarse", 1.0)}, SmallPlot());
  const cv::Mat image = cv::imread(path, cv::IMREAD_COLOR);
  ASSERT_FALSE(image.empty());
  EXPECT_EQ(image.cols, 320);
  EXPECT_EQ(image.rows, 240);
  EXPECT_EQ(FilesIn(dir), std::vector<std::string>{"error.png"});
}

TEST(Plot, DifferentSeriesGiveDifferentImages) {
  const std::string dir = MakeTempDir("plot_differ");
  WriteLinePlot(dir + "/a.png", {Line("s", 0.5)}, SmallPlot());
  WriteLinePlot(dir + "/b.png", {Line("s", -0.5)}, SmallPlot());
  WriteLinePlot(dir + "/c.png", {Line("s", 0.5)}, SmallPlot());
  const cv::Mat a = cv::imread(dir + "/a.png"), b = cv::imread(dir + "/b.png"),
                c = cv::imread(dir + "/c.png");
  ASSERT_FALSE(a.empty() || b.empty() || c.empty());
  EXPECT_GT(cv::norm(a, b, cv::NORM_L1), 0.0);
  EXPECT_EQ(cv::norm(a, c, cv::NORM_L1), 0.0);  // The same data draws the same image.
}

TEST(Plot, SpecialCharactersInTextAreShownNotInterpreted) {
  const std::string dir = MakeTempDir("plot_text");
  const std::string marker = dir + "/injected";
  PlotOptions options = SmallPlot();
  // Quotes, a backslash, gnuplot markup, a line break and a command that must not run.
  options.title = "it's \"50%\" done \\ a^2_{x} @&\nsystem('touch " + marker + "')";
  options.x_label = "'; set output '" + dir + "/other.png";
  options.y_label = "`echo hi` $(touch " + marker + ")";
  PlotSeries series = Line("k's \"name\" # not a comment", 0.1);
  series.y[3] = std::numeric_limits<double>::quiet_NaN();  // A gap in the curve.
  options.log_y = true;
  WriteLinePlot(dir + "/text.png", {series}, options);
  EXPECT_FALSE(cv::imread(dir + "/text.png").empty());
  EXPECT_FALSE(fs::exists(marker));
  EXPECT_EQ(FilesIn(dir), std::vector<std::string>{"text.png"});
}

TEST(Plot, BadSeriesNameTheOutputFile) {
  const std::string dir = MakeTempDir("plot_bad");
  const std::string path = dir + "/bad.png";
  ExpectErrorMentions([&] { WriteLinePlot(path, {}, SmallPlot()); }, {path, "no series"});
  PlotSeries uneven = Line("uneven", 1.0);
  uneven.y.pop_back();
  ExpectErrorMentions([&] { WriteLinePlot(path, {uneven}, SmallPlot()); },
                      {path, "'uneven'", "20 x values but 19 y values"});
  ExpectErrorMentions(
      [&] {
        WriteLinePlot(path, {PlotSeries{"empty", {}, {}}}, SmallPlot());
      },
      {path, "'empty'", "no points"});
  EXPECT_TRUE(FilesIn(dir).empty());
}

TEST(Plot, GnuplotFailureNamesTheFileAndGnuplotsMessage) {
  const std::string dir = MakeTempDir("plot_fail");
  const std::string path = dir + "/fail.png";
  // Every y undefined: gnuplot refuses to plot and says why.
  PlotSeries undefined = Line("undefined", 1.0);
  for (double& y : undefined.y) y = std::numeric_limits<double>::quiet_NaN();
  ExpectErrorMentions([&] { WriteLinePlot(path, {undefined}, SmallPlot()); },
                      {path, "gnuplot failed", "undefined"});
  EXPECT_TRUE(FilesIn(dir).empty());
}

TEST(Plot, MissingGnuplotNamesTheFile) {
  const std::string path = MakeTempDir("plot_missing") + "/missing.png";
  PlotOptions options = SmallPlot();
  options.gnuplot = "/nonexistent/gnuplot";
  ExpectErrorMentions([&] { WriteLinePlot(path, {Line("s", 1.0)}, options); },
                      {path, "cannot run gnuplot"});
  EXPECT_FALSE(fs::exists(path));
}

TEST(Plot, OptionsCheckRejectsBadSizes) {
  PlotOptions options;
  options.width = 0;
  ExpectErrorMentions([&] { options.Check(); }, {"plot options", "width 0"});
  options = PlotOptions();
  options.height = 100000;
  ExpectErrorMentions([&] { options.Check(); }, {"height 100000"});
  options = PlotOptions();
  options.gnuplot.clear();
  ExpectErrorMentions([&] { options.Check(); }, {"gnuplot program"});
}

}  // namespace
}  // namespace finecap
