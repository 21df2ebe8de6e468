#include "finecap/model/image_gaussians.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <set>

#include <gtest/gtest.h>

#include "finecap/util/error.h"

namespace finecap {
namespace {

ImageGaussianOptions SmallTreeOptions(int min_leaf_size, int max_depth, double threshold) {
  ImageGaussianOptions options;
  options.min_leaf_size = min_leaf_size;
  options.max_depth = max_depth;
  options.split_threshold = threshold;
  return options;
}

// Smooth colour ramps, a few flat blocks and a noisy corner: leaves of many sizes.
cv::Mat MakeVariedImage(int width, int height, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> noise(-40, 40);
  cv::Mat image(height, width, CV_8UC3);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      cv::Vec3b& pixel = image.at<cv::Vec3b>(y, x);
      if (x < width / 2 && y < height / 2) {
        pixel = cv::Vec3b(40, 90, 200);  // Flat.
      } else if (x >= width / 2 && y < height / 2) {
        pixel = cv::Vec3b(x % 256, (2 * y) % 256, 128);  // Ramps.
      } else {
        const int base = ((x / 8 + y / 8) % 2) ? 60 : 180;
        const int jitter = (x < width / 4) ? noise(rng) : 0;  // Noisy corner.
        pixel = cv::Vec3b(cv::saturate_cast<uint8_t>(base + jitter), 120,
                          cv::saturate_cast<uint8_t>(255 - base + jitter));
      }
    }
  }
  return image;
}

struct SquareStats {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  double spread = 0.0;  // RMS distance to the mean.
  int count = 0;
};

// Direct statistics of the pixels of a square (inside the image and the mask), for checking.
SquareStats DirectStats(const cv::Mat& colors, const cv::Mat& mask, int x0, int y0, int side) {
  SquareStats stats;
  std::vector<Eigen::Vector3d> pixels;
  for (int y = std::max(0, y0); y < std::min(colors.rows, y0 + side); ++y) {
    for (int x = std::max(0, x0); x < std::min(colors.cols, x0 + side); ++x) {
      if (!mask.empty() && mask.at<uint8_t>(y, x) == 0) continue;
      const cv::Vec3f c = colors.at<cv::Vec3f>(y, x);
      pixels.emplace_back(c[0], c[1], c[2]);
      stats.mean += pixels.back();
    }
  }
  stats.count = static_cast<int>(pixels.size());
  if (stats.count == 0) return stats;
  stats.mean /= stats.count;
  for (const Eigen::Vector3d& p : pixels) stats.spread += (p - stats.mean).squaredNorm();
  stats.spread = std::sqrt(stats.spread / stats.count);
  return stats;
}

// The square a Gaussian stands for: side 2 sigma, top-left pixel mean - (side - 1) / 2.
struct Square {
  int x0, y0, side;
};
Square SquareOf(const ImageGaussian& g) {
  const int side = static_cast<int>(std::lround(2.0 * g.sigma));
  return {static_cast<int>(std::lround(g.x - 0.5 * (side - 1))),
          static_cast<int>(std::lround(g.y - 0.5 * (side - 1))), side};
}

std::vector<int> Sorted(std::vector<int> values) {
  std::sort(values.begin(), values.end());
  return values;
}

template <typename Inside>
std::vector<int> BruteForce(const ImageGaussians& gaussians, Inside inside) {
  std::vector<int> found;
  for (int i = 0; i < gaussians.size(); ++i) {
    if (inside(gaussians[i])) found.push_back(i);
  }
  return found;
}

// The Gaussians within reach of the segment [start, end], by a scan of every one.
std::vector<int> ReachingSegmentByScan(const ImageGaussians& gaussians,
                                       const Eigen::Vector2d& start, const Eigen::Vector2d& end,
                                       double sigma, double cutoff) {
  return BruteForce(gaussians, [&](const ImageGaussian& g) {
    const Eigen::Vector2d direction = end - start;
    const Eigen::Vector2d offset = Eigen::Vector2d(g.x, g.y) - start;
    const double length_squared = direction.squaredNorm();
    const double t =
        length_squared > 0.0 ? std::clamp(offset.dot(direction) / length_squared, 0.0, 1.0) : 0.0;
    const double sigma_i = g.sigma, cutoff_squared = cutoff * cutoff;
    return (offset - t * direction).squaredNorm() <=
           cutoff_squared * sigma * sigma + cutoff_squared * sigma_i * sigma_i;
  });
}

// Runs random FindWithin and FindReaching queries against a scan of every Gaussian.
void ExpectQueriesMatchBruteForce(const ImageGaussians& gaussians, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> px(-60.0, gaussians.width() + 60.0);
  std::uniform_real_distribution<double> py(-60.0, gaussians.height() + 60.0);
  std::uniform_real_distribution<double> radius(0.0, 40.0), sigma(0.3, 8.0), cutoff(0.5, 4.0);
  std::vector<int> found;
  for (int q = 0; q < 300; ++q) {
    const Eigen::Vector2d p(px(rng), py(rng));
    const double r = radius(rng);
    gaussians.FindWithin(p, r, &found);
    const auto within = [&](const ImageGaussian& g) {
      return (Eigen::Vector2d(g.x, g.y) - p).squaredNorm() <= r * r;
    };
    EXPECT_EQ(Sorted(found), BruteForce(gaussians, within)) << "within " << r << " of " << p;

    const double s = sigma(rng), c = cutoff(rng);
    gaussians.FindReaching(p, s, c, &found);
    const auto reaching = [&](const ImageGaussian& g) {
      const double sigma_i = g.sigma;
      return (Eigen::Vector2d(g.x, g.y) - p).squaredNorm() <= c * c * (s * s + sigma_i * sigma_i);
    };
    EXPECT_EQ(Sorted(found), BruteForce(gaussians, reaching)) << "sigma " << s << " at " << p;

    // A segment in any direction, as the path of a surface Gaussian's projection: level and
    // upright ones too, whose rows or columns the scan bounds exactly.
    const double angle = q % 5 == 0 ? 0.0 : q % 5 == 1 ? M_PI / 2 : 0.02 * q;
    const Eigen::Vector2d end =
        p + radius(rng) * 1.5 * Eigen::Vector2d(std::cos(angle), std::sin(angle));
    gaussians.FindReachingSegment(p, end, s, c, &found);
    EXPECT_EQ(Sorted(found), ReachingSegmentByScan(gaussians, p, end, s, c))
        << "sigma " << s << " from " << p.transpose() << " to " << end.transpose();
  }
}

// Segments that a bound of the scan tighter than the exact test would cut: long diagonal ones
// with small reach, ones crossing the grid's edge or lying far outside it, points, and ones
// ending exactly on a Gaussian's mean. The result must be the scan's, in the scan's (ascending)
// order: sums over it downstream are added in that order.
void ExpectSegmentQueriesMatchScanInOrder(const ImageGaussians& gaussians, unsigned seed) {
  std::mt19937 rng(seed);
  const double width = gaussians.width(), height = gaussians.height();
  std::uniform_real_distribution<double> px(-0.5 * width, 1.5 * width);
  std::uniform_real_distribution<double> py(-0.5 * height, 1.5 * height);
  std::uniform_real_distribution<double> angle(0.0, 2.0 * M_PI), length(0.0, 2.0 * width);
  std::uniform_real_distribution<double> sigma(0.05, 3.0), cutoff(0.2, 3.0);
  std::uniform_int_distribution<int> pick(0, gaussians.size() - 1);
  std::vector<int> found;
  size_t total_found = 0;
  for (int q = 0; q < 400; ++q) {
    Eigen::Vector2d start(px(rng), py(rng));
    const double a = q % 7 == 0 ? M_PI / 4 : q % 7 == 1 ? 0.0 : q % 7 == 2 ? M_PI / 2 : angle(rng);
    Eigen::Vector2d end = start + length(rng) * Eigen::Vector2d(std::cos(a), std::sin(a));
    if (q % 11 == 0) end = start;
    if (q % 13 == 0) {
      const ImageGaussian& g = gaussians[pick(rng)];
      end = Eigen::Vector2d(g.x, g.y);
    }
    if (q % 17 == 0) start *= 1e6;  // Far outside.
    const double s = sigma(rng), c = cutoff(rng);
    gaussians.FindReachingSegment(start, end, s, c, &found);
    EXPECT_EQ(found, ReachingSegmentByScan(gaussians, start, end, s, c))
        << "sigma " << s << " cutoff " << c << " from " << start.transpose() << " to "
        << end.transpose();
    total_found += found.size();
  }
  EXPECT_GT(total_found, 400u) << "the queries should reach Gaussians";
}

template <typename Call>
void ExpectErrorMentions(Call call, const std::vector<std::string>& parts) {
  try {
    call();
    FAIL() << "no error raised";
  } catch (const Error& error) {
    const std::string message = error.what();
    for (const std::string& part : parts) {
      EXPECT_NE(message.find(part), std::string::npos) << "'" << part << "' not in: " << message;
    }
  }
}

TEST(ImageGaussianOptionsTest, CheckNamesTheBadField) {
  EXPECT_NO_THROW(ImageGaussianOptions().Check());
  EXPECT_EQ(ImageGaussianOptions().RootSide(), 1024);
  ExpectErrorMentions([] { SmallTreeOptions(4, 17, 0.1).Check(); }, {"max_depth", "17"});
  ExpectErrorMentions([] { SmallTreeOptions(4, -1, 0.1).Check(); }, {"max_depth"});
  ExpectErrorMentions([] { SmallTreeOptions(0, 4, 0.1).Check(); }, {"min_leaf_size"});
  ExpectErrorMentions([] { SmallTreeOptions(32, 16, 0.1).Check(); }, {"min_leaf_size", "2^20"});
  ExpectErrorMentions([] { SmallTreeOptions(4, 4, -0.1).Check(); }, {"split_threshold"});
  ExpectErrorMentions([] { SmallTreeOptions(4, 4, std::nan("")).Check(); }, {"split_threshold"});
}

TEST(ImageGaussiansTest, ConstantImageGivesOneGaussianPerRootSquare) {
  const cv::Vec3b bgr(30, 160, 220);
  const cv::Mat image(128, 192, CV_8UC3, cv::Scalar(bgr));
  for (ColorSpace space : {ColorSpace::kHsv, ColorSpace::kNormalizedRgb, ColorSpace::kLab}) {
    ImageGaussianOptions options = SmallTreeOptions(4, 4, 0.0);  // Root side 64.
    options.color_space = space;
    const ImageGaussians gaussians = BuildImageGaussians(image, cv::Mat(), options, "flat.png");
    ASSERT_EQ(gaussians.size(), 6);
    std::set<std::pair<float, float>> centres;
    for (const ImageGaussian& g : gaussians.gaussians()) {
      EXPECT_EQ(g.sigma, 32.0f);
      EXPECT_LT((g.Color() - ConvertColor(bgr, space)).norm(), 1e-6);
      centres.insert({g.x, g.y});
    }
    const std::set<std::pair<float, float>> expected = {{31.5f, 31.5f},  {95.5f, 31.5f},
                                                        {159.5f, 31.5f}, {31.5f, 95.5f},
                                                        {95.5f, 95.5f},  {159.5f, 95.5f}};
    EXPECT_EQ(centres, expected);
  }
}

TEST(ImageGaussiansTest, DefaultRootIs1024Pixels) {
  const cv::Mat image(1024, 2048, CV_8UC3, cv::Scalar(200, 10, 10));
  const ImageGaussians gaussians =
      BuildImageGaussians(image, cv::Mat(), ImageGaussianOptions(), "wide.png");
  ASSERT_EQ(gaussians.size(), 2);
  EXPECT_EQ(gaussians[0].sigma, 512.0f);
  EXPECT_EQ(gaussians[0].y, 511.5f);
  EXPECT_EQ(std::min(gaussians[0].x, gaussians[1].x), 511.5f);
  EXPECT_EQ(std::max(gaussians[0].x, gaussians[1].x), 1535.5f);
}

TEST(ImageGaussiansTest, CheckerboardSplitsExactlyIntoItsCells) {
  const cv::Vec3b dark(20, 40, 90), light(200, 220, 120);
  cv::Mat board(64, 64, CV_8UC3);
  for (int y = 0; y < 64; ++y) {
    for (int x = 0; x < 64; ++x) board.at<cv::Vec3b>(y, x) = ((x / 8 + y / 8) % 2) ? light : dark;
  }
  // Root 64 reached with smallest leaves of 1, 4 and 8 pixels: the cells are found in each case.
  for (const auto& [min_leaf_size, max_depth] : {std::pair{1, 6}, {4, 4}, {8, 3}}) {
    const ImageGaussians gaussians = BuildImageGaussians(
        board, cv::Mat(), SmallTreeOptions(min_leaf_size, max_depth, 0.01), "board.png");
    ASSERT_EQ(gaussians.size(), 64) << "min_leaf_size " << min_leaf_size;
    std::set<std::pair<float, float>> centres;
    for (const ImageGaussian& g : gaussians.gaussians()) {
      EXPECT_EQ(g.sigma, 4.0f);
      // Centre of the cell [8i, 8i + 8): 8i + 3.5.
      EXPECT_EQ(std::fmod(g.x, 8.0f), 3.5f);
      EXPECT_EQ(std::fmod(g.y, 8.0f), 3.5f);
      const int cell_x = static_cast<int>(g.x) / 8, cell_y = static_cast<int>(g.y) / 8;
      const cv::Vec3b expected = ((cell_x + cell_y) % 2) ? light : dark;
      EXPECT_LT((g.Color() - ConvertColor(expected, ColorSpace::kHsv)).norm(), 1e-6);
      centres.insert({g.x, g.y});
    }
    EXPECT_EQ(centres.size(), 64u);
  }
}

TEST(ImageGaussiansTest, RootsOverTheBorderAreSplitToFit) {
  // Root 64 on a 96 x 64 image: one whole root, and the right one's two left quarters.
  const cv::Mat image(64, 96, CV_8UC3, cv::Scalar(90, 90, 90));
  const ImageGaussians gaussians =
      BuildImageGaussians(image, cv::Mat(), SmallTreeOptions(4, 4, 0.05), "border.png");
  std::set<std::tuple<float, float, float>> found;
  for (const ImageGaussian& g : gaussians.gaussians()) found.insert({g.x, g.y, g.sigma});
  const std::set<std::tuple<float, float, float>> expected = {
      {31.5f, 31.5f, 32.0f}, {79.5f, 15.5f, 16.0f}, {79.5f, 47.5f, 16.0f}};
  EXPECT_EQ(found, expected);
}

TEST(ImageGaussiansTest, LeavesTileTheImageAndObeyTheSplitRule) {
  const cv::Mat image = MakeVariedImage(128, 128, 1);
  const ImageGaussianOptions options = SmallTreeOptions(2, 5, 0.03);  // Root 64.
  const cv::Mat colors = ConvertImage(image, options.color_space, "varied.png");
  const ImageGaussians gaussians = BuildImageGaussians(image, cv::Mat(), options, "varied.png");

  cv::Mat coverage(image.size(), CV_32S, cv::Scalar(0));
  std::set<float> sigmas;
  for (const ImageGaussian& g : gaussians.gaussians()) {
    const Square square = SquareOf(g);
    sigmas.insert(g.sigma);
    coverage(cv::Rect(square.x0, square.y0, square.side, square.side)) += 1;
    const SquareStats stats = DirectStats(colors, cv::Mat(), square.x0, square.y0, square.side);
    ASSERT_EQ(stats.count, square.side * square.side);
    EXPECT_LT((g.Color().cast<double>() - stats.mean).norm(), 1e-5);
    if (square.side > options.min_leaf_size) {
      EXPECT_LE(stats.spread, options.split_threshold);
    }
    if (square.side < options.RootSide()) {
      // Its parent was split, so the parent's spread exceeds the threshold.
      const int parent_side = 2 * square.side;
      const SquareStats parent = DirectStats(colors, cv::Mat(), square.x0 - square.x0 % parent_side,
                                             square.y0 - square.y0 % parent_side, parent_side);
      EXPECT_GT(parent.spread, options.split_threshold);
    }
  }
  double min_coverage, max_coverage;
  cv::minMaxLoc(coverage, &min_coverage, &max_coverage);
  EXPECT_EQ(min_coverage, 1.0);
  EXPECT_EQ(max_coverage, 1.0);
  EXPECT_GE(sigmas.size(), 4u) << "the test image should produce leaves of many sizes";
}

TEST(ImageGaussiansTest, MaskedPixelsBelongToNoGaussian) {
  // Red background left of x = 30 and above y = 10, masked out; green foreground.
  const int size = 64;
  cv::Mat image(size, size, CV_8UC3, cv::Scalar(0, 0, 255));
  cv::Mat mask(size, size, CV_8UC1, cv::Scalar(0));
  const cv::Rect foreground(30, 10, size - 30, size - 10);
  image(foreground).setTo(cv::Scalar(0, 255, 0));
  mask(foreground).setTo(255);
  const ImageGaussianOptions options = SmallTreeOptions(4, 4, 0.02);
  const ImageGaussians gaussians = BuildImageGaussians(image, mask, options, "masked.png");

  const Eigen::Vector3f green = ConvertColor(cv::Vec3b(0, 255, 0), options.color_space);
  cv::Mat covered(image.size(), CV_8UC1, cv::Scalar(0));
  for (const ImageGaussian& g : gaussians.gaussians()) {
    const Square square = SquareOf(g);
    const cv::Rect rect(square.x0, square.y0, square.side, square.side);
    const int inside = (rect & foreground).area();
    // Colours average the foreground only, even in squares that straddle the mask's edge.
    EXPECT_LT((g.Color() - green).norm(), 1e-6);
    if (square.side > options.min_leaf_size) {
      EXPECT_EQ(inside, rect.area());
    }
    EXPECT_GE(2 * inside, rect.area());
    covered(rect) = 255;
  }
  // Every smallest square with a foreground majority is kept.
  for (int y0 = 0; y0 < size; y0 += 4) {
    for (int x0 = 0; x0 < size; x0 += 4) {
      const cv::Rect block(x0, y0, 4, 4);
      if (2 * (block & foreground).area() >= block.area()) {
        EXPECT_EQ(covered.at<uint8_t>(y0, x0), 255) << x0 << "," << y0;
      }
    }
  }
}

TEST(ImageGaussiansTest, ConvertedInputGivesTheSameGaussians) {
  const cv::Mat image = MakeVariedImage(80, 72, 2);
  ImageGaussianOptions options = SmallTreeOptions(2, 4, 0.03);
  options.color_space = ColorSpace::kLab;
  const ImageGaussians from_bgr = BuildImageGaussians(image, cv::Mat(), options, "a.png");
  const ImageGaussians from_converted = BuildImageGaussians(
      ConvertImage(image, ColorSpace::kLab, "a.png"), cv::Mat(), options, "a.png");
  ASSERT_EQ(from_bgr.size(), from_converted.size());
  for (int i = 0; i < from_bgr.size(); ++i) {
    EXPECT_EQ(from_bgr[i].x, from_converted[i].x);
    EXPECT_EQ(from_bgr[i].y, from_converted[i].y);
    EXPECT_EQ(from_bgr[i].sigma, from_converted[i].sigma);
    EXPECT_EQ(from_bgr[i].Color(), from_converted[i].Color());
  }
}

TEST(ImageGaussiansTest, QueriesMatchBruteForceOnQuadTreeLeaves) {
  // 200 x 150 with root 128: borders split, many sizes.
  const ImageGaussians gaussians = BuildImageGaussians(MakeVariedImage(200, 150, 3), cv::Mat(),
                                                       SmallTreeOptions(2, 6, 0.03), "leaves.png");
  ASSERT_GT(gaussians.size(), 500);
  ExpectQueriesMatchBruteForce(gaussians, 17);
  ExpectSegmentQueriesMatchScanInOrder(gaussians, 18);
}

TEST(ImageGaussiansTest, QueriesMatchBruteForceOnArbitraryGaussians) {
  std::mt19937 rng(19);
  std::uniform_real_distribution<float> position(-30.0f, 130.0f);
  std::lognormal_distribution<float> sigma(0.5f, 1.2f);
  std::vector<ImageGaussian> list(700);
  for (ImageGaussian& g : list) {
    g.x = position(rng);
    g.y = position(rng);
    g.sigma = sigma(rng);
  }
  list[0].x = 5000.0f;  // One far outlier must not blow up the grid.
  const ImageGaussians gaussians(100, 100, ColorSpace::kHsv, list, "hand-made");
  EXPECT_EQ(gaussians.size(), 700);
  ExpectQueriesMatchBruteForce(gaussians, 23);
  ExpectSegmentQueriesMatchScanInOrder(gaussians, 24);
}

TEST(ImageGaussiansTest, RejectsInvalidGaussians) {
  std::vector<ImageGaussian> list(2);
  list[0].sigma = 1.0f;
  ExpectErrorMentions([&] { ImageGaussians(10, 10, ColorSpace::kHsv, list, "cam2/0004.png"); },
                      {"cam2/0004.png", "sigma"});
  list[1].sigma = 1.0f;
  list[1].x = std::nanf("");
  ExpectErrorMentions([&] { ImageGaussians(10, 10, ColorSpace::kHsv, list, "cam2/0004.png"); },
                      {"cam2/0004.png", "non-finite"});
}

TEST(ImageGaussiansTest, BadInputsNameTheImage) {
  const cv::Mat image(32, 48, CV_8UC3, cv::Scalar::all(50));
  const ImageGaussianOptions options = SmallTreeOptions(2, 3, 0.05);
  ExpectErrorMentions(
      [&] { BuildImageGaussians(image, cv::Mat(32, 40, CV_8UC1), options, "cam1/0003.png"); },
      {"cam1/0003.png", "40x32", "48x32"});
  ExpectErrorMentions(
      [&] { BuildImageGaussians(image, cv::Mat(32, 48, CV_32FC1), options, "cam1/0003.png"); },
      {"cam1/0003.png", "CV_32FC1"});
  ExpectErrorMentions(
      [&] { BuildImageGaussians(cv::Mat(32, 48, CV_16UC3), cv::Mat(), options, "cam1/0003.png"); },
      {"cam1/0003.png", "CV_16UC3"});
  ExpectErrorMentions([&] { BuildImageGaussians(cv::Mat(), cv::Mat(), options, "none.png"); },
                      {"none.png", "empty"});
  ExpectErrorMentions(
      [&] { BuildImageGaussians(image, cv::Mat(), SmallTreeOptions(2, 3, -1.0), "cam1/0003.png"); },
      {"split_threshold"});
}

TEST(ImageGaussiansTest, FrameBuildMatchesSingleBuildsAndChecksEveryImage) {
  std::vector<cv::Mat> images = {MakeVariedImage(64, 48, 4), MakeVariedImage(40, 56, 5),
                                 MakeVariedImage(64, 64, 6)};
  std::vector<cv::Mat> masks = {cv::Mat(), cv::Mat(56, 40, CV_8UC1, cv::Scalar(1)), cv::Mat()};
  const std::vector<std::string> names = {"cam0.png", "cam1.png", "cam2.png"};
  const ImageGaussianOptions options = SmallTreeOptions(2, 4, 0.03);
  const std::vector<ImageGaussians> frame = BuildFrameImageGaussians(images, masks, options, names);
  ASSERT_EQ(frame.size(), 3u);
  for (int c = 0; c < 3; ++c) {
    const ImageGaussians single = BuildImageGaussians(images[c], masks[c], options, names[c]);
    ASSERT_EQ(frame[c].size(), single.size());
    for (int i = 0; i < single.size(); ++i) {
      EXPECT_EQ(frame[c][i].x, single[i].x);
      EXPECT_EQ(frame[c][i].Color(), single[i].Color());
    }
  }
  masks[2] = cv::Mat(10, 10, CV_8UC1);
  ExpectErrorMentions([&] { BuildFrameImageGaussians(images, masks, options, names); },
                      {"cam2.png", "mask"});
  ExpectErrorMentions([&] { BuildFrameImageGaussians(images, {}, options, {"cam0.png"}); },
                      {"3 images but 1 names"});
}

}  // namespace
}  // namespace finecap
