// A config file: LoadConfig on arbitrary bytes, no overrides.
#include "finecap/config/config.h"
#include "fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace finecap;
  const std::string path = fuzz::WriteScratchFile("config.yaml", data, size);
  fuzz::ExpectOnlyErrors([&] { LoadConfig(path, {}); });
  return 0;
}
