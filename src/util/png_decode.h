// A fast decoder for the PNG files cameras and renderers write most: 8 bits per channel, grey,
// grey with alpha, RGB or RGBA, not interlaced. The frame loop decodes every camera's image of
// every frame, and for such files most of a general decoder's time goes to zlib's inflate:
// libdeflate inflates the whole image data in one call, two to three times as fast, and the rows'
// filters are undone in place.
//
// The result is what OpenCV's imdecode gives with IMREAD_COLOR: 8-bit BGR, grey replicated into
// the three channels, alpha dropped (not composited), no gamma applied. Files of any other kind
// (palette, 1/2/4 or 16 bits per channel, interlaced, an unknown critical chunk) are left to the
// general decoder (libpng, image_codec.h). Chunk checksums are not checked: the image data's own
// Adler-32 checksum, which libdeflate checks, covers the pixels, and the other chunks' contents are
// not used.
#ifndef FINECAP_SRC_UTIL_PNG_DECODE_H_
#define FINECAP_SRC_UTIL_PNG_DECODE_H_

#include <string>

#include <opencv2/core.hpp>

namespace finecap {
namespace internal {

enum class PngDecodeResult {
  kDecoded,      // *image holds the BGR pixels.
  kUnsupported,  // Not a kind this decoder reads: use a general decoder.
  kDamaged,      // A PNG of a supported kind that cannot be decoded; *problem says why.
};

// Decodes the PNG file held in `bytes`.
PngDecodeResult DecodeCommonPng(const std::string& bytes, cv::Mat* image, std::string* problem);

}  // namespace internal
}  // namespace finecap

#endif  // FINECAP_SRC_UTIL_PNG_DECODE_H_
