// A .off mesh: ReadMesh on arbitrary bytes; a mesh that reads is valid (Mesh::Validate).
#include "finecap/io/mesh_io.h"
#include "fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace finecap;
  const std::string path = fuzz::WriteScratchFile("mesh.off", data, size);
  fuzz::ExpectOnlyErrors([&] { ReadMesh(path).Validate(path); });
  return 0;
}
