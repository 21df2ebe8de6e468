// cameras.yaml: ReadCamerasYaml on arbitrary bytes; a rig that reads must survive a round trip
// through WriteCamerasYaml unchanged.
#include "finecap/io/camera_io.h"
#include "fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace finecap;
  const std::string path = fuzz::WriteScratchFile("cameras.yaml", data, size);
  fuzz::ExpectOnlyErrors([&] {
    const std::vector<Camera> cameras = ReadCamerasYaml(path);
    const std::string copy = (fuzz::ScratchDir() / "copy.yaml").string();
    WriteCamerasYaml(cameras, copy);
    const std::vector<Camera> back = ReadCamerasYaml(copy);
    for (size_t c = 0; c < cameras.size(); ++c) {
      if (back.size() != cameras.size() || back[c].name != cameras[c].name ||
          back[c].K != cameras[c].K || back[c].R != cameras[c].R || back[c].t != cameras[c].t) {
        std::abort();  // The writer and the reader disagree.
      }
    }
  });
  return 0;
}
