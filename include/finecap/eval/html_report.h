// A self-contained HTML report: one file with its style and images inside, readable offline and
// easy to send around (the evaluation's summary of metrics, plots and renders).
#ifndef FINECAP_EVAL_HTML_REPORT_H_
#define FINECAP_EVAL_HTML_REPORT_H_

#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

namespace finecap {

// `text` with the characters that HTML gives meaning to (& < > " ') written as entities, safe
// both between tags and inside attribute values.
std::string EscapeHtml(const std::string& text);

// Standard base64 (RFC 4648, alphabet A-Z a-z 0-9 + /, '=' padding) of arbitrary bytes.
std::string Base64Encode(const std::string& bytes);

// A colour scale legend as an HTML fragment: a bar of OpenCV's turbo map (the colours of
// HeatMapColors, evaluation.h) from `low` (blue) to `high` (dark red), its ends and middle labelled
// in `unit`, after `title`. Throws Error unless low < high, both finite.
std::string ColorScaleHtml(const std::string& title, double low, double high,
                           const std::string& unit);

// One picture of a row of panels (HtmlReport::AddPanelRow): an image and the label over it.
struct ReportPanel {
  std::string label;
  cv::Mat image;  // 8-bit BGR or grey.
};

// One table cell: text shown as it is, or a number. Numbers are right-aligned; an integer is
// shown in full, any other number with `significant_digits` significant digits (default 4, as
// printf's %g), and a non-finite number as "n/a" (e.g. an ErrorStats of an empty region).
class TableCell {
 public:
  TableCell(const char* text) : text_(text) {}         // NOLINT: implicit by design.
  TableCell(const std::string& text) : text_(text) {}  // NOLINT
  template <typename Number, typename = std::enable_if_t<std::is_arithmetic_v<Number> &&
                                                         !std::is_same_v<Number, bool>>>
  TableCell(Number number)  // NOLINT
      : text_(std::is_integral_v<Number> ? std::to_string(number)
                                         : FormatNumber(static_cast<double>(number), 4)),
        is_number_(true) {}

  // A number with a chosen count of significant digits (1..17).
  static TableCell Number(double number, int significant_digits);

  const std::string& text() const { return text_; }
  bool is_number() const { return is_number_; }

 private:
  static std::string FormatNumber(double number, int significant_digits);
  TableCell(std::string text, bool is_number) : text_(std::move(text)), is_number_(is_number) {}

  std::string text_;
  bool is_number_ = false;
};

// Builds the report top to bottom, then writes it. All text is HTML-escaped: a caption or a
// file name can hold any character. Images are embedded as base64 data URIs, so the file refers
// to nothing outside itself.
class HtmlReport {
 public:
  // `title` is the page title and the top heading.
  explicit HtmlReport(const std::string& title);

  // Starts a new section under `heading`; what follows belongs to it. The section is listed in
  // the contents at the top of the page, linked by `id` (default: made of the heading).
  void AddSection(const std::string& heading, const std::string& id = "");
  void AddParagraph(const std::string& text);
  // A table with one header row. Throws Error when a row's cell count differs from the
  // header's.
  void AddTable(const std::vector<std::string>& header,
                const std::vector<std::vector<TableCell>>& rows, const std::string& caption = "");
  // Embeds a PNG or JPEG file as it is (its bytes, not re-encoded). Throws Error naming the
  // file when it is missing or neither PNG nor JPEG.
  void AddImageFile(const std::string& path, const std::string& caption = "");
  // Embeds an 8- or 16-bit image with 1, 3 (BGR, OpenCV's order) or 4 channels, PNG-encoded.
  // Throws Error when it is empty or of another type.
  void AddImage(const cv::Mat& image, const std::string& caption = "");
  // Pictures side by side, each under its label, with one caption under the row: the same view
  // seen in several ways (a photo beside what two meshes predict of it). The row is marked
  // `class="panels" data-panels="<name>"` and each picture `data-panel="<label>"`, so that a
  // browser test can find them. Throws Error when `panels` is empty or a picture is empty or not
  // 8-bit grey or BGR.
  void AddPanelRow(const std::string& name, const std::vector<ReportPanel>& panels,
                   const std::string& caption = "");
  // Inserts `html` as it is, not escaped: for generated fragments such as the 3D viewer
  // (mesh_viewer.h). The caller vouches that it is well formed and self-contained.
  void AddRawHtml(const std::string& html);

  // The whole document.
  std::string Html() const;
  // Writes Html() to `path` atomically (see atomic_file.h). Throws Error naming the file.
  void Write(const std::string& path) const;

 private:
  void AddEmbeddedImage(const std::string& mime_type, const std::string& bytes,
                        const std::string& caption);
  std::string Where() const;
  // Links to the sections, in order; empty with fewer than two.
  std::string Contents() const;

  std::string title_;
  std::string body_;
  std::vector<std::pair<std::string, std::string>> contents_;  // Section id, heading.
  bool section_open_ = false;
};

}  // namespace finecap

#endif  // FINECAP_EVAL_HTML_REPORT_H_
