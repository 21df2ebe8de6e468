// A COLMAP text model: the input is cameras.txt, then a line "%%", then images.txt.
#include <filesystem>

#include "finecap/io/camera_io.h"
#include "fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace finecap;
  const auto [cameras, images] = fuzz::SplitInTwo(data, size);
  std::filesystem::create_directories(fuzz::ScratchDir() / "colmap");
  fuzz::WriteScratchText("colmap/cameras.txt", cameras);
  fuzz::WriteScratchText("colmap/images.txt", images);
  fuzz::ExpectOnlyErrors([&] { ReadColmapTextModel((fuzz::ScratchDir() / "colmap").string()); });
  return 0;
}
