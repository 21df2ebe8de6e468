#include "finecap/io/capture.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <exception>
#include <filesystem>
#include <map>
#include <sstream>
#include <utility>

#include "finecap/io/camera_io.h"
#include "finecap/io/mesh_io.h"
#include "finecap/io/vertex_mask.h"
#include "finecap/util/error.h"
#include "finecap/util/threads.h"
#include "util/io_util.h"

namespace finecap {
namespace {

namespace fs = std::filesystem;

bool IsNumber(const std::string& name) {
  return !name.empty() && std::all_of(name.begin(), name.end(),
                                      [](unsigned char c) { return std::isdigit(c) != 0; });
}

// Numeric order for digit strings of any length: fewer significant digits first, then by digits.
bool NumericallyBefore(const std::string& a, const std::string& b) {
  const std::string a_digits = a.substr(std::min(a.find_first_not_of('0'), a.size()));
  const std::string b_digits = b.substr(std::min(b.find_first_not_of('0'), b.size()));
  if (a_digits.size() != b_digits.size()) return a_digits.size() < b_digits.size();
  return a_digits != b_digits ? a_digits < b_digits : a < b;
}

void SortFrameNames(std::vector<std::string>* names) {
  if (std::all_of(names->begin(), names->end(), IsNumber)) {
    std::sort(names->begin(), names->end(), NumericallyBefore);
  } else {
    std::sort(names->begin(), names->end());
  }
}

// images/<camera> if present, else the video videos/<camera>.<any extension>; empty if neither.
std::string FindCameraStream(const fs::path& dir, const std::string& camera_name) {
  std::error_code error;
  const fs::path images = dir / "images" / camera_name;
  if (fs::is_directory(images, error)) return images.string();
  if (!fs::is_directory(dir / "videos", error)) return "";
  for (const fs::directory_entry& entry : fs::directory_iterator(dir / "videos", error)) {
    if (entry.is_regular_file(error) && entry.path().stem() == camera_name) {
      return entry.path().string();
    }
  }
  return "";
}

// The folder of foreground masks: masks/, else mask/ (ZJU-MoCap, EasyMocap); empty if neither.
std::string FindMaskFolder(const fs::path& dir) {
  std::error_code error;
  for (const char* name : {"masks", "mask"}) {
    if (fs::is_directory(dir / name, error)) return (dir / name).string();
  }
  return "";
}

Eigen::VectorXd ParseDisplacements(const std::string& path, int num_vertices) {
  std::istringstream stream(internal::ReadWholeFile(path));
  std::vector<double> values;
  int line_number = 0;
  for (std::string line; std::getline(stream, line);) {
    ++line_number;
    const std::vector<std::string> tokens = internal::SplitWhitespace(line);
    if (tokens.empty()) continue;
    const std::string where = path + " line " + std::to_string(line_number);
    double value = 0.0;
    Require(tokens.size() == 1 && internal::ParseDouble(tokens[0], &value), where,
            "expected one displacement (a number or nan), got '" + line + "'");
    Require(!std::isinf(value), where, "infinite displacement");
    values.push_back(value);
  }
  Require(static_cast<int>(values.size()) == num_vertices, path,
          "has " + std::to_string(values.size()) + " displacements but the coarse mesh has " +
              std::to_string(num_vertices) + " vertices");
  return Eigen::Map<const Eigen::VectorXd>(values.data(), num_vertices);
}

}  // namespace

Capture Capture::Open(const std::string& dir) {
  std::error_code error;
  Require(fs::is_directory(dir, error), dir, "capture folder not found");
  Capture capture;
  capture.directory_ = dir;
  capture.rig_ = ReadRig(dir, &capture.rig_source_);
  capture.FindFrames();
  capture.ReadCameras();
  capture.OpenFrameSources();
  capture.OpenMaskSources();
  capture.ReadOptionalFiles();
  return capture;
}

void Capture::FindFrames() {
  const fs::path meshes = fs::path(directory_) / "meshes";
  std::error_code error;
  Require(fs::is_directory(meshes, error), meshes.string(),
          "mesh folder not found (one coarse mesh per frame is needed)");
  std::map<std::string, std::string> path_of_frame;
  for (const fs::directory_entry& entry : fs::directory_iterator(meshes, error)) {
    const fs::path& path = entry.path();
    if (!entry.is_regular_file(error) || path.filename().string()[0] == '.') continue;
    const bool is_new = path_of_frame.emplace(path.stem().string(), path.string()).second;
    Require(is_new, path.string(), "a second mesh for frame '" + path.stem().string() + "'");
  }
  Require(!path_of_frame.empty(), meshes.string(), "no mesh files: at least one frame is needed");
  for (const auto& entry : path_of_frame) frame_names_.push_back(entry.first);
  SortFrameNames(&frame_names_);
  for (const std::string& name : frame_names_) mesh_paths_.push_back(path_of_frame[name]);
  first_mesh_ = ReadMesh(mesh_paths_[0]);
}

// Fills in the image size of rigs that do not state it (intri/extri), from the first image.
void Capture::ReadCameras() {
  for (Camera& camera : rig_) {
    const std::string stream = FindCameraStream(directory_, camera.name);
    Require(!stream.empty(), directory_,
            "camera " + camera.name + " has neither an image folder images/" + camera.name +
                "/ nor a video videos/" + camera.name + ".*");
    if (camera.width == 0 && camera.height == 0) {
      const cv::Size size = ReadFirstFrameSize(stream, frame_names_);
      camera.width = size.width;
      camera.height = size.height;
    }
    camera.Validate(directory_);
    cameras_.push_back(camera.Undistorted());
  }
}

void Capture::OpenFrameSources() {
  for (const Camera& camera : rig_) {
    sources_.push_back(
        OpenFrameSource(FindCameraStream(directory_, camera.name), frame_names_, camera));
  }
  // Decodes and checks the first image of each camera, the cameras side by side; a failure is
  // reported as the cameras taken in the rig's order would meet it.
  first_images_.resize(sources_.size());
  ParallelFor(static_cast<int>(sources_.size()),
              [this](int c) { first_images_[c] = sources_[c]->Read(0); });
}

void Capture::OpenMaskSources() {
  const std::string folder = FindMaskFolder(directory_);
  if (folder.empty()) return;
  for (const Camera& camera : rig_) {
    const fs::path camera_folder = fs::path(folder) / camera.name;
    std::error_code error;
    Require(fs::is_directory(camera_folder, error), camera_folder.string(),
            "mask folder not found: with " + folder + " every camera needs its masks");
    mask_sources_.push_back(MakeMaskFolderSource(camera_folder.string(), frame_names_, camera));
  }
  // Checks the first mask of each camera, as the first images are checked.
  ParallelFor(static_cast<int>(mask_sources_.size()), [this](int c) { mask_sources_[c]->Read(0); });
}

void Capture::ReadOptionalFiles() {
  const fs::path dir(directory_);
  std::error_code error;
  has_vertex_mask_ = fs::exists(dir / "mask.txt", error);
  if (has_vertex_mask_) {
    vertex_mask_ = ReadVertexMask((dir / "mask.txt").string(), num_coarse_vertices());
  }
  has_ground_truth_ = fs::is_directory(dir / "gt", error);
  if (fs::exists(dir / "gt" / "textureless.txt", error)) {
    textureless_vertices_ =
        ReadVertexMask((dir / "gt" / "textureless.txt").string(), num_coarse_vertices());
  }
}

void Capture::RequireFrame(int frame) const {
  Require(
      frame >= 0 && frame < num_frames(), directory_,
      "frame " + std::to_string(frame) + " is outside [0, " + std::to_string(num_frames()) + ")");
}

const std::string& Capture::frame_name(int frame) const {
  RequireFrame(frame);
  return frame_names_[frame];
}

const std::string& Capture::mesh_path(int frame) const {
  RequireFrame(frame);
  return mesh_paths_[frame];
}

Mesh Capture::ReadCoarseMesh(int frame) const {
  RequireFrame(frame);
  if (frame == 0) return first_mesh_;
  Mesh mesh = ReadMesh(mesh_paths_[frame]);
  RequireSameTopology(first_mesh_, mesh, mesh_paths_[frame]);
  return mesh;
}

void Capture::RequireCamera(int camera_index) const {
  Require(camera_index >= 0 && camera_index < num_cameras(), directory_,
          "camera index " + std::to_string(camera_index) + " is outside [0, " +
              std::to_string(num_cameras()) + ")");
}

cv::Mat Capture::ReadImage(int camera_index, int frame) {
  RequireCamera(camera_index);
  RequireFrame(frame);
  cv::Mat& first = first_images_[camera_index];
  if (!first.empty()) {
    if (frame == 0) return std::exchange(first, cv::Mat());
    first.release();
  }
  return sources_[camera_index]->Read(frame);
}

cv::Mat Capture::ReadMask(int camera_index, int frame) {
  RequireCamera(camera_index);
  RequireFrame(frame);
  if (!has_masks()) return cv::Mat();
  return mask_sources_[camera_index]->Read(frame);
}

std::string Capture::GroundTruthPath(int frame, const std::string& suffix) const {
  RequireFrame(frame);
  return (fs::path(directory_) / "gt" / (frame_names_[frame] + suffix)).string();
}

bool Capture::HasTrueSurface(int frame) const {
  std::error_code error;
  return fs::exists(GroundTruthPath(frame, ".ply"), error);
}

bool Capture::HasTrueDisplacement(int frame) const {
  std::error_code error;
  return fs::exists(GroundTruthPath(frame, "_k.txt"), error);
}

Mesh Capture::ReadTrueSurface(int frame) const { return ReadMesh(GroundTruthPath(frame, ".ply")); }

Eigen::VectorXd Capture::ReadTrueDisplacement(int frame) const {
  return ParseDisplacements(GroundTruthPath(frame, "_k.txt"), num_coarse_vertices());
}

}  // namespace finecap
