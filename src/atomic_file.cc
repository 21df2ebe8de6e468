#include "finecap/atomic_file.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "finecap/error.h"

namespace finecap {

std::string TemporaryPathFor(const std::string& path) {
  const std::filesystem::path target(path);
  return (target.parent_path() /
          (".tmp-" + std::to_string(getpid()) + "-" + target.filename().string()))
      .string();
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
