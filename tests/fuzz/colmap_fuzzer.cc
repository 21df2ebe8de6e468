// A COLMAP model: the input is cameras.txt, then a line "%%", then images.txt; the same two parts
// are also read as cameras.bin and images.bin, the binary model.
#include <filesystem>

#include "finecap/io/camera_io.h"
#include "fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace finecap;
  const auto [cameras, images] = fuzz::SplitInTwo(data, size);
  std::filesystem::create_directories(fuzz::ScratchDir() / "colmap");
  for (const char* extension : {"txt", "bin"}) {
    fuzz::WriteScratchText(std::string("colmap/cameras.") + extension, cameras);
    fuzz::WriteScratchText(std::string("colmap/images.") + extension, images);
  }
  const std::string folder = (fuzz::ScratchDir() / "colmap").string();
  fuzz::ExpectOnlyErrors([&] { ReadColmapTextModel(folder); });
  fuzz::ExpectOnlyErrors([&] { ReadColmapBinaryModel(folder); });
  return 0;
}
