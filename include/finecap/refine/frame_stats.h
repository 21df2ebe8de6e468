// The statistics record of one refined frame: one JSON object per frame, one line each in the
// output folder's stats.jsonl.
#ifndef FINECAP_REFINE_FRAME_STATS_H_
#define FINECAP_REFINE_FRAME_STATS_H_

#include <limits>
#include <string>
#include <vector>

#include "finecap/refine/refine.h"

namespace finecap {

struct FrameStats {
  std::string frame;       // The frame's name.
  std::string solver;      // solver.type.
  std::string similarity;  // energy.similarity.
  double energy_start = 0.0;
  double energy_end = 0.0;
  double ls_cost_start = 0.0;
  double ls_cost_end = 0.0;
  int iterations = 0;
  int evaluations = 0;
  std::string termination;
  // The frame's time on the run's thread, waiting for its read, solving and writing included; a
  // preparation done ahead (prepared_ahead), while the frame before was solved, is not in it.
  double seconds = 0.0;
  double seconds_preparation = 0.0;  // Subdivision, visibility, image Gaussians, pairs.
  double seconds_solve = 0.0;
  double seconds_evaluation = 0.0;     // Of the solve: residuals, Jacobians, energies.
  double seconds_linear_solver = 0.0;  // Of the solve: Ceres' linear solver.
  double seconds_similarity = 0.0;  // Of the evaluation, Ceres only: the similarity's shared work.
  double seconds_heldout = 0.0;     // After the solve: the held-out score (validation.cameras).
  // The process's CPU time (user and system, every thread) over `seconds`: the frame's own work and
  // whatever ran beside it (the preparation of the frames ahead). The frames' windows follow one
  // another, so over a run its mean is the CPU a frame costs, and cpu_seconds / seconds the cores
  // kept busy. On a machine whose cores are all busy, frames per minute follow the CPU per frame,
  // whichever part of a frame's work it goes to.
  double cpu_seconds = 0.0;
  int surface_gaussians = 0;
  // The share of the refined vertices refined with confidence (ConfidentShare, refine.h), in
  // [0, 1]: where the rest lie, the confidence pull keeps the input. Low on a sparse rig.
  double confident_share = std::numeric_limits<double>::quiet_NaN();
  // The range of the displacements the frame was solved in (energy.k_max, or wider where its
  // plane sweep found that limiting), millimetres.
  double k_max_mm = std::numeric_limits<double>::quiet_NaN();
  // The largest shift of a camera's principal point that the detail stage's alignment made
  // (refine.camera_alignment), pixels: how far the calibration as given is from what the images
  // say, at most. NaN without the alignment.
  double camera_shift_px = std::numeric_limits<double>::quiet_NaN();
  long image_gaussians = 0;
  long pairs = 0;
  bool worse = false;       // The run's own energy, or the held-out NCC, says the frame got worse.
  bool kept_input = false;  // And the input surface was written instead.
  bool prepared_ahead = false;  // PrepareFrameAhead, with the plane sweep, while another frame
                                // was solved.
  // Against ground truth, when the capture has it (NaN otherwise): RMS error over the refined
  // vertices of the textured region, millimetres (FineGroundTruth), of the coarse mesh as given
  // (the input as its user gave it, its triangles sampled at the fine vertices), of its
  // subdivision (k = 0, where the refinement starts) and of the result (k - k_true).
  double rms_coarse_mm = 0.0;
  double rms_subdivided_mm = 0.0;
  double rms_refined_mm = 0.0;
  // The flicker of the same three surfaces, millimetres: the RMS over the same vertices of the
  // change of their signed error (ComputeFlicker, metrics.h) since the frame before, over the
  // vertices with a truth and a refined k in both frames. NaN when the frame before has no errors
  // here: the first frame, a frame without truth, or one whose predecessor was not done in the
  // run folder when it was refined (a shard's first frame while the shard before still runs).
  double flicker_coarse_mm = std::numeric_limits<double>::quiet_NaN();
  double flicker_subdivided_mm = std::numeric_limits<double>::quiet_NaN();
  double flicker_refined_mm = std::numeric_limits<double>::quiet_NaN();
  // The same over the textureless region (NaN when the capture marks none).
  double rms_textureless_coarse_mm = 0.0;
  double rms_textureless_subdivided_mm = 0.0;
  double rms_textureless_refined_mm = 0.0;
  // In the held-out cameras (validation.cameras; heldout_score.h), NaN when there are none: the
  // mean local NCC and mean absolute grey-level difference between each held-out image and the
  // training views warped into it through the coarse mesh as given (input), through its
  // subdivision and through the refined mesh as solved (before refine.keep_input_if_worse puts
  // the subdivided input back). A refined NCC below the input's flags the frame `worse`.
  double heldout_ncc_input = std::numeric_limits<double>::quiet_NaN();
  double heldout_ncc_subdivided = std::numeric_limits<double>::quiet_NaN();
  double heldout_ncc_refined = std::numeric_limits<double>::quiet_NaN();
  double heldout_mad_input = std::numeric_limits<double>::quiet_NaN();
  double heldout_mad_subdivided = std::numeric_limits<double>::quiet_NaN();
  double heldout_mad_refined = std::numeric_limits<double>::quiet_NaN();
  // Cameras left out of this frame because their image could not be read
  // (capture.skip_unreadable_cameras); empty when every camera was used.
  std::vector<std::string> skipped_cameras;
  // The process's peak resident memory when the frame was done (getrusage's ru_maxrss), MB of
  // 2^20 bytes. Over a long run it should stay flat: nothing grows with the frames.
  double peak_rss_mb = 0.0;
  // The bytes the heap holds in live blocks when the frame was done (glibc's mallinfo2: uordblks
  // and hblkhd), MB of 2^20 bytes; 0 where another allocator replaces glibc's (the sanitizers).
  // Where peak_rss_mb also counts pages that were touched once and kept (the heap is not given
  // back, and is backed by 2 MB pages: util/process.h), this is what a leak would make grow. Frames
  // prepared ahead on other threads make it vary by a few MB from frame to frame.
  double heap_in_use_mb = 0.0;
};

// The peak resident memory of this process so far, MB of 2^20 bytes (getrusage's ru_maxrss).
double PeakResidentMegabytes();

// The heap's live blocks now, MB of 2^20 bytes (see FrameStats::heap_in_use_mb).
double HeapInUseMegabytes();

// The CPU time this process has used so far, every thread, user and system, seconds.
double ProcessCpuSeconds();

FrameStats MakeFrameStats(const std::string& frame, const RefineOptions& options,
                          const FrameResult& result);

// One line of JSON (no newline). Non-finite numbers are written as null.
std::string ToJson(const FrameStats& stats);

// The inverse of ToJson: one stats record (a line of stats.jsonl, with or without its newline).
// null reads as NaN for the real-valued fields. A key that ToJson does not write, a value of the
// wrong type, an integer out of range or malformed JSON throws Error(where, ...) naming the key or
// the character; a missing key keeps its default (records of older versions lack newer keys),
// except "frame", which is required. Numbers come back as ToJson rounded them (10 digits).
FrameStats ParseFrameStats(const std::string& line, const std::string& where);

// Reads one frame's statistics record as a run folder holds it (frames/<frame>.json; null
// numbers read as NaN). Throws Error naming the file when it is missing, malformed or lacks a
// field.
FrameStats ReadFrameStats(const std::string& path);

}  // namespace finecap

#endif  // FINECAP_REFINE_FRAME_STATS_H_
