// Finding a capture's camera rig among the supported formats.
#include "finecap/io/camera_io.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <utility>

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

// The COLMAP model of a capture folder, binary or text, with its images under images/.
Rig ReadColmapRig(const fs::path& dir, const fs::path& folder, bool binary) {
  std::error_code error;
  const std::string relative = fs::relative(folder, dir, error).string();
  Rig rig;
  rig.source = std::string("COLMAP ") + (binary ? "binary" : "text") + " model" +
               (relative == "." ? std::string() : " in " + relative);
  ColmapModel model =
      binary ? ReadColmapBinaryModel(folder.string()) : ReadColmapTextModel(folder.string());
  rig.cameras = std::move(model.cameras);
  for (const std::string& name : model.image_names) {
    rig.colmap_images.push_back((dir / "images" / name).string());
  }
  return rig;
}

}  // namespace

Rig ReadRig(const std::string& capture_dir) {
  const fs::path dir(capture_dir);
  std::error_code error;
  Require(fs::is_directory(dir, error), capture_dir, "capture folder not found");
  if (fs::exists(dir / "cameras.yaml", error)) {
    return {ReadCamerasYaml((dir / "cameras.yaml").string()), "cameras.yaml", {}};
  }
  if (fs::exists(dir / "intri.yml", error) || fs::exists(dir / "extri.yml", error)) {
    return {ReadIntriExtri((dir / "intri.yml").string(), (dir / "extri.yml").string()),
            "intri.yml + extri.yml",
            {}};
  }
  const std::vector<fs::path> tomls = CalibTomlFiles(dir);
  if (tomls.size() > 1) {
    std::vector<std::string> names;
    for (const fs::path& toml : tomls) names.push_back(toml.filename().string());
    throw Error(capture_dir, "more than one calibration file (" + internal::JoinWithCommas(names) +
                                 "): keep the one that calibrates these images");
  }
  if (tomls.size() == 1) {
    return {ReadCalibToml(tomls.front().string()),
            tomls.front().filename().string() + " (Pose2Sim/anipose)",
            {}};
  }
  for (const fs::path& folder : {dir / "sparse", dir / "sparse" / "0", dir}) {
    // COLMAP itself reads the binary model when both are there.
    if (fs::exists(folder / "cameras.bin", error)) return ReadColmapRig(dir, folder, true);
    if (fs::exists(folder / "cameras.txt", error)) return ReadColmapRig(dir, folder, false);
  }
  throw Error(capture_dir,
              "no camera rig found: expected cameras.yaml, intri.yml + extri.yml, a Calib.toml "
              "(Pose2Sim, anipose) or a COLMAP model (cameras.bin + images.bin or cameras.txt + "
              "images.txt in sparse/, sparse/0/ or the folder itself)");
}

}  // namespace finecap
