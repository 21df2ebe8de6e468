#include "finecap/atomic_file.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "finecap/error.h"

namespace finecap {

void WriteFileAtomically(const std::string& path,
                         const std::function<void(const std::string& temporary_path)>& write) {
  namespace fs = std::filesystem;
  // Keep the extension last: some writers (OpenCV, assimp) choose the format by it.
  const fs::path target(path);
  const fs::path temporary = target.parent_path() / (".tmp-" + std::to_string(getpid()) + "-" +
                                                     target.filename().string());
  try {
    write(temporary.string());
  } catch (...) {
    std::error_code ignored;
    fs::remove(temporary, ignored);
    throw;
  }
  std::error_code error;
  fs::rename(temporary, target, error);
  if (error) {
    fs::remove(temporary, error);
    throw Error(path, "cannot move the finished file into place");
  }
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
