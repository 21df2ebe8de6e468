#include "util/png_decode.h"

#include <libdeflate.h>

#include <cstdlib>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace finecap {
namespace internal {
namespace {

// A random image of `type` whose rows are smooth in places and noisy in others, so that a PNG
// encoder picks every filter somewhere.
cv::Mat TestImage(int type, int rows, int cols, unsigned seed) {
  cv::Mat image(rows, cols, type);
  cv::RNG rng(seed);
  rng.fill(image, cv::RNG::UNIFORM, 0, 256);
  const cv::Rect smooth(0, 0, cols / 2, rows / 2);
  cv::Mat gradient(smooth.height, smooth.width, type);
  for (int y = 0; y < gradient.rows; ++y) {
    for (int x = 0; x < gradient.cols * image.channels(); ++x) {
      gradient.ptr<unsigned char>(y)[x] = static_cast<unsigned char>(x + 3 * y);
    }
  }
  gradient.copyTo(image(smooth));
  return image;
}

std::string Encode(const cv::Mat& image, const std::vector<int>& parameters = {}) {
  std::vector<unsigned char> bytes;
  EXPECT_TRUE(cv::imencode(".png", image, bytes, parameters));
  return std::string(bytes.begin(), bytes.end());
}

cv::Mat OpenCvDecode(const std::string& bytes) {
  return cv::imdecode(
      cv::Mat(1, static_cast<int>(bytes.size()), CV_8U, const_cast<char*>(bytes.data())),
      cv::IMREAD_COLOR);
}

void ExpectSame(const cv::Mat& expected, const cv::Mat& actual) {
  ASSERT_EQ(expected.size(), actual.size());
  ASSERT_EQ(expected.type(), actual.type());
  EXPECT_EQ(cv::norm(expected, actual, cv::NORM_INF), 0.0);
}

void AppendBigEndian32(uint32_t value, std::string* out) {
  for (int shift = 24; shift >= 0; shift -= 8) out->push_back(static_cast<char>(value >> shift));
}

void AppendChunk(const std::string& type, const std::string& data, std::string* png) {
  AppendBigEndian32(static_cast<uint32_t>(data.size()), png);
  const std::string typed = type + data;
  png->append(typed);
  AppendBigEndian32(libdeflate_crc32(0, typed.data(), typed.size()), png);
}

int PaethPredictor(int left, int up, int up_left) {
  const int estimate = left + up - up_left;
  const int a = std::abs(estimate - left), b = std::abs(estimate - up),
            c = std::abs(estimate - up_left);
  return a <= b && a <= c ? left : (b <= c ? up : up_left);
}

// A PNG of `image` (8 bits, 1 to 4 channels as grey, grey + alpha, RGB, RGBA in OpenCV's channel
// order) whose row y is filtered with filter (y + first_filter) % 5: every filter, in every
// colour type, whatever an encoder would have chosen.
std::string HandMadePng(const cv::Mat& image, int first_filter) {
  const int channels = image.channels();
  const int color_type[] = {0, 0, 4, 2, 6};
  std::string header;
  AppendBigEndian32(image.cols, &header);
  AppendBigEndian32(image.rows, &header);
  header += std::string{8, static_cast<char>(color_type[channels]), 0, 0, 0};
  const size_t row_bytes = size_t(image.cols) * channels;
  std::string raw;
  std::vector<unsigned char> previous(row_bytes, 0), row(row_bytes);
  for (int y = 0; y < image.rows; ++y) {
    const unsigned char* pixels = image.ptr<unsigned char>(y);
    for (int x = 0; x < image.cols; ++x) {
      for (int c = 0; c < channels; ++c) {
        // PNG stores RGB(A); OpenCV holds BGR(A).
        const int source = channels >= 3 && c < 3 ? 2 - c : c;
        row[x * channels + c] = pixels[x * channels + source];
      }
    }
    const int filter = (y + first_filter) % 5;
    raw.push_back(static_cast<char>(filter));
    for (size_t i = 0; i < row_bytes; ++i) {
      const int left = i >= size_t(channels) ? row[i - channels] : 0;
      const int up = previous[i];
      const int up_left = i >= size_t(channels) ? previous[i - channels] : 0;
      const int predictions[] = {0, left, up, (left + up) / 2, PaethPredictor(left, up, up_left)};
      raw.push_back(static_cast<char>(row[i] - predictions[filter]));
    }
    previous = row;
  }
  libdeflate_compressor* compressor = libdeflate_alloc_compressor(6);
  std::string compressed(libdeflate_zlib_compress_bound(compressor, raw.size()), '\0');
  compressed.resize(libdeflate_zlib_compress(compressor, raw.data(), raw.size(), compressed.data(),
                                             compressed.size()));
  libdeflate_free_compressor(compressor);
  std::string png = "\x89PNG\r\n\x1A\n";
  AppendChunk("IHDR", header, &png);
  AppendChunk("tEXt", std::string("Comment\0hand made", 18), &png);
  // The image data split over two chunks, as encoders do for large images.
  AppendChunk("IDAT", compressed.substr(0, compressed.size() / 2), &png);
  AppendChunk("IDAT", compressed.substr(compressed.size() / 2), &png);
  AppendChunk("IEND", "", &png);
  return png;
}

// What IMREAD_COLOR makes of `image`: BGR, grey replicated, alpha dropped.
cv::Mat AsBgr(const cv::Mat& image) {
  cv::Mat bgr;
  const int codes[] = {0, cv::COLOR_GRAY2BGR, -1, -1, cv::COLOR_BGRA2BGR};
  if (image.channels() == 3) return image;
  if (image.channels() == 2) {
    cv::Mat grey;
    cv::extractChannel(image, grey, 0);
    cv::cvtColor(grey, bgr, cv::COLOR_GRAY2BGR);
    return bgr;
  }
  cv::cvtColor(image, bgr, codes[image.channels()]);
  return bgr;
}

struct Kind {
  const char* name;
  int type;
};

class PngDecodeKindTest : public ::testing::TestWithParam<Kind> {};

TEST_P(PngDecodeKindTest, UndoesEveryFilter) {
  const cv::Mat image = TestImage(GetParam().type, 23, 31, 11u);
  for (int first_filter = 0; first_filter < 5; ++first_filter) {
    const std::string bytes = HandMadePng(image, first_filter);
    cv::Mat decoded;
    std::string problem;
    ASSERT_EQ(DecodeCommonPng(bytes, &decoded, &problem), PngDecodeResult::kDecoded) << problem;
    ExpectSame(AsBgr(image), decoded);
    ExpectSame(OpenCvDecode(bytes), decoded);
  }
}

// OpenCV writes no grey + alpha PNG.
class PngDecodeOpenCvKindTest : public ::testing::TestWithParam<Kind> {};

TEST_P(PngDecodeOpenCvKindTest, DecodesWhatOpenCvWritesAsOpenCvDoes) {
  // Odd sizes, each compression strategy (with its filters) OpenCV's encoder offers.
  for (int strategy : {cv::IMWRITE_PNG_STRATEGY_DEFAULT, cv::IMWRITE_PNG_STRATEGY_FILTERED,
                       cv::IMWRITE_PNG_STRATEGY_RLE, cv::IMWRITE_PNG_STRATEGY_HUFFMAN_ONLY}) {
    const cv::Mat image = TestImage(GetParam().type, 37, 53, 7u + strategy);
    const std::string bytes =
        Encode(image, {cv::IMWRITE_PNG_STRATEGY, strategy, cv::IMWRITE_PNG_COMPRESSION, 9});
    cv::Mat decoded;
    std::string problem;
    ASSERT_EQ(DecodeCommonPng(bytes, &decoded, &problem), PngDecodeResult::kDecoded) << problem;
    ExpectSame(OpenCvDecode(bytes), decoded);
  }
}

INSTANTIATE_TEST_SUITE_P(Kinds, PngDecodeKindTest,
                         ::testing::Values(Kind{"grey", CV_8UC1}, Kind{"grey_alpha", CV_8UC2},
                                           Kind{"bgr", CV_8UC3}, Kind{"bgra", CV_8UC4}),
                         [](const auto& info) { return std::string(info.param.name); });
INSTANTIATE_TEST_SUITE_P(Kinds, PngDecodeOpenCvKindTest,
                         ::testing::Values(Kind{"grey", CV_8UC1}, Kind{"bgr", CV_8UC3},
                                           Kind{"bgra", CV_8UC4}),
                         [](const auto& info) { return std::string(info.param.name); });

TEST(PngDecodeTest, LeavesSixteenBitImagesToTheGeneralDecoder) {
  cv::Mat image(8, 8, CV_16UC3, cv::Scalar(1000, 20000, 65535));
  cv::Mat decoded;
  std::string problem;
  EXPECT_EQ(DecodeCommonPng(Encode(image), &decoded, &problem), PngDecodeResult::kUnsupported);
}

TEST(PngDecodeTest, LeavesOtherFilesToTheGeneralDecoder) {
  cv::Mat decoded;
  std::string problem;
  EXPECT_EQ(DecodeCommonPng("\xFF\xD8\xFF\xE0 not a PNG", &decoded, &problem),
            PngDecodeResult::kUnsupported);
  EXPECT_EQ(DecodeCommonPng("", &decoded, &problem), PngDecodeResult::kUnsupported);
}

TEST(PngDecodeTest, RefusesTruncatedFiles) {
  const std::string bytes = Encode(TestImage(CV_8UC3, 40, 40, 3));
  for (size_t keep : {size_t{20}, bytes.size() / 2, bytes.size() - 1}) {
    cv::Mat decoded;
    std::string problem;
    EXPECT_EQ(DecodeCommonPng(bytes.substr(0, keep), &decoded, &problem), PngDecodeResult::kDamaged)
        << keep;
    EXPECT_NE(problem.find("truncated"), std::string::npos) << problem;
  }
}

TEST(PngDecodeTest, RefusesDamagedImageData) {
  std::string bytes = Encode(TestImage(CV_8UC3, 40, 40, 5));
  const size_t data = bytes.find("IDAT");
  ASSERT_NE(data, std::string::npos);
  // Bytes inside the compressed data, past the zlib header: the inflate or its checksum fails.
  for (size_t i = data + 12; i < data + 40; ++i) bytes[i] = static_cast<char>(~bytes[i]);
  cv::Mat decoded;
  std::string problem;
  EXPECT_EQ(DecodeCommonPng(bytes, &decoded, &problem), PngDecodeResult::kDamaged);
  EXPECT_FALSE(problem.empty());
}

}  // namespace
}  // namespace internal
}  // namespace finecap
