#include "util/image_codec.h"

#include <csetjmp>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <vector>

// jpeglib.h needs size_t and FILE declared before it.
#include <jpeglib.h>
#include <png.h>
#include <zlib.h>

#include "finecap/util/error.h"
#include "util/png_decode.h"

namespace finecap {
namespace internal {
namespace {

// OpenCV's limits on a decoded image (CV_IO_MAX_IMAGE_WIDTH, _HEIGHT, _PIXELS), so that a damaged
// header cannot ask for terabytes.
constexpr uint64_t kMaxSide = uint64_t{1} << 20;
constexpr uint64_t kMaxPixels = uint64_t{1} << 30;

bool SizeWithinLimits(uint64_t width, uint64_t height) {
  return width > 0 && height > 0 && width <= kMaxSide && height <= kMaxSide &&
         width * height <= kMaxPixels;
}

constexpr char kTooLarge[] = "its size exceeds 2^20 pixels a side or 2^30 in all";

bool StartsWith(const std::string& bytes, const char* prefix, size_t length) {
  return bytes.size() >= length && bytes.compare(0, length, prefix, length) == 0;
}

bool IsPng(const std::string& bytes) { return StartsWith(bytes, "\x89PNG\r\n\x1a\n", 8); }
bool IsJpeg(const std::string& bytes) { return StartsWith(bytes, "\xFF\xD8", 2); }

Error DecodeError(const std::string& path, const char* reason) {
  return Error(path, std::string("cannot decode the image: ") + reason);
}

// ---------------------------------------------------------------------------------------------
// PNG

// What libpng reads from and where it reports: the bytes, the read position, the error message.
struct PngStream {
  const std::string* bytes = nullptr;
  size_t offset = 0;
  std::string* output = nullptr;  // Encoding: the PNG so far.
  char error[256] = "";
};

// libpng's error callback must not return: it keeps the message and jumps back to the setjmp of
// the call that failed.
[[noreturn]] void OnPngError(png_structp png, png_const_charp message) {
  auto* stream = static_cast<PngStream*>(png_get_error_ptr(png));
  std::snprintf(stream->error, sizeof(stream->error), "%s", message);
  png_longjmp(png, 1);
}

// Warnings (an sRGB profile libpng knows to be wrong, a damaged ancillary chunk) leave the pixels
// intact; the library prints nothing of its own.
void IgnorePngWarning(png_structp, png_const_charp) {}

void ReadPngBytes(png_structp png, png_bytep out, size_t count) {
  auto* stream = static_cast<PngStream*>(png_get_io_ptr(png));
  if (count > stream->bytes->size() - stream->offset) png_error(png, "the PNG data ends early");
  std::memcpy(out, stream->bytes->data() + stream->offset, count);
  stream->offset += count;
}

void AppendPngBytes(png_structp png, png_bytep data, size_t count) {
  static_cast<PngStream*>(png_get_io_ptr(png))
      ->output->append(reinterpret_cast<char*>(data), count);
}

void FlushNothing(png_structp) {}

// Destroys libpng's structures on every way out, the jump included.
struct PngReadStructs {
  png_structp png = nullptr;
  png_infop info = nullptr;
  ~PngReadStructs() { png_destroy_read_struct(&png, &info, nullptr); }
};

struct PngWriteStructs {
  png_structp png = nullptr;
  png_infop info = nullptr;
  ~PngWriteStructs() { png_destroy_write_struct(&png, &info); }
};

// The libpng calls of a decode, between the setjmp that an error jumps back to and its return:
// nothing declared here owns memory, so the jump leaks nothing (the image and the row pointers
// belong to the caller). The transformations are OpenCV 4.6's for IMREAD_COLOR, in its order.
bool ReadPng(png_structp png, png_infop info, cv::Mat* image, std::vector<png_bytep>* rows) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_read_info(png, info);
  png_uint_32 width = 0, height = 0;
  int bit_depth = 0, color_type = 0;
  png_get_IHDR(png, info, &width, &height, &bit_depth, &color_type, nullptr, nullptr, nullptr);
  if (!SizeWithinLimits(width, height)) png_error(png, kTooLarge);
  if (bit_depth == 16) png_set_strip_16(png);  // The high byte, as OpenCV.
  png_set_strip_alpha(png);
  if (color_type == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if ((color_type & PNG_COLOR_MASK_COLOR) == 0 && bit_depth < 8) {
    png_set_expand_gray_1_2_4_to_8(png);
  }
  if (color_type & PNG_COLOR_MASK_COLOR) {
    png_set_bgr(png);
  } else {
    png_set_gray_to_rgb(png);
  }
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  if (png_get_rowbytes(png, info) != 3 * static_cast<size_t>(width)) {
    png_error(png, "unexpected pixel layout after conversion to BGR");
  }
  image->create(static_cast<int>(height), static_cast<int>(width), CV_8UC3);
  rows->resize(height);
  for (png_uint_32 y = 0; y < height; ++y) (*rows)[y] = image->ptr(static_cast<int>(y));
  png_read_image(png, rows->data());
  png_read_end(png, nullptr);
  return true;
}

cv::Mat DecodePng(const std::string& bytes, const std::string& path) {
  PngStream stream;
  stream.bytes = &bytes;
  PngReadStructs structs;
  structs.png =
      png_create_read_struct(PNG_LIBPNG_VER_STRING, &stream, OnPngError, IgnorePngWarning);
  if (structs.png != nullptr) structs.info = png_create_info_struct(structs.png);
  if (structs.info == nullptr) throw DecodeError(path, "out of memory");
  png_set_read_fn(structs.png, &stream, ReadPngBytes);
  cv::Mat image;
  std::vector<png_bytep> rows;
  if (!ReadPng(structs.png, structs.info, &image, &rows)) throw DecodeError(path, stream.error);
  return image;
}

bool IsLittleEndian() {
  const uint16_t one = 1;
  unsigned char first = 0;
  std::memcpy(&first, &one, 1);
  return first == 1;
}

// As ReadPng, for the encoder: OpenCV 4.6's default settings and calls, in its order.
bool WritePng(png_structp png, png_infop info, const cv::Mat& image, std::vector<png_bytep>* rows) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
  png_set_compression_level(png, Z_BEST_SPEED);
  png_set_compression_strategy(png, Z_RLE);
  const int channels = image.channels();
  const int color_type = channels == 1   ? PNG_COLOR_TYPE_GRAY
                         : channels == 3 ? PNG_COLOR_TYPE_RGB
                                         : PNG_COLOR_TYPE_RGB_ALPHA;
  png_set_IHDR(png, info, image.cols, image.rows, image.depth() == CV_8U ? 8 : 16, color_type,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  png_set_bgr(png);
  if (IsLittleEndian()) png_set_swap(png);  // PNG's 16-bit samples are big-endian.
  rows->resize(image.rows);
  for (int y = 0; y < image.rows; ++y) (*rows)[y] = const_cast<png_bytep>(image.ptr(y));
  png_write_image(png, rows->data());
  png_write_end(png, info);
  return true;
}

// ---------------------------------------------------------------------------------------------
// JPEG

// libjpeg's error manager, extended with where to jump and the message. `base` comes first, so
// that the j_common_ptr's `err` that libjpeg passes to the callbacks converts back.
struct JpegErrors {
  jpeg_error_mgr base;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX] = "";
};

// libjpeg's default error_exit calls exit(): this one keeps the message and jumps back instead.
[[noreturn]] void OnJpegError(j_common_ptr cinfo) {
  auto* errors = reinterpret_cast<JpegErrors*>(cinfo->err);
  (*cinfo->err->format_message)(cinfo, errors->message);
  std::longjmp(errors->jump, 1);
}

// libjpeg's warnings ("Corrupt JPEG data: extraneous bytes before marker", common in cameras'
// files that decode fine) would go to stderr; the library prints nothing of its own.
void IgnoreJpegMessage(j_common_ptr) {}

[[noreturn]] void FailJpeg(JpegErrors* errors, const char* message) {
  std::snprintf(errors->message, sizeof(errors->message), "%s", message);
  std::longjmp(errors->jump, 1);
}

// The libjpeg calls of a decode, between the setjmp and its return, as ReadPng. A 4-component
// (CMYK, YCCK) image is read as CMYK into `cmyk`, which libjpeg-turbo 2.1 cannot turn into BGR;
// any other straight into `image` as BGR. OpenCV 4.6 reads both the same way.
bool ReadJpeg(jpeg_decompress_struct* cinfo, JpegErrors* errors, const std::string& bytes,
              cv::Mat* image, cv::Mat* cmyk) {
  if (setjmp(errors->jump)) return false;
  jpeg_create_decompress(cinfo);
  jpeg_mem_src(cinfo, reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size());
  jpeg_read_header(cinfo, TRUE);
  if (!SizeWithinLimits(cinfo->image_width, cinfo->image_height)) FailJpeg(errors, kTooLarge);
  cinfo->out_color_space = cinfo->num_components == 4 ? JCS_CMYK : JCS_EXT_BGR;
  jpeg_start_decompress(cinfo);
  cv::Mat* target = image;
  if (cinfo->out_color_space == JCS_CMYK) {
    cmyk->create(cinfo->output_height, cinfo->output_width, CV_8UC4);
    target = cmyk;
  } else {
    image->create(cinfo->output_height, cinfo->output_width, CV_8UC3);
  }
  while (cinfo->output_scanline < cinfo->output_height) {
    JSAMPROW row = target->ptr(static_cast<int>(cinfo->output_scanline));
    if (jpeg_read_scanlines(cinfo, &row, 1) != 1) FailJpeg(errors, "the JPEG data ends early");
  }
  jpeg_finish_decompress(cinfo);
  return true;
}

// Adobe's inverted CMYK to BGR, with OpenCV's integer arithmetic (icvCvt_CMYK2BGR_8u_C4C3R).
cv::Mat CmykToBgr(const cv::Mat& cmyk) {
  cv::Mat bgr(cmyk.size(), CV_8UC3);
  for (int y = 0; y < cmyk.rows; ++y) {
    const unsigned char* in = cmyk.ptr(y);
    unsigned char* out = bgr.ptr(y);
    for (int x = 0; x < cmyk.cols; ++x, in += 4, out += 3) {
      const int k = in[3];
      out[2] = static_cast<unsigned char>(k - ((255 - in[0]) * k >> 8));
      out[1] = static_cast<unsigned char>(k - ((255 - in[1]) * k >> 8));
      out[0] = static_cast<unsigned char>(k - ((255 - in[2]) * k >> 8));
    }
  }
  return bgr;
}

cv::Mat DecodeJpeg(const std::string& bytes, const std::string& path) {
  jpeg_decompress_struct cinfo{};
  JpegErrors errors;
  cinfo.err = jpeg_std_error(&errors.base);
  errors.base.error_exit = OnJpegError;
  errors.base.output_message = IgnoreJpegMessage;
  cv::Mat image, cmyk;
  const bool decoded = ReadJpeg(&cinfo, &errors, bytes, &image, &cmyk);
  jpeg_destroy_decompress(&cinfo);
  if (!decoded) throw DecodeError(path, errors.message);
  return cmyk.empty() ? image : CmykToBgr(cmyk);
}

}  // namespace

cv::Mat DecodeImage(const std::string& bytes, const std::string& path) {
  if (IsPng(bytes)) {
    cv::Mat image;
    std::string problem;
    switch (DecodeCommonPng(bytes, &image, &problem)) {
      case PngDecodeResult::kDecoded:
        return image;
      case PngDecodeResult::kDamaged:
        throw Error(path, "cannot decode the image: " + problem);
      case PngDecodeResult::kUnsupported:
        return DecodePng(bytes, path);  // libpng reads every kind.
    }
  }
  if (IsJpeg(bytes)) return DecodeJpeg(bytes, path);
  throw DecodeError(path, "not a PNG or JPEG file");
}

std::string EncodePng(const cv::Mat& image, const std::string& where) {
  const int depth = image.depth(), channels = image.channels();
  Require(!image.empty(), where, "cannot encode an empty image as PNG");
  Require((depth == CV_8U || depth == CV_16U) && (channels == 1 || channels == 3 || channels == 4),
          where,
          "cannot encode the image as PNG: it must be 8- or 16-bit with 1, 3 or 4 channels, not " +
              cv::typeToString(image.type()));
  std::string png;
  PngStream stream;
  stream.output = &png;
  PngWriteStructs structs;
  structs.png =
      png_create_write_struct(PNG_LIBPNG_VER_STRING, &stream, OnPngError, IgnorePngWarning);
  if (structs.png != nullptr) structs.info = png_create_info_struct(structs.png);
  Require(structs.info != nullptr, where, "cannot encode the image as PNG: out of memory");
  png_set_write_fn(structs.png, &stream, AppendPngBytes, FlushNothing);
  std::vector<png_bytep> rows;
  Require(WritePng(structs.png, structs.info, image, &rows), where,
          std::string("cannot encode the image as PNG: ") + stream.error);
  return png;
}

}  // namespace internal
}  // namespace finecap
