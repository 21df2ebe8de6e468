// The run folder, where a sequence's refinement (sequence.h) writes its results, as a record of
// progress shared safely by a resumed run and by the shards of one run: which files a frame owns,
// their readers and writers, when a frame counts as done, and stats.jsonl, the per-frame records
// gathered in frame order. This is the only place that knows the folder's layout:
//
//   meshes/<frame>.<ply|obj>   the refined mesh, its normals, the displacement as vertex quality
//   k/<frame>.txt              the displacement of every fine vertex (WriteDisplacement)
//   traces/<frame>.csv         the solver's convergence
//   frames/<frame>.json        the frame's statistics record (frame_stats.h), written last
//   stats.jsonl                every done frame's record, in frame order
//   reference_colors.txt       the sequence's reference colours (surface_gaussians.h)
//   colors/<frame>.txt         with model.follow_colors: the colours the frame after it uses
//   appearance/<frame>.txt     with energy.consensus.shared_appearance: the colours the frame's
//                              refined surface showed at its surface samples, for the frame after
//   eval/, export/             what finecap eval and finecap export make of the run
//
// A frame is done when its mesh, its displacement and its stats record all exist. Each is written
// under a temporary name and renamed, and the stats record is written last, so a run killed at
// any moment leaves every frame either done or without its record, never half-written.
#ifndef FINECAP_REFINE_RUN_FOLDER_H_
#define FINECAP_REFINE_RUN_FOLDER_H_

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "finecap/io/frame_range.h"
#include "finecap/io/mesh_io.h"

namespace finecap {

// The files a refined frame owns, in the order they are written.
struct FrameFiles {
  std::string mesh;          // meshes/<frame>.<mesh_format>
  std::string displacement;  // k/<frame>.txt
  std::string trace;         // traces/<frame>.csv, the solver's convergence (not needed to resume)
  // confidence/<frame>.txt, per fine vertex how surely the images decide it (FrameResult::
  // confidence; not needed to resume, and absent from runs of versions before it).
  std::string confidence;
  std::string stats;  // frames/<frame>.json, written last: it marks the frame done.
};

// "ply" or "obj": the extension of a mesh written in `format`.
std::string MeshFormatExtension(MeshFormat format);

FrameFiles FrameFilesIn(const std::string& out, const std::string& frame, MeshFormat mesh_format);

// True when all of the frame's files exist.
bool FrameDone(const FrameFiles& files);

// Where the run folder `out` keeps its reference colours, and what eval and export write.
std::string ReferenceColorsPath(const std::string& out);
// Where the colours followed up to `frame` are kept (model.follow_colors), and their folder.
std::string FollowedColorsPath(const std::string& out, const std::string& frame);
std::string FollowedColorsFolder(const std::string& out);
// Where the appearance of `frame`'s refined surface is kept (energy.consensus.shared_appearance),
// and its folder.
std::string AppearancePath(const std::string& out, const std::string& frame);
std::string AppearanceFolder(const std::string& out);
std::string EvalFolder(const std::string& out);
std::string ExportFolder(const std::string& out);

// Writes k/<frame>.txt: one number (or nan) per fine vertex, in the shortest form that reads back
// to the same double, so that a frame seeded from it (a resumed run's warm start) starts exactly
// where a run that never stopped would.
void WriteDisplacement(const std::string& path, const Eigen::VectorXd& k);

// Reads k/<frame>.txt; an Error names the file when a line is not a number or nan ('#' lines are
// comments) or when it does not hold `num_vertices` of them.
Eigen::VectorXd ReadDisplacement(const std::string& path, int num_vertices);

// confidence/<frame>.txt, as k/<frame>.txt: one number in [0, 1] (or nan) per fine vertex.
void WriteConfidence(const std::string& path, const Eigen::VectorXd& confidence);
Eigen::VectorXd ReadConfidence(const std::string& path, int num_vertices);

// appearance/<frame>.txt: one colour per surface sample (FrameResult::appearance), three numbers
// a line in the shortest form that reads back to the same double (nan where no camera saw the
// sample), so that a frame that reads it compares its patches with exactly what a run that never
// stopped compares them with. ReadAppearance throws an Error naming the file when a line is not
// three numbers or nan.
void WriteAppearance(const std::string& path, const Eigen::Matrix3Xd& appearance);
Eigen::Matrix3Xd ReadAppearance(const std::string& path);

// A done frame of a run folder.
struct RefinedFrame {
  int index = 0;     // In the capture's sorted frame list.
  std::string name;  // The capture's name for it.
  FrameFiles files;
};

// The frames of `frames` (indices into `frame_names`, the capture's sorted frames) done in `out`,
// in frame order; an Error naming `out` when there is none (`capture` names the capture in it).
std::vector<RefinedFrame> FindRefinedFrames(const std::string& out,
                                            const std::vector<std::string>& frame_names,
                                            const FrameRange& frames, MeshFormat mesh_format,
                                            const std::string& capture);

// Frame `frame` (an index into `frame_names`, the capture's sorted frames) of `out` when it is
// done there; nullopt otherwise (also when `frame` is not one of them).
std::optional<RefinedFrame> FindRefinedFrame(const std::string& out,
                                             const std::vector<std::string>& frame_names, int frame,
                                             MeshFormat mesh_format);

// Creates the subfolders of a run folder (colors/ only for a run whose colours follow the
// sequence, appearance/ only for one that shares the appearance between frames) and removes the
// temporaries that killed runs left in it (RemoveStaleTemporaries); returns how many were removed.
int PrepareRunSubfolders(const std::string& out, bool followed_colors,
                         bool shared_appearance = false);

// stats.jsonl of a run folder. Appending and rebuilding hold an advisory lock (flock on
// out/.stats.lock), so shards sharing the folder never interleave their writes; a record is
// appended with one write() so that a killed run leaves whole lines only.
class StatsLog {
 public:
  // `frame_names`: the capture's sorted frames, the order of a rebuilt stats.jsonl;
  // `mesh_format` names the frames' mesh files.
  StatsLog(const std::string& out, std::vector<std::string> frame_names, MeshFormat mesh_format);

  // Appends one record (a line of JSON without its newline): O(1) per frame.
  void Append(const std::string& record) const;

  // Rewrites stats.jsonl atomically from the frames/<frame>.json records of every done frame,
  // in frame order: drops what a killed run or a concurrent shard left out of order or missing.
  void Rebuild() const;

 private:
  std::string out_;
  std::vector<std::string> frame_names_;
  MeshFormat mesh_format_;
};

}  // namespace finecap

#endif  // FINECAP_REFINE_RUN_FOLDER_H_
