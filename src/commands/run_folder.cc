#include "commands/run_folder.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <filesystem>
#include <fstream>

#include "finecap/atomic_file.h"
#include "finecap/error.h"

namespace finecap {
namespace internal {
namespace {

namespace fs = std::filesystem;

const char* const kSubfolders[] = {"meshes", "k", "traces", "frames"};

// Holds an exclusive flock on `path` (created if missing) while it lives.
class FileLock {
 public:
  explicit FileLock(const std::string& path)
      : descriptor_(open(path.c_str(), O_CREAT | O_RDWR | O_CLOEXEC, 0644)) {
    Require(descriptor_ >= 0, path, "cannot create the lock file of the output folder");
    while (flock(descriptor_, LOCK_EX) != 0) {
      Require(errno == EINTR, path, "cannot lock the output folder");
    }
  }
  ~FileLock() { close(descriptor_); }  // Closing releases the lock.
  FileLock(const FileLock&) = delete;
  FileLock& operator=(const FileLock&) = delete;

 private:
  int descriptor_;
};

}  // namespace

FrameFiles FrameFilesIn(const std::string& out, const std::string& frame,
                        const std::string& mesh_format) {
  return {out + "/meshes/" + frame + "." + mesh_format, out + "/k/" + frame + ".txt",
          out + "/traces/" + frame + ".csv", out + "/frames/" + frame + ".json"};
}

bool FrameDone(const FrameFiles& files) {
  return fs::is_regular_file(files.mesh) && fs::is_regular_file(files.displacement) &&
         fs::is_regular_file(files.stats);
}

int PrepareRunSubfolders(const std::string& out) {
  int removed = RemoveStaleTemporaries(out);
  for (const char* name : kSubfolders) {
    const std::string folder = out + "/" + name;
    std::error_code error;
    fs::create_directories(folder, error);
    // Another shard may create it at the same moment: what matters is that it exists.
    Require(fs::is_directory(folder), folder, "cannot create the folder: " + error.message());
    removed += RemoveStaleTemporaries(folder);
  }
  return removed;
}

StatsLog::StatsLog(const std::string& out, std::vector<std::string> frame_names,
                   const std::string& mesh_format)
    : out_(out), frame_names_(std::move(frame_names)), mesh_format_(mesh_format) {}

void StatsLog::Append(const std::string& record) const {
  const FileLock lock(out_ + "/.stats.lock");
  const std::string path = out_ + "/stats.jsonl";
  const int descriptor = open(path.c_str(), O_CREAT | O_WRONLY | O_APPEND | O_CLOEXEC, 0644);
  Require(descriptor >= 0, path, "cannot open the statistics for appending");
  const std::string line = record + "\n";
  const ssize_t written = write(descriptor, line.data(), line.size());
  close(descriptor);
  Require(written == static_cast<ssize_t>(line.size()), path, "cannot append a frame's record");
}

void StatsLog::Rebuild() const {
  const FileLock lock(out_ + "/.stats.lock");
  std::string lines;
  for (const std::string& frame : frame_names_) {
    const FrameFiles files = FrameFilesIn(out_, frame, mesh_format_);
    if (!FrameDone(files)) continue;
    std::ifstream record(files.stats);
    std::string line;
    if (std::getline(record, line) && !line.empty()) lines += line + "\n";
  }
  WriteTextFileAtomically(out_ + "/stats.jsonl", lines);
}

}  // namespace internal
}  // namespace finecap
