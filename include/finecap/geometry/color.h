// Colour spaces in which finecap compares and averages colours.
//
// The energy compares colours with the Euclidean distance and a Wendland cut-off (the paper: HSV,
// D = 0.05). For one threshold to mean about the same thing in every space, each space is embedded
// in R^3 so that every channel spans an interval of length about one and the Euclidean distance
// of the embedded coordinates is the colour distance:
//
// * kHsv ("hsv"): the HSV cone, (x, y, z) = (0.5 * C * cos(h), 0.5 * C * sin(h), V), where
//   V = max(R, G, B) / 255, C = (max - min) / 255 = S * V is the chroma and h is HSV's (hexagonal)
//   hue angle, red at 0, green at 120, blue at 240 degrees. Why not the raw (h, s, v) triple:
//   hue is an angle, so 359 and 1 degree must be close, which the point on the circle gives; and
//   hue (and saturation) mean nothing for grey or dark pixels, where sensor noise flips the hue at
//   random. Scaling the hue circle by the chroma S * V makes the hue count in proportion to how
//   colourful the pixel is: greys of any hue lie on the axis (0, 0, V), and all colours collapse
//   towards black. The chroma plane spans [-0.5, 0.5]^2 and V spans [0, 1]. Consequence for the
//   threshold: between two saturated bright colours a distance of 0.05 is a hue difference of
//   about 5.7 degrees; between greys it is a difference of 0.05 in value (~13 grey levels).
// * kNormalizedRgb ("normalized_rgb"): (R, G, B) / 255, each channel in [0, 1]. It is linear RGB
//   in the camera's encoding, not the intensity-free chromaticity R / (R + G + B).
// * kLab ("lab"): CIE L*a*b* (sRGB input, D65 white, as OpenCV's COLOR_BGR2Lab) divided by 100:
//   L in [0, 1], a and b in about [-1, 1]. One uniform scale keeps Lab's perceptual distance, so
//   a distance of 0.05 is Delta E (CIE76) = 5.
// * kChromaticity ("chromaticity"): (R, G, B) / (R + G + B + 38), each in [0, 1]: the colour
//   without its brightness, so that shading (a fold turned away from the light is darker, the
//   same cloth under a changed light) does not count as a colour difference. The constant 38
//   (3 x 5 % of 255) makes dark pixels, whose chromaticity is mostly noise, fade towards black.
//   A texture that varies only in brightness (grey print) looks uniform in this space.
//
// Averaging. A mean colour is the mean of the embedded coordinates (convert first, then average).
// That mean minimises the sum of squared colour distances to the pixels, so averaging agrees with
// the distance in every space; in HSV it also avoids averaging angles (the mean of 359 and 1 degree
// is 0, not 180). The mean of embedded HSV points lies inside the cone but need not be the image of
// any 8-bit colour; it is a valid point to measure distances from.
#ifndef FINECAP_GEOMETRY_COLOR_H_
#define FINECAP_GEOMETRY_COLOR_H_

#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "finecap/util/enum_names.h"

namespace finecap {

enum class ColorSpace { kHsv, kNormalizedRgb, kLab, kChromaticity };
// The names used in config files: "hsv", "normalized_rgb", "lab" and "chromaticity".
const std::vector<EnumName<ColorSpace>>& EnumNames(ColorSpace);

// EnumToString(space).
std::string ColorSpaceName(ColorSpace space);

// Inverse of ColorSpaceName (exact, lower case). Throws Error(where, ...) listing the valid names
// for any other string; `where` is the config key or file the name came from.
ColorSpace ParseColorSpace(const std::string& name, const std::string& where);

// The embedded coordinates (see above) of one 8-bit colour given in OpenCV's BGR order.
Eigen::Vector3f ConvertColor(const cv::Vec3b& bgr, ColorSpace space);

// The embedded coordinates of every pixel of an 8-bit BGR image (CV_8UC3), as a CV_32FC3 image of
// the same size; pixel (x, y) equals ConvertColor(bgr(x, y)) (within float rounding for kLab).
// Throws Error(where, ...) when the image is empty or not CV_8UC3; `where` names the image.
cv::Mat ConvertImage(const cv::Mat& bgr, ColorSpace space, const std::string& where);

// Whether `space` is converted pixel by pixel with no vectorised library path (kHsv,
// kChromaticity): ConvertPixels then gives, for any run of pixels, exactly the values
// ConvertImage gives them, so an image may be converted a row, or a part of a row, at a time.
bool ConvertsPixelByPixel(ColorSpace space);

// The embedded coordinates of the `count` 8-bit BGR pixels at `bgr`, into out[0, count): bit for
// bit ConvertImage's values for these pixels. Throws Error for a space that is not
// ConvertsPixelByPixel (OpenCV converts those, and its vectorised code may round a pixel
// differently depending on where a run of pixels starts).
void ConvertPixels(const cv::Vec3b* bgr, int count, ColorSpace space, cv::Vec3f* out);

// The distance between two embedded colours of the same space: the Euclidean norm of a - b in
// every space above (the space is an argument so that a non-Euclidean metric could be added
// without changing callers). Symmetric, zero only for equal colours, about [0, 1.7] in range.
double ColorDistance(const Eigen::Vector3f& a, const Eigen::Vector3f& b, ColorSpace space);

}  // namespace finecap

#endif  // FINECAP_GEOMETRY_COLOR_H_
