#include "finecap/eval/html_report.h"

#include <cstdio>
#include <fstream>
#include <iterator>
#include <limits>
#include <regex>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "test_util.h"

namespace finecap {
namespace {

using testing_util::Base64Decode;
using testing_util::ExpectErrorMentions;
using testing_util::FileBytes;
using testing_util::MakeTempDir;
using testing_util::WriteText;

// The payloads of every data URI image in `html`, in order.
std::vector<std::string> EmbeddedImages(const std::string& html) {
  std::vector<std::string> images;
  const std::regex data_uri(R"re(src="data:image/(png|jpeg);base64,([A-Za-z0-9+/=]*)")re");
  for (auto it = std::sregex_iterator(html.begin(), html.end(), data_uri);
       it != std::sregex_iterator(); ++it) {
    images.push_back(Base64Decode((*it)[2].str()));
  }
  return images;
}

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

size_t Count(const std::string& text, const std::string& part) {
  size_t count = 0;
  for (size_t at = text.find(part); at != std::string::npos; at = text.find(part, at + 1)) ++count;
  return count;
}

cv::Mat Gradient() {
  cv::Mat image(24, 32, CV_8UC3);
  for (int y = 0; y < image.rows; ++y) {
    for (int x = 0; x < image.cols; ++x) image.at<cv::Vec3b>(y, x) = cv::Vec3b(8 * x, 10 * y, 77);
  }
  return image;
}

TEST(HtmlReport, Base64MatchesTheRfcVectors) {
  EXPECT_EQ(Base64Encode(""), "");
  EXPECT_EQ(Base64Encode("f"), "Zg==");
  EXPECT_EQ(Base64Encode("fo"), "Zm8=");
  EXPECT_EQ(Base64Encode("foo"), "Zm9v");
  EXPECT_EQ(Base64Encode("foob"), "Zm9vYg==");
  EXPECT_EQ(Base64Encode("fooba"), "Zm9vYmE=");
  EXPECT_EQ(Base64Encode("foobar"), "Zm9vYmFy");
  EXPECT_EQ(Base64Encode(std::string("\xff\xfe\x00", 3)), "//4A");
}

TEST(HtmlReport, EscapesEveryText) {
  EXPECT_EQ(EscapeHtml("a < b && c > \"d\" 'e'"),
            "a &lt; b &amp;&amp; c &gt; &quot;d&quot; &#39;e&#39;");
  HtmlReport report("<script>alert(1)</script>");
  report.AddSection("x < y");
  report.AddParagraph("Tom & \"Jerry\"");
  report.AddTable({"<b>"}, {{"</td>"}}, "caption's");
  report.AddImage(Gradient(), "\" onerror=\"alert(2)");
  const std::string html = report.Html();
  EXPECT_FALSE(Contains(html, "<script>"));
  EXPECT_FALSE(Contains(html, "<b>"));
  EXPECT_FALSE(Contains(html, "\" onerror=\""));
  EXPECT_TRUE(Contains(html, "<title>&lt;script&gt;alert(1)&lt;/script&gt;</title>"));
  EXPECT_TRUE(Contains(html, "<h2>x &lt; y</h2>"));
  EXPECT_TRUE(Contains(html, "<p>Tom &amp; &quot;Jerry&quot;</p>"));
  EXPECT_TRUE(Contains(html, "<td>&lt;/td&gt;</td>"));
  EXPECT_TRUE(Contains(html, "<caption>caption&#39;s</caption>"));
}

TEST(HtmlReport, TableHasItsRowsAndFormattedNumbers) {
  HtmlReport report("Metrics");
  report.AddSection("Displacement error");
  report.AddTable({"region", "vertices", "RMS (m)", "recovered"},
                  {{"all", 1200, 0.000123456, 0.8125},
                   {"textured", 700, 1.5e-5, TableCell::Number(0.3333333, 2)},
                   {"textureless", 0, std::numeric_limits<double>::quiet_NaN(), 1.0}});
  const std::string html = report.Html();
  EXPECT_EQ(Count(html, "<tr>"), 4u);  // Header and three rows.
  EXPECT_EQ(Count(html, "<th>"), 4u);
  EXPECT_EQ(Count(html, "<td"), 12u);
  EXPECT_TRUE(Contains(html, "<td class=\"number\">1200</td>"));
  EXPECT_TRUE(Contains(html, "<td class=\"number\">0.0001235</td>"));
  EXPECT_TRUE(Contains(html, "<td class=\"number\">1.5e-05</td>"));
  EXPECT_TRUE(Contains(html, "<td class=\"number\">0.33</td>"));
  EXPECT_TRUE(Contains(html, "<td class=\"number\">n/a</td>"));
  EXPECT_TRUE(Contains(html, "<td>textureless</td>"));
}

TEST(HtmlReport, RowOfTheWrongWidthIsRefused) {
  HtmlReport report("Metrics");
  ExpectErrorMentions(
      [&] {
        report.AddTable({"a", "b"}, {{1, 2}, {3}});
      },
      {"HTML report 'Metrics'", "table row 1 has 1 cells for 2 columns"});
}

TEST(HtmlReport, EmbeddedImagesDecodeToTheSameBytesAndPixels) {
  const std::string dir = MakeTempDir("html_images");
  const std::string png_path = dir + "/plot.png";
  ASSERT_TRUE(cv::imwrite(png_path, Gradient()));
  HtmlReport report("Images");
  report.AddImageFile(png_path, "from disk");
  report.AddImage(Gradient(), "from memory");
  const std::vector<std::string> images = EmbeddedImages(report.Html());
  ASSERT_EQ(images.size(), 2u);
  EXPECT_EQ(images[0], FileBytes(png_path));
  const cv::Mat decoded =
      cv::imdecode(std::vector<uchar>(images[1].begin(), images[1].end()), cv::IMREAD_UNCHANGED);
  ASSERT_FALSE(decoded.empty());
  EXPECT_EQ(cv::norm(decoded, Gradient(), cv::NORM_INF), 0.0);
}

TEST(HtmlReport, WrittenFileIsSelfContained) {
  const std::string dir = MakeTempDir("html_offline");
  const std::string png_path = dir + "/plot.png";
  ASSERT_TRUE(cv::imwrite(png_path, Gradient()));
  HtmlReport report("Offline");
  report.AddSection("Plots");
  report.AddImageFile(png_path, "plot");
  report.AddSection("Renders");
  report.AddImage(Gradient());
  const std::string path = dir + "/report.html";
  report.Write(path);
  const std::string html = FileBytes(path);
  EXPECT_EQ(html, report.Html());
  EXPECT_FALSE(Contains(html, "http:"));
  EXPECT_FALSE(Contains(html, "https:"));
  EXPECT_FALSE(Contains(html, "url("));
  // Links only within the page: the contents, one per section.
  EXPECT_EQ(Count(html, "href="), 2u);
  EXPECT_EQ(Count(html, "href=\"#"), 2u);
  EXPECT_EQ(Count(html, "src="), 2u);
  EXPECT_EQ(Count(html, "src=\"data:"), 2u);
  EXPECT_EQ(Count(html, "<section"), Count(html, "</section>"));
  EXPECT_EQ(Count(html, "<section"), 2u);
}

TEST(HtmlReport, ContentsLinkEverySectionByAUniqueId) {
  HtmlReport report("Contents");
  report.AddSection("3D view");
  report.AddSection("Held-out cameras");
  report.AddSection("Held-out cameras");
  report.AddSection("Confidence", "per-vertex confidence");
  const std::string html = report.Html();
  for (const std::string id :
       {"3d-view", "held-out-cameras", "held-out-cameras-2", "per-vertex-confidence"}) {
    SCOPED_TRACE(id);
    EXPECT_EQ(Count(html, "<section id=\"" + id + "\">"), 1u);
    EXPECT_EQ(Count(html, "href=\"#" + id + "\""), 1u);
  }
  EXPECT_LT(html.find("href=\"#3d-view\""), html.find("<section id=\"3d-view\">"));
  // One section needs no contents.
  HtmlReport single("Single");
  single.AddSection("Only");
  EXPECT_FALSE(Contains(single.Html(), "href="));
}

TEST(HtmlReport, PanelRowLabelsEveryPictureAndKeepsItsPixels) {
  HtmlReport report("Panels");
  cv::Mat grey(6, 5, CV_8UC1, cv::Scalar(90));
  report.AddPanelRow("held-out frame 000000, cam03",
                     {{"photo", Gradient()}, {"predicted <refined>", grey}}, "a caption");
  const std::string html = report.Html();
  EXPECT_TRUE(Contains(html, "data-panels=\"held-out frame 000000, cam03\""));
  EXPECT_TRUE(Contains(html, "data-panel=\"photo\""));
  EXPECT_TRUE(Contains(html, "data-panel=\"predicted &lt;refined&gt;\""));
  EXPECT_TRUE(Contains(html, "<figcaption>a caption</figcaption>"));
  const std::vector<std::string> images = EmbeddedImages(html);
  ASSERT_EQ(images.size(), 2u);
  const cv::Mat decoded =
      cv::imdecode(std::vector<uchar>(images[0].begin(), images[0].end()), cv::IMREAD_UNCHANGED);
  ASSERT_FALSE(decoded.empty());
  EXPECT_EQ(cv::norm(decoded, Gradient(), cv::NORM_INF), 0.0);
  ExpectErrorMentions([&] { report.AddPanelRow("row", {}); }, {"row", "no panel"});
  ExpectErrorMentions(
      [&] {
        report.AddPanelRow("row", {{"blank", cv::Mat()}});
      },
      {"blank", "empty"});
}

TEST(HtmlReport, ColorScaleRunsFromBlueToDarkRedWithItsEndsInItsUnit) {
  const std::string html = ColorScaleHtml("|k - k_true|", 0.0, 15.5, "mm");
  EXPECT_TRUE(Contains(html, "0 mm"));
  EXPECT_TRUE(Contains(html, "15.5 mm"));
  EXPECT_TRUE(Contains(html, "|k - k_true|"));
  // OpenCV's turbo map: dark blue first, dark red last.
  const size_t first = html.find("rgb("), last = html.rfind("rgb(");
  ASSERT_NE(first, std::string::npos);
  int r0, g0, b0, r1, g1, b1;
  ASSERT_EQ(std::sscanf(html.c_str() + first, "rgb(%d,%d,%d)", &r0, &g0, &b0), 3);
  ASSERT_EQ(std::sscanf(html.c_str() + last, "rgb(%d,%d,%d)", &r1, &g1, &b1), 3);
  EXPECT_GT(b0, r0);
  EXPECT_GT(r1, b1);
  ExpectErrorMentions([] { ColorScaleHtml("ncc", 1.0, -1.0, ""); }, {"ncc", "low below the high"});
}

TEST(HtmlReport, BadImagesNameTheProblem) {
  const std::string dir = MakeTempDir("html_bad");
  HtmlReport report("Bad");
  ExpectErrorMentions([&] { report.AddImageFile(dir + "/absent.png"); }, {"absent.png"});
  WriteText(dir + "/text.png", "not an image");
  ExpectErrorMentions([&] { report.AddImageFile(dir + "/text.png"); },
                      {"text.png", "not a PNG or JPEG"});
  ExpectErrorMentions([&] { report.AddImage(cv::Mat()); }, {"HTML report 'Bad'", "empty"});
  ExpectErrorMentions([&] { report.AddImage(cv::Mat(4, 4, CV_32FC1, 0.5f)); },
                      {"8- or 16-bit", "CV_32FC1"});
}

}  // namespace
}  // namespace finecap
