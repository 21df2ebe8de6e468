// Bilinear reads of a three-channel float image (CV_32FC3) and of their derivative along a
// direction of the image: what the detail stage reads the images with at the surface's samples,
// and what the alignment of the cameras before that stage reads them with.
#ifndef FINECAP_GEOMETRY_BILINEAR_H_
#define FINECAP_GEOMETRY_BILINEAR_H_

#include <algorithm>

#include <opencv2/core.hpp>

namespace finecap {

// Where a bilinear read of a CV_32FC3 image at (x, y) reads (pixel centres at integers): the
// first of the four pixels around it, its offsets u, v from that pixel, and the direction
// (dx, dy) along which the read's derivative is taken (that of the interpolant, so that it is
// exact for the function the solvers see). Outside the image the position is clamped to its
// border, where the derivative across the border is zero.
struct BilinearCell {
  const float* top;  // The row below it is `row_step` floats on.
  double u, v, dx, dy;
};

inline BilinearCell CellAt(const cv::Mat& image, double x, double y, double dx, double dy) {
  const double max_x = image.cols - 1.0, max_y = image.rows - 1.0;
  if (!(x > 0.0 && x < max_x)) {
    x = std::clamp(x, 0.0, max_x);
    dx = 0.0;
  }
  if (!(y > 0.0 && y < max_y)) {
    y = std::clamp(y, 0.0, max_y);
    dy = 0.0;
  }
  const int x0 = std::min(static_cast<int>(x), image.cols - 2);
  const int y0 = std::min(static_cast<int>(y), image.rows - 2);
  return {image.ptr<float>(y0) + 3 * x0, x - x0, y - y0, dx, dy};
}

// Channel `channel` of the bilinear interpolant at `cell`: its value and its derivatives along the
// image's x and y; `row_step` floats from one image row to the next.
struct CellChannelRead {
  double color, along_x, along_y;
};
inline CellChannelRead ReadCellChannel(const BilinearCell& cell, long row_step, int channel) {
  const float* top = cell.top + channel;
  const float* bottom = top + row_step;
  const double c00 = top[0], c10 = top[3];
  const double c01 = bottom[0], c11 = bottom[3];
  const double along_top = c10 - c00, along_bottom = c11 - c01;
  const double upper = c00 + cell.u * along_top, lower = c01 + cell.u * along_bottom;
  return {upper + cell.v * (lower - upper), along_top + cell.v * (along_bottom - along_top),
          lower - upper};
}

// Writes the bilinear interpolant at `cell` (three channels) to `color` and, when `derivative` is
// not null, its derivative along the cell's direction to it; `row_step` floats from one image row
// to the next.
inline void ReadCell(const BilinearCell& cell, long row_step, double* color, double* derivative) {
  for (int channel = 0; channel < 3; ++channel) {
    const CellChannelRead read = ReadCellChannel(cell, row_step, channel);
    color[channel] = read.color;
    if (derivative != nullptr) {
      derivative[channel] = cell.dx * read.along_x + cell.dy * read.along_y;
    }
  }
}

// The derivatives of the bilinear interpolant at `cell` along the image's x and y (three channels
// each), times the cell's dx and dy: CellAt with dx = dy = 1 gives the gradient, zero across the
// image's border. The read of ReadCell along (1, 0) and (0, 1) at once.
inline void ReadCellGradient(const BilinearCell& cell, long row_step, double* along_x,
                             double* along_y) {
  for (int channel = 0; channel < 3; ++channel) {
    const CellChannelRead read = ReadCellChannel(cell, row_step, channel);
    along_x[channel] = cell.dx * read.along_x;
    along_y[channel] = cell.dy * read.along_y;
  }
}

// Floats from one row of a CV_32FC3 image to the next.
inline long RowStep(const cv::Mat& image) { return static_cast<long>(image.step1()); }

// The bilinear interpolant of a CV_32FC3 image at (x, y), as CellAt and ReadCell.
inline void ReadBilinear(const cv::Mat& image, double x, double y, double dx, double dy,
                         double* color, double* derivative) {
  ReadCell(CellAt(image, x, y, dx, dy), RowStep(image), color, derivative);
}

}  // namespace finecap

#endif  // FINECAP_GEOMETRY_BILINEAR_H_
