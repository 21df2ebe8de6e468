#include "finecap/util/memory.h"

#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

namespace finecap {
namespace {

constexpr double kBytesPerMegabyte = 1e6;

// The whole text of `path`; empty when it cannot be read.
std::string ReadSmallFile(const std::string& path) {
  std::ifstream file(path);
  std::stringstream text;
  text << file.rdbuf();
  return file ? text.str() : std::string();
}

// The cgroup v2 path of this process ("/user.slice/..."), from the "0::" line of
// /proc/self/cgroup; empty when it has none.
std::string CgroupV2Path(const std::string& root) {
  std::istringstream lines(ReadSmallFile(root + "/proc/self/cgroup"));
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("0::", 0) == 0) return line.substr(3);
  }
  return "";
}

}  // namespace

double ParseMemAvailableMegabytes(const std::string& meminfo) {
  std::istringstream lines(meminfo);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("MemAvailable:", 0) != 0) continue;
    std::istringstream fields(line.substr(13));
    double kilobytes = -1.0;
    std::string unit;
    if (!(fields >> kilobytes >> unit) || unit != "kB" || kilobytes < 0.0) return -1.0;
    return kilobytes * 1024.0 / kBytesPerMegabyte;
  }
  return -1.0;
}

double ParseCgroupLimitMegabytes(const std::string& text) {
  std::istringstream fields(text);
  std::string word;
  if (!(fields >> word)) return -1.0;
  if (word == "max") return std::numeric_limits<double>::infinity();
  if (word.find_first_not_of("0123456789") != std::string::npos) return -1.0;
  size_t used = 0;
  unsigned long long bytes = 0;
  try {
    bytes = std::stoull(word, &used);
  } catch (const std::exception&) {
    return -1.0;
  }
  if (used != word.size()) return -1.0;
  // cgroup v1 writes "no limit" as the largest page-aligned signed 64-bit figure.
  if (bytes >= (1ULL << 62)) return std::numeric_limits<double>::infinity();
  return static_cast<double>(bytes) / kBytesPerMegabyte;
}

AvailableMemory ReadAvailableMemory(const std::string& root) {
  AvailableMemory available{std::numeric_limits<double>::infinity(), ""};
  const auto consider = [&](const std::string& path, double megabytes) {
    if (megabytes >= 0.0 && megabytes < available.megabytes) available = {megabytes, path};
  };
  const std::string meminfo = "/proc/meminfo";
  consider(meminfo, ParseMemAvailableMegabytes(ReadSmallFile(root + meminfo)));
  // The first cgroup file that exists: the process's own v2 cgroup, the root a container sees
  // (v2), then v1's memory controller.
  const std::string v2_path = CgroupV2Path(root);
  for (const std::string& path :
       {"/sys/fs/cgroup" + (v2_path == "/" ? std::string() : v2_path) + "/memory.max",
        std::string("/sys/fs/cgroup/memory.max"),
        std::string("/sys/fs/cgroup/memory/memory.limit_in_bytes")}) {
    const std::string text = ReadSmallFile(root + path);
    if (text.empty()) continue;
    consider(path, ParseCgroupLimitMegabytes(text));
    break;
  }
  return available;
}

}  // namespace finecap
