#include "finecap/util/atomic_file.h"

#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <filesystem>
#include <fstream>

#include "finecap/util/error.h"

namespace finecap {

namespace {

const char kTemporaryPrefix[] = ".tmp-";

// This machine's name; host names hold no '+', which ends it in a temporary's name.
std::string HostName() {
  char name[HOST_NAME_MAX + 1] = {};
  if (gethostname(name, sizeof(name) - 1) != 0) return "localhost";
  return name;
}

// The writer of a temporary named ".tmp-<host>+<pid>-<file>"; false for other names.
bool ParseTemporaryName(const std::string& name, std::string* host, long* pid) {
  if (name.rfind(kTemporaryPrefix, 0) != 0) return false;
  const size_t plus = name.find('+');
  const size_t dash = plus == std::string::npos ? plus : name.find('-', plus);
  if (dash == std::string::npos || dash == plus + 1) return false;
  const std::string digits = name.substr(plus + 1, dash - plus - 1);
  if (digits.find_first_not_of("0123456789") != std::string::npos) return false;
  *host = name.substr(sizeof(kTemporaryPrefix) - 1, plus - (sizeof(kTemporaryPrefix) - 1));
  *pid = std::stol(digits);
  return true;
}

bool ProcessRuns(long pid) { return kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM; }

}  // namespace

std::string TemporaryPathFor(const std::string& path) {
  const std::filesystem::path target(path);
  return (target.parent_path() / (kTemporaryPrefix + HostName() + "+" + std::to_string(getpid()) +
                                  "-" + target.filename().string()))
      .string();
}

int RemoveStaleTemporaries(const std::string& folder) {
  std::error_code error;
  std::filesystem::directory_iterator entries(folder, error);
  if (error) return 0;
  const std::string host = HostName();
  int removed = 0;
  for (const auto& entry : entries) {
    std::string writer_host;
    long pid = 0;
    if (!ParseTemporaryName(entry.path().filename().string(), &writer_host, &pid)) continue;
    if (writer_host != host || pid == getpid() || ProcessRuns(pid)) continue;
    if (std::filesystem::remove(entry.path(), error)) ++removed;
  }
  return removed;
}

void MoveIntoPlace(const std::string& temporary_path, const std::string& path) {
  std::error_code error;
  std::filesystem::rename(temporary_path, path, error);
  if (error) {
    std::filesystem::remove(temporary_path, error);
    throw Error(path, "cannot move the finished file into place");
  }
}

void WriteFileAtomically(const std::string& path,
                         const std::function<void(const std::string& temporary_path)>& write) {
  const std::string temporary = TemporaryPathFor(path);
  try {
    write(temporary);
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
    throw;
  }
  MoveIntoPlace(temporary, path);
}

void WriteTextFileAtomically(const std::string& path, const std::string& contents) {
  WriteFileAtomically(path, [&](const std::string& temporary_path) {
    std::ofstream stream(temporary_path, std::ios::binary);
    stream << contents;
    stream.close();
    Require(static_cast<bool>(stream), path, "cannot write the file");
  });
}

}  // namespace finecap
