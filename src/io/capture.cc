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

// The meshes COLMAP's poisson_mesher and delaunay_mesher write into a dense workspace.
std::vector<fs::path> ColmapMeshes(const fs::path& dir) {
  std::vector<fs::path> meshes;
  std::error_code error;
  for (const fs::directory_entry& entry : fs::directory_iterator(dir, error)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("meshed-", 0) == 0 && entry.path().extension() == ".ply" &&
        entry.is_regular_file(error)) {
      meshes.push_back(entry.path());
    }
  }
  std::sort(meshes.begin(), meshes.end());
  return meshes;
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

// The camera's images, checked to exist: what is missing is named, for a COLMAP camera the image
// the model names.
std::string RequireCameraStream(const std::string& stream, const Camera& camera,
                                const std::string& colmap_image, const std::string& rig_source,
                                const std::string& dir) {
  const std::string elsewhere =
      "an image folder images/" + camera.name + "/ nor a video videos/" + camera.name + ".*";
  if (colmap_image.empty()) {
    Require(!stream.empty(), dir, "camera " + camera.name + " has neither " + elsewhere);
  } else {
    Require(!stream.empty(), colmap_image,
            "not found: the " + rig_source + " names it as the image of camera " + camera.name +
                ", and there is neither " + elsewhere);
  }
  return stream;
}

}  // namespace

Capture Capture::Open(const std::string& dir, const std::string& mesh) {
  std::error_code error;
  Require(fs::is_directory(dir, error), dir, "capture folder not found");
  Capture capture;
  capture.directory_ = dir;
  Rig rig = ReadRig(dir);
  capture.rig_ = std::move(rig.cameras);
  capture.rig_source_ = std::move(rig.source);
  capture.FindFrames(mesh);
  capture.ReadCameras(rig.colmap_images);
  capture.OpenFrameSources();
  capture.OpenMaskSources();
  capture.ReadOptionalFiles();
  return capture;
}

void Capture::FindFrames(const std::string& mesh) {
  std::error_code error;
  if (!mesh.empty()) {
    frame_names_ = {fs::path(mesh).stem().string()};
    mesh_paths_ = {mesh};
  } else if (fs::is_directory(fs::path(directory_) / "meshes", error)) {
    FindFramesInMeshFolder();
  } else {
    FindColmapMesh();
  }
  first_mesh_ = ReadMesh(mesh_paths_[0]);
}

void Capture::FindFramesInMeshFolder() {
  const fs::path meshes = fs::path(directory_) / "meshes";
  std::error_code error;
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
}

// The mesh of a COLMAP dense workspace, its one frame.
void Capture::FindColmapMesh() {
  const std::vector<fs::path> meshes = ColmapMeshes(directory_);
  Require(!meshes.empty(), (fs::path(directory_) / "meshes").string(),
          "mesh folder not found (one coarse mesh per frame is needed; a one-frame capture may "
          "instead give its mesh with --mesh FILE or hold COLMAP's meshed-poisson.ply or "
          "meshed-delaunay.ply)");
  if (meshes.size() > 1) {
    std::vector<std::string> names;
    for (const fs::path& path : meshes) names.push_back(path.filename().string());
    throw Error(directory_, "more than one COLMAP mesh (" + internal::JoinWithCommas(names) +
                                "): choose one with --mesh FILE");
  }
  frame_names_ = {meshes[0].stem().string()};
  mesh_paths_ = {meshes[0].string()};
}

// images/<camera>/ if present, else the video videos/<camera>.<any extension>, else the image of
// a COLMAP model (images/NAME); empty if none.
std::string Capture::FindCameraStream(const Camera& camera, const std::string& colmap_image) const {
  const fs::path dir(directory_);
  std::error_code error;
  const fs::path images = dir / "images" / camera.name;
  if (fs::is_directory(images, error)) return images.string();
  if (fs::is_directory(dir / "videos", error)) {
    for (const fs::directory_entry& entry : fs::directory_iterator(dir / "videos", error)) {
      if (entry.is_regular_file(error) && entry.path().stem() == camera.name) {
        return entry.path().string();
      }
    }
  }
  if (!colmap_image.empty() && fs::is_regular_file(colmap_image, error)) return colmap_image;
  return "";
}

// Fills in the image size of rigs that do not state it (intri/extri), from the first image.
void Capture::ReadCameras(const std::vector<std::string>& colmap_images) {
  for (size_t c = 0; c < rig_.size(); ++c) {
    Camera& camera = rig_[c];
    const std::string colmap_image = colmap_images.empty() ? "" : colmap_images[c];
    streams_.push_back(RequireCameraStream(FindCameraStream(camera, colmap_image), camera,
                                           colmap_image, rig_source_, directory_));
    std::error_code error;
    flat_image_names_.push_back(
        streams_.back() == colmap_image
            ? fs::relative(colmap_image, fs::path(directory_) / "images", error).string()
            : "");
    Require(streams_.back() != colmap_image || num_frames() == 1, colmap_image,
            "a single image (COLMAP's flat images/ layout) holds one frame, but the capture has " +
                std::to_string(num_frames()) + " meshes");
    if (camera.width == 0 && camera.height == 0) {
      const cv::Size size = ReadFirstFrameSize(streams_.back(), frame_names_);
      camera.width = size.width;
      camera.height = size.height;
    }
    camera.Validate(directory_);
    cameras_.push_back(camera.Undistorted());
  }
}

void Capture::OpenFrameSources() {
  for (size_t c = 0; c < rig_.size(); ++c) {
    sources_.push_back(OpenFrameSource(streams_[c], frame_names_, rig_[c]));
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
  for (size_t c = 0; c < rig_.size(); ++c) {
    const Camera& camera = rig_[c];
    const fs::path camera_folder = fs::path(folder) / camera.name;
    std::error_code error;
    if (!flat_image_names_[c].empty() && !fs::is_directory(camera_folder, error)) {
      // COLMAP's layout: the mask of images/NAME is masks/NAME.png.
      const std::string mask = (fs::path(folder) / (flat_image_names_[c] + ".png")).string();
      Require(fs::is_regular_file(mask, error), mask,
              "mask not found: with " + folder + " every image needs its mask (COLMAP's masks/" +
                  flat_image_names_[c] + ".png, or masks/" + camera.name + "/)");
      mask_sources_.push_back(MakeMaskFileSource(mask, camera));
      continue;
    }
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
