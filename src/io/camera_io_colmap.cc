// COLMAP's camera models mapped to finecap's cameras, and COLMAP's text model (cameras.txt +
// images.txt).
#include "io/camera_io_colmap.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <utility>

#include <Eigen/Geometry>

#include "finecap/util/error.h"
#include "util/io_util.h"

namespace finecap {
namespace internal {
namespace {

// The names of the models finecap reads, for the refusal of the others.
std::string SupportedModelNames() {
  std::vector<std::string> names;
  for (const ColmapModelInfo& model : ColmapModels()) {
    if (model.has_opencv_equivalent) names.push_back(model.name);
  }
  return JoinWithCommas(names);
}

// The K of a model's parameters. COLMAP puts the top-left pixel's centre at (0.5, 0.5), finecap
// at (0, 0): the principal point moves by -0.5. The models with one focal length list f cx cy,
// the others fx fy cx cy.
Eigen::Matrix3d IntrinsicMatrix(const std::string& model, const std::vector<double>& p) {
  const bool single_focal =
      model == "SIMPLE_PINHOLE" || model == "SIMPLE_RADIAL" || model == "RADIAL";
  const double fx = p[0];
  const double fy = single_focal ? p[0] : p[1];
  const size_t principal = single_focal ? 1 : 2;
  Eigen::Matrix3d K;
  K << fx, 0.0, p[principal] - 0.5, 0.0, fy, p[principal + 1] - 0.5, 0.0, 0.0, 1.0;
  return K;
}

// OpenCV's distortion of a model's parameters: the radial models' k1 (k2), the OpenCV models'
// coefficients in OpenCV's own order (FULL_OPENCV's k1 k2 p1 p2 k3 k4 k5 k6).
std::array<double, 12> OpenCvDistortionOfModel(const std::string& model,
                                               const std::vector<double>& p) {
  std::array<double, 12> d = {};
  size_t first = p.size();
  if (model == "SIMPLE_RADIAL" || model == "RADIAL") first = 3;
  if (model == "OPENCV" || model == "FULL_OPENCV") first = 4;
  std::copy(p.begin() + first, p.end(), d.begin());
  return d;
}

// The intrinsic part of a camera: size, K and distortion.
Camera IntrinsicsOf(const ColmapCameraRecord& record) {
  const ColmapModelInfo* model = FindColmapModel(record.model);
  Require(model != nullptr && model->has_opencv_equivalent, record.where,
          "unsupported camera model '" + record.model +
              "': it has no OpenCV equivalent (supported: " + SupportedModelNames() + ")");
  Require(static_cast<int>(record.params.size()) == model->num_params, record.where,
          "model " + record.model + " takes " + std::to_string(model->num_params) +
              " parameters, not " + std::to_string(record.params.size()));
  constexpr long long kMaxSide = 1 << 20;  // Larger than any image a decoder accepts.
  Require(record.width > 0 && record.height > 0 && record.width <= kMaxSide &&
              record.height <= kMaxSide,
          record.where,
          "image size " + std::to_string(record.width) + "x" + std::to_string(record.height) +
              " is not a plausible image size");
  Camera camera;
  camera.width = static_cast<int>(record.width);
  camera.height = static_cast<int>(record.height);
  camera.K = IntrinsicMatrix(record.model, record.params);
  camera.distortion = OpenCvDistortionOfModel(record.model, record.params);
  return camera;
}

// `cam03/000000.jpg` -> `cam03`; `cam03.jpg` -> `cam03`.
std::string CameraNameOfImage(const std::string& image_name) {
  const std::filesystem::path name(image_name);
  const std::string folder = name.parent_path().filename().string();
  return folder.empty() ? name.stem().string() : folder;
}

// Sets the pose of `camera` from an image's quaternion and translation.
void SetPose(const ColmapImageRecord& image, Camera* camera) {
  const double* q = image.quaternion;
  const Eigen::Quaterniond rotation(q[0], q[1], q[2], q[3]);
  // COLMAP writes unit quaternions; anything far from unit length is a damaged file.
  Require(std::isfinite(rotation.norm()) && std::abs(rotation.norm() - 1.0) < 1e-3, image.where,
          "the quaternion QW QX QY QZ is not of unit length");
  camera->R = rotation.normalized().toRotationMatrix();
  camera->t = image.t;
}

}  // namespace

const std::vector<ColmapModelInfo>& ColmapModels() {
  static const std::vector<ColmapModelInfo> kModels = {
      {"SIMPLE_PINHOLE", 3, true},
      {"PINHOLE", 4, true},
      {"SIMPLE_RADIAL", 4, true},
      {"RADIAL", 5, true},
      {"OPENCV", 8, true},
      {"OPENCV_FISHEYE", 8, false},
      {"FULL_OPENCV", 12, true},
      {"FOV", 5, false},
      {"SIMPLE_RADIAL_FISHEYE", 4, false},
      {"RADIAL_FISHEYE", 5, false},
      {"THIN_PRISM_FISHEYE", 12, false},
      {"RAD_TAN_THIN_PRISM_FISHEYE", 16, false},
  };
  return kModels;
}

const ColmapModelInfo* FindColmapModel(const std::string& name) {
  for (const ColmapModelInfo& model : ColmapModels()) {
    if (name == model.name) return &model;
  }
  return nullptr;
}

ColmapModel CamerasOfColmapRecords(const std::map<int, ColmapCameraRecord>& cameras,
                                   std::vector<ColmapImageRecord> images,
                                   const std::string& images_path) {
  // Every camera is checked, those no image uses too: a damaged record is a damaged file.
  std::map<int, Camera> intrinsics;
  for (const auto& [camera_id, record] : cameras) intrinsics[camera_id] = IntrinsicsOf(record);
  Require(!images.empty(), images_path, "no images in the file");
  std::sort(images.begin(), images.end(),
            [](const ColmapImageRecord& a, const ColmapImageRecord& b) {
              return a.image_id < b.image_id;
            });
  ColmapModel model;
  for (const ColmapImageRecord& image : images) {
    const std::string name = CameraNameOfImage(image.name);
    bool seen = false;
    for (const Camera& camera : model.cameras) seen = seen || camera.name == name;
    if (seen) continue;  // A later frame of a camera already posed.
    const auto found = intrinsics.find(image.camera_id);
    Require(found != intrinsics.end(), image.where,
            "image '" + image.name + "' refers to CAMERA_ID " + std::to_string(image.camera_id) +
                ", which the model's cameras do not define");
    Camera camera = found->second;
    camera.name = name;
    SetPose(image, &camera);
    camera.Validate(image.where);
    model.cameras.push_back(camera);
    model.image_names.push_back(image.name);
  }
  return model;
}

}  // namespace internal

namespace {

std::string LineLocation(const std::string& path, int line_number) {
  return path + " line " + std::to_string(line_number);
}

std::vector<double> ParseNumbers(const std::vector<std::string>& tokens, size_t first,
                                 const std::string& where) {
  std::vector<double> numbers;
  for (size_t i = first; i < tokens.size(); ++i) {
    double value = 0.0;
    Require(internal::ParseDouble(tokens[i], &value), where, "'" + tokens[i] + "' is not a number");
    numbers.push_back(value);
  }
  return numbers;
}

internal::ColmapCameraRecord ParseCameraLine(const std::vector<std::string>& tokens,
                                             const std::string& where) {
  Require(tokens.size() >= 4, where, "expected CAMERA_ID MODEL WIDTH HEIGHT PARAMS[]");
  internal::ColmapCameraRecord record;
  record.model = tokens[1];
  record.where = where;
  int width = 0;
  int height = 0;
  Require(internal::ParseInt(tokens[2], &width) && internal::ParseInt(tokens[3], &height), where,
          "WIDTH and HEIGHT must be integers");
  record.width = width;
  record.height = height;
  record.params = ParseNumbers(tokens, 4, where);
  return record;
}

// Non-empty lines that are not comments, with their 1-based line numbers.
std::vector<std::pair<int, std::string>> ContentLines(const std::string& path,
                                                      bool keep_line_after_content) {
  std::istringstream stream(internal::ReadWholeFile(path));
  std::vector<std::pair<int, std::string>> lines;
  int line_number = 0;
  bool previous_was_content = false;
  for (std::string line; std::getline(stream, line);) {
    ++line_number;
    const size_t start = line.find_first_not_of(" \t\r");
    const bool skip = start == std::string::npos || line[start] == '#';
    // In images.txt the line after an image line holds its 2D points and may be empty.
    if (keep_line_after_content && previous_was_content) {
      lines.emplace_back(line_number, line);
      previous_was_content = false;
      continue;
    }
    if (skip) continue;
    lines.emplace_back(line_number, line);
    previous_was_content = true;
  }
  return lines;
}

std::map<int, internal::ColmapCameraRecord> ReadCamerasTxt(const std::string& path) {
  std::map<int, internal::ColmapCameraRecord> cameras;
  for (const auto& [line_number, line] : ContentLines(path, false)) {
    const std::string where = LineLocation(path, line_number);
    const std::vector<std::string> tokens = internal::SplitWhitespace(line);
    int camera_id = 0;
    Require(!tokens.empty() && internal::ParseInt(tokens[0], &camera_id), where,
            "CAMERA_ID must be an integer");
    Require(cameras.count(camera_id) == 0, where,
            "CAMERA_ID " + std::to_string(camera_id) + " appears twice");
    cameras[camera_id] = ParseCameraLine(tokens, where);
  }
  Require(!cameras.empty(), path, "no cameras in the file");
  return cameras;
}

internal::ColmapImageRecord ParseImageLine(const std::string& line, const std::string& where) {
  const std::vector<std::string> tokens = internal::SplitWhitespace(line);
  Require(tokens.size() == 10, where, "expected IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME");
  internal::ColmapImageRecord image;
  Require(internal::ParseInt(tokens[0], &image.image_id) &&
              internal::ParseInt(tokens[8], &image.camera_id),
          where, "IMAGE_ID and CAMERA_ID must be integers");
  const std::vector<double> pose = ParseNumbers({tokens.begin() + 1, tokens.begin() + 8}, 0, where);
  std::copy(pose.begin(), pose.begin() + 4, image.quaternion);
  image.t = Eigen::Vector3d(pose[4], pose[5], pose[6]);
  image.name = tokens[9];
  image.where = where;
  return image;
}

std::vector<internal::ColmapImageRecord> ReadImagesTxt(const std::string& path) {
  std::vector<internal::ColmapImageRecord> images;
  std::map<int, bool> seen_ids;
  const auto lines = ContentLines(path, true);
  for (size_t i = 0; i < lines.size(); i += 2) {  // Odd lines: the 2D points, unused.
    const std::string where = LineLocation(path, lines[i].first);
    internal::ColmapImageRecord image = ParseImageLine(lines[i].second, where);
    Require(!seen_ids[image.image_id], where,
            "IMAGE_ID " + std::to_string(image.image_id) + " appears twice");
    seen_ids[image.image_id] = true;
    images.push_back(std::move(image));
  }
  return images;
}

}  // namespace

ColmapModel ReadColmapTextModel(const std::string& folder) {
  const std::string cameras_path = (std::filesystem::path(folder) / "cameras.txt").string();
  const std::string images_path = (std::filesystem::path(folder) / "images.txt").string();
  const std::map<int, internal::ColmapCameraRecord> cameras = ReadCamerasTxt(cameras_path);
  return internal::CamerasOfColmapRecords(cameras, ReadImagesTxt(images_path), images_path);
}

}  // namespace finecap
