// Finding a capture's camera rig among the supported formats.
#include "finecap/io/camera_io.h"

#include <algorithm>
#include <cctype>
#include <filesystem>

#include "finecap/util/error.h"
#include "util/io_util.h"

namespace finecap {
namespace {

namespace fs = std::filesystem;

// Pose2Sim names its file Calib.toml or Calib_<method>.toml, anipose calibration.toml, FreeMoCap
// <recording>_camera_calibration.toml; Pose2Sim's Config.toml is not one.
std::vector<fs::path> CalibTomlFiles(const fs::path& dir) {
  std::vector<fs::path> files;
  std::error_code error;
  for (const fs::directory_entry& entry : fs::directory_iterator(dir, error)) {
    std::string name = entry.path().filename().string();
    std::transform(name.begin(), name.end(), name.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    const bool toml = name.size() > 5 && name.compare(name.size() - 5, 5, ".toml") == 0;
    if (toml && name.find("calib") != std::string::npos && entry.is_regular_file(error)) {
      files.push_back(entry.path());
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

}  // namespace

std::vector<Camera> ReadRig(const std::string& capture_dir, std::string* source) {
  const fs::path dir(capture_dir);
  std::error_code error;
  std::string unused;
  std::string& read_from = source != nullptr ? *source : unused;
  Require(fs::is_directory(dir, error), capture_dir, "capture folder not found");
  if (fs::exists(dir / "cameras.yaml", error)) {
    read_from = "cameras.yaml";
    return ReadCamerasYaml((dir / "cameras.yaml").string());
  }
  if (fs::exists(dir / "intri.yml", error) || fs::exists(dir / "extri.yml", error)) {
    read_from = "intri.yml + extri.yml";
    return ReadIntriExtri((dir / "intri.yml").string(), (dir / "extri.yml").string());
  }
  const std::vector<fs::path> tomls = CalibTomlFiles(dir);
  if (tomls.size() > 1) {
    std::vector<std::string> names;
    for (const fs::path& toml : tomls) names.push_back(toml.filename().string());
    throw Error(capture_dir, "more than one calibration file (" + internal::JoinWithCommas(names) +
                                 "): keep the one that calibrates these images");
  }
  if (tomls.size() == 1) {
    read_from = tomls.front().filename().string() + " (Pose2Sim/anipose)";
    return ReadCalibToml(tomls.front().string());
  }
  for (const fs::path& folder : {dir / "sparse", dir / "sparse" / "0", dir}) {
    if (fs::exists(folder / "cameras.txt", error)) {
      const std::string relative = fs::relative(folder, dir, error).string();
      read_from = "COLMAP text model" + (relative == "." ? std::string() : " in " + relative);
      return ReadColmapTextModel(folder.string());
    }
  }
  throw Error(capture_dir,
              "no camera rig found: expected cameras.yaml, intri.yml + extri.yml, a Calib.toml "
              "(Pose2Sim, anipose) or a COLMAP text model (cameras.txt + images.txt in sparse/, "
              "sparse/0/ or the folder itself)");
}

}  // namespace finecap
