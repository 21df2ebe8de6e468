// COLMAP's text model (cameras.txt + images.txt).
#include <cmath>
#include <filesystem>
#include <map>
#include <sstream>

#include <Eigen/Geometry>

#include "finecap/io/camera_io.h"
#include "finecap/util/error.h"
#include "util/io_util.h"

namespace finecap {
namespace {

// An intrinsic calibration of cameras.txt, already in finecap's convention.
struct ColmapIntrinsics {
  int width = 0;
  int height = 0;
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
  std::array<double, 12> distortion = {};
};

// One posed image of images.txt.
struct ColmapImage {
  int image_id = 0;
  int camera_id = 0;
  std::string camera_name;
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
};

// The supported camera models and how many parameters each takes.
struct ColmapModel {
  const char* name;
  size_t num_params;
};
const ColmapModel kModels[] = {
    {"SIMPLE_PINHOLE", 3}, {"PINHOLE", 4}, {"SIMPLE_RADIAL", 4}, {"RADIAL", 5}, {"OPENCV", 8}};

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

// Maps a model's parameters to K and OpenCV distortion. COLMAP puts the top-left pixel's centre
// at (0.5, 0.5), finecap at (0, 0): the principal point moves by -0.5.
void SetIntrinsicsFromParams(const std::string& model, const std::vector<double>& p,
                             ColmapIntrinsics* intrinsics) {
  const bool single_focal = model != "PINHOLE" && model != "OPENCV";
  const double fx = p[0];
  const double fy = single_focal ? p[0] : p[1];
  const size_t principal = single_focal ? 1 : 2;
  intrinsics->K << fx, 0.0, p[principal] - 0.5, 0.0, fy, p[principal + 1] - 0.5, 0.0, 0.0, 1.0;
  auto& d = intrinsics->distortion;
  if (model == "SIMPLE_RADIAL") d[0] = p[3];
  if (model == "RADIAL") d[0] = p[3], d[1] = p[4];
  if (model == "OPENCV") d[0] = p[4], d[1] = p[5], d[2] = p[6], d[3] = p[7];
}

ColmapIntrinsics ParseCameraLine(const std::vector<std::string>& tokens, const std::string& where) {
  Require(tokens.size() >= 4, where, "expected CAMERA_ID MODEL WIDTH HEIGHT PARAMS[]");
  const std::string& model = tokens[1];
  const ColmapModel* known = nullptr;
  for (const ColmapModel& candidate : kModels) {
    if (model == candidate.name) known = &candidate;
  }
  Require(known != nullptr, where,
          "unsupported camera model '" + model +
              "' (supported: SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV)");
  ColmapIntrinsics intrinsics;
  Require(internal::ParseInt(tokens[2], &intrinsics.width) &&
              internal::ParseInt(tokens[3], &intrinsics.height),
          where, "WIDTH and HEIGHT must be integers");
  const std::vector<double> params = ParseNumbers(tokens, 4, where);
  Require(params.size() == known->num_params, where,
          "model " + model + " takes " + std::to_string(known->num_params) + " parameters, not " +
              std::to_string(params.size()));
  SetIntrinsicsFromParams(model, params, &intrinsics);
  return intrinsics;
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

std::map<int, ColmapIntrinsics> ReadColmapCameras(const std::string& path) {
  std::map<int, ColmapIntrinsics> cameras;
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

// `cam03/000000.jpg` -> `cam03`; `cam03.jpg` -> `cam03`.
std::string CameraNameOfImage(const std::string& image_name) {
  const std::filesystem::path name(image_name);
  const std::string folder = name.parent_path().filename().string();
  return folder.empty() ? name.stem().string() : folder;
}

ColmapImage ParseImageLine(const std::string& line, const std::string& where) {
  const std::vector<std::string> tokens = internal::SplitWhitespace(line);
  Require(tokens.size() == 10, where, "expected IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME");
  ColmapImage image;
  Require(internal::ParseInt(tokens[0], &image.image_id) &&
              internal::ParseInt(tokens[8], &image.camera_id),
          where, "IMAGE_ID and CAMERA_ID must be integers");
  const std::vector<double> pose = ParseNumbers({tokens.begin() + 1, tokens.begin() + 8}, 0, where);
  Eigen::Quaterniond rotation(pose[0], pose[1], pose[2], pose[3]);
  // COLMAP writes unit quaternions; anything far from unit length is a damaged file.
  Require(std::isfinite(rotation.norm()) && std::abs(rotation.norm() - 1.0) < 1e-3, where,
          "the quaternion QW QX QY QZ is not of unit length");
  image.R = rotation.normalized().toRotationMatrix();
  image.t = Eigen::Vector3d(pose[4], pose[5], pose[6]);
  image.camera_name = CameraNameOfImage(tokens[9]);
  return image;
}

std::vector<ColmapImage> ReadColmapImages(const std::string& path) {
  std::map<int, ColmapImage> by_id;  // Ordered by IMAGE_ID.
  const auto lines = ContentLines(path, true);
  for (size_t i = 0; i < lines.size(); i += 2) {  // Odd lines: the 2D points, unused.
    const std::string where = LineLocation(path, lines[i].first);
    ColmapImage image = ParseImageLine(lines[i].second, where);
    Require(by_id.count(image.image_id) == 0, where,
            "IMAGE_ID " + std::to_string(image.image_id) + " appears twice");
    by_id[image.image_id] = image;
  }
  Require(!by_id.empty(), path, "no images in the file");
  std::vector<ColmapImage> images;
  for (const auto& entry : by_id) images.push_back(entry.second);
  return images;
}

}  // namespace

std::vector<Camera> ReadColmapTextModel(const std::string& folder) {
  const std::string cameras_path = (std::filesystem::path(folder) / "cameras.txt").string();
  const std::string images_path = (std::filesystem::path(folder) / "images.txt").string();
  const std::map<int, ColmapIntrinsics> intrinsics = ReadColmapCameras(cameras_path);
  std::vector<Camera> cameras;
  for (const ColmapImage& image : ReadColmapImages(images_path)) {
    bool seen = false;
    for (const Camera& camera : cameras) seen = seen || camera.name == image.camera_name;
    if (seen) continue;  // A later frame of a camera already posed.
    const auto found = intrinsics.find(image.camera_id);
    Require(found != intrinsics.end(), images_path,
            "image of camera '" + image.camera_name + "' refers to CAMERA_ID " +
                std::to_string(image.camera_id) + ", which cameras.txt does not define");
    Camera camera;
    camera.name = image.camera_name;
    camera.width = found->second.width;
    camera.height = found->second.height;
    camera.K = found->second.K;
    camera.distortion = found->second.distortion;
    camera.R = image.R;
    camera.t = image.t;
    camera.Validate(images_path);
    cameras.push_back(camera);
  }
  return cameras;
}

}  // namespace finecap
