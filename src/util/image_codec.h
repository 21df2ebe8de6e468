// PNG and JPEG, read and written with libpng and libjpeg-turbo directly (not part of the public
// API). OpenCV's imgcodecs module would do the same, but it links GDAL and ~140 shared libraries
// that every start of finecap would load for two codecs.
//
// Decoding gives what cv::imdecode(bytes, cv::IMREAD_COLOR | cv::IMREAD_IGNORE_ORIENTATION)
// gives, pixel for pixel, with the same libraries underneath: an 8-bit, 3-channel BGR image.
//   PNG: palette and grey expanded to three channels (1-, 2- and 4-bit grey to 8 bits first),
//        16-bit samples cut to their high byte, alpha and tRNS transparency dropped (not
//        composited on a background).
//   JPEG: grey and YCbCr converted by libjpeg-turbo (islow DCT, fancy upsampling, its defaults);
//         CMYK and YCCK (Adobe, inverted) converted as OpenCV does.
// The PNG files of 8 bits per channel that cameras and renderers write most are inflated by
// libdeflate instead of libpng's zlib (png_decode.h), to the same pixels, in a third of the time.
// The EXIF orientation tag is ignored, unlike IMREAD_COLOR alone: a camera is calibrated on the
// pixels its images store, and an image turned upright by its tag would no longer match its
// calibration (COLMAP reads images the same way).
#ifndef FINECAP_SRC_UTIL_IMAGE_CODEC_H_
#define FINECAP_SRC_UTIL_IMAGE_CODEC_H_

#include <string>

#include <opencv2/core.hpp>

namespace finecap {
namespace internal {

// Decodes the PNG or JPEG image in `bytes` (told apart by its signature) to CV_8UC3 BGR. Throws
// Error(path, "cannot decode the image: ...") when it is neither, damaged or truncated (a JPEG
// whose entropy-coded data merely stops is filled grey by libjpeg: see the caller's end-marker
// check), or larger than 2^20 pixels a side or 2^30 in all (OpenCV's limits).
cv::Mat DecodeImage(const std::string& bytes, const std::string& path);

// `image` (8- or 16-bit, 1, 3 or 4 channels, BGR(A) order, any row stride) as PNG bytes, encoded
// as cv::imencode(".png", image) does by default (SUB filter, zlib level 1, RLE strategy): fast,
// and byte-identical to OpenCV's with the same libpng and zlib. Throws Error(where, ...) for any
// other type.
std::string EncodePng(const cv::Mat& image, const std::string& where);

}  // namespace internal
}  // namespace finecap

#endif  // FINECAP_SRC_UTIL_IMAGE_CODEC_H_
