// The image model of the energy: each input image cut into squares of coherent colour, every
// square a 2D isotropic Gaussian (Robertini et al. 2014, section 4.2, after Stoll et al. 2011).
//
// Conventions. Pixel centres lie at integer coordinates, the top-left pixel's at (0, 0). A square
// covering the pixels [x0, x0 + w) x [y0, y0 + w) becomes a Gaussian with mean
// (x0 + (w - 1) / 2, y0 + (w - 1) / 2), standard deviation w / 2 pixels, and colour the mean of
// the embedded colours of its pixels (finecap/geometry/color.h: convert, then average).
//
// The quad-tree. The image is tiled from (0, 0) by root squares of side
// RootSide() = min_leaf_size * 2^max_depth (1024 px by default, so a 1004 x 1004 image has one
// root and its smallest leaves are 4 px, sigma 2 px). A square is a leaf when it is *uniform*
// (every pixel inside the image and in the foreground) and its colour spread is at most
// split_threshold, or when it has the minimum side; otherwise it is split into its four quarters.
// The spread of a square is the root mean square colour distance of its pixels to their mean,
// sqrt(mean |c - mean c|^2), in the units of ColorDistance. Squares hanging over the image border
// or the mask's edge are therefore split down to squares that fit; squares with no pixel inside
// are dropped; a square of minimum side is kept when at least half of its pixels are inside and
// in the foreground, its colour then being the mean over those pixels only. So, when the image's
// width and height are multiples of min_leaf_size and no mask is given, the leaves tile the image
// exactly.
//
// Speed. The per-square sums of colours, squared colour norms and pixel counts are kept in a
// pyramid, so each split test is O(1), as with summed-area tables. The pyramid stores only the
// squares of 4 px and more (all of them when min_leaf_size is 4 or more; the roots when they are
// smaller): at 1 px leaves that is 1/12 of a node per pixel (~3 MB for 1004 x 1004) instead of 4/3
// (~53 MB). Its lowest stored level is summed a band of rows at a time, the levels below it over
// that band only; when the walker splits a lowest stored square, the levels below it are summed
// again from that square's pixels alone, so a pixel is read at most twice. The buffers are kept per
// thread from one image to the next. Every sum is added in one fixed order, whatever is stored: a
// smallest square's pixels row by row, then each square as the sum of its quarters top-left,
// top-right, bottom-left, bottom-right; the leaves are therefore the same to the bit as those of a
// pyramid kept whole. HSV and chromaticity are converted a run of pixels at a time (ConvertPixels),
// with no full-image float copy. A textured 1004 x 1004 image builds in about 20 ms on one core
// with 1 px leaves (~180k leaves) and 7 ms with 4 px leaves (~43k), its HSV conversion included.
#ifndef FINECAP_IMAGE_GAUSSIANS_H_
#define FINECAP_IMAGE_GAUSSIANS_H_

#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "finecap/geometry/color.h"
#include "finecap/util/option_fields.h"

namespace finecap {

// How images are cut into image Gaussians. The fields are documented where Fields() declares them
// (docs/configuration.md: image_gaussians); the comments below add what the documentation does
// not say.
struct ImageGaussianOptions {
  ColorSpace color_space = ColorSpace::kHsv;  // finecap/geometry/color.h

  // Leaves have side RootSide() / 2^depth for a depth in [0, max_depth].
  int max_depth = 8;

  // The largest RootSide(), and the largest min_leaf_size, pixels.
  static constexpr int kMaxRootSide = 1 << 20;
  static constexpr int kMaxMinLeafSize = 1024;

  // RootSide() may not exceed kMaxRootSide. 4: sigma 2 px, about the projected size of the
  // paper's 7 mm surface Gaussians at 2-3 m with a focal length of ~1000 px.
  int min_leaf_size = 4;

  // In units of ColorDistance. 0.025: half the paper's colour cut-off D = 0.05, so that the
  // typical pixel of a leaf lies well inside the range in which colours still count as similar.
  double split_threshold = 0.025;

  // Side of a root square, pixels: min_leaf_size * 2^max_depth.
  int RootSide() const { return min_leaf_size << max_depth; }

  static const OptionFields<ImageGaussianOptions>& Fields();  // option_fields.h
  // Throws Error naming the field when a value is out of range.
  void Check() const;
};

// One image Gaussian: a plain 24-byte record, stored contiguously for the energy's hot loop.
struct ImageGaussian {
  float x = 0.0f;  // Mean, pixels (pixel centres at integer coordinates).
  float y = 0.0f;
  float sigma = 0.0f;                   // Standard deviation, pixels: half the side of the square.
  float color[3] = {0.0f, 0.0f, 0.0f};  // Mean colour, embedded in the set's colour space.

  Eigen::Map<const Eigen::Vector3f> Color() const {
    return Eigen::Map<const Eigen::Vector3f>(color);
  }
};

// The image Gaussians of one image, with a spatial index. The Gaussians are stored sorted for
// the index (by size class, then by grid cell), so their order is not the quad-tree's; indices
// returned by the queries refer to gaussians().
class ImageGaussians {
 public:
  ImageGaussians() = default;

  // Takes any Gaussians (not only quad-tree leaves; centres may lie outside the image) and builds
  // the index. Throws Error(where, ...) when a mean or colour is not finite, a sigma is not
  // positive and finite, or width or height is negative. `where` names the image.
  ImageGaussians(int width, int height, ColorSpace color_space,
                 std::vector<ImageGaussian> gaussians, const std::string& where);

  int width() const { return width_; }
  int height() const { return height_; }
  ColorSpace color_space() const { return color_space_; }
  int size() const { return static_cast<int>(gaussians_.size()); }
  bool empty() const { return gaussians_.empty(); }
  const ImageGaussian& operator[](int i) const { return gaussians_[i]; }
  const std::vector<ImageGaussian>& gaussians() const { return gaussians_; }

  // Replaces *indices by the indices of the Gaussians whose mean lies within `radius` pixels of
  // `point` (|mean - point| <= radius), in no particular order.
  void FindWithin(const Eigen::Vector2d& point, double radius, std::vector<int>* indices) const;

  // Replaces *indices by the indices of the Gaussians i that a Gaussian of standard deviation
  // `sigma` at `point` reaches within `cutoff` standard deviations of the pair:
  // |mean_i - point|^2 <= cutoff^2 * (sigma^2 + sigma_i^2). This is the neighbourhood the overlap
  // of two Gaussians needs: large image Gaussians are found from far away, small ones only nearby.
  void FindReaching(const Eigen::Vector2d& point, double sigma, double cutoff,
                    std::vector<int>* indices) const;

  // The same for a Gaussian anywhere on the segment [start, end]: the Gaussians i whose squared
  // distance to the segment is at most cutoff^2 * (sigma^2 + sigma_i^2), in no particular order
  // (the same for the same query). What a surface Gaussian can reach as it moves along its normal.
  void FindReachingSegment(const Eigen::Vector2d& start, const Eigen::Vector2d& end, double sigma,
                           double cutoff, std::vector<int>* indices) const;

 private:
  // The Gaussians with sigma in [2^k, 2^(k+1)) for one k, bucketed in a uniform grid whose cell
  // is about one such Gaussian's square, so a cell holds about one Gaussian.
  struct SizeClass {
    int begin = 0;  // Range of gaussians_ in this class.
    float max_sigma = 0.0f;
    double origin_x = 0.0;  // Grid origin and cell side, pixels.
    double origin_y = 0.0;
    double cell = 1.0;
    int cols = 0;
    int rows = 0;
    // gaussians_[cell_begin[c] .. cell_begin[c + 1]) lie in cell c = row * cols + col.
    std::vector<int> cell_begin;

    // The cell holding g's mean.
    int CellOf(const ImageGaussian& g) const;
    // First and last cell, along an axis with `count` cells from `origin`, that the coordinates
    // [low, high] touch; first > last when none.
    std::pair<int, int> CellRange(double low, double high, double origin, int count) const;
  };

  // Appends the `count` Gaussians all[members[0 .. count)], whose sigmas lie in
  // [2^exponent, 2^(exponent+1)), as a new size class; within a cell they keep their given order.
  void AppendSizeClass(const std::vector<ImageGaussian>& all, const int* members, int count,
                       int exponent);

  // Appends the Gaussians whose squared distance to the segment [start, end] (a point when they
  // are equal) is at most base + sigma_factor * sigma_i^2.
  void CollectNear(const Eigen::Vector2d& start, const Eigen::Vector2d& end, double base,
                   double sigma_factor, std::vector<int>* indices) const;

  int width_ = 0;
  int height_ = 0;
  ColorSpace color_space_ = ColorSpace::kHsv;
  std::vector<ImageGaussian> gaussians_;
  std::vector<SizeClass> classes_;
};

// The quad-tree leaves of one image as image Gaussians (conventions above).
//
// `image` is either an 8-bit BGR image (CV_8UC3), converted here to options.color_space, or an
// image already converted by ConvertImage to that space (CV_32FC3). `mask`, when not empty, is a
// CV_8UC1 image of the same size: pixels where it is zero are background and belong to no
// Gaussian. Throws Error(where, ...) for an empty image, a wrong type, or a mask of the wrong
// type or size; `where` names the image (its file).
ImageGaussians BuildImageGaussians(const cv::Mat& image, const cv::Mat& mask,
                                   const ImageGaussianOptions& options, const std::string& where);

// BuildImageGaussians for every camera of a frame, in parallel (OpenMP, one image per thread).
// `masks` is empty (no masks) or has one entry per image, each possibly empty; `names` has one
// entry per image and is used in error messages. Inputs are all checked before any work starts.
std::vector<ImageGaussians> BuildFrameImageGaussians(const std::vector<cv::Mat>& images,
                                                     const std::vector<cv::Mat>& masks,
                                                     const ImageGaussianOptions& options,
                                                     const std::vector<std::string>& names);

}  // namespace finecap

#endif  // FINECAP_IMAGE_GAUSSIANS_H_
