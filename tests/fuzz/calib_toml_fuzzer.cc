// Calib.toml (Pose2Sim, anipose): ReadCalibToml on arbitrary bytes; a rig that reads must survive
// a round trip through cameras.yaml unchanged (an Error there is a bug too: finecap would have
// accepted a rig it cannot write).
#include <cstdio>

#include "finecap/io/camera_io.h"
#include "fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace finecap;
  const std::string path = fuzz::WriteScratchFile("Calib.toml", data, size);
  std::vector<Camera> cameras;
  fuzz::ExpectOnlyErrors([&] { cameras = ReadCalibToml(path); });
  if (cameras.empty()) return 0;
  try {
    const std::string copy = (fuzz::ScratchDir() / "cameras.yaml").string();
    WriteCamerasYaml(cameras, copy);
    const std::vector<Camera> back = ReadCamerasYaml(copy);
    for (size_t c = 0; c < cameras.size(); ++c) {
      if (back.size() != cameras.size() || back[c].name != cameras[c].name ||
          back[c].width != cameras[c].width || back[c].height != cameras[c].height ||
          back[c].K != cameras[c].K || back[c].R != cameras[c].R || back[c].t != cameras[c].t ||
          back[c].distortion != cameras[c].distortion) {
        std::fprintf(stderr, "camera %zu changed in the round trip through cameras.yaml\n", c);
        std::abort();
      }
    }
  } catch (const std::exception& error) {
    std::fprintf(stderr, "a rig read from Calib.toml failed the cameras.yaml round trip: %s\n",
                 error.what());
    std::abort();
  }
  return 0;
}
