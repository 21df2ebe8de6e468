#include "finecap/geometry/color.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "finecap/util/error.h"

namespace finecap {
namespace {

constexpr float kInv255 = 1.0f / 255.0f;
// Radius of the HSV cone's base: makes the chroma plane span [-0.5, 0.5]^2.
constexpr double kHsvChromaRadius = 0.5;
constexpr double kLabScale = 0.01;
// Added to R + G + B (8-bit units) before dividing: dark pixels, whose chromaticity is mostly
// noise, fade towards black (0, 0, 0) instead of jumping around.
constexpr float kChromaticityDarkLevel = 3.0f * 0.05f * 255.0f;

// The chroma-plane point (0.5 * C * cos, 0.5 * C * sin) of a hue 60 * d / C degrees from its
// sector's base, for every 8-bit chroma C in [1, 255] and 0 <= d <= C. HSV's hue is the rational
// d / C of two bytes, so a table of about 33k entries gives the exact embedding without
// trigonometry per pixel; negative d and the sector's base are handled by symmetry and rotation.
class HueTable {
 public:
  HueTable() : entries_(Index(255, 255) + 1) {
    for (int chroma = 1; chroma <= 255; ++chroma) {
      for (int d = 0; d <= chroma; ++d) {
        const double angle = (M_PI / 3.0) * d / chroma;
        const double radius = kHsvChromaRadius * chroma / 255.0;
        entries_[Index(chroma, d)] = {static_cast<float>(radius * std::cos(angle)),
                                      static_cast<float>(radius * std::sin(angle))};
      }
    }
  }

  // The point for chroma `chroma` in [1, 255] and signed offset `d` in [-chroma, chroma].
  std::array<float, 2> Lookup(int chroma, int d) const {
    const std::array<float, 2>& entry = entries_[Index(chroma, std::abs(d))];
    return {entry[0], d < 0 ? -entry[1] : entry[1]};
  }

 private:
  static int Index(int chroma, int d) { return chroma * (chroma + 1) / 2 + d; }

  std::vector<std::array<float, 2>> entries_;
};

const HueTable& GetHueTable() {
  static const HueTable table;
  return table;
}

Eigen::Vector3f HsvCone(int b, int g, int r, const HueTable& table) {
  const int max = std::max(std::max(b, g), r);
  const int chroma = max - std::min(std::min(b, g), r);
  const float value = max * kInv255;
  if (chroma == 0) return Eigen::Vector3f(0.0f, 0.0f, value);

  // Hexagonal hue: the sector is named by the largest channel (red 0, green 120, blue 240
  // degrees), the offset inside it by the difference of the other two. Selects, not branches:
  // the sector of a textured image's pixels is unpredictable.
  static constexpr float kCosBase[3] = {1.0f, -0.5f, -0.5f};
  static constexpr float kSinBase[3] = {0.0f, 0.866025403784438647f, -0.866025403784438647f};
  const int sector = (max == r) ? 0 : (max == g ? 1 : 2);
  const int offset = (max == r) ? g - b : (max == g ? b - r : r - g);
  const std::array<float, 2> p = table.Lookup(chroma, offset);
  const float cos_base = kCosBase[sector], sin_base = kSinBase[sector];
  return Eigen::Vector3f(cos_base * p[0] - sin_base * p[1], sin_base * p[0] + cos_base * p[1],
                         value);
}

void ConvertToHsvCone(const cv::Vec3b* bgr, int count, cv::Vec3f* out) {
  const HueTable& table = GetHueTable();
  for (int x = 0; x < count; ++x) {
    const Eigen::Vector3f c = HsvCone(bgr[x][0], bgr[x][1], bgr[x][2], table);
    out[x] = cv::Vec3f(c.x(), c.y(), c.z());
  }
}

cv::Mat ConvertToNormalizedRgb(const cv::Mat& bgr) {
  cv::Mat rgb, out;
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  rgb.convertTo(out, CV_32FC3, kInv255);
  return out;
}

void ConvertToChromaticity(const cv::Vec3b* bgr, int count, cv::Vec3f* out) {
  for (int x = 0; x < count; ++x) {
    const float b = bgr[x][0], g = bgr[x][1], r = bgr[x][2];
    const float scale = 1.0f / (r + g + b + kChromaticityDarkLevel);
    out[x] = cv::Vec3f(r * scale, g * scale, b * scale);
  }
}

// An image converted row by row with ConvertPixels: the same values as any part converted alone.
cv::Mat ConvertRows(const cv::Mat& bgr, ColorSpace space) {
  cv::Mat out(bgr.size(), CV_32FC3);
  for (int y = 0; y < bgr.rows; ++y) {
    ConvertPixels(bgr.ptr<cv::Vec3b>(y), bgr.cols, space, out.ptr<cv::Vec3f>(y));
  }
  return out;
}

cv::Mat ConvertToLab(const cv::Mat& bgr) {
  // OpenCV's 8-bit Lab output is quantised to bytes; its float path keeps full precision.
  cv::Mat unit_bgr, lab;
  bgr.convertTo(unit_bgr, CV_32FC3, kInv255);
  cv::cvtColor(unit_bgr, lab, cv::COLOR_BGR2Lab);
  lab *= kLabScale;
  return lab;
}

cv::Mat ConvertUnchecked(const cv::Mat& bgr, ColorSpace space) {
  switch (space) {
    case ColorSpace::kHsv:
    case ColorSpace::kChromaticity:
      return ConvertRows(bgr, space);
    case ColorSpace::kNormalizedRgb:
      return ConvertToNormalizedRgb(bgr);
    case ColorSpace::kLab:
      return ConvertToLab(bgr);
  }
  throw Error("", "unknown colour space");
}

}  // namespace

const std::vector<EnumName<ColorSpace>>& EnumNames(ColorSpace) {
  static const std::vector<EnumName<ColorSpace>> names = {
      {ColorSpace::kHsv, "hsv"},
      {ColorSpace::kNormalizedRgb, "normalized_rgb"},
      {ColorSpace::kLab, "lab"},
      {ColorSpace::kChromaticity, "chromaticity"}};
  return names;
}

std::string ColorSpaceName(ColorSpace space) { return EnumToString(space); }

ColorSpace ParseColorSpace(const std::string& name, const std::string& where) {
  ColorSpace space = ColorSpace::kHsv;
  Require(StringToEnum(name, &space), where,
          "unknown colour space '" + name + "'; expected hsv, normalized_rgb, lab or chromaticity");
  return space;
}

Eigen::Vector3f ConvertColor(const cv::Vec3b& bgr, ColorSpace space) {
  if (space == ColorSpace::kHsv) return HsvCone(bgr[0], bgr[1], bgr[2], GetHueTable());
  const cv::Mat converted = ConvertUnchecked(cv::Mat(1, 1, CV_8UC3, cv::Scalar(bgr)), space);
  const cv::Vec3f c = converted.at<cv::Vec3f>(0, 0);
  return Eigen::Vector3f(c[0], c[1], c[2]);
}

bool ConvertsPixelByPixel(ColorSpace space) {
  return space == ColorSpace::kHsv || space == ColorSpace::kChromaticity;
}

void ConvertPixels(const cv::Vec3b* bgr, int count, ColorSpace space, cv::Vec3f* out) {
  switch (space) {
    case ColorSpace::kHsv:
      return ConvertToHsvCone(bgr, count, out);
    case ColorSpace::kChromaticity:
      return ConvertToChromaticity(bgr, count, out);
    case ColorSpace::kNormalizedRgb:
    case ColorSpace::kLab:
      break;
  }
  throw Error("ConvertPixels", "colour space '" + ColorSpaceName(space) +
                                   "' is converted by whole images only (ConvertImage)");
}

cv::Mat ConvertImage(const cv::Mat& bgr, ColorSpace space, const std::string& where) {
  Require(!bgr.empty(), where, "image is empty");
  Require(bgr.type() == CV_8UC3, where,
          "expected an 8-bit 3-channel BGR image, got OpenCV type " + cv::typeToString(bgr.type()));
  return ConvertUnchecked(bgr, space);
}

double ColorDistance(const Eigen::Vector3f& a, const Eigen::Vector3f& b, ColorSpace /*space*/) {
  return static_cast<double>((a - b).norm());
}

}  // namespace finecap
