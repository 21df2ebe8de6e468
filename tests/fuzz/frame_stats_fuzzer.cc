// A stats record (a line of stats.jsonl): ParseFrameStats on arbitrary bytes; a record that reads
// must read again, unchanged, once written by ToJson.
#include "finecap/refine/frame_stats.h"
#include "fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace finecap;
  const std::string line(reinterpret_cast<const char*>(data), size);
  fuzz::ExpectOnlyErrors([&] {
    const std::string json = ToJson(ParseFrameStats(line, "record"));
    if (ToJson(ParseFrameStats(json, "written record")) != json) std::abort();
  });
  return 0;
}
