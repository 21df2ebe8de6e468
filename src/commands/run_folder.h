// The output folder of `finecap refine` as a record of progress, shared safely by a resumed run
// and by the shards of one run: which files a frame owns, when a frame counts as done, and
// stats.jsonl, the per-frame records gathered in frame order.
//
// A frame is done when its mesh, its displacement and its stats record all exist. Each is written
// under a temporary name and renamed, and the stats record is written last, so a run killed at
// any moment leaves every frame either done or without its record, never half-written.
#ifndef FINECAP_SRC_COMMANDS_RUN_FOLDER_H_
#define FINECAP_SRC_COMMANDS_RUN_FOLDER_H_

#include <string>
#include <vector>

namespace finecap {
namespace internal {

// The files `finecap refine` writes for one frame, in the order it writes them.
struct FrameFiles {
  std::string mesh;          // meshes/<frame>.<mesh_format>
  std::string displacement;  // k/<frame>.txt
  std::string trace;         // traces/<frame>.csv, the solver's convergence (not needed to resume)
  std::string stats;         // frames/<frame>.json, written last: it marks the frame done.
};

FrameFiles FrameFilesIn(const std::string& out, const std::string& frame,
                        const std::string& mesh_format);

// True when all of the frame's files exist.
bool FrameDone(const FrameFiles& files);

// Creates the subfolders of a run folder and removes the temporaries that killed runs left in
// it (RemoveStaleTemporaries); returns how many were removed.
int PrepareRunSubfolders(const std::string& out);

// stats.jsonl of a run folder. Appending and rebuilding hold an advisory lock (flock on
// out/.stats.lock), so shards sharing the folder never interleave their writes; a record is
// appended with one write() so that a killed run leaves whole lines only.
class StatsLog {
 public:
  // `frame_names`: the capture's sorted frames, the order of a rebuilt stats.jsonl;
  // `mesh_format`: output.mesh_format, which names the frames' mesh files.
  StatsLog(const std::string& out, std::vector<std::string> frame_names,
           const std::string& mesh_format);

  // Appends one record (a line of JSON without its newline): O(1) per frame.
  void Append(const std::string& record) const;

  // Rewrites stats.jsonl atomically from the frames/<frame>.json records of every done frame,
  // in frame order: drops what a killed run or a concurrent shard left out of order or missing.
  void Rebuild() const;

 private:
  std::string out_;
  std::vector<std::string> frame_names_;
  std::string mesh_format_;
};

}  // namespace internal
}  // namespace finecap

#endif  // FINECAP_SRC_COMMANDS_RUN_FOLDER_H_
