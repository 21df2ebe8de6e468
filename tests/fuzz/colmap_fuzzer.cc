// A COLMAP text model: the input is cameras.txt, then a line "%%", then images.txt.
#include <filesystem>

#include "finecap/camera_io.h"
#include "fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace finecap;
  const std::string input(reinterpret_cast<const char*>(data), size);
  const std::string separator = "\n%%\n";
  const size_t split = input.find(separator);
  const std::string cameras = input.substr(0, split);
  const std::string images =
      split == std::string::npos ? "" : input.substr(split + separator.size());
  std::filesystem::create_directories(fuzz::ScratchDir() / "colmap");
  fuzz::WriteScratchFile("colmap/cameras.txt", reinterpret_cast<const uint8_t*>(cameras.data()),
                         cameras.size());
  fuzz::WriteScratchFile("colmap/images.txt", reinterpret_cast<const uint8_t*>(images.data()),
                         images.size());
  fuzz::ExpectOnlyErrors([&] { ReadColmapTextModel((fuzz::ScratchDir() / "colmap").string()); });
  return 0;
}
