#include "finecap/model/image_gaussians.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>

#include "finecap/util/error.h"
#include "finecap/util/threads.h"

namespace finecap {
namespace {

// Spread^2 below this counts as zero: the rounding error of the pyramid's sums is far smaller,
// and the smallest real spread of 8-bit colours (one grey level in 2^20 pixels) far larger.
constexpr double kSpreadSquaredTolerance = 1e-13;
constexpr int kMaxRootSide = ImageGaussianOptions::kMaxRootSide;

// The smallest squares that the moment pyramid stores have at least this side, pixels; the levels
// below are summed again from the pixels of a stored square when the walker splits it. At 1 px
// leaves this keeps 1/16 of a node per pixel instead of 4/3, and re-reads only the pixels of the
// squares that split that far.
constexpr int kMinStoredSide = 4;

// Sums over the foreground pixels of one quad-tree square.
struct Moments {
  double sum[3] = {0.0, 0.0, 0.0};  // Of the embedded colours.
  double sum_squared = 0.0;         // Of the squared norms of the embedded colours.
  int64_t count = 0;                // Of the pixels.

  void AddPixel(const cv::Vec3f& c) {
    sum[0] += c[0];
    sum[1] += c[1];
    sum[2] += c[2];
    sum_squared += double(c[0]) * c[0] + double(c[1]) * c[1] + double(c[2]) * c[2];
    ++count;
  }

  void Add(const Moments& other) {
    for (int c = 0; c < 3; ++c) sum[c] += other.sum[c];
    sum_squared += other.sum_squared;
    count += other.count;
  }

  double SpreadSquared() const {
    const double inv = 1.0 / static_cast<double>(count);
    double mean_norm_squared = 0.0;
    for (int c = 0; c < 3; ++c) mean_norm_squared += (sum[c] * inv) * (sum[c] * inv);
    return sum_squared * inv - mean_norm_squared;
  }
};

// One level of a moment pyramid: a grid of squares of equal side.
struct MomentGrid {
  int cols = 0;
  int rows = 0;
  std::vector<Moments> cells;

  // Zeroes the grid in the memory it already holds, when it is large enough.
  void Reset(int num_cols, int num_rows) {
    cols = num_cols;
    rows = num_rows;
    cells.assign(size_t(num_cols) * num_rows, Moments());
  }
  bool Contains(int col, int row) const { return col < cols && row < rows; }
  Moments& at(int col, int row) { return cells[size_t(row) * cols + col]; }
  const Moments& at(int col, int row) const { return cells[size_t(row) * cols + col]; }
};

int CeilDiv(int a, int b) { return (a + b - 1) / b; }

// The embedded colours of an image a run of pixels at a time: rows of an image given or
// converted whole, or, in a space converted pixel by pixel, runs of the 8-bit image converted
// when asked (no full-image float copy; the pixels of split squares are converted twice).
class ColorRuns {
 public:
  ColorRuns(const cv::Mat& image, ColorSpace space, const std::string& where) : space_(space) {
    if (image.type() == CV_32FC3) {
      colors_ = image;
    } else if (ConvertsPixelByPixel(space)) {
      bgr_ = image;
    } else {
      colors_ = ConvertImage(image, space, where);
    }
  }

  // The colours of the pixels [x, x + count) of row y; `scratch` has room for `count` colours.
  const cv::Vec3f* Run(int y, int x, int count, cv::Vec3f* scratch) const {
    if (!colors_.empty()) return colors_.ptr<cv::Vec3f>(y) + x;
    ConvertPixels(bgr_.ptr<cv::Vec3b>(y) + x, count, space_, scratch);
    return scratch;
  }

 private:
  ColorSpace space_;
  cv::Mat colors_;
  cv::Mat bgr_;
};

// Buffers of one thread's builds, kept from image to image so that their memory is faulted in
// once rather than for every image of every frame.
struct BuildBuffers {
  std::vector<MomentGrid> stored;  // The pyramid's levels from the first stored one up.
  std::vector<MomentGrid> band;    // Levels 0 .. first stored, over one row of stored squares.
  std::vector<MomentGrid> block;   // Levels below the first stored, over one stored square.
  std::vector<cv::Vec3f> run;      // Colours of one run of pixels.
};

BuildBuffers& ThreadBuildBuffers() {
  thread_local BuildBuffers buffers;
  return buffers;
}

// The pixels of `area`, whose corner lies on the grid of squares of side `side`.
struct PixelArea {
  const ColorRuns& colors;
  const cv::Mat& mask;
  cv::Rect rect;
};

// Level 0 over `area`: the sums of its squares of side `side`, each over its pixels row by row.
void SmallestSquareMoments(const PixelArea& area, int side, std::vector<cv::Vec3f>* run,
                           MomentGrid* grid) {
  const cv::Rect& rect = area.rect;
  grid->Reset(CeilDiv(rect.width, side), CeilDiv(rect.height, side));
  run->resize(std::max<size_t>(run->size(), rect.width));
  for (int dy = 0; dy < rect.height; ++dy) {
    const int y = rect.y + dy;
    const cv::Vec3f* color_row = area.colors.Run(y, rect.x, rect.width, run->data());
    const uint8_t* mask_row = area.mask.empty() ? nullptr : area.mask.ptr<uint8_t>(y) + rect.x;
    Moments* cell_row = &grid->at(0, dy / side);
    for (int col = 0; col < grid->cols; ++col) {
      Moments& cell = cell_row[col];
      const int x_end = std::min(rect.width, (col + 1) * side);
      for (int x = col * side; x < x_end; ++x) {
        if (mask_row == nullptr || mask_row[x] != 0) cell.AddPixel(color_row[x]);
      }
    }
  }
}

// Level 1 over `area` straight from its pixels when the smallest squares are single pixels: a
// pixel's level-0 sums are its own values, so adding the pixels in the order CoarserMoments adds
// their squares gives level 1 to the bit, without writing level 0.
void PixelPairMoments(const PixelArea& area, std::vector<cv::Vec3f>* run, MomentGrid* grid) {
  const cv::Rect& rect = area.rect;
  grid->Reset(CeilDiv(rect.width, 2), CeilDiv(rect.height, 2));
  run->resize(std::max<size_t>(run->size(), rect.width));
  for (int dy = 0; dy < rect.height; ++dy) {
    const int y = rect.y + dy;
    const cv::Vec3f* color_row = area.colors.Run(y, rect.x, rect.width, run->data());
    const uint8_t* mask_row = area.mask.empty() ? nullptr : area.mask.ptr<uint8_t>(y) + rect.x;
    Moments* cell_row = &grid->at(0, dy / 2);
    for (int x = 0; x < rect.width; ++x) {
      if (mask_row == nullptr || mask_row[x] != 0) cell_row[x / 2].AddPixel(color_row[x]);
    }
  }
}

// The level above `fine`: each square the sum of its quarters, top-left, top-right, bottom-left,
// bottom-right. This order, with the row-by-row order of level 0, fixes every sum to the bit.
void CoarserMoments(const MomentGrid& fine, MomentGrid* coarse) {
  coarse->Reset(CeilDiv(fine.cols, 2), CeilDiv(fine.rows, 2));
  for (int row = 0; row < fine.rows; ++row) {
    for (int col = 0; col < fine.cols; ++col) coarse->at(col / 2, row / 2).Add(fine.at(col, row));
  }
}

// Levels bottom .. top of the pyramid over `area`, into (*levels)[bottom .. top]; bottom is 0, or
// 1 when the smallest squares are single pixels.
void BuildPyramid(const PixelArea& area, int min_side, int bottom, int top,
                  std::vector<cv::Vec3f>* run, std::vector<MomentGrid>* levels) {
  if (static_cast<int>(levels->size()) < top + 1) levels->resize(top + 1);
  if (bottom == 0) {
    SmallestSquareMoments(area, min_side, run, &(*levels)[0]);
  } else {
    PixelPairMoments(area, run, &(*levels)[1]);
  }
  for (int level = bottom + 1; level <= top; ++level) {
    CoarserMoments((*levels)[level - 1], &(*levels)[level]);
  }
}

// The pyramid's levels first .. top over the whole image, into (*buffers).stored[0 .. top -
// first]. Level `first` is summed one row of its squares at a time, through the levels below it
// over that band of rows only, so those levels never exist for the whole image.
void BuildStoredLevels(const ColorRuns& colors, const cv::Mat& mask, const cv::Size& size,
                       int min_side, int first, int top, BuildBuffers* buffers) {
  std::vector<MomentGrid>& stored = buffers->stored;
  if (static_cast<int>(stored.size()) < top - first + 1) stored.resize(top - first + 1);
  const int band_side = min_side << first;
  stored[0].Reset(CeilDiv(size.width, band_side), CeilDiv(size.height, band_side));
  for (int row = 0; row < stored[0].rows; ++row) {
    const int y = row * band_side;
    const PixelArea band{colors, mask,
                         cv::Rect(0, y, size.width, std::min(band_side, size.height - y))};
    BuildPyramid(band, min_side, (min_side == 1 && first >= 1) ? 1 : 0, first, &buffers->run,
                 &buffers->band);
    const std::vector<Moments>& band_cells = buffers->band[first].cells;
    std::copy(band_cells.begin(), band_cells.end(), &stored[0].at(0, row));
  }
  for (int level = 1; level <= top - first; ++level)
    CoarserMoments(stored[level - 1], &stored[level]);
}

// Levels [first, first + grids.size()) of a pyramid whose squares tile the pixels from `origin`.
struct PyramidView {
  const std::vector<MomentGrid>& grids;
  int first;
  cv::Point origin;

  const MomentGrid& Level(int level) const { return grids[level - first]; }
};

// Walks the quad-tree top-down over the moment pyramid, emitting the leaves.
class QuadTreeWalker {
 public:
  QuadTreeWalker(const ColorRuns& colors, const cv::Mat& mask, const cv::Size& size,
                 const ImageGaussianOptions& options, BuildBuffers* buffers,
                 std::vector<ImageGaussian>* leaves)
      : colors_(colors),
        mask_(mask),
        size_(size),
        min_side_(options.min_leaf_size),
        max_spread_squared_(options.split_threshold * options.split_threshold +
                            kSpreadSquaredTolerance),
        buffers_(*buffers),
        leaves_(leaves) {}

  void WalkAllRoots(int first_stored, int top) {
    const PyramidView stored{buffers_.stored, first_stored, cv::Point(0, 0)};
    for (int row = 0; row < stored.Level(top).rows; ++row) {
      for (int col = 0; col < stored.Level(top).cols; ++col) Visit(stored, top, col, row);
    }
  }

 private:
  void Visit(const PyramidView& view, int level, int col, int row) {
    const Moments& square = view.Level(level).at(col, row);
    if (square.count == 0) return;
    const int side = min_side_ << level;
    const int64_t area = int64_t(side) * side;
    const cv::Point corner = view.origin + cv::Point(col * side, row * side);
    if (level == 0) {
      if (2 * square.count >= area) Emit(square, corner, side);
      return;
    }
    if (square.count == area && square.SpreadSquared() <= max_spread_squared_) {
      Emit(square, corner, side);
      return;
    }
    if (level == view.first) {
      SplitFromPixels(corner, level);
      return;
    }
    VisitQuarters(view, level - 1, col, row);
  }

  void VisitQuarters(const PyramidView& view, int quarter_level, int col, int row) {
    const MomentGrid& finer = view.Level(quarter_level);
    for (int child_row = 2 * row; child_row <= 2 * row + 1; ++child_row) {
      for (int child_col = 2 * col; child_col <= 2 * col + 1; ++child_col) {
        if (finer.Contains(child_col, child_row)) Visit(view, quarter_level, child_col, child_row);
      }
    }
  }

  // Splits the lowest stored square at `corner`: its levels below are summed from its pixels.
  // Squares of these levels never split into stored ones, so the block buffer is not reentered.
  void SplitFromPixels(const cv::Point& corner, int level) {
    const int side = min_side_ << level;
    const cv::Rect rect(corner.x, corner.y, std::min(side, size_.width - corner.x),
                        std::min(side, size_.height - corner.y));
    BuildPyramid(PixelArea{colors_, mask_, rect}, min_side_, 0, level - 1, &buffers_.run,
                 &buffers_.block);
    VisitQuarters(PyramidView{buffers_.block, 0, corner}, level - 1, 0, 0);
  }

  void Emit(const Moments& square, const cv::Point& corner, int side) {
    ImageGaussian leaf;
    const double centre_offset = 0.5 * (side - 1);
    leaf.x = static_cast<float>(double(corner.x) + centre_offset);
    leaf.y = static_cast<float>(double(corner.y) + centre_offset);
    leaf.sigma = 0.5f * side;
    for (int c = 0; c < 3; ++c) leaf.color[c] = static_cast<float>(square.sum[c] / square.count);
    leaves_->push_back(leaf);
  }

  const ColorRuns& colors_;
  const cv::Mat& mask_;
  const cv::Size size_;
  const int min_side_;
  const double max_spread_squared_;
  BuildBuffers& buffers_;
  std::vector<ImageGaussian>* leaves_;
};

void CheckImageAndMask(const cv::Mat& image, const cv::Mat& mask, const std::string& where) {
  Require(!image.empty(), where, "image is empty");
  Require(image.type() == CV_8UC3 || image.type() == CV_32FC3, where,
          "expected an 8-bit BGR image (CV_8UC3) or a converted colour image (CV_32FC3), got "
          "OpenCV type " +
              cv::typeToString(image.type()));
  if (mask.empty()) return;
  Require(mask.type() == CV_8UC1, where,
          "expected an 8-bit single-channel mask (CV_8UC1), got OpenCV type " +
              cv::typeToString(mask.type()));
  Require(mask.size() == image.size(), where,
          "mask is " + std::to_string(mask.cols) + "x" + std::to_string(mask.rows) +
              " pixels but the image is " + std::to_string(image.cols) + "x" +
              std::to_string(image.rows));
}

// The lowest level the pyramid stores: the first whose squares have kMinStoredSide pixels.
int FirstStoredLevel(const ImageGaussianOptions& options) {
  int level = 0;
  while (level < options.max_depth && (options.min_leaf_size << level) < kMinStoredSide) ++level;
  return level;
}

ImageGaussians BuildChecked(const cv::Mat& image, const cv::Mat& mask,
                            const ImageGaussianOptions& options, const std::string& where) {
  const ColorRuns colors(image, options.color_space, where);
  BuildBuffers& buffers = ThreadBuildBuffers();
  const int first_stored = FirstStoredLevel(options);
  BuildStoredLevels(colors, mask, image.size(), options.min_leaf_size, first_stored,
                    options.max_depth, &buffers);
  std::vector<ImageGaussian> leaves;
  leaves.reserve(size_t(CeilDiv(image.cols, options.min_leaf_size)) *
                 CeilDiv(image.rows, options.min_leaf_size) / 4);
  QuadTreeWalker(colors, mask, image.size(), options, &buffers, &leaves)
      .WalkAllRoots(first_stored, options.max_depth);
  return ImageGaussians(image.cols, image.rows, options.color_space, std::move(leaves), where);
}

bool IsFinite(const ImageGaussian& g) {
  return std::isfinite(g.x) && std::isfinite(g.y) && std::isfinite(g.color[0]) &&
         std::isfinite(g.color[1]) && std::isfinite(g.color[2]);
}

// Size classes are the binary exponents of sigma: sigma in [2^k, 2^(k+1)). Read from the bits
// of the (positive) float: std::ilogb is an out-of-line library call, once per Gaussian.
int SizeExponent(float sigma) {
  uint32_t bits;
  std::memcpy(&bits, &sigma, sizeof(bits));
  return static_cast<int>((bits >> 23) & 0xffu) - 127;
}

// The indices of `keys` ordered by key, in their given order within a key (*order), and where
// each key's run begins in that order (*begin, num_keys + 1 entries). Keys lie in [0, num_keys).
void CountingSort(const std::vector<int>& keys, int num_keys, std::vector<int>* begin,
                  std::vector<int>* order) {
  begin->assign(num_keys + 1, 0);
  for (int key : keys) ++(*begin)[key + 1];
  for (int key = 0; key < num_keys; ++key) (*begin)[key + 1] += (*begin)[key];
  std::vector<int> next(begin->begin(), begin->end() - 1);
  order->resize(keys.size());
  for (size_t i = 0; i < keys.size(); ++i) (*order)[next[keys[i]]++] = static_cast<int>(i);
}

// A query of CollectNear: the segment [start, end] (a point when they are equal) and the
// threshold base + sigma_factor * sigma_i^2 on the squared distance.
struct NearQuery {
  NearQuery(const Eigen::Vector2d& start, const Eigen::Vector2d& end, double base,
            double sigma_factor)
      : start(start),
        direction(end - start),
        length_squared(direction.squaredNorm()),
        is_point(!(length_squared > 0.0)),
        base(base),
        sigma_factor(sigma_factor) {}

  Eigen::Vector2d start;
  Eigen::Vector2d direction;
  double length_squared;
  bool is_point;
  double base;
  double sigma_factor;
};

// Whether Gaussians i and j (possibly the same) are within the query's reach, as a pair of lanes:
// two at a time in SIMD, and the clamp to the segment as max and min, with no branch on which end
// is nearest. The arithmetic is in double from the stored floats, operation for operation that of
// the nearest point of the segment, so that the same Gaussians pass at the boundary; Eigen's max
// and min take std::max and std::min's operand on ties and NaN, as std::clamp does. Inline: GCC
// would otherwise call it, reloading the query for every pair.
template <bool kSegment>
inline Eigen::Array<bool, 2, 1> WithinReach(const ImageGaussian* gaussians, int i, int j,
                                            const NearQuery& query) {
  Eigen::Array2d offset_x(double(gaussians[i].x), double(gaussians[j].x));
  Eigen::Array2d offset_y(double(gaussians[i].y), double(gaussians[j].y));
  offset_x -= query.start.x();
  offset_y -= query.start.y();
  if constexpr (kSegment) {
    const Eigen::Array2d along =
        (offset_x * query.direction.x() + offset_y * query.direction.y()) / query.length_squared;
    const Eigen::Array2d t = along.max(0.0).min(1.0);
    offset_x -= t * query.direction.x();
    offset_y -= t * query.direction.y();
  }
  const Eigen::Array2d sigma(double(gaussians[i].sigma), double(gaussians[j].sigma));
  return offset_x * offset_x + offset_y * offset_y <=
         query.base + query.sigma_factor * sigma * sigma;
}

// Writes the indices in [begin, stop) of the Gaussians within the query's reach to `out`, in
// order, and returns how many. Every index is written and kept by advancing past it: no branch
// on the test, whose outcome is close to a coin flip.
template <bool kSegment>
int ScanRun(const ImageGaussian* gaussians, int begin, int stop, const NearQuery& query, int* out) {
  int kept = 0;
  int i = begin;
  for (; i + 1 < stop; i += 2) {
    const Eigen::Array<bool, 2, 1> within = WithinReach<kSegment>(gaussians, i, i + 1, query);
    out[kept] = i;
    kept += within[0];
    out[kept] = i + 1;
    kept += within[1];
  }
  if (i < stop) {
    out[kept] = i;
    kept += WithinReach<kSegment>(gaussians, i, i, query)[0];
  }
  return kept;
}

}  // namespace

const OptionFields<ImageGaussianOptions>& ImageGaussianOptions::Fields() {
  static const OptionFields<ImageGaussianOptions> fields = [] {
    OptionFields<ImageGaussianOptions> f;
    f.AddEnum("color_space", &ImageGaussianOptions::color_space,
              "Colour space in which colours are averaged and compared (paper: hsv).");
    f.AddInt("max_depth", &ImageGaussianOptions::max_depth,
             "Quad-tree depth: leaves are min_leaf_size * 2^(max_depth - depth) pixels (paper: 8).",
             0, 16);
    f.AddInt("min_leaf_size", &ImageGaussianOptions::min_leaf_size,
             "Side of the smallest quad-tree leaf, pixels (its sigma is half of it).", 1,
             kMaxMinLeafSize);
    f.AddDouble("split_threshold", &ImageGaussianOptions::split_threshold,
                "A square is split while the RMS colour distance of its pixels to their mean "
                "exceeds this.",
                0.0, 10.0);
    return f;
  }();
  return fields;
}

void ImageGaussianOptions::Check() const {
  Fields().CheckValues(*this, "ImageGaussianOptions::");
  Require(min_leaf_size <= (kMaxRootSide >> max_depth), "ImageGaussianOptions::min_leaf_size",
          "min_leaf_size * 2^max_depth may not exceed 2^20, got " + std::to_string(min_leaf_size) +
              " * 2^" + std::to_string(max_depth));
}

ImageGaussians::ImageGaussians(int width, int height, ColorSpace color_space,
                               std::vector<ImageGaussian> gaussians, const std::string& where)
    : width_(width), height_(height), color_space_(color_space) {
  Require(width >= 0 && height >= 0, where, "negative image size");
  for (const ImageGaussian& g : gaussians) {
    // Plain ifs: the message is built only on failure, not once per Gaussian.
    if (!IsFinite(g)) throw Error(where, "image Gaussian with a non-finite mean or colour");
    if (!(std::isfinite(g.sigma) && g.sigma > 0.0f)) {
      throw Error(where,
                  "image Gaussian with sigma " + std::to_string(g.sigma) + "; must be positive");
    }
  }
  if (gaussians.empty()) return;

  std::vector<int> exponents(gaussians.size());
  for (size_t i = 0; i < gaussians.size(); ++i) exponents[i] = SizeExponent(gaussians[i].sigma);
  const auto extremes = std::minmax_element(exponents.begin(), exponents.end());
  const int lowest = *extremes.first, num_classes = *extremes.second - lowest + 1;
  for (int& exponent : exponents) exponent -= lowest;
  std::vector<int> class_begin, by_class;
  CountingSort(exponents, num_classes, &class_begin, &by_class);
  gaussians_.reserve(gaussians.size());
  for (size_t k = 0; k + 1 < class_begin.size(); ++k) {
    const int* members = by_class.data() + class_begin[k];
    const int count = class_begin[k + 1] - class_begin[k];
    if (count > 0) AppendSizeClass(gaussians, members, count, lowest + static_cast<int>(k));
  }
}

void ImageGaussians::AppendSizeClass(const std::vector<ImageGaussian>& all, const int* members,
                                     int count, int exponent) {
  SizeClass size_class;
  size_class.begin = static_cast<int>(gaussians_.size());
  float min_x = all[members[0]].x, max_x = min_x;
  float min_y = all[members[0]].y, max_y = min_y;
  for (int j = 0; j < count; ++j) {
    const ImageGaussian& g = all[members[j]];
    size_class.max_sigma = std::max(size_class.max_sigma, g.sigma);
    min_x = std::min(min_x, g.x);
    max_x = std::max(max_x, g.x);
    min_y = std::min(min_y, g.y);
    max_y = std::max(max_y, g.y);
  }
  // A cell the side of the class's smallest square holds about one quad-tree leaf; a class that
  // is sparse over its extent gets coarser cells, keeping the grid within ~4 cells per Gaussian.
  const double max_cells = 4.0 * count + 64.0;
  size_class.cell = std::ldexp(1.0, exponent + 1);
  while ((double(max_x - min_x) / size_class.cell + 1.0) *
             (double(max_y - min_y) / size_class.cell + 1.0) >
         max_cells) {
    size_class.cell *= 2.0;
  }
  size_class.origin_x = min_x;
  size_class.origin_y = min_y;
  size_class.cols = static_cast<int>((max_x - min_x) / size_class.cell) + 1;
  size_class.rows = static_cast<int>((max_y - min_y) / size_class.cell) + 1;

  // Sorted by cell: each cell's Gaussians, and each grid row's, end up contiguous.
  std::vector<int> cells(count), by_cell;
  for (int j = 0; j < count; ++j) cells[j] = size_class.CellOf(all[members[j]]);
  CountingSort(cells, size_class.cols * size_class.rows, &size_class.cell_begin, &by_cell);
  for (int& begin : size_class.cell_begin) begin += size_class.begin;
  for (int j : by_cell) gaussians_.push_back(all[members[j]]);
  classes_.push_back(std::move(size_class));
}

int ImageGaussians::SizeClass::CellOf(const ImageGaussian& g) const {
  const int col = std::min(cols - 1, static_cast<int>((g.x - origin_x) / cell));
  const int row = std::min(rows - 1, static_cast<int>((g.y - origin_y) / cell));
  return row * cols + col;
}

std::pair<int, int> ImageGaussians::SizeClass::CellRange(double low, double high, double origin,
                                                         int count) const {
  // Clamped in double first: a far-away query must not overflow the conversion to int.
  const auto clamped_cell = [&](double coordinate) {
    return static_cast<int>(
        std::clamp(std::floor((coordinate - origin) / cell), -1.0, static_cast<double>(count)));
  };
  return {std::max(0, clamped_cell(low)), std::min(count - 1, clamped_cell(high))};
}

void ImageGaussians::CollectNear(const Eigen::Vector2d& start, const Eigen::Vector2d& end,
                                 double base, double sigma_factor,
                                 std::vector<int>* indices) const {
  const NearQuery query(start, end, base, sigma_factor);
  const Eigen::Vector2d low = start.cwiseMin(end), high = start.cwiseMax(end);
  for (const SizeClass& size_class : classes_) {
    const double max_sigma = size_class.max_sigma;
    const double radius_squared = base + sigma_factor * max_sigma * max_sigma;
    if (!(radius_squared >= 0.0)) continue;
    const double radius = std::sqrt(radius_squared);
    const auto [col_first, col_last] = size_class.CellRange(low.x() - radius, high.x() + radius,
                                                            size_class.origin_x, size_class.cols);
    const auto [row_first, row_last] = size_class.CellRange(low.y() - radius, high.y() + radius,
                                                            size_class.origin_y, size_class.rows);
    // Room for every candidate, for ScanRun writes each one before it knows whether to keep it.
    int candidates = 0;
    for (int row = row_first; row <= row_last; ++row) {
      candidates += size_class.cell_begin[row * size_class.cols + col_last + 1] -
                    size_class.cell_begin[row * size_class.cols + col_first];
    }
    if (candidates == 0) continue;
    const size_t kept_before = indices->size();
    indices->resize(kept_before + candidates);
    int* out = indices->data() + kept_before;
    for (int row = row_first; row <= row_last; ++row) {
      // The cells of one grid row are contiguous in gaussians_.
      const int begin = size_class.cell_begin[row * size_class.cols + col_first];
      const int stop = size_class.cell_begin[row * size_class.cols + col_last + 1];
      out += query.is_point ? ScanRun<false>(gaussians_.data(), begin, stop, query, out)
                            : ScanRun<true>(gaussians_.data(), begin, stop, query, out);
    }
    indices->resize(out - indices->data());
  }
}

void ImageGaussians::FindWithin(const Eigen::Vector2d& point, double radius,
                                std::vector<int>* indices) const {
  indices->clear();
  if (radius >= 0.0) CollectNear(point, point, radius * radius, 0.0, indices);
}

void ImageGaussians::FindReaching(const Eigen::Vector2d& point, double sigma, double cutoff,
                                  std::vector<int>* indices) const {
  FindReachingSegment(point, point, sigma, cutoff, indices);
}

void ImageGaussians::FindReachingSegment(const Eigen::Vector2d& start, const Eigen::Vector2d& end,
                                         double sigma, double cutoff,
                                         std::vector<int>* indices) const {
  indices->clear();
  const double cutoff_squared = cutoff * cutoff;
  CollectNear(start, end, cutoff_squared * sigma * sigma, cutoff_squared, indices);
}

ImageGaussians BuildImageGaussians(const cv::Mat& image, const cv::Mat& mask,
                                   const ImageGaussianOptions& options, const std::string& where) {
  options.Check();
  CheckImageAndMask(image, mask, where);
  return BuildChecked(image, mask, options, where);
}

std::vector<ImageGaussians> BuildFrameImageGaussians(const std::vector<cv::Mat>& images,
                                                     const std::vector<cv::Mat>& masks,
                                                     const ImageGaussianOptions& options,
                                                     const std::vector<std::string>& names) {
  options.Check();
  Require(names.size() == images.size(), "BuildFrameImageGaussians",
          std::to_string(images.size()) + " images but " + std::to_string(names.size()) + " names");
  Require(masks.empty() || masks.size() == images.size(), "BuildFrameImageGaussians",
          std::to_string(images.size()) + " images but " + std::to_string(masks.size()) + " masks");
  static const cv::Mat kNoMask;
  const auto mask_of = [&masks](size_t i) -> const cv::Mat& {
    return masks.empty() ? kNoMask : masks[i];
  };
  for (size_t i = 0; i < images.size(); ++i) CheckImageAndMask(images[i], mask_of(i), names[i]);

  std::vector<ImageGaussians> result(images.size());
  ParallelFor(static_cast<int>(images.size()),
              [&](int i) { result[i] = BuildChecked(images[i], mask_of(i), options, names[i]); });
  return result;
}

}  // namespace finecap
