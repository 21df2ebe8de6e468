// Calib.toml (Pose2Sim, anipose): ReadCalibToml on arbitrary bytes; a rig that reads must survive
// a round trip through cameras.yaml unchanged.
#include "finecap/camera_io.h"
#include "fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace finecap;
  const std::string path = fuzz::WriteScratchFile("Calib.toml", data, size);
  fuzz::ExpectOnlyErrors([&] {
    const std::vector<Camera> cameras = ReadCalibToml(path);
    const std::string copy = (fuzz::ScratchDir() / "cameras.yaml").string();
    WriteCamerasYaml(cameras, copy);
    const std::vector<Camera> back = ReadCamerasYaml(copy);
    for (size_t c = 0; c < cameras.size(); ++c) {
      if (back.size() != cameras.size() || back[c].name != cameras[c].name ||
          back[c].width != cameras[c].width || back[c].height != cameras[c].height ||
          back[c].K != cameras[c].K || back[c].R != cameras[c].R || back[c].t != cameras[c].t ||
          back[c].distortion != cameras[c].distortion) {
        std::abort();  // The TOML reader produced a rig that cameras.yaml cannot carry.
      }
    }
  });
  return 0;
}
