// A vertex mask file (mask.txt, gt/textureless.txt) of a 1000-vertex mesh; what reads must be
// sorted, unique and in range.
#include "finecap/io/vertex_mask.h"
#include "fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace finecap;
  const std::string path = fuzz::WriteScratchFile("mask.txt", data, size);
  fuzz::ExpectOnlyErrors([&] {
    const std::vector<int> ids = ReadVertexMask(path, 1000);
    for (size_t i = 0; i < ids.size(); ++i) {
      if (ids[i] < 0 || ids[i] >= 1000 || (i > 0 && ids[i - 1] >= ids[i])) std::abort();
    }
  });
  return 0;
}
