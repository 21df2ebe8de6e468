#include "util/image_codec.h"

#include <csetjmp>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <jpeglib.h>
#include <png.h>
#include <opencv2/imgcodecs.hpp>

#include "finecap/util/error.h"
#include "test_util.h"
#include "util/io_util.h"

namespace finecap {
namespace {

using internal::DecodeImage;
using internal::EncodePng;
using testing_util::ExpectErrorMentions;
using testing_util::MakeTempDir;

std::string Bytes(const std::vector<uchar>& buffer) {
  return std::string(buffer.begin(), buffer.end());
}

// OpenCV's decoder, the reference: IMREAD_COLOR without the EXIF rotation (see image_codec.h).
cv::Mat OpenCvDecode(const std::string& bytes,
                     int flags = cv::IMREAD_COLOR | cv::IMREAD_IGNORE_ORIENTATION) {
  return cv::imdecode(std::vector<uchar>(bytes.begin(), bytes.end()), flags);
}

cv::Mat RandomImage(int rows, int cols, int type, unsigned seed) {
  cv::Mat image(rows, cols, type);
  cv::theRNG().state = seed;
  cv::randu(image, 0, CV_MAT_DEPTH(type) == CV_16U ? 65536 : 256);
  return image;
}

// A smooth image, which JPEG keeps close to: what a camera gives.
cv::Mat SmoothImage(int rows, int cols, int channels) {
  cv::Mat image(rows, cols, CV_8UC(channels));
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) {
      for (int c = 0; c < channels; ++c) {
        image.ptr(y)[x * channels + c] =
            static_cast<uchar>(128 + 100 * std::sin(0.11 * x * (c + 1) + 0.07 * y));
      }
    }
  }
  return image;
}

void ExpectSamePixels(const cv::Mat& ours, const cv::Mat& reference, const std::string& what,
                      double tolerance = 0.0) {
  ASSERT_FALSE(reference.empty()) << what;
  ASSERT_EQ(ours.type(), CV_8UC3) << what;
  ASSERT_EQ(ours.size(), reference.size()) << what;
  ASSERT_EQ(reference.type(), CV_8UC3) << what;
  EXPECT_LE(cv::norm(ours, reference, cv::NORM_INF), tolerance) << what;
}

// A PNG written by libpng itself, for the colour types and bit depths OpenCV does not write:
// `packed` holds the rows as PNG stores them (big-endian samples, sub-byte pixels packed).
struct PngSpec {
  int width = 37, height = 23, bit_depth = 8, color_type = PNG_COLOR_TYPE_GRAY;
  int interlace = PNG_INTERLACE_NONE;
  bool transparency = false;  // A tRNS chunk: per palette entry, or one grey or RGB colour.
};

int Channels(int color_type) {
  switch (color_type) {
    case PNG_COLOR_TYPE_GRAY_ALPHA:
      return 2;
    case PNG_COLOR_TYPE_RGB:
      return 3;
    case PNG_COLOR_TYPE_RGB_ALPHA:
      return 4;
    default:
      return 1;
  }
}

void AppendBytes(png_structp png, png_bytep data, size_t count) {
  static_cast<std::string*>(png_get_io_ptr(png))->append(reinterpret_cast<char*>(data), count);
}

// The libpng calls, apart from the C++ objects they write from: a jump back to the setjmp skips no
// destructor.
bool WritePngCalls(png_structp png, png_infop info, const PngSpec& spec, png_bytepp rows,
                   std::vector<png_color>* palette, std::vector<png_byte>* alphas,
                   std::string* out) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_set_write_fn(png, out, AppendBytes, nullptr);
  png_set_IHDR(png, info, spec.width, spec.height, spec.bit_depth, spec.color_type, spec.interlace,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  if (spec.color_type == PNG_COLOR_TYPE_PALETTE) {
    png_set_PLTE(png, info, palette->data(), static_cast<int>(palette->size()));
    if (spec.transparency) {
      png_set_tRNS(png, info, alphas->data(), static_cast<int>(alphas->size()), nullptr);
    }
  } else if (spec.transparency) {
    png_color_16 colour{0, 1, 1, 1, 1};
    png_set_tRNS(png, info, nullptr, 0, &colour);
  }
  png_write_info(png, info);
  png_write_image(png, rows);
  png_write_end(png, info);
  return true;
}

std::string WriteWithLibpng(const PngSpec& spec, unsigned seed) {
  const size_t row_bytes =
      (static_cast<size_t>(spec.width) * Channels(spec.color_type) * spec.bit_depth + 7) / 8;
  std::vector<unsigned char> packed(row_bytes * spec.height);
  std::mt19937 random(seed);
  for (unsigned char& byte : packed) byte = static_cast<unsigned char>(random());
  std::vector<png_bytep> rows(spec.height);
  for (int y = 0; y < spec.height; ++y) rows[y] = packed.data() + y * row_bytes;
  std::vector<png_color> palette(size_t{1} << spec.bit_depth);
  std::vector<png_byte> alphas(palette.size());
  for (size_t i = 0; i < palette.size(); ++i) {
    palette[i] = {static_cast<png_byte>(random()), static_cast<png_byte>(random()),
                  static_cast<png_byte>(random())};
    alphas[i] = static_cast<png_byte>(random());
  }
  std::string png_bytes;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  EXPECT_TRUE(WritePngCalls(png, info, spec, rows.data(), &palette, &alphas, &png_bytes));
  png_destroy_write_struct(&png, &info);
  return png_bytes;
}

TEST(ImageCodecTest, PngDecodesAsOpenCvReadsItInColour) {
  struct Case {
    std::string name;
    int type;
  };
  for (const Case& c : std::vector<Case>{{"8-bit BGR", CV_8UC3},
                                         {"8-bit grey", CV_8UC1},
                                         {"8-bit BGRA", CV_8UC4},
                                         {"16-bit BGR", CV_16UC3},
                                         {"16-bit grey", CV_16UC1},
                                         {"16-bit BGRA", CV_16UC4}}) {
    std::vector<uchar> png;
    ASSERT_TRUE(cv::imencode(".png", RandomImage(29, 41, c.type, 7), png)) << c.name;
    ExpectSamePixels(DecodeImage(Bytes(png), "a.png"), OpenCvDecode(Bytes(png)), c.name);
  }
}

TEST(ImageCodecTest, PngOfEveryColourTypeDecodesAsOpenCvReadsIt) {
  struct Case {
    std::string name;
    PngSpec spec;
  };
  std::vector<Case> cases;
  for (int depth : {1, 2, 4, 8, 16}) {
    PngSpec grey;
    grey.bit_depth = depth;
    cases.push_back({"grey " + std::to_string(depth) + "-bit", grey});
    grey.transparency = true;
    cases.push_back({"grey " + std::to_string(depth) + "-bit with tRNS", grey});
  }
  for (int depth : {1, 2, 4, 8}) {
    PngSpec palette;
    palette.color_type = PNG_COLOR_TYPE_PALETTE;
    palette.bit_depth = depth;
    cases.push_back({"palette " + std::to_string(depth) + "-bit", palette});
    palette.transparency = true;
    cases.push_back({"palette " + std::to_string(depth) + "-bit with tRNS", palette});
  }
  for (int depth : {8, 16}) {
    for (int type : {PNG_COLOR_TYPE_GRAY_ALPHA, PNG_COLOR_TYPE_RGB, PNG_COLOR_TYPE_RGB_ALPHA}) {
      PngSpec spec;
      spec.color_type = type;
      spec.bit_depth = depth;
      const std::string name =
          "type " + std::to_string(type) + ", " + std::to_string(depth) + "-bit";
      cases.push_back({name, spec});
      spec.interlace = PNG_INTERLACE_ADAM7;
      cases.push_back({name + ", interlaced", spec});
      if (type == PNG_COLOR_TYPE_RGB) {
        spec.transparency = true;
        cases.push_back({name + ", interlaced, with tRNS", spec});
      }
    }
  }
  unsigned seed = 1;
  for (const Case& c : cases) {
    const std::string png = WriteWithLibpng(c.spec, seed++);
    ExpectSamePixels(DecodeImage(png, "a.png"), OpenCvDecode(png), c.name);
  }
}

TEST(ImageCodecTest, JpegDecodesAsOpenCvReadsIt) {
  struct Case {
    std::string name;
    cv::Mat image;
    std::vector<int> parameters;
  };
  for (const Case& c : std::vector<Case>{
           {"colour 4:2:0", SmoothImage(45, 67, 3), {cv::IMWRITE_JPEG_QUALITY, 90}},
           {"grey", SmoothImage(45, 67, 1), {}},
           {"colour, progressive", SmoothImage(45, 67, 3), {cv::IMWRITE_JPEG_PROGRESSIVE, 1}},
           {"colour, noise, quality 100",
            RandomImage(33, 20, CV_8UC3, 3),
            {cv::IMWRITE_JPEG_QUALITY, 100}}}) {
    std::vector<uchar> jpeg;
    ASSERT_TRUE(cv::imencode(".jpg", c.image, jpeg, c.parameters)) << c.name;
    ExpectSamePixels(DecodeImage(Bytes(jpeg), "a.jpg"), OpenCvDecode(Bytes(jpeg)), c.name);
  }
}

struct JpegWriteErrors {
  jpeg_error_mgr base;
  std::jmp_buf jump;
};

// An Adobe CMYK JPEG written by libjpeg (OpenCV writes none).
std::string WriteCmykJpeg(int width, int height) {
  const cv::Mat cmyk = SmoothImage(height, width, 4);
  jpeg_compress_struct cinfo{};
  JpegWriteErrors errors;
  cinfo.err = jpeg_std_error(&errors.base);
  errors.base.error_exit = [](j_common_ptr common) {
    std::longjmp(reinterpret_cast<JpegWriteErrors*>(common->err)->jump, 1);
  };
  unsigned char* buffer = nullptr;
  unsigned long size = 0;
  if (setjmp(errors.jump)) {
    jpeg_destroy_compress(&cinfo);
    ADD_FAILURE() << "libjpeg could not write the test image";
    return "";
  }
  jpeg_create_compress(&cinfo);
  jpeg_mem_dest(&cinfo, &buffer, &size);
  cinfo.image_width = width;
  cinfo.image_height = height;
  cinfo.input_components = 4;
  cinfo.in_color_space = JCS_CMYK;
  jpeg_set_defaults(&cinfo);
  jpeg_set_quality(&cinfo, 95, TRUE);
  jpeg_start_compress(&cinfo, TRUE);
  while (cinfo.next_scanline < cinfo.image_height) {
    JSAMPROW row = const_cast<JSAMPROW>(cmyk.ptr(static_cast<int>(cinfo.next_scanline)));
    jpeg_write_scanlines(&cinfo, &row, 1);
  }
  jpeg_finish_compress(&cinfo);
  jpeg_destroy_compress(&cinfo);
  const std::string bytes(reinterpret_cast<char*>(buffer), size);
  std::free(buffer);
  return bytes;
}

TEST(ImageCodecTest, CmykJpegDecodesAsOpenCvReadsIt) {
  const std::string jpeg = WriteCmykJpeg(31, 17);
  ExpectSamePixels(DecodeImage(jpeg, "cmyk.jpg"), OpenCvDecode(jpeg), "CMYK");
}

// `jpeg` with an EXIF block after its SOI whose only tag is the orientation `orientation`.
std::string WithExifOrientation(const std::string& jpeg, int orientation) {
  const std::string tiff = std::string("II*\0\x08\0\0\0", 8) +           // little-endian, IFD at 8
                           std::string("\x01\0", 2) +                    // one entry
                           std::string("\x12\x01\x03\0\x01\0\0\0", 8) +  // 0x0112 SHORT x1
                           std::string(1, static_cast<char>(orientation)) +
                           std::string("\0\0\0", 3) + std::string("\0\0\0\0", 4);  // no next IFD
  const std::string payload = std::string("Exif\0\0", 6) + tiff;
  const size_t length = payload.size() + 2;
  const std::string app1 = std::string("\xFF\xE1", 2) + static_cast<char>(length >> 8) +
                           static_cast<char>(length & 0xFF) + payload;
  return jpeg.substr(0, 2) + app1 + jpeg.substr(2);
}

TEST(ImageCodecTest, ExifOrientationIsIgnoredTheStoredPixelsAreKept) {
  const cv::Mat stored = SmoothImage(20, 48, 3);
  std::vector<uchar> jpeg;
  ASSERT_TRUE(cv::imencode(".jpg", stored, jpeg));
  const std::string rotated = WithExifOrientation(Bytes(jpeg), 6);  // "turn 90 degrees clockwise"
  // OpenCV's IMREAD_COLOR applies the tag: the test's EXIF block is one it reads.
  EXPECT_EQ(OpenCvDecode(rotated, cv::IMREAD_COLOR).size(), cv::Size(20, 48));
  const cv::Mat ours = DecodeImage(rotated, "rotated.jpg");
  EXPECT_EQ(ours.size(), cv::Size(48, 20));
  ExpectSamePixels(ours, OpenCvDecode(Bytes(jpeg)), "stored pixels");
}

TEST(ImageCodecTest, DamagedImagesGiveOneErrorNamingTheFile) {
  std::vector<uchar> png_buffer, jpeg_buffer;
  ASSERT_TRUE(cv::imencode(".png", RandomImage(30, 40, CV_8UC3, 5), png_buffer));
  ASSERT_TRUE(cv::imencode(".jpg", SmoothImage(30, 40, 3), jpeg_buffer));
  const std::string png = Bytes(png_buffer), jpeg = Bytes(jpeg_buffer);

  std::string damaged = png;  // A byte of the image data changed: zlib's check fails.
  damaged[png.size() / 2] = static_cast<char>(damaged[png.size() / 2] ^ 0x55);
  ExpectErrorMentions([&] { DecodeImage(damaged, "/data/damaged.png"); },
                      {"/data/damaged.png", "cannot decode the image: ", "IDAT"});
  ExpectErrorMentions([&] { DecodeImage(png.substr(0, png.size() / 2), "/data/half.png"); },
                      {"/data/half.png", "cannot decode the image: ", "ends early"});

  std::string zero_width = jpeg;  // The frame header (SOF0) says 0 pixels wide.
  const size_t sof = zero_width.find("\xFF\xC0");
  ASSERT_NE(sof, std::string::npos);
  zero_width[sof + 7] = zero_width[sof + 8] = '\0';
  ExpectErrorMentions([&] { DecodeImage(zero_width, "/data/zero.jpg"); },
                      {"/data/zero.jpg", "cannot decode the image: "});
  ExpectErrorMentions([&] { DecodeImage(std::string("\xFF\xD8\xFF\xD9", 4), "/data/empty.jpg"); },
                      {"/data/empty.jpg", "cannot decode the image: "});
  ExpectErrorMentions([&] { DecodeImage("GIF89a", "/data/a.gif"); },
                      {"/data/a.gif", "not a PNG or JPEG"});
}

TEST(ImageCodecTest, PngEncodingRoundTripsAndMatchesOpenCvsBytes) {
  for (int type : {CV_8UC1, CV_8UC3, CV_8UC4, CV_16UC1, CV_16UC3, CV_16UC4}) {
    const cv::Mat image = RandomImage(26, 35, type, 11);
    const std::string png = EncodePng(image, "test");
    std::vector<uchar> opencv;
    ASSERT_TRUE(cv::imencode(".png", image, opencv));
    EXPECT_EQ(png, Bytes(opencv)) << cv::typeToString(type);
    const cv::Mat back = OpenCvDecode(png, cv::IMREAD_UNCHANGED);
    ASSERT_EQ(back.type(), type);
    EXPECT_EQ(cv::norm(back, image, cv::NORM_INF), 0.0) << cv::typeToString(type);
  }
  const cv::Mat bgr = RandomImage(40, 50, CV_8UC3, 12);
  const cv::Mat window = bgr(cv::Rect(3, 5, 31, 17));  // Rows apart in memory.
  EXPECT_EQ(cv::norm(DecodeImage(EncodePng(window, "test"), "window.png"), window, cv::NORM_INF),
            0.0);
  ExpectErrorMentions([&] { EncodePng(cv::Mat(4, 4, CV_32FC1), "/out/float.png"); },
                      {"/out/float.png", "8- or 16-bit", "CV_32FC1"});
  ExpectErrorMentions([&] { EncodePng(cv::Mat(), "/out/empty.png"); }, {"/out/empty.png", "empty"});
}

TEST(ImageCodecTest, OpenCvReadsTheFilesWeWrite) {
  const std::string path = MakeTempDir("codec") + "/picture.png";
  const cv::Mat image = RandomImage(21, 34, CV_8UC3, 13);
  internal::WritePng(path, image);
  const cv::Mat read = cv::imread(path, cv::IMREAD_UNCHANGED);
  ASSERT_EQ(read.type(), CV_8UC3);
  EXPECT_EQ(cv::norm(read, image, cv::NORM_INF), 0.0);
}

// What finecap's binary loads at start: none of the OpenCV modules that are loaded on use.
TEST(ImageCodecTest, TheBinaryLinksNoneOfTheOpenCvExtras) {
  FILE* pipe = popen("ldd " FINECAP_BINARY " 2>&1", "r");
  ASSERT_NE(pipe, nullptr);
  std::string listing;
  char buffer[4096];
  while (size_t count = fread(buffer, 1, sizeof(buffer), pipe)) listing.append(buffer, count);
  ASSERT_EQ(pclose(pipe), 0) << listing;
  EXPECT_NE(listing.find("libopencv_core"), std::string::npos) << listing;
  for (const char* library : {"libopencv_imgcodecs", "libopencv_videoio", "libopencv_optflow",
                              "libopencv_ximgproc", "libgdal"}) {
    EXPECT_EQ(listing.find(library), std::string::npos) << library;
  }
}

}  // namespace
}  // namespace finecap
