#include "finecap/io/export.h"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>

#include "finecap/io/mesh_io.h"
#include "finecap/util/atomic_file.h"
#include "finecap/util/error.h"
#include "util/io_util.h"

namespace finecap {
namespace {

constexpr char kPc2Signature[12] = {'P', 'O', 'I', 'N', 'T', 'C', 'A', 'C', 'H', 'E', '2', '\0'};
constexpr int kPc2Version = 1;
constexpr size_t kPc2HeaderBytes = 32;
constexpr size_t kPc2SampleCountOffset = 28;
constexpr size_t kBytesPerPoint = 3 * sizeof(float);

// Bytes are assembled with shifts, so the layout is little-endian on any host.
void AppendUint32(uint32_t value, std::string* out) {
  for (int byte = 0; byte < 4; ++byte) out->push_back(static_cast<char>(value >> (8 * byte)));
}
void AppendInt32(int32_t value, std::string* out) {
  AppendUint32(static_cast<uint32_t>(value), out);
}
void AppendFloat32(float value, std::string* out) {
  uint32_t bits = 0;
  std::memcpy(&bits, &value, sizeof(bits));
  AppendUint32(bits, out);
}

uint32_t Uint32At(const std::string& bytes, size_t offset) {
  uint32_t value = 0;
  for (int byte = 0; byte < 4; ++byte) {
    value |= static_cast<uint32_t>(static_cast<unsigned char>(bytes[offset + byte])) << (8 * byte);
  }
  return value;
}
int32_t Int32At(const std::string& bytes, size_t offset) {
  return static_cast<int32_t>(Uint32At(bytes, offset));
}
float Float32At(const std::string& bytes, size_t offset) {
  const uint32_t bits = Uint32At(bytes, offset);
  float value = 0.0f;
  std::memcpy(&value, &bits, sizeof(value));
  return value;
}

std::string EncodePc2Header(const Pc2Header& header) {
  std::string bytes(kPc2Signature, sizeof(kPc2Signature));
  AppendInt32(kPc2Version, &bytes);
  AppendInt32(header.num_points, &bytes);
  AppendFloat32(header.start_frame, &bytes);
  AppendFloat32(header.sample_rate, &bytes);
  AppendInt32(header.num_samples, &bytes);
  return bytes;
}

Pc2Header DecodePc2Header(const std::string& bytes, const std::string& path) {
  Require(bytes.size() >= kPc2HeaderBytes &&
              bytes.compare(0, sizeof(kPc2Signature),
                            std::string(kPc2Signature, sizeof(kPc2Signature))) == 0,
          path, "not a PC2 point cache (no POINTCACHE2 signature)");
  const int version = Int32At(bytes, 12);
  Require(version == kPc2Version, path,
          "PC2 version " + std::to_string(version) + " is not supported (only 1)");
  Pc2Header header;
  header.num_points = Int32At(bytes, 16);
  header.start_frame = Float32At(bytes, 20);
  header.sample_rate = Float32At(bytes, 24);
  header.num_samples = Int32At(bytes, 28);
  Require(header.num_points >= 0 && header.num_samples >= 0, path,
          "negative point or sample count in the PC2 header");
  return header;
}

std::string EncodeSample(const Eigen::Matrix3Xd& points, int sample, const std::string& path) {
  std::string bytes;
  bytes.reserve(points.cols() * kBytesPerPoint);
  for (Eigen::Index p = 0; p < points.cols(); ++p) {
    Require(points.col(p).allFinite(), path,
            "sample " + std::to_string(sample) + " has a non-finite coordinate at point " +
                std::to_string(p));
    for (int axis = 0; axis < 3; ++axis) {
      AppendFloat32(static_cast<float>(points(axis, p)), &bytes);
    }
  }
  return bytes;
}

}  // namespace

Pc2Writer::Pc2Writer(const std::string& path, int num_points, float start_frame, float sample_rate)
    : path_(path), temporary_path_(TemporaryPathFor(path)) {
  Require(num_points > 0, path, "a point cache needs at least one point");
  Require(std::isfinite(start_frame), path, "the start frame is not finite");
  Require(std::isfinite(sample_rate) && sample_rate > 0.0f, path,
          "the sample rate must be positive and finite");
  header_.num_points = num_points;
  header_.start_frame = start_frame;
  header_.sample_rate = sample_rate;
  stream_.open(temporary_path_, std::ios::binary | std::ios::trunc);
  Require(stream_.is_open(), path, "cannot create the file");
  // The sample count stays 0 until Finish() patches it in.
  const std::string header = EncodePc2Header(header_);
  stream_.write(header.data(), static_cast<std::streamsize>(header.size()));
}

Pc2Writer::~Pc2Writer() {
  if (finished_) return;
  stream_.close();
  std::remove(temporary_path_.c_str());
}

void Pc2Writer::RequireOpen() const {
  Require(!finished_, path_, "the point cache is already finished");
}

void Pc2Writer::Append(const Eigen::Matrix3Xd& points) {
  RequireOpen();
  Require(points.cols() == header_.num_points, path_,
          "sample " + std::to_string(header_.num_samples) + " has " +
              std::to_string(points.cols()) + " points, the cache " +
              std::to_string(header_.num_points));
  const std::string bytes = EncodeSample(points, header_.num_samples, path_);
  stream_.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  Require(static_cast<bool>(stream_), path_,
          "cannot write sample " + std::to_string(header_.num_samples));
  ++header_.num_samples;
}

void Pc2Writer::Finish() {
  RequireOpen();
  std::string count;
  AppendInt32(header_.num_samples, &count);
  stream_.seekp(kPc2SampleCountOffset);
  stream_.write(count.data(), static_cast<std::streamsize>(count.size()));
  stream_.close();
  Require(static_cast<bool>(stream_), path_, "cannot finish writing the file");
  MoveIntoPlace(temporary_path_, path_);
  finished_ = true;
}

Pc2Cache ReadPc2(const std::string& path) {
  const std::string bytes = internal::ReadWholeFile(path);
  Pc2Cache cache;
  cache.header = DecodePc2Header(bytes, path);
  // Compared by division: the product of two header counts can overflow.
  const uint64_t sample_bytes = static_cast<uint64_t>(cache.header.num_points) * kBytesPerPoint;
  const uint64_t body_bytes = bytes.size() - kPc2HeaderBytes;
  const bool size_matches =
      sample_bytes == 0
          ? body_bytes == 0
          : body_bytes % sample_bytes == 0 &&
                body_bytes / sample_bytes == static_cast<uint64_t>(cache.header.num_samples);
  Require(size_matches, path,
          "the file has " + std::to_string(body_bytes) + " bytes of samples, not the " +
              std::to_string(cache.header.num_samples) + " samples of " +
              std::to_string(cache.header.num_points) + " points its header announces");
  size_t offset = kPc2HeaderBytes;
  cache.samples.resize(cache.header.num_samples, Eigen::Matrix3Xf(3, cache.header.num_points));
  for (Eigen::Matrix3Xf& sample : cache.samples) {
    for (Eigen::Index p = 0; p < sample.cols(); ++p) {
      for (int axis = 0; axis < 3; ++axis, offset += sizeof(float)) {
        sample(axis, p) = Float32At(bytes, offset);
      }
    }
  }
  return cache;
}

void WriteDisplacementPly(const std::string& path, const Mesh& mesh,
                          const Eigen::VectorXd& displacement) {
  VertexAttributes attributes;
  attributes.quality = displacement;
  WriteMesh(path, mesh, attributes, MeshFormat::kPly);
}

}  // namespace finecap
