// Procedural cloth prints: plaid, stripes, printed motifs and noise, with metric feature sizes
// (0.5 to 5 cm) so that 7 mm surface Gaussians see colour change, and seamless around u.
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "synth/synth_internal.h"

namespace finecap {
namespace synth_internal {
namespace {

using Rgb = cv::Vec3f;

Rgb HsvToRgb(double hue, double saturation, double value) {
  const double h = std::fmod(hue, 1.0) * 6.0;
  const int sector = static_cast<int>(h);
  const double f = h - sector;
  const float p = value * (1 - saturation);
  const float q = value * (1 - saturation * f);
  const float t = value * (1 - saturation * (1 - f));
  const float v = value;
  switch (sector % 6) {
    case 0:
      return {v, t, p};
    case 1:
      return {q, v, p};
    case 2:
      return {p, v, t};
    case 3:
      return {p, q, v};
    case 4:
      return {t, p, v};
    default:
      return {v, p, q};
  }
}

// Saturated colours of well-separated hues, and some darker and lighter ones.
std::vector<Rgb> MakePalette(std::mt19937_64& rng, int size) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double first_hue = unit(rng);
  std::vector<Rgb> palette;
  for (int i = 0; i < size; ++i) {
    const double hue = first_hue + 0.618034 * i + 0.08 * unit(rng);
    palette.push_back(HsvToRgb(hue, 0.4 + 0.5 * unit(rng), 0.45 + 0.55 * unit(rng)));
  }
  return palette;
}

// A repeating sequence of coloured stripes of random widths along one coordinate (metres).
class StripeSequence {
 public:
  StripeSequence(std::mt19937_64& rng, const std::vector<Rgb>& palette, double repeat,
                 double min_width, double max_width) {
    std::uniform_real_distribution<double> width(min_width, max_width);
    std::uniform_int_distribution<int> pick(0, static_cast<int>(palette.size()) - 1);
    double end = 0.0;
    while (end < repeat) {
      end = std::min(repeat, end + width(rng));
      ends_.push_back(end);
      colors_.push_back(palette[pick(rng)]);
    }
    repeat_ = end;
  }
  double repeat() const { return repeat_; }

  Rgb At(double coordinate) const {
    double q = std::fmod(coordinate, repeat_);
    if (q < 0.0) q += repeat_;
    const size_t k = std::upper_bound(ends_.begin(), ends_.end(), q) - ends_.begin();
    return colors_[std::min(k, colors_.size() - 1)];
  }

 private:
  std::vector<double> ends_;
  std::vector<Rgb> colors_;
  double repeat_ = 1.0;
};

// A repeat length near `wanted` that fits a whole number of times into `span`.
double FittingRepeat(double span, double wanted) {
  return span / std::max(1.0, std::round(span / wanted));
}

// Value noise in [0, 1], several octaves, periodic in x with period `circumference` metres.
class PeriodicNoise {
 public:
  PeriodicNoise(std::mt19937_64& rng, double circumference, double height, double cell) {
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (int octave = 0; octave < kOctaves; ++octave) {
      const double size = cell / (1 << octave);
      Lattice lattice;
      lattice.columns = std::max(1, static_cast<int>(std::round(circumference / size)));
      lattice.rows = static_cast<int>(std::ceil(height / size)) + 2;
      lattice.cell_x = circumference / lattice.columns;
      lattice.cell_y = size;
      lattice.values.resize(lattice.columns * lattice.rows);
      for (double& value : lattice.values) value = unit(rng);
      lattices_.push_back(lattice);
    }
  }

  double At(double x, double y) const {
    double sum = 0.0;
    double weight = 1.0;
    double total = 0.0;
    for (const Lattice& lattice : lattices_) {
      sum += weight * lattice.At(x, y);
      total += weight;
      weight *= 0.55;
    }
    return sum / total;
  }

 private:
  static constexpr int kOctaves = 3;
  struct Lattice {
    int columns = 1;
    int rows = 1;
    double cell_x = 1.0;
    double cell_y = 1.0;
    std::vector<double> values;

    double At(double x, double y) const {
      const double gx = x / cell_x;
      const double gy = std::clamp(y / cell_y, 0.0, rows - 1.001);
      const int x0 = static_cast<int>(std::floor(gx));
      const int y0 = static_cast<int>(gy);
      const double ax = Smooth(gx - x0);
      const double ay = Smooth(gy - y0);
      auto value = [&](int column, int row) {
        return values[row * columns + ((column % columns) + columns) % columns];
      };
      return (1 - ay) * ((1 - ax) * value(x0, y0) + ax * value(x0 + 1, y0)) +
             ay * ((1 - ax) * value(x0, y0 + 1) + ax * value(x0 + 1, y0 + 1));
    }
    static double Smooth(double a) { return a * a * (3.0 - 2.0 * a); }
  };
  std::vector<Lattice> lattices_;
};

// Fills an RGB float texture texel by texel from f(x metres, y metres).
template <typename Pattern>
void Fill(cv::Mat* texture, double circumference, double height, const Pattern& pattern) {
#pragma omp parallel for
  for (int row = 0; row < texture->rows; ++row) {
    Rgb* texels = texture->ptr<Rgb>(row);
    const double y = (row + 0.5) / texture->rows * height;
    for (int column = 0; column < texture->cols; ++column) {
      texels[column] = pattern((column + 0.5) / texture->cols * circumference, y);
    }
  }
}

// Scattered flowers (a disc ringed by petals), 0.8 to 2.2 cm across, about one per
// `spacing` x `spacing` metres; drawn again one texture width to each side so they wrap.
void DrawPrints(cv::Mat* texture, std::mt19937_64& rng, const std::vector<Rgb>& palette,
                double circumference, double height, double spacing) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::uniform_int_distribution<int> pick(0, static_cast<int>(palette.size()) - 1);
  const double texels_per_metre_x = texture->cols / circumference;
  const double texels_per_metre_y = texture->rows / height;
  const int count = static_cast<int>(circumference * height / (spacing * spacing)) + 1;
  for (int n = 0; n < count; ++n) {
    const double x = unit(rng) * texture->cols;
    const double y = unit(rng) * texture->rows;
    const double radius = 0.004 + 0.007 * unit(rng);
    const Rgb petal = palette[pick(rng)];
    const Rgb heart = palette[pick(rng)];
    const int petals = 4 + static_cast<int>(4 * unit(rng));
    const double turn = unit(rng) * 2.0 * M_PI;
    for (double shift : {-1.0, 0.0, 1.0}) {
      const double cx = x + shift * texture->cols;
      for (int k = 0; k < petals; ++k) {
        const double angle = turn + 2.0 * M_PI * k / petals;
        const cv::Point2d centre(cx + radius * std::cos(angle) * texels_per_metre_x,
                                 y + radius * std::sin(angle) * texels_per_metre_y);
        cv::ellipse(*texture,
                    cv::RotatedRect(centre,
                                    cv::Size2f(1.4 * radius * texels_per_metre_x,
                                               0.7 * radius * texels_per_metre_y),
                                    angle * 180.0 / M_PI),
                    cv::Scalar(petal[0], petal[1], petal[2]), cv::FILLED, cv::LINE_AA);
      }
      cv::ellipse(
          *texture, cv::Point2d(cx, y),
          cv::Size2d(0.45 * radius * texels_per_metre_x, 0.45 * radius * texels_per_metre_y), 0.0,
          0.0, 360.0, cv::Scalar(heart[0], heart[1], heart[2]), cv::FILLED, cv::LINE_AA);
    }
  }
}

void PaintPattern(const TextureOptions& options, double circumference, double height,
                  std::mt19937_64& rng, cv::Mat* texture) {
  const std::vector<Rgb> palette = MakePalette(rng, 6);
  const PeriodicNoise noise(rng, circumference, height, 0.04);
  const StripeSequence warp(rng, palette, FittingRepeat(circumference, 0.12), 0.004, 0.03);
  const StripeSequence weft(rng, palette, 0.12, 0.004, 0.03);
  const auto plaid = [&](double x, double y) { return 0.5f * (warp.At(x) + weft.At(y)); };
  if (options.pattern == TexturePattern::kPlaid) {
    Fill(texture, circumference, height, plaid);
  } else if (options.pattern == TexturePattern::kStripes) {
    // Diagonal stripes at 30 degrees whose repeat fits around the subject.
    const double slope = std::tan(M_PI / 6.0);
    const StripeSequence diagonal(rng, palette, FittingRepeat(circumference, 0.1), 0.005, 0.025);
    Fill(texture, circumference, height,
         [&](double x, double y) { return diagonal.At(x + slope * y); });
  } else if (options.pattern == TexturePattern::kNoise) {
    const PeriodicNoise second(rng, circumference, height, 0.025);
    Fill(texture, circumference, height, [&](double x, double y) {
      const float a = static_cast<float>(noise.At(x, y));
      const float b = static_cast<float>(second.At(x, y));
      return a * palette[0] + (1.0f - a) * palette[1] + (b - 0.5f) * palette[2];
    });
  } else if (options.pattern == TexturePattern::kPrint) {
    texture->setTo(cv::Scalar(palette[0][0], palette[0][1], palette[0][2]));
    DrawPrints(texture, rng, palette, circumference, height, 0.035);
  } else {  // kMixed
    Fill(texture, circumference, height, [&](double x, double y) {
      return plaid(x, y) * static_cast<float>(0.6 + 0.8 * noise.At(x, y));
    });
    DrawPrints(texture, rng, palette, circumference, height, 0.06);
  }
}

}  // namespace

cv::Mat MakeClothTexture(const TextureOptions& options, double circumference, double surface_height,
                         std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  cv::Mat texture(options.height, options.width, CV_32FC3);
  PaintPattern(options, circumference, surface_height, rng, &texture);
  if (options.textureless_end > options.textureless_begin) {
    const int first = static_cast<int>(std::floor(options.textureless_begin * texture.rows));
    const int last = static_cast<int>(std::ceil(options.textureless_end * texture.rows));
    const Eigen::Vector3d& plain = options.textureless_color;
    texture.rowRange(std::max(0, first), std::min(texture.rows, last))
        .setTo(cv::Scalar(plain.x(), plain.y(), plain.z()));
  }
  cv::Mat bgr;
  texture.convertTo(texture, CV_8UC3, 255.0);
  cv::cvtColor(texture, bgr, cv::COLOR_RGB2BGR);
  return bgr;
}

}  // namespace synth_internal
}  // namespace finecap
