#include "util/opencv_extras.h"

#include <dlfcn.h>
#include <unistd.h>

#include <climits>
#include <vector>

#include "finecap/util/error.h"

namespace finecap {
namespace internal {
namespace {

constexpr char kLibraryName[] = "libfinecap_opencv_extras.so";

// The folder of the running executable, with its trailing slash; empty when /proc is not there.
std::string ExecutableFolder() {
  char path[PATH_MAX];
  const ssize_t length = readlink("/proc/self/exe", path, sizeof(path) - 1);
  if (length <= 0) return "";
  const std::string executable(path, static_cast<size_t>(length));
  return executable.substr(0, executable.rfind('/') + 1);
}

struct Loaded {
  const OpenCvExtras* table = nullptr;
  std::string failure;  // Why it could not be loaded: each place tried, and what went wrong.
};

// Never unloaded: OpenCV's video back ends keep state in their own libraries until exit.
Loaded Load(const std::vector<std::string>& candidates) {
  Loaded loaded;
  for (const std::string& path : candidates) {
    void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (handle == nullptr) {
      const char* reason = dlerror();
      loaded.failure += "\n  " + (reason != nullptr ? std::string(reason) : path);
      continue;
    }
    using Entry = const OpenCvExtras* (*)();
    const auto entry = reinterpret_cast<Entry>(dlsym(handle, FINECAP_OPENCV_EXTRAS_SYMBOL));
    if (entry == nullptr) {
      loaded.failure +=
          "\n  " + path + ": no " + FINECAP_OPENCV_EXTRAS_SYMBOL + " (not this version's library)";
      dlclose(handle);
      continue;
    }
    loaded.table = entry();
    return loaded;
  }
  return loaded;
}

const OpenCvExtras& TableOrError(const Loaded& loaded, const std::string& needed_for) {
  Require(loaded.table != nullptr, kLibraryName,
          "cannot load finecap's OpenCV extras, needed for " + needed_for +
              "; tried:" + loaded.failure);
  return *loaded.table;
}

}  // namespace

std::vector<std::string> OpenCvExtrasCandidates() {
  std::vector<std::string> candidates;
  const std::string folder = ExecutableFolder();
  if (!folder.empty()) candidates.push_back(folder + kLibraryName);
#ifdef FINECAP_OPENCV_EXTRAS_PATH
  if (candidates.empty() || candidates[0] != FINECAP_OPENCV_EXTRAS_PATH) {
    candidates.push_back(FINECAP_OPENCV_EXTRAS_PATH);
  }
#endif
  return candidates;
}

const OpenCvExtras& LoadOpenCvExtras(const std::string& needed_for) {
  static const Loaded loaded = Load(OpenCvExtrasCandidates());
  return TableOrError(loaded, needed_for);
}

const OpenCvExtras& LoadOpenCvExtrasFrom(const std::vector<std::string>& candidates,
                                         const std::string& needed_for) {
  return TableOrError(Load(candidates), needed_for);
}

}  // namespace internal
}  // namespace finecap
