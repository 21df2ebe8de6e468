// Runs the built finecap binary (FINECAP_BINARY, defined by the test target) the way a user's
// shell does, for the tests of the command line and the quality tests.
#ifndef FINECAP_TESTS_RUN_FINECAP_H_
#define FINECAP_TESTS_RUN_FINECAP_H_

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace finecap {
namespace testing_util {

struct RunResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr together.
};

// Runs `prefix` (e.g. environment settings) followed by the finecap binary with `arguments`.
inline RunResult RunFinecap(const std::string& arguments, const std::string& prefix = "") {
  RunResult result;
  const std::string command = prefix + std::string(FINECAP_BINARY) + " " + arguments + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return result;
  std::array<char, 4096> buffer;
  while (fgets(buffer.data(), buffer.size(), pipe) != nullptr) result.output += buffer.data();
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

}  // namespace testing_util
}  // namespace finecap

#endif  // FINECAP_TESTS_RUN_FINECAP_H_
