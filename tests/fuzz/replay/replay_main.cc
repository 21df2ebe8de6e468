// Runs a fuzz target's LLVMFuzzerTestOneInput on every file given or found below the folders
// given, as libFuzzer does when it replays a corpus, but with any compiler and no libFuzzer: the
// ordinary test build replays the committed seeds, among them every input a fuzzer has found, and
// the sanitizer build does so under AddressSanitizer and UBSan. A target reports a bug by aborting
// (fuzz::ExpectOnlyErrors), and so fails the test.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <system_error>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

namespace {

namespace fs = std::filesystem;

// The regular files named by `arguments` or lying below them, sorted, so that every run replays
// the same inputs in the same order. False, with a message, when an argument does not exist.
bool CollectInputs(const std::vector<std::string>& arguments, std::vector<fs::path>* inputs) {
  for (const std::string& argument : arguments) {
    std::error_code error;
    if (fs::is_regular_file(argument, error)) {
      inputs->push_back(argument);
    } else if (fs::is_directory(argument, error)) {
      for (const auto& entry : fs::recursive_directory_iterator(argument)) {
        if (entry.is_regular_file()) inputs->push_back(entry.path());
      }
    } else {
      std::fprintf(stderr, "%s: no such file or folder\n", argument.c_str());
      return false;
    }
  }
  std::sort(inputs->begin(), inputs->end());
  return true;
}

bool ReadBytes(const fs::path& path, std::string* bytes) {
  std::ifstream stream(path, std::ios::binary);
  bytes->assign(std::istreambuf_iterator<char>(stream), std::istreambuf_iterator<char>());
  return !stream.bad() && stream.is_open();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s FILE_OR_FOLDER...\n", argv[0]);
    return 2;
  }
  std::vector<fs::path> inputs;
  if (!CollectInputs(std::vector<std::string>(argv + 1, argv + argc), &inputs)) return 1;
  if (inputs.empty()) {
    std::fprintf(stderr, "no inputs to replay in the files and folders given\n");
    return 1;
  }
  for (const fs::path& input : inputs) {
    std::string bytes;
    if (!ReadBytes(input, &bytes)) {
      std::fprintf(stderr, "%s: cannot read the file\n", input.c_str());
      return 1;
    }
    std::printf("replaying %s (%zu bytes)\n", input.c_str(), bytes.size());
    std::fflush(stdout);  // Names the input that was running if the target aborts.
    LLVMFuzzerTestOneInput(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
  }
  std::printf("replayed %zu inputs\n", inputs.size());
  return 0;
}
