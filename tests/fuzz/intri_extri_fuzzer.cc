// The OpenCV FileStorage pair intri.yml / extri.yml: the input is intri.yml, then a line "%%",
// then extri.yml.
#include "finecap/io/camera_io.h"
#include "fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace finecap;
  const auto [intri, extri] = fuzz::SplitInTwo(data, size);
  const std::string intri_path = fuzz::WriteScratchText("intri.yml", intri);
  const std::string extri_path = fuzz::WriteScratchText("extri.yml", extri);
  fuzz::ExpectOnlyErrors([&] { ReadIntriExtri(intri_path, extri_path); });
  return 0;
}
