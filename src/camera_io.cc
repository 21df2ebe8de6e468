// Finding a capture's camera rig among the supported formats.
#include "finecap/camera_io.h"

#include <filesystem>

#include "finecap/error.h"

namespace finecap {

std::vector<Camera> ReadRig(const std::string& capture_dir, std::string* source) {
  namespace fs = std::filesystem;
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
  for (const fs::path& folder : {dir / "sparse", dir / "sparse" / "0", dir}) {
    if (fs::exists(folder / "cameras.txt", error)) {
      const std::string relative = fs::relative(folder, dir, error).string();
      read_from = "COLMAP text model" + (relative == "." ? std::string() : " in " + relative);
      return ReadColmapTextModel(folder.string());
    }
  }
  throw Error(capture_dir,
              "no camera rig found: expected cameras.yaml, intri.yml + extri.yml, or a COLMAP "
              "text model (cameras.txt + images.txt in sparse/, sparse/0/ or the folder itself)");
}

}  // namespace finecap
