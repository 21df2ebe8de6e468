// COLMAP's binary model (cameras.bin + images.bin), as COLMAP's Reconstruction::WriteBinary lays
// it out: little-endian, a uint64 count and then the records, cameras as
//   uint32 camera_id, int32 model_id, uint64 width, uint64 height, double params[num_params]
// and images as
//   uint32 image_id, double qw qx qy qz, double tx ty tz, uint32 camera_id, NAME '\0',
//   uint64 num_points2D, then per point double x, double y, uint64 point3D_id.
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "finecap/util/error.h"
#include "io/camera_io_colmap.h"
#include "util/io_util.h"

namespace finecap {
namespace {

// Reads a file's little-endian values in order; running past the end is an error naming the file,
// the value and where it stopped.
class LittleEndianReader {
 public:
  explicit LittleEndianReader(const std::string& path)
      : path_(path), bytes_(internal::ReadWholeFile(path)) {}

  uint64_t Unsigned(int num_bytes, const std::string& what) {
    RequireBytes(static_cast<uint64_t>(num_bytes), what);
    uint64_t value = 0;
    for (int i = num_bytes - 1; i >= 0; --i) {
      value = (value << 8) | static_cast<unsigned char>(bytes_[offset_ + i]);
    }
    offset_ += num_bytes;
    return value;
  }

  uint64_t Uint64(const std::string& what) { return Unsigned(8, what); }
  uint32_t Uint32(const std::string& what) { return static_cast<uint32_t>(Unsigned(4, what)); }
  int32_t Int32(const std::string& what) { return static_cast<int32_t>(Uint32(what)); }

  double Double(const std::string& what) {
    const uint64_t bits = Uint64(what);
    double value = 0.0;
    std::memcpy(&value, &bits, sizeof value);
    return value;
  }

  // A string ended by '\0'.
  std::string String(const std::string& what) {
    const size_t end = bytes_.find('\0', offset_);
    Require(end != std::string::npos, path_, Truncated(what));
    std::string text = bytes_.substr(offset_, end - offset_);
    offset_ = end + 1;
    return text;
  }

  void Skip(uint64_t count, uint64_t size, const std::string& what) {
    Require(count <= Remaining() / size, path_, Truncated(what));
    offset_ += count * size;
  }

  // Refuses bytes after the last record: the counts and the file disagree.
  void RequireEnd() const {
    Require(Remaining() == 0, path_,
            std::to_string(Remaining()) + " bytes follow the last record (damaged file?)");
  }

  const std::string& path() const { return path_; }

 private:
  uint64_t Remaining() const { return bytes_.size() - offset_; }

  void RequireBytes(uint64_t count, const std::string& what) const {
    Require(count <= Remaining(), path_, Truncated(what));
  }

  std::string Truncated(const std::string& what) const {
    return "truncated: the file ends in " + what + " (byte " + std::to_string(offset_) + " of " +
           std::to_string(bytes_.size()) + ")";
  }

  std::string path_;
  std::string bytes_;
  size_t offset_ = 0;
};

// COLMAP's name of `model_id`; an id COLMAP does not define is an error at `where`.
std::string ModelName(int32_t model_id, const std::string& where) {
  const std::vector<internal::ColmapModelInfo>& models = internal::ColmapModels();
  Require(model_id >= 0 && model_id < static_cast<int32_t>(models.size()), where,
          "unknown camera model id " + std::to_string(model_id) + " (COLMAP's are 0 to " +
              std::to_string(models.size() - 1) + ")");
  return models[model_id].name;
}

internal::ColmapCameraRecord ReadCameraRecord(LittleEndianReader* file, int camera_id) {
  const std::string record = "camera " + std::to_string(camera_id);
  internal::ColmapCameraRecord camera;
  camera.where = file->path() + " (" + record + ")";
  camera.model = ModelName(file->Int32(record + "'s model id"), camera.where);
  const uint64_t width = file->Uint64(record + "'s width");
  const uint64_t height = file->Uint64(record + "'s height");
  // A damaged size may not fit the record's signed integers: capped far above any image, it is
  // still refused, by the size check every model shares.
  constexpr uint64_t kTooLarge = uint64_t{1} << 40;
  camera.width = static_cast<long long>(std::min(width, kTooLarge));
  camera.height = static_cast<long long>(std::min(height, kTooLarge));
  const int num_params = internal::FindColmapModel(camera.model)->num_params;
  for (int i = 0; i < num_params; ++i) camera.params.push_back(file->Double(record + "'s params"));
  return camera;
}

std::map<int, internal::ColmapCameraRecord> ReadCamerasBin(const std::string& path) {
  LittleEndianReader file(path);
  const uint64_t count = file.Uint64("the camera count");
  std::map<int, internal::ColmapCameraRecord> cameras;
  for (uint64_t i = 0; i < count; ++i) {
    const int camera_id =
        static_cast<int>(file.Uint32("the id of camera record " + std::to_string(i + 1)));
    Require(cameras.count(camera_id) == 0, path,
            "camera id " + std::to_string(camera_id) + " appears twice");
    cameras[camera_id] = ReadCameraRecord(&file, camera_id);
  }
  file.RequireEnd();
  Require(!cameras.empty(), path, "no cameras in the file");
  return cameras;
}

internal::ColmapImageRecord ReadImageRecord(LittleEndianReader* file, int image_id) {
  const std::string record = "image " + std::to_string(image_id);
  internal::ColmapImageRecord image;
  image.image_id = image_id;
  for (double& value : image.quaternion) value = file->Double(record + "'s quaternion");
  for (int i = 0; i < 3; ++i) image.t[i] = file->Double(record + "'s translation");
  image.camera_id = static_cast<int>(file->Uint32(record + "'s camera id"));
  image.name = file->String(record + "'s name");
  image.where = file->path() + " (" + record + ", " + image.name + ")";
  Require(!image.name.empty(), image.where, "the image has no name");
  const uint64_t num_points = file->Uint64(record + "'s 2D point count");
  // x, y (doubles) and the id of its 3D point (uint64): not used.
  file->Skip(num_points, 24, record + "'s 2D points");
  return image;
}

std::vector<internal::ColmapImageRecord> ReadImagesBin(const std::string& path) {
  LittleEndianReader file(path);
  const uint64_t count = file.Uint64("the image count");
  std::vector<internal::ColmapImageRecord> images;
  std::map<int, bool> seen_ids;
  for (uint64_t i = 0; i < count; ++i) {
    const int image_id =
        static_cast<int>(file.Uint32("the id of image record " + std::to_string(i + 1)));
    Require(!seen_ids[image_id], path, "image id " + std::to_string(image_id) + " appears twice");
    seen_ids[image_id] = true;
    images.push_back(ReadImageRecord(&file, image_id));
  }
  file.RequireEnd();
  return images;
}

}  // namespace

ColmapModel ReadColmapBinaryModel(const std::string& folder) {
  const std::string cameras_path = (std::filesystem::path(folder) / "cameras.bin").string();
  const std::string images_path = (std::filesystem::path(folder) / "images.bin").string();
  const std::map<int, internal::ColmapCameraRecord> cameras = ReadCamerasBin(cameras_path);
  return internal::CamerasOfColmapRecords(cameras, ReadImagesBin(images_path), images_path);
}

}  // namespace finecap
