// The quad-tree's leaves against a straightforward recursive reference, bit for bit: whatever
// the builder stores or recomputes, its sums must be added in the documented order (a smallest
// square's pixels row by row, a larger square's four quarters top-left, top-right, bottom-left,
// bottom-right), so that its leaves, their order and every float agree exactly.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "finecap/model/image_gaussians.h"

namespace finecap {
namespace {

// The tolerance the builder adds to split_threshold^2 (image_gaussians.cc).
constexpr double kSpreadSquaredTolerance = 1e-13;

struct ReferenceSums {
  double sum[3] = {0.0, 0.0, 0.0};
  double sum_squared = 0.0;
  int64_t count = 0;
};

// Recomputes every square from its pixels, with no pyramid and no shortcut.
class ReferenceQuadTree {
 public:
  ReferenceQuadTree(const cv::Mat& colors, const cv::Mat& mask, const ImageGaussianOptions& options)
      : colors_(colors), mask_(mask), options_(options) {}

  std::vector<ImageGaussian> Leaves() {
    const int root = options_.RootSide();
    for (int y0 = 0; y0 < colors_.rows; y0 += root) {
      for (int x0 = 0; x0 < colors_.cols; x0 += root) Visit(x0, y0, root);
    }
    return leaves_;
  }

 private:
  ReferenceSums Sums(int x0, int y0, int side) const {
    ReferenceSums sums;
    if (side == options_.min_leaf_size) {
      for (int y = y0; y < std::min(colors_.rows, y0 + side); ++y) {
        for (int x = x0; x < std::min(colors_.cols, x0 + side); ++x) {
          if (!mask_.empty() && mask_.at<uint8_t>(y, x) == 0) continue;
          const cv::Vec3f c = colors_.at<cv::Vec3f>(y, x);
          for (int k = 0; k < 3; ++k) sums.sum[k] += c[k];
          sums.sum_squared += double(c[0]) * c[0] + double(c[1]) * c[1] + double(c[2]) * c[2];
          ++sums.count;
        }
      }
      return sums;
    }
    const int half = side / 2;
    for (int dy = 0; dy < side; dy += half) {
      for (int dx = 0; dx < side; dx += half) {
        if (x0 + dx >= colors_.cols || y0 + dy >= colors_.rows) continue;
        const ReferenceSums quarter = Sums(x0 + dx, y0 + dy, half);
        for (int k = 0; k < 3; ++k) sums.sum[k] += quarter.sum[k];
        sums.sum_squared += quarter.sum_squared;
        sums.count += quarter.count;
      }
    }
    return sums;
  }

  void Visit(int x0, int y0, int side) {
    const ReferenceSums sums = Sums(x0, y0, side);
    if (sums.count == 0) return;
    const int64_t area = int64_t(side) * side;
    if (side == options_.min_leaf_size) {
      if (2 * sums.count >= area) Emit(sums, x0, y0, side);
      return;
    }
    const double inv = 1.0 / static_cast<double>(sums.count);
    double mean_norm_squared = 0.0;
    for (int k = 0; k < 3; ++k) mean_norm_squared += (sums.sum[k] * inv) * (sums.sum[k] * inv);
    const double spread_squared = sums.sum_squared * inv - mean_norm_squared;
    const double threshold = options_.split_threshold;
    if (sums.count == area && spread_squared <= threshold * threshold + kSpreadSquaredTolerance) {
      Emit(sums, x0, y0, side);
      return;
    }
    const int half = side / 2;
    for (int dy = 0; dy < side; dy += half) {
      for (int dx = 0; dx < side; dx += half) {
        if (x0 + dx < colors_.cols && y0 + dy < colors_.rows) Visit(x0 + dx, y0 + dy, half);
      }
    }
  }

  void Emit(const ReferenceSums& sums, int x0, int y0, int side) {
    ImageGaussian leaf;
    leaf.x = static_cast<float>(x0 + 0.5 * (side - 1));
    leaf.y = static_cast<float>(y0 + 0.5 * (side - 1));
    leaf.sigma = 0.5f * side;
    for (int k = 0; k < 3; ++k) leaf.color[k] = static_cast<float>(sums.sum[k] / sums.count);
    leaves_.push_back(leaf);
  }

  const cv::Mat& colors_;
  const cv::Mat& mask_;
  const ImageGaussianOptions& options_;
  std::vector<ImageGaussian> leaves_;
};

// Patches of flat colour, of colour ramps and of noise, in random places and sizes: leaves of
// every size, and spreads near any threshold.
cv::Mat MakePatchworkImage(int width, int height, std::mt19937* rng) {
  std::uniform_int_distribution<int> byte(0, 255), kind(0, 2), patch_side(1, 40);
  cv::Mat image(height, width, CV_8UC3, cv::Scalar(byte(*rng), byte(*rng), byte(*rng)));
  for (int p = 0; p < 12; ++p) {
    const cv::Rect patch =
        cv::Rect(byte(*rng) % width, byte(*rng) % height, patch_side(*rng), patch_side(*rng)) &
        cv::Rect(0, 0, width, height);
    const cv::Vec3b base(byte(*rng), byte(*rng), byte(*rng));
    const int patch_kind = kind(*rng);
    for (int y = patch.y; y < patch.y + patch.height; ++y) {
      for (int x = patch.x; x < patch.x + patch.width; ++x) {
        cv::Vec3b& pixel = image.at<cv::Vec3b>(y, x);
        if (patch_kind == 0) {
          pixel = base;
        } else if (patch_kind == 1) {
          pixel = cv::Vec3b(base[0], uint8_t(base[1] + x), uint8_t(base[2] + 2 * y));
        } else {
          pixel = cv::Vec3b(byte(*rng), byte(*rng), byte(*rng));
        }
      }
    }
  }
  return image;
}

// Colours as a converted image: mostly small, a quarter +-2^60. A small value added to +-2^60 is
// lost, one added after two of them cancel is kept, so the mean of a square of few pixels depends
// on the order in which its pixels are added, and a builder that adds them in another order than
// the reference's fails. (Between larger squares the order rarely shows: their sums of 8-bit
// colours are nearly exact in double, and the means are rounded to float.)
cv::Mat MakeCancellingColors(int width, int height, std::mt19937* rng) {
  std::uniform_real_distribution<float> small(-0.004f, 0.004f);
  std::uniform_int_distribution<int> kind(0, 7);
  const float huge = std::ldexp(1.0f, 60);
  cv::Mat colors(height, width, CV_32FC3);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      for (int k = 0; k < 3; ++k) {
        const int pick = kind(*rng);
        colors.at<cv::Vec3f>(y, x)[k] = pick == 0 ? huge : (pick == 1 ? -huge : small(*rng));
      }
    }
  }
  return colors;
}

// A few random discs of foreground, or none (no mask).
cv::Mat MakeMask(int width, int height, std::mt19937* rng) {
  if ((*rng)() % 3 == 0) return cv::Mat();
  cv::Mat mask(height, width, CV_8UC1, cv::Scalar(0));
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int d = 0; d < 4; ++d) {
    const double cx = unit(*rng) * width, cy = unit(*rng) * height;
    const double radius = 2.0 + unit(*rng) * 0.4 * (width + height);
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        if ((x - cx) * (x - cx) + (y - cy) * (y - cy) <= radius * radius) {
          mask.at<uint8_t>(y, x) = static_cast<uint8_t>(1 + (*rng)() % 255);
        }
      }
    }
  }
  return mask;
}

void ExpectBitwiseEqual(const ImageGaussians& built, const ImageGaussians& reference,
                        const std::string& what) {
  ASSERT_EQ(built.size(), reference.size()) << what;
  for (int i = 0; i < built.size(); ++i) {
    ASSERT_EQ(std::memcmp(&built[i], &reference[i], sizeof(ImageGaussian)), 0)
        << what << ", leaf " << i << ": (" << built[i].x << ", " << built[i].y << ", "
        << built[i].sigma << ") against (" << reference[i].x << ", " << reference[i].y << ", "
        << reference[i].sigma << ")";
  }
}

struct Case {
  int width, height, min_leaf_size, max_depth;
  double threshold;
};

ImageGaussianOptions CaseOptions(const Case& c, ColorSpace space) {
  ImageGaussianOptions options;
  options.color_space = space;
  options.min_leaf_size = c.min_leaf_size;
  options.max_depth = c.max_depth;
  options.split_threshold = c.threshold;
  return options;
}

TEST(ImageGaussiansReferenceTest, LeavesEqualTheRecursiveReferenceBitForBit) {
  const Case cases[] = {
      {1, 1, 1, 0, 0.0},      {1, 1, 1, 3, 0.02},   {37, 53, 1, 6, 0.02},    {64, 64, 1, 6, 0.0},
      {101, 77, 1, 8, 0.03},  {3, 90, 1, 5, 0.05},  {90, 3, 2, 4, 0.01},     {63, 65, 2, 5, 0.02},
      {129, 97, 3, 5, 0.025}, {50, 41, 5, 3, 0.04}, {200, 150, 4, 6, 0.025}, {70, 70, 1, 2, 0.02},
      {45, 61, 7, 1, 0.1},    {33, 29, 1, 1, 0.02}, {120, 88, 2, 0, 0.02},   {17, 200, 1, 4, 0.3}};
  const ColorSpace spaces[] = {ColorSpace::kHsv, ColorSpace::kNormalizedRgb, ColorSpace::kLab,
                               ColorSpace::kChromaticity};
  std::mt19937 rng(41);
  int total_leaves = 0;
  for (const Case& c : cases) {
    for (ColorSpace space : spaces) {
      const ImageGaussianOptions options = CaseOptions(c, space);
      const cv::Mat image = MakePatchworkImage(c.width, c.height, &rng);
      const cv::Mat mask = MakeMask(c.width, c.height, &rng);
      const cv::Mat colors = ConvertImage(image, space, "patchwork.png");
      const ImageGaussians reference(
          c.width, c.height, space, ReferenceQuadTree(colors, mask, options).Leaves(), "reference");
      const std::string what = std::to_string(c.width) + "x" + std::to_string(c.height) +
                               ", min_leaf_size " + std::to_string(c.min_leaf_size) +
                               ", max_depth " + std::to_string(c.max_depth) + ", " +
                               ColorSpaceName(space) + (mask.empty() ? "" : ", masked");
      ExpectBitwiseEqual(BuildImageGaussians(image, mask, options, "patchwork.png"), reference,
                         what + ", from BGR");
      ExpectBitwiseEqual(BuildImageGaussians(colors, mask, options, "patchwork.png"), reference,
                         what + ", from converted colours");
      total_leaves += reference.size();
    }
    const ImageGaussianOptions options = CaseOptions(c, ColorSpace::kHsv);
    const cv::Mat colors = MakeCancellingColors(c.width, c.height, &rng);
    const cv::Mat mask = MakeMask(c.width, c.height, &rng);
    const ImageGaussians reference(c.width, c.height, options.color_space,
                                   ReferenceQuadTree(colors, mask, options).Leaves(), "reference");
    ExpectBitwiseEqual(BuildImageGaussians(colors, mask, options, "cancelling.exr"), reference,
                       std::to_string(c.width) + "x" + std::to_string(c.height) +
                           ", cancelling colours, min_leaf_size " +
                           std::to_string(c.min_leaf_size));
  }
  EXPECT_GT(total_leaves, 10000);
}

TEST(ImageGaussiansReferenceTest, FrameBuildsEqualTheReferenceOnManyImages) {
  // More images than threads, of different sizes, so per-thread buffers are reused across
  // images of other shapes.
  std::mt19937 rng(43);
  ImageGaussianOptions options;
  options.min_leaf_size = 1;
  options.max_depth = 7;
  options.split_threshold = 0.025;
  std::vector<cv::Mat> images, masks;
  std::vector<std::string> names;
  for (int i = 0; i < 9; ++i) {
    const int width = 40 + 23 * i, height = 170 - 13 * i;
    images.push_back(MakePatchworkImage(width, height, &rng));
    cv::Mat mask = MakeMask(width, height, &rng);
    masks.push_back(mask.empty() ? cv::Mat(height, width, CV_8UC1, cv::Scalar(255)) : mask);
    names.push_back("cam" + std::to_string(i) + ".png");
  }
  const std::vector<ImageGaussians> frame = BuildFrameImageGaussians(images, masks, options, names);
  ASSERT_EQ(frame.size(), images.size());
  for (size_t i = 0; i < images.size(); ++i) {
    const cv::Mat colors = ConvertImage(images[i], options.color_space, names[i]);
    const ImageGaussians reference(images[i].cols, images[i].rows, options.color_space,
                                   ReferenceQuadTree(colors, masks[i], options).Leaves(),
                                   "reference");
    ExpectBitwiseEqual(frame[i], reference, names[i]);
  }
}

}  // namespace
}  // namespace finecap
