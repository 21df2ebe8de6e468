// What every fuzz target shares. The parsers read files, so each input is written to a file in a
// temporary folder of the process; and finecap::Error, the one error type for bad input, is the
// only acceptable failure: any other exception is reported and aborts, which libFuzzer records
// as a crash together with the input.
#ifndef FINECAP_TESTS_FUZZ_FUZZ_UTIL_H_
#define FINECAP_TESTS_FUZZ_FUZZ_UTIL_H_

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>

#include "finecap/util/error.h"

namespace finecap {
namespace fuzz {

// The process's scratch folder, created on first use and removed at exit.
inline const std::filesystem::path& ScratchDir() {
  static const std::filesystem::path dir = [] {
    const char* base = std::getenv("TMPDIR");
    const std::filesystem::path path = std::filesystem::path(base != nullptr ? base : "/tmp") /
                                       ("finecap_fuzz_" + std::to_string(getpid()));
    std::filesystem::create_directories(path);
    std::atexit([] { std::filesystem::remove_all(ScratchDir()); });
    return path;
  }();
  return dir;
}

// Writes `size` bytes at `data` to `name` in the scratch folder; returns the file's path.
inline std::string WriteScratchFile(const std::string& name, const uint8_t* data, size_t size) {
  const std::string path = (ScratchDir() / name).string();
  std::ofstream stream(path, std::ios::binary | std::ios::trunc);
  stream.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  if (!stream) std::abort();  // The fuzzer's own failure, not the parser's.
  return path;
}

// The two files of a format that comes as a pair (COLMAP's cameras.txt + images.txt, intri.yml +
// extri.yml): the input up to the first line "%%", and the rest (empty without such a line).
inline std::pair<std::string, std::string> SplitInTwo(const uint8_t* data, size_t size) {
  const std::string input(reinterpret_cast<const char*>(data), size);
  const std::string separator = "\n%%\n";
  const size_t split = input.find(separator);
  if (split == std::string::npos) return {input, ""};
  return {input.substr(0, split), input.substr(split + separator.size())};
}

// Writes `text` to `name` in the scratch folder; returns the file's path.
inline std::string WriteScratchText(const std::string& name, const std::string& text) {
  return WriteScratchFile(name, reinterpret_cast<const uint8_t*>(text.data()), text.size());
}

// Runs `parse`; an Error is the expected outcome of bad input, anything else a bug.
template <typename Parse>
void ExpectOnlyErrors(Parse&& parse) {
  try {
    parse();
  } catch (const Error&) {
  } catch (const std::exception& other) {
    std::fprintf(stderr, "exception other than finecap::Error escaped: %s\n", other.what());
    std::abort();
  } catch (...) {
    std::fprintf(stderr, "a non-std exception escaped\n");
    std::abort();
  }
}

}  // namespace fuzz
}  // namespace finecap

#endif  // FINECAP_TESTS_FUZZ_FUZZ_UTIL_H_
