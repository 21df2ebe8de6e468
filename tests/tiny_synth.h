// A synthetic capture small enough for unit tests, shared by the tests that generate one.
#ifndef FINECAP_TESTS_TINY_SYNTH_H_
#define FINECAP_TESTS_TINY_SYNTH_H_

#include <string>

#include "finecap/config/config.h"
#include "finecap/io/capture.h"
#include "finecap/refine/run_folder.h"
#include "finecap/refine/sequence.h"
#include "finecap/synth/synth.h"

namespace finecap {
namespace testing_util {

// 2 cameras of 64 x 64, a 16 x 10 skirt (160 coarse vertices), 2 frames, a 256 x 128 texture, one
// sample per pixel and folds at full amplitude from the first frame.
inline SynthOptions TinySynthOptions() {
  SynthOptions options;
  options.num_frames = 2;
  options.skirt.around = 16;
  options.skirt.down = 10;
  options.texture.width = 256;
  options.texture.height = 128;
  options.cameras.count = 2;
  options.cameras.width = 64;
  options.cameras.height = 64;
  options.cameras.focal = 60.0;
  options.render.supersampling = 1;
  options.fold_ramp_frames = 0;
  return options;
}

// A config that refines `capture` into `out` quickly: one thread, few iterations.
inline Config TinyRunConfig(const std::string& capture, const std::string& out,
                            int max_iterations) {
  Config config;
  config.capture.dir = capture;
  config.output.dir = out;
  config.runtime.threads = 1;
  config.refine.solver.max_iterations = max_iterations;
  config.refine.solver.num_threads = 1;
  return config;
}

// TinySynthOptions with 6 cameras of 96 x 96 that see the skirt large and a 16 x 8 skirt:
// still tiny, but each frame gives refinement something to do. Six: the consensus similarity
// compares a patch (a Gaussian and its ring, 45 degrees of the skirt) between two cameras that
// both see all of it within their 60 degrees (VisibilityOptions::max_view_angle_deg); cameras 90
// or 120 degrees apart share no such patch, and the energy would hold the regulariser alone.
inline SynthOptions TinyRefinableSynthOptions(int num_frames) {
  SynthOptions options = TinySynthOptions();
  options.num_frames = num_frames;
  options.skirt.down = 8;
  options.cameras.count = 6;
  options.cameras.width = 96;
  options.cameras.height = 96;
  options.cameras.focal = 300.0;
  return options;
}

// A tiny refinable capture of `frames` frames, generated in `root`/capture, opened.
inline Capture OpenTinyCapture(const std::string& root, int frames) {
  GenerateSyntheticCapture(TinyRefinableSynthOptions(frames), root + "/capture");
  return Capture::Open(root + "/capture");
}

// Options that refine a tiny capture's sequence quickly: one thread, two iterations, no sweep.
inline SequenceOptions QuickSequenceOptions() {
  SequenceOptions options;
  options.refine.solver.max_iterations = 2;
  options.refine.solver.num_threads = 1;
  options.refine.sweep.samples = 0;
  return options;
}

// Frames 0-2 of `capture` refined into `out` as a run stopped after frame 0 and resumed to frame 1,
// then frame 2 as a shard of its own.
inline void RefineInParts(Capture* capture, const SequenceOptions& options,
                          const std::string& out) {
  for (const FrameRange part : {FrameRange{0, 1}, FrameRange{0, 2}, FrameRange{2, 3}}) {
    RefineSequence(capture, part, options, out);
  }
}

// The largest difference of the displacements that the run folders `a` and `b` saved for
// `frame`, over the vertices refined in both, metres.
inline double LargestDisplacementDifference(const std::string& a, const std::string& b,
                                            const std::string& frame, int num_vertices) {
  const Eigen::VectorXd k_a =
      ReadDisplacement(FrameFilesIn(a, frame, MeshFormat::kPly).displacement, num_vertices);
  const Eigen::VectorXd k_b =
      ReadDisplacement(FrameFilesIn(b, frame, MeshFormat::kPly).displacement, num_vertices);
  return (k_a - k_b).array().isFinite().select(k_a - k_b, 0.0).cwiseAbs().maxCoeff();
}

}  // namespace testing_util
}  // namespace finecap

#endif  // FINECAP_TESTS_TINY_SYNTH_H_
