#include "finecap/eval/html_report.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>

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
)";

bool StartsWith(const std::string& bytes, const std::string& prefix) {
  return bytes.compare(0, prefix.size(), prefix) == 0;
}

// The MIME type of an image judged by its signature; empty when it is neither PNG nor JPEG.
std::string ImageMimeType(const std::string& bytes) {
  if (StartsWith(bytes, std::string("\x89PNG\r\n\x1a\n", 8))) return "image/png";
  if (StartsWith(bytes, "\xff\xd8\xff")) return "image/jpeg";
  return "";
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

void HtmlReport::AddSection(const std::string& heading) {
  if (section_open_) body_ += "</section>\n";
  body_ += "<section>\n<h2>" + EscapeHtml(heading) + "</h2>\n";
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
         EscapeHtml(title_) + "</h1>\n" + body_ + (section_open_ ? "</section>\n" : "") +
         "</body>\n</html>\n";
}

void HtmlReport::Write(const std::string& path) const { WriteTextFileAtomically(path, Html()); }

}  // namespace finecap
