#include "finecap/geometry/color.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "finecap/util/error.h"

namespace finecap {
namespace {

constexpr double kDegree = M_PI / 180.0;

// The HSV cone from OpenCV's float HSV conversion (hue in degrees, S and V in [0, 1]): an
// independent route to the embedding that color.cc computes from a table.
Eigen::Vector3f ReferenceHsvCone(const cv::Vec3b& bgr) {
  cv::Mat unit_bgr, hsv;
  cv::Mat(1, 1, CV_8UC3, cv::Scalar(bgr)).convertTo(unit_bgr, CV_32FC3, 1.0 / 255.0);
  cv::cvtColor(unit_bgr, hsv, cv::COLOR_BGR2HSV);
  const cv::Vec3f h_s_v = hsv.at<cv::Vec3f>(0, 0);
  const double chroma = h_s_v[1] * h_s_v[2];
  return Eigen::Vector3f(0.5 * chroma * std::cos(h_s_v[0] * kDegree),
                         0.5 * chroma * std::sin(h_s_v[0] * kDegree), h_s_v[2]);
}

cv::Vec3b RandomBgr(std::mt19937* rng) {
  std::uniform_int_distribution<int> byte(0, 255);
  return cv::Vec3b(byte(*rng), byte(*rng), byte(*rng));
}

const ColorSpace kAllSpaces[] = {ColorSpace::kHsv, ColorSpace::kNormalizedRgb, ColorSpace::kLab};

TEST(ColorTest, NamesRoundTrip) {
  for (ColorSpace space : kAllSpaces) {
    EXPECT_EQ(ParseColorSpace(ColorSpaceName(space), "config.yaml"), space);
  }
  EXPECT_EQ(ColorSpaceName(ColorSpace::kNormalizedRgb), "normalized_rgb");
}

TEST(ColorTest, UnknownNameNamesKeyAndValue) {
  try {
    ParseColorSpace("HSL", "demo.yaml: image_gaussians.color_space");
    FAIL() << "no error for an unknown colour space";
  } catch (const Error& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("demo.yaml: image_gaussians.color_space"), std::string::npos) << message;
    EXPECT_NE(message.find("'HSL'"), std::string::npos) << message;
    EXPECT_NE(message.find("normalized_rgb"), std::string::npos) << message;
  }
}

TEST(ColorTest, HsvConeOfPrimariesAndGreys) {
  const double s = std::sqrt(3.0) / 4.0;  // 0.5 * sin(120 degrees).
  const struct {
    cv::Vec3b bgr;
    Eigen::Vector3f expected;
  } cases[] = {
      {{0, 0, 255}, {0.5f, 0.0f, 1.0f}},                      // red, 0 degrees
      {{0, 255, 0}, {-0.25f, static_cast<float>(s), 1.0f}},   // green, 120 degrees
      {{255, 0, 0}, {-0.25f, static_cast<float>(-s), 1.0f}},  // blue, 240 degrees
      {{0, 255, 255}, {0.25f, static_cast<float>(s), 1.0f}},  // yellow, 60 degrees
      {{0, 0, 128}, {0.5f * 128 / 255, 0.0f, 128.0f / 255}},  // dark red: chroma scales
      {{255, 255, 255}, {0.0f, 0.0f, 1.0f}},
      {{77, 77, 77}, {0.0f, 0.0f, 77.0f / 255}},
      {{0, 0, 0}, {0.0f, 0.0f, 0.0f}},
  };
  for (const auto& c : cases) {
    const Eigen::Vector3f actual = ConvertColor(c.bgr, ColorSpace::kHsv);
    EXPECT_LT((actual - c.expected).norm(), 1e-6) << c.bgr << " -> " << actual.transpose();
  }
}

TEST(ColorTest, HsvConeMatchesOpenCvHsvOnRandomColours) {
  std::mt19937 rng(3);
  for (int i = 0; i < 2000; ++i) {
    const cv::Vec3b bgr = RandomBgr(&rng);
    const Eigen::Vector3f actual = ConvertColor(bgr, ColorSpace::kHsv);
    EXPECT_LT((actual - ReferenceHsvCone(bgr)).norm(), 2e-5) << bgr;
  }
}

TEST(ColorTest, HueWrapsAround) {
  // Hues of -0.94 and +0.94 degrees (359.06 and 0.94): neighbours on the circle.
  const cv::Vec3b just_below_red(4, 0, 255), just_above_red(0, 4, 255), cyan(255, 255, 0);
  const double half_angle = 60.0 * 4.0 / 255.0 * kDegree;
  const double expected = 2.0 * 0.5 * std::sin(half_angle);
  const double wrapped =
      ColorDistance(ConvertColor(just_below_red, ColorSpace::kHsv),
                    ConvertColor(just_above_red, ColorSpace::kHsv), ColorSpace::kHsv);
  EXPECT_NEAR(wrapped, expected, 1e-6);
  EXPECT_LT(wrapped, 0.02);
  EXPECT_NEAR(ColorDistance(ConvertColor(just_above_red, ColorSpace::kHsv),
                            ConvertColor(cyan, ColorSpace::kHsv), ColorSpace::kHsv),
              1.0, 1e-3);
}

TEST(ColorTest, GreyAndDarkPixelsOfAnyHueAreClose) {
  // Nearly grey pixels whose HSV hues are 0, 120 and 240 degrees, and nearly black ones.
  const cv::Vec3b greyish[] = {{100, 100, 102}, {100, 102, 100}, {102, 100, 100}};
  const cv::Vec3b darkish[] = {{0, 0, 3}, {0, 3, 0}, {3, 0, 0}};
  for (const auto* group : {greyish, darkish}) {
    for (int a = 0; a < 3; ++a) {
      for (int b = 0; b < 3; ++b) {
        EXPECT_LT(ColorDistance(ConvertColor(group[a], ColorSpace::kHsv),
                                ConvertColor(group[b], ColorSpace::kHsv), ColorSpace::kHsv),
                  0.0125)  // A quarter of the paper's cut-off; their hues differ by 120 degrees.
            << group[a] << " vs " << group[b];
      }
    }
  }
}

TEST(ColorTest, LabOfKnownColours) {
  // Textbook CIE L*a*b* (D65) of sRGB primaries, white and black, scaled by 1/100.
  const struct {
    cv::Vec3b bgr;
    Eigen::Vector3f lab;
  } cases[] = {
      {{0, 0, 255}, {53.24f, 80.09f, 67.20f}},   {{0, 255, 0}, {87.73f, -86.18f, 83.18f}},
      {{255, 0, 0}, {32.30f, 79.19f, -107.86f}}, {{255, 255, 255}, {100.0f, 0.0f, 0.0f}},
      {{0, 0, 0}, {0.0f, 0.0f, 0.0f}},
  };
  for (const auto& c : cases) {
    const Eigen::Vector3f actual = ConvertColor(c.bgr, ColorSpace::kLab);
    EXPECT_LT((actual - 0.01f * c.lab).cwiseAbs().maxCoeff(), 0.003) << c.bgr;
  }
}

TEST(ColorTest, LabMatchesOpenCvEightBitConversion) {
  // OpenCV's 8-bit path stores L * 255 / 100 and a + 128, b + 128, rounded to bytes.
  std::mt19937 rng(5);
  for (int i = 0; i < 500; ++i) {
    const cv::Vec3b bgr = RandomBgr(&rng);
    cv::Mat lab8;
    cv::cvtColor(cv::Mat(1, 1, CV_8UC3, cv::Scalar(bgr)), lab8, cv::COLOR_BGR2Lab);
    const cv::Vec3b q = lab8.at<cv::Vec3b>(0, 0);
    const Eigen::Vector3f expected(q[0] / 255.0f, (q[1] - 128.0f) / 100.0f,
                                   (q[2] - 128.0f) / 100.0f);
    const Eigen::Vector3f actual = ConvertColor(bgr, ColorSpace::kLab);
    EXPECT_LT((actual - expected).cwiseAbs().maxCoeff(), 0.012) << bgr;
  }
}

TEST(ColorTest, NormalizedRgbIsRgbOverTwoFiftyFive) {
  const Eigen::Vector3f rgb = ConvertColor(cv::Vec3b(10, 20, 30), ColorSpace::kNormalizedRgb);
  EXPECT_FLOAT_EQ(rgb.x(), 30.0f / 255);
  EXPECT_FLOAT_EQ(rgb.y(), 20.0f / 255);
  EXPECT_FLOAT_EQ(rgb.z(), 10.0f / 255);
}

TEST(ColorTest, ImageConversionMatchesPerColourConversion) {
  std::mt19937 rng(11);
  cv::Mat bgr(9, 13, CV_8UC3);
  for (int y = 0; y < bgr.rows; ++y) {
    for (int x = 0; x < bgr.cols; ++x) bgr.at<cv::Vec3b>(y, x) = RandomBgr(&rng);
  }
  for (ColorSpace space : kAllSpaces) {
    const cv::Mat converted = ConvertImage(bgr, space, "cam0/0000.png");
    ASSERT_EQ(converted.type(), CV_32FC3);
    ASSERT_EQ(converted.size(), bgr.size());
    for (int y = 0; y < bgr.rows; ++y) {
      for (int x = 0; x < bgr.cols; ++x) {
        const cv::Vec3f c = converted.at<cv::Vec3f>(y, x);
        const Eigen::Vector3f expected = ConvertColor(bgr.at<cv::Vec3b>(y, x), space);
        EXPECT_LT((Eigen::Vector3f(c[0], c[1], c[2]) - expected).norm(), 1e-5)
            << ColorSpaceName(space) << " at " << x << "," << y;
      }
    }
  }
}

TEST(ColorTest, ImageConversionRejectsWrongType) {
  const cv::Mat grey(4, 4, CV_8UC1, cv::Scalar(7));
  try {
    ConvertImage(grey, ColorSpace::kHsv, "images/cam3/0007.png");
    FAIL() << "no error for a grey image";
  } catch (const Error& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("images/cam3/0007.png"), std::string::npos) << message;
    EXPECT_NE(message.find("CV_8UC1"), std::string::npos) << message;
  }
  EXPECT_THROW(ConvertImage(cv::Mat(), ColorSpace::kLab, "empty.png"), Error);
}

TEST(ColorTest, DistanceIsSymmetricAndKnown) {
  std::mt19937 rng(13);
  for (ColorSpace space : kAllSpaces) {
    for (int i = 0; i < 200; ++i) {
      const Eigen::Vector3f a = ConvertColor(RandomBgr(&rng), space);
      const Eigen::Vector3f b = ConvertColor(RandomBgr(&rng), space);
      EXPECT_EQ(ColorDistance(a, b, space), ColorDistance(b, a, space));
      EXPECT_EQ(ColorDistance(a, a, space), 0.0);
    }
  }
  const cv::Vec3b red(0, 0, 255), green(0, 255, 0), white(255, 255, 255), black(0, 0, 0);
  const auto distance = [](const cv::Vec3b& a, const cv::Vec3b& b, ColorSpace space) {
    return ColorDistance(ConvertColor(a, space), ConvertColor(b, space), space);
  };
  EXPECT_NEAR(distance(red, green, ColorSpace::kHsv), std::sqrt(3.0) / 2.0, 1e-6);
  EXPECT_NEAR(distance(red, green, ColorSpace::kNormalizedRgb), std::sqrt(2.0), 1e-6);
  EXPECT_NEAR(distance(white, black, ColorSpace::kHsv), 1.0, 1e-6);
  EXPECT_NEAR(distance(white, black, ColorSpace::kLab), 1.0, 1e-3);
}

}  // namespace
}  // namespace finecap
