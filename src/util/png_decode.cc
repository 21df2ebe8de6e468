#include "util/png_decode.h"

#include <libdeflate.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <vector>

namespace finecap {
namespace internal {
namespace {

constexpr unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
// Larger images are left to the general decoder, which reads them row by row.
constexpr uint64_t kMaxPixels = uint64_t{1} << 28;

uint32_t BigEndian32(const unsigned char* bytes) {
  return (uint32_t{bytes[0]} << 24) | (uint32_t{bytes[1]} << 16) | (uint32_t{bytes[2]} << 8) |
         uint32_t{bytes[3]};
}

struct Header {
  uint32_t width = 0, height = 0;
  int channels = 0;  // 1 grey, 2 grey + alpha, 3 RGB, 4 RGBA.
};

// The channels of colour type `color_type` at 8 bits, or 0 for a kind this decoder leaves.
int ChannelsOf(int color_type) {
  switch (color_type) {
    case 0:
      return 1;
    case 2:
      return 3;
    case 4:
      return 2;
    case 6:
      return 4;
    default:
      return 0;  // 3: palette.
  }
}

// The chunks of a PNG file: its header and its image data, concatenated.
struct Chunks {
  Header header;
  std::string data;
};

// Walks the chunks of `bytes` into *chunks; kUnsupported or kDamaged as DecodeCommonPng says.
PngDecodeResult ReadChunks(const std::string& bytes, Chunks* chunks, std::string* problem) {
  const auto* begin = reinterpret_cast<const unsigned char*>(bytes.data());
  if (bytes.size() < 8 || std::memcmp(begin, kSignature, 8) != 0) {
    return PngDecodeResult::kUnsupported;
  }
  size_t position = 8;
  bool has_header = false;
  while (true) {
    if (bytes.size() - position < 12) {
      *problem = "the PNG file ends early, before its IEND chunk (truncated)";
      return PngDecodeResult::kDamaged;
    }
    const uint32_t length = BigEndian32(begin + position);
    const std::string type(bytes, position + 4, 4);
    const unsigned char* data = begin + position + 8;
    if (length > bytes.size() - position - 12) {
      *problem = "the PNG file ends early, inside its " + type + " chunk (truncated)";
      return PngDecodeResult::kDamaged;
    }
    position += 12 + size_t{length};
    if (type == "IHDR") {
      if (length != 13) return PngDecodeResult::kUnsupported;
      chunks->header.width = BigEndian32(data);
      chunks->header.height = BigEndian32(data + 4);
      const int bit_depth = data[8], color_type = data[9], interlace = data[12];
      chunks->header.channels = ChannelsOf(color_type);
      if (bit_depth != 8 || chunks->header.channels == 0 || interlace != 0 || data[10] != 0 ||
          data[11] != 0) {
        return PngDecodeResult::kUnsupported;
      }
      has_header = true;
    } else if (!has_header) {
      return PngDecodeResult::kUnsupported;  // IHDR must come first: let libpng say so.
    } else if (type == "IDAT") {
      chunks->data.append(reinterpret_cast<const char*>(data), length);
    } else if (type == "IEND") {
      return PngDecodeResult::kDecoded;
    } else if (type != "PLTE" && (type[0] & 0x20) == 0) {
      // A critical chunk this decoder does not know (a suggested palette is ancillary in RGB).
      return PngDecodeResult::kUnsupported;
    }
  }
}

int Paeth(int left, int up, int up_left) {
  const int estimate = left + up - up_left;
  const int to_left = std::abs(estimate - left), to_up = std::abs(estimate - up),
            to_up_left = std::abs(estimate - up_left);
  if (to_left <= to_up && to_left <= to_up_left) return left;
  return to_up <= to_up_left ? up : up_left;
}

// Undoes the filter of one row in place: `row` holds `length` filtered bytes, `previous` the
// row above unfiltered (zeros above the first), `stride` the bytes of one pixel.
bool Unfilter(int filter, unsigned char* row, const unsigned char* previous, size_t length,
              size_t stride) {
  switch (filter) {
    case 0:
      return true;
    case 1:
      for (size_t i = stride; i < length; ++i) row[i] += row[i - stride];
      return true;
    case 2:
      for (size_t i = 0; i < length; ++i) row[i] += previous[i];
      return true;
    case 3:
      for (size_t i = 0; i < length; ++i) {
        const int left = i >= stride ? row[i - stride] : 0;
        row[i] += static_cast<unsigned char>((left + previous[i]) / 2);
      }
      return true;
    case 4:
      for (size_t i = 0; i < length; ++i) {
        const int left = i >= stride ? row[i - stride] : 0;
        const int up_left = i >= stride ? previous[i - stride] : 0;
        row[i] += static_cast<unsigned char>(Paeth(left, previous[i], up_left));
      }
      return true;
    default:
      return false;
  }
}

// One unfiltered row of `channels` channels into BGR.
void ToBgr(const unsigned char* row, int channels, int width, unsigned char* bgr) {
  for (int x = 0; x < width; ++x, row += channels, bgr += 3) {
    if (channels <= 2) {
      bgr[0] = bgr[1] = bgr[2] = row[0];
    } else {
      bgr[0] = row[2];
      bgr[1] = row[1];
      bgr[2] = row[0];
    }
  }
}

struct DecompressorDeleter {
  void operator()(libdeflate_decompressor* decompressor) const {
    libdeflate_free_decompressor(decompressor);
  }
};

}  // namespace

PngDecodeResult DecodeCommonPng(const std::string& bytes, cv::Mat* image, std::string* problem) {
  Chunks chunks;
  const PngDecodeResult read = ReadChunks(bytes, &chunks, problem);
  if (read != PngDecodeResult::kDecoded) return read;
  const Header& header = chunks.header;
  if (header.width == 0 || header.height == 0 ||
      uint64_t{header.width} * header.height > kMaxPixels) {
    return PngDecodeResult::kUnsupported;
  }
  const size_t row_bytes = size_t{header.width} * header.channels;
  const size_t expected = size_t{header.height} * (1 + row_bytes);
  std::vector<unsigned char> raw(expected);
  const std::unique_ptr<libdeflate_decompressor, DecompressorDeleter> decompressor(
      libdeflate_alloc_decompressor());
  if (decompressor == nullptr) return PngDecodeResult::kUnsupported;
  size_t inflated = 0;
  const libdeflate_result result =
      libdeflate_zlib_decompress(decompressor.get(), chunks.data.data(), chunks.data.size(),
                                 raw.data(), raw.size(), &inflated);
  if (result != LIBDEFLATE_SUCCESS || inflated != expected) {
    *problem = result == LIBDEFLATE_SUCCESS || result == LIBDEFLATE_INSUFFICIENT_SPACE
                   ? "the PNG image data (IDAT) does not hold the pixels its header promises"
                   : "the PNG image data (IDAT) is damaged (it does not inflate)";
    return PngDecodeResult::kDamaged;
  }
  *image = cv::Mat(static_cast<int>(header.height), static_cast<int>(header.width), CV_8UC3);
  const std::vector<unsigned char> zeros(row_bytes, 0);
  const unsigned char* previous = zeros.data();
  for (uint32_t y = 0; y < header.height; ++y) {
    unsigned char* line = &raw[y * (1 + row_bytes)];
    if (!Unfilter(line[0], line + 1, previous, row_bytes, header.channels)) {
      *problem = "the PNG row " + std::to_string(y) + " has an unknown filter type " +
                 std::to_string(line[0]);
      return PngDecodeResult::kDamaged;
    }
    ToBgr(line + 1, header.channels, static_cast<int>(header.width), image->ptr<unsigned char>(y));
    previous = line + 1;
  }
  return PngDecodeResult::kDecoded;
}

}  // namespace internal
}  // namespace finecap
