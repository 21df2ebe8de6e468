// The OpenCV FileStorage pair intri.yml / extri.yml: the input is intri.yml, then a line "%%",
// then extri.yml.
#include "finecap/camera_io.h"
#include "fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace finecap;
  const std::string input(reinterpret_cast<const char*>(data), size);
  const std::string separator = "\n%%\n";
  const size_t split = input.find(separator);
  const std::string intri = input.substr(0, split);
  const std::string extri =
      split == std::string::npos ? "" : input.substr(split + separator.size());
  const std::string intri_path = fuzz::WriteScratchFile(
      "intri.yml", reinterpret_cast<const uint8_t*>(intri.data()), intri.size());
  const std::string extri_path = fuzz::WriteScratchFile(
      "extri.yml", reinterpret_cast<const uint8_t*>(extri.data()), extri.size());
  fuzz::ExpectOnlyErrors([&] { ReadIntriExtri(intri_path, extri_path); });
  return 0;
}
