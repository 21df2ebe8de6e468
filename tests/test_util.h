// Helpers shared by the I/O tests: temporary folders, small files, error-message checks.
#ifndef FINECAP_TESTS_TEST_UTIL_H_
#define FINECAP_TESTS_TEST_UTIL_H_

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <string>
#include <system_error>
#include <vector>

#include <gtest/gtest.h>

#include "finecap/util/error.h"
#include "finecap/util/threads.h"

namespace finecap {
namespace testing_util {

// One OpenMP thread while in scope: the energy's sums then come out the same on every
// evaluation (an unmoved surface's energy equals its start exactly, two runs give the same bytes).
struct OneWorkerThread {
  OneWorkerThread() { SetWorkerThreads(1); }
  ~OneWorkerThread() { SetWorkerThreads(0); }
};

// The folders MakeTempDir made in this process, removed with everything in them when the process
// ends (its static objects destroyed), so that test runs leave nothing in the temp dir. A child
// process the tests fork ends with _exit, which leaves them to the parent.
class TempDirsOfThisProcess {
 public:
  static TempDirsOfThisProcess& Get() {
    static TempDirsOfThisProcess dirs;
    return dirs;
  }
  void Add(const std::string& dir) { dirs_.push_back(dir); }
  ~TempDirsOfThisProcess() {
    for (const std::string& dir : dirs_) {
      std::error_code ignored;  // Whatever cannot be removed is left, as before.
      std::filesystem::remove_all(dir, ignored);
    }
  }

 private:
  std::vector<std::string> dirs_;
};

// A fresh, empty folder under the test temp dir, unique per process and call, removed when the
// process ends.
inline std::string MakeTempDir(const std::string& name) {
  static int counter = 0;
  const std::filesystem::path dir =
      std::filesystem::path(::testing::TempDir()) /
      ("finecap_" + name + "_" + std::to_string(getpid()) + "_" + std::to_string(counter++));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  TempDirsOfThisProcess::Get().Add(dir.string());
  return dir.string();
}

inline void WriteText(const std::string& path, const std::string& contents) {
  std::filesystem::create_directories(std::filesystem::path(path).parent_path());
  std::ofstream stream(path, std::ios::binary);
  stream << contents;
  ASSERT_TRUE(static_cast<bool>(stream)) << path;
}

// The whole file as bytes; empty when it cannot be read.
inline std::string FileBytes(const std::string& path) {
  std::ifstream stream(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(stream), std::istreambuf_iterator<char>());
}

// The names of the entries of `dir`, sorted: shows that no temporary or stray file is left.
inline std::vector<std::string> FilesIn(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    names.push_back(entry.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

// Expects `action` to throw finecap::Error whose message contains every one of `parts`.
inline void ExpectErrorMentions(const std::function<void()>& action,
                                const std::vector<std::string>& parts) {
  try {
    action();
    ADD_FAILURE() << "expected finecap::Error mentioning '" << parts.front() << "'";
  } catch (const Error& error) {
    const std::string message = error.what();
    for (const std::string& part : parts) {
      EXPECT_NE(message.find(part), std::string::npos)
          << "message '" << message << "' lacks '" << part << "'";
    }
  }
}

// An independent base64 decoder: looks every character up in the alphabet string.
inline std::string Base64Decode(const std::string& text) {
  const std::string alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string bytes;
  unsigned bits = 0;  // Only the low bit_count bits are pending.
  int bit_count = 0;
  for (char c : text) {
    if (c == '=') break;
    const size_t value = alphabet.find(c);
    EXPECT_NE(value, std::string::npos) << "not base64: " << c;
    bits = ((bits << 6) | static_cast<unsigned>(value)) & 0xfffu;
    bit_count += 6;
    if (bit_count >= 8) {
      bit_count -= 8;
      bytes.push_back(static_cast<char>((bits >> bit_count) & 0xff));
    }
  }
  return bytes;
}

}  // namespace testing_util
}  // namespace finecap

#endif  // FINECAP_TESTS_TEST_UTIL_H_
