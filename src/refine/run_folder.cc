#include "finecap/refine/run_folder.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "finecap/util/atomic_file.h"
#include "finecap/util/error.h"
#include "util/io_util.h"

namespace finecap {
namespace {

namespace fs = std::filesystem;

const char* const kSubfolders[] = {"meshes", "k", "traces", "frames", "confidence"};

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

std::string MeshFormatExtension(MeshFormat format) {
  return format == MeshFormat::kObj ? "obj" : "ply";
}

FrameFiles FrameFilesIn(const std::string& out, const std::string& frame, MeshFormat mesh_format) {
  return {out + "/meshes/" + frame + "." + MeshFormatExtension(mesh_format),
          out + "/k/" + frame + ".txt", out + "/traces/" + frame + ".csv",
          out + "/confidence/" + frame + ".txt", out + "/frames/" + frame + ".json"};
}

bool FrameDone(const FrameFiles& files) {
  return fs::is_regular_file(files.mesh) && fs::is_regular_file(files.displacement) &&
         fs::is_regular_file(files.stats);
}

std::string ReferenceColorsPath(const std::string& out) { return out + "/reference_colors.txt"; }
std::string FollowedColorsFolder(const std::string& out) { return out + "/colors"; }
std::string FollowedColorsPath(const std::string& out, const std::string& frame) {
  return FollowedColorsFolder(out) + "/" + frame + ".txt";
}
std::string AppearanceFolder(const std::string& out) { return out + "/appearance"; }
std::string AppearancePath(const std::string& out, const std::string& frame) {
  return AppearanceFolder(out) + "/" + frame + ".txt";
}
std::string EvalFolder(const std::string& out) { return out + "/eval"; }
std::string ExportFolder(const std::string& out) { return out + "/export"; }

namespace {

// One number per vertex after a '#' header line, each in the shortest form that reads back to the
// same double.
void WriteVertexValues(const std::string& path, const std::string& header,
                       const Eigen::VectorXd& values) {
  std::string text = "# " + header + "\n";
  char number[64];
  for (int v = 0; v < values.size(); ++v) {
    const auto written = std::to_chars(number, number + sizeof(number), values[v]);
    text.append(number, written.ptr).push_back('\n');
  }
  WriteTextFileAtomically(path, text);
}

// WriteVertexValues' numbers, `what` naming them in an Error.
Eigen::VectorXd ReadVertexValues(const std::string& path, int num_vertices,
                                 const std::string& what) {
  std::istringstream text(internal::ReadWholeFile(path));
  std::vector<double> values;
  std::string line;
  for (int line_number = 1; std::getline(text, line); ++line_number) {
    if (line.empty() || line[0] == '#') continue;
    double value = 0.0;
    Require(
        internal::ParseDouble(line, &value) && !std::isinf(value), path,
        "line " + std::to_string(line_number) + ": expected a number or nan, got '" + line + "'");
    values.push_back(value);
  }
  Require(static_cast<int>(values.size()) == num_vertices, path,
          "holds " + std::to_string(values.size()) + " " + what + ", the refined mesh has " +
              std::to_string(num_vertices) + " vertices");
  return Eigen::Map<const Eigen::VectorXd>(values.data(), values.size());
}

}  // namespace

void WriteDisplacement(const std::string& path, const Eigen::VectorXd& k) {
  WriteVertexValues(path,
                    "displacement along the normal of each vertex of the refined mesh, metres; "
                    "nan where not refined",
                    k);
}

Eigen::VectorXd ReadDisplacement(const std::string& path, int num_vertices) {
  return ReadVertexValues(path, num_vertices, "displacements");
}

void WriteConfidence(const std::string& path, const Eigen::VectorXd& confidence) {
  WriteVertexValues(path,
                    "confidence of each vertex of the refined mesh, 0 (held near the input) to 1 "
                    "(the images decide it); nan where not refined",
                    confidence);
}

Eigen::VectorXd ReadConfidence(const std::string& path, int num_vertices) {
  return ReadVertexValues(path, num_vertices, "confidences");
}

void WriteAppearance(const std::string& path, const Eigen::Matrix3Xd& appearance) {
  std::string text =
      "# colour of each surface sample at the refined surface, in the similarity's colour space; "
      "nan where no camera saw it\n";
  char number[64];
  for (int j = 0; j < appearance.cols(); ++j) {
    for (int channel = 0; channel < 3; ++channel) {
      const auto written = std::to_chars(number, number + sizeof(number), appearance(channel, j));
      text.append(number, written.ptr).push_back(channel < 2 ? ' ' : '\n');
    }
  }
  WriteTextFileAtomically(path, text);
}

Eigen::Matrix3Xd ReadAppearance(const std::string& path) {
  std::istringstream text(internal::ReadWholeFile(path));
  std::vector<double> values;
  std::string line;
  for (int line_number = 1; std::getline(text, line); ++line_number) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    std::string field;
    int count = 0;
    while (fields >> field) {
      double value = 0.0;
      Require(internal::ParseDouble(field, &value) && !std::isinf(value) && count < 3, path,
              "line " + std::to_string(line_number) + ": expected three numbers or nan, got '" +
                  line + "'");
      values.push_back(value);
      ++count;
    }
    Require(count == 3, path,
            "line " + std::to_string(line_number) + ": expected three numbers, got '" + line + "'");
  }
  return Eigen::Map<const Eigen::Matrix3Xd>(values.data(), 3,
                                            static_cast<Eigen::Index>(values.size() / 3));
}

std::optional<RefinedFrame> FindRefinedFrame(const std::string& out,
                                             const std::vector<std::string>& frame_names, int frame,
                                             MeshFormat mesh_format) {
  if (frame < 0 || frame >= static_cast<int>(frame_names.size())) return std::nullopt;
  const FrameFiles files = FrameFilesIn(out, frame_names[frame], mesh_format);
  if (!FrameDone(files)) return std::nullopt;
  return RefinedFrame{frame, frame_names[frame], files};
}

std::vector<RefinedFrame> FindRefinedFrames(const std::string& out,
                                            const std::vector<std::string>& frame_names,
                                            const FrameRange& frames, MeshFormat mesh_format,
                                            const std::string& capture) {
  std::vector<RefinedFrame> done;
  for (int frame = frames.begin; frame < frames.end; ++frame) {
    if (auto refined = FindRefinedFrame(out, frame_names, frame, mesh_format)) {
      done.push_back(*refined);
    }
  }
  Require(!done.empty(), out,
          "holds no refined run of the configured frames of " + capture + " (no meshes/<frame>." +
              MeshFormatExtension(mesh_format) +
              " with k/<frame>.txt and frames/<frame>.json): run finecap refine first");
  return done;
}

int PrepareRunSubfolders(const std::string& out, bool followed_colors, bool shared_appearance) {
  int removed = RemoveStaleTemporaries(out);
  std::vector<std::string> folders;
  for (const char* name : kSubfolders) folders.push_back(out + "/" + name);
  if (followed_colors) folders.push_back(FollowedColorsFolder(out));
  if (shared_appearance) folders.push_back(AppearanceFolder(out));
  for (const std::string& folder : folders) {
    std::error_code error;
    fs::create_directories(folder, error);
    // Another shard may create it at the same moment: what matters is that it exists.
    Require(fs::is_directory(folder), folder, "cannot create the folder: " + error.message());
    removed += RemoveStaleTemporaries(folder);
  }
  return removed;
}

StatsLog::StatsLog(const std::string& out, std::vector<std::string> frame_names,
                   MeshFormat mesh_format)
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

}  // namespace finecap
