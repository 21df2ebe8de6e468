#include "finecap/eval/html_report.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>

#include <opencv2/imgproc.hpp>

#include "finecap/util/atomic_file.h"
#include "finecap/util/error.h"
#include "util/image_codec.h"
#include "util/io_util.h"

namespace finecap {
namespace {

constexpr char kStyle[] = R"(
body { font-family: -apple-system, "Segoe UI", Helvetica, Arial, sans-serif; color: #222;
       max-width: 1100px; margin: 2em auto; padding: 0 1em; line-height: 1.45; }
h1 { border-bottom: 2px solid #446; padding-bottom: 0.2em; }
h2 { color: #334; margin-top: 1.6em; }
table { border-collapse: collapse; margin: 1em 0; font-size: 0.95em; }
caption { caption-side: top; text-align: left; font-weight: bold; padding-bottom: 0.3em; }
th, td { border: 1px solid #ccd; padding: 0.3em 0.7em; }
th { background: #eef; }
tr:nth-child(even) td { background: #f8f8fc; }
td.number { text-align: right; font-variant-numeric: tabular-nums; }
figure { margin: 1em 0; }
figure img { max-width: 100%; border: 1px solid #ddd; }
figcaption { color: #555; font-size: 0.9em; }
nav.contents { font-size: 0.95em; }
nav.contents a { margin-right: 1.2em; }
figure.panels > div.row { display: flex; flex-wrap: wrap; gap: 6px; align-items: flex-end; }
figure.panels div.panel { flex: 1 1 0; min-width: 120px; text-align: center; }
figure.panels div.panel div { font-size: 0.85em; font-weight: bold; color: #334; }
figure.panels div.panel img { width: 100%; image-rendering: pixelated; }
div.color-scale { display: flex; align-items: center; gap: 0.6em; font-size: 0.9em;
                  margin: 0.4em 0; }
div.color-scale .bar { width: 240px; height: 14px; border: 1px solid #889; }
)";

// Colour stops of the legend's bar: enough that the CSS gradient follows the turbo map closely.
constexpr int kColorScaleStops = 17;

bool StartsWith(const std::string& bytes, const std::string& prefix) {
  return bytes.compare(0, prefix.size(), prefix) == 0;
}

// The MIME type of an image judged by its signature; empty when it is neither PNG nor JPEG.
std::string ImageMimeType(const std::string& bytes) {
  if (StartsWith(bytes, std::string("\x89PNG\r\n\x1a\n", 8))) return "image/png";
  if (StartsWith(bytes, "\xff\xd8\xff")) return "image/jpeg";
  return "";
}

// An id for an HTML element made of `text`: lower-case letters and digits, runs of anything else
// as one '-'.
std::string IdOf(const std::string& text) {
  std::string id;
  for (char c : text) {
    if (std::isalnum(static_cast<unsigned char>(c))) {
      id += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    } else if (!id.empty() && id.back() != '-') {
      id += '-';
    }
  }
  while (!id.empty() && id.back() == '-') id.pop_back();
  return id.empty() ? "section" : id;
}

std::string LegendNumber(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.3g", value);
  return buffer;
}

}  // namespace

std::string EscapeHtml(const std::string& text) {
  std::string escaped;
  escaped.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&':
        escaped += "&amp;";
        break;
      case '<':
        escaped += "&lt;";
        break;
      case '>':
        escaped += "&gt;";
        break;
      case '"':
        escaped += "&quot;";
        break;
      case '\'':
        escaped += "&#39;";
        break;
      default:
        escaped += c;
    }
  }
  return escaped;
}

std::string Base64Encode(const std::string& bytes) {
  static constexpr char kAlphabet[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string encoded;
  encoded.reserve((bytes.size() + 2) / 3 * 4);
  for (size_t i = 0; i < bytes.size(); i += 3) {
    const size_t available = std::min<size_t>(3, bytes.size() - i);
    uint32_t group = 0;
    for (size_t j = 0; j < 3; ++j) {
      const uint32_t byte = j < available ? static_cast<unsigned char>(bytes[i + j]) : 0;
      group = (group << 8) | byte;
    }
    // `available` bytes fill available + 1 six-bit digits; '=' pads the group to four.
    for (size_t digit = 0; digit < 4; ++digit) {
      encoded += digit <= available ? kAlphabet[(group >> (18 - 6 * digit)) & 0x3f] : '=';
    }
  }
  return encoded;
}

std::string ColorScaleHtml(const std::string& title, double low, double high,
                           const std::string& unit) {
  Require(std::isfinite(low) && std::isfinite(high) && low < high, "colour scale '" + title + "'",
          "needs finite ends, the low below the high, got " + std::to_string(low) + " and " +
              std::to_string(high));
  cv::Mat levels(1, kColorScaleStops, CV_8U), bgr;
  for (int i = 0; i < kColorScaleStops; ++i) {
    levels.at<unsigned char>(0, i) =
        cv::saturate_cast<unsigned char>(255.0 * i / (kColorScaleStops - 1));
  }
  cv::applyColorMap(levels, bgr, cv::COLORMAP_TURBO);
  std::string gradient = "linear-gradient(to right";
  for (int i = 0; i < kColorScaleStops; ++i) {
    const cv::Vec3b pixel = bgr.at<cv::Vec3b>(0, i);
    gradient += ", rgb(" + std::to_string(pixel[2]) + "," + std::to_string(pixel[1]) + "," +
                std::to_string(pixel[0]) + ")";
  }
  gradient += ")";
  const std::string suffix = unit.empty() ? "" : " " + EscapeHtml(unit);
  return "<div class=\"color-scale\" data-low=\"" + LegendNumber(low) + "\" data-high=\"" +
         LegendNumber(high) + "\"><span>" + EscapeHtml(title) + "</span><span>" +
         LegendNumber(low) + suffix + "</span><span class=\"bar\" style=\"background: " + gradient +
         ";\"></span><span>" + LegendNumber(high) + suffix + "</span></div>\n";
}

TableCell TableCell::Number(double number, int significant_digits) {
  return TableCell(FormatNumber(number, significant_digits), true);
}

std::string TableCell::FormatNumber(double number, int significant_digits) {
  if (!std::isfinite(number)) return "n/a";
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.*g", std::clamp(significant_digits, 1, 17), number);
  return buffer;
}

HtmlReport::HtmlReport(const std::string& title) : title_(title) {}

std::string HtmlReport::Where() const { return "HTML report '" + title_ + "'"; }

void HtmlReport::AddSection(const std::string& heading, const std::string& id) {
  if (section_open_) body_ += "</section>\n";
  std::string anchor = IdOf(id.empty() ? heading : id);
  // Ids stay unique when two sections share a heading.
  for (int n = 2; std::any_of(contents_.begin(), contents_.end(),
                              [&](const auto& entry) { return entry.first == anchor; });
       ++n) {
    anchor = IdOf(id.empty() ? heading : id) + "-" + std::to_string(n);
  }
  contents_.push_back({anchor, heading});
  body_ += "<section id=\"" + anchor + "\">\n<h2>" + EscapeHtml(heading) + "</h2>\n";
  section_open_ = true;
}

void HtmlReport::AddParagraph(const std::string& text) {
  body_ += "<p>" + EscapeHtml(text) + "</p>\n";
}

void HtmlReport::AddTable(const std::vector<std::string>& header,
                          const std::vector<std::vector<TableCell>>& rows,
                          const std::string& caption) {
  for (size_t r = 0; r < rows.size(); ++r) {
    Require(rows[r].size() == header.size(), Where(),
            "table row " + std::to_string(r) + " has " + std::to_string(rows[r].size()) +
                " cells for " + std::to_string(header.size()) + " columns");
  }
  std::string table = "<table>\n";
  if (!caption.empty()) table += "<caption>" + EscapeHtml(caption) + "</caption>\n";
  table += "<thead><tr>";
  for (const std::string& name : header) table += "<th>" + EscapeHtml(name) + "</th>";
  table += "</tr></thead>\n<tbody>\n";
  for (const std::vector<TableCell>& row : rows) {
    table += "<tr>";
    for (const TableCell& cell : row) {
      table +=
          (cell.is_number() ? "<td class=\"number\">" : "<td>") + EscapeHtml(cell.text()) + "</td>";
    }
    table += "</tr>\n";
  }
  body_ += table + "</tbody>\n</table>\n";
}

void HtmlReport::AddImageFile(const std::string& path, const std::string& caption) {
  const std::string bytes = internal::ReadWholeFile(path);
  const std::string mime_type = ImageMimeType(bytes);
  Require(!mime_type.empty(), path, "not a PNG or JPEG image");
  AddEmbeddedImage(mime_type, bytes, caption);
}

void HtmlReport::AddImage(const cv::Mat& image, const std::string& caption) {
  Require(!image.empty(), Where(), "an image to embed is empty");
  const int depth = image.depth(), channels = image.channels();
  Require((depth == CV_8U || depth == CV_16U) && (channels == 1 || channels == 3 || channels == 4),
          Where(),
          "an image to embed must be 8- or 16-bit with 1, 3 or 4 channels, not type " +
              cv::typeToString(image.type()));
  AddEmbeddedImage("image/png", internal::EncodePng(image, Where()), caption);
}

void HtmlReport::AddPanelRow(const std::string& name, const std::vector<ReportPanel>& panels,
                             const std::string& caption) {
  Require(!panels.empty(), Where(), "a row of panels '" + name + "' has no panel");
  std::string row =
      "<figure class=\"panels\" data-panels=\"" + EscapeHtml(name) + "\"><div class=\"row\">";
  for (const ReportPanel& panel : panels) {
    Require(!panel.image.empty(), Where(),
            "panel '" + panel.label + "' of '" + name + "' has an empty picture");
    Require(panel.image.depth() == CV_8U &&
                (panel.image.channels() == 1 || panel.image.channels() == 3),
            Where(), "panel '" + panel.label + "' of '" + name + "' must be 8-bit grey or BGR");
    row += "<div class=\"panel\"><div>" + EscapeHtml(panel.label) + "</div><img alt=\"" +
           EscapeHtml(name + ": " + panel.label) + "\" data-panel=\"" + EscapeHtml(panel.label) +
           "\" src=\"data:image/png;base64," +
           Base64Encode(internal::EncodePng(panel.image, Where())) + "\"></div>";
  }
  row += "</div>";
  if (!caption.empty()) row += "<figcaption>" + EscapeHtml(caption) + "</figcaption>";
  body_ += row + "</figure>\n";
}

void HtmlReport::AddRawHtml(const std::string& html) { body_ += html; }

void HtmlReport::AddEmbeddedImage(const std::string& mime_type, const std::string& bytes,
                                  const std::string& caption) {
  body_ += "<figure><img alt=\"" + EscapeHtml(caption) + "\" src=\"data:" + mime_type + ";base64," +
           Base64Encode(bytes) + "\">";
  if (!caption.empty()) body_ += "<figcaption>" + EscapeHtml(caption) + "</figcaption>";
  body_ += "</figure>\n";
}

std::string HtmlReport::Html() const {
  return "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>" +
         EscapeHtml(title_) + "</title>\n<style>" + kStyle + "</style>\n</head>\n<body>\n<h1>" +
         EscapeHtml(title_) + "</h1>\n" + Contents() + body_ +
         (section_open_ ? "</section>\n" : "") + "</body>\n</html>\n";
}

std::string HtmlReport::Contents() const {
  if (contents_.size() < 2) return "";
  std::string contents = "<nav class=\"contents\">";
  for (const auto& [id, heading] : contents_) {
    contents += "<a href=\"#" + id + "\">" + EscapeHtml(heading) + "</a>";
  }
  return contents + "</nav>\n";
}

void HtmlReport::Write(const std::string& path) const { WriteTextFileAtomically(path, Html()); }

}  // namespace finecap
