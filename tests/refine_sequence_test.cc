// A sequence refined frame after frame: how one frame's result seeds the next (warm start) when
// bias compensation and kept inputs are involved.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "finecap/commands.h"
#include "finecap/config.h"
#include "finecap/frame_stats.h"
#include "finecap/synth.h"
#include "finecap/threads.h"
#include "test_util.h"
#include "tiny_synth.h"

namespace finecap {
namespace {

using testing_util::FileBytes;
using testing_util::MakeTempDir;

FrameStats Record(const std::string& out, const std::string& frame) {
  return ParseFrameStats(FileBytes(out + "/frames/" + frame + ".json"), out);
}

// One OpenMP thread while in scope: two runs then evaluate the energy to the same bits.
struct OneWorkerThread {
  OneWorkerThread() { SetWorkerThreads(1); }
  ~OneWorkerThread() { SetWorkerThreads(0); }
};

// A frame whose input was kept has, as solved, displacement 0: the frame after it starts there,
// as a frame without a predecessor does, and not at -sigma_hat (its saved 0 with the bias
// compensation taken off as if it had been added).
TEST(RefineSequenceTest, TheFrameAfterAKeptInputStartsWhereAFirstFrameStarts) {
  const OneWorkerThread one_thread;
  const std::string root = MakeTempDir("sequence_after_kept");
  const std::string capture = root + "/capture";
  // No folds: the input is the true surface, so the 4 cm the bias compensation of wide Gaussians
  // adds without an iteration makes frame 0 worse in the held-out camera, and its input is kept.
  SynthOptions options = testing_util::TinyRefinableSynthOptions(2);
  options.cameras.count = 6;
  options.folds.clear();
  GenerateSyntheticCapture(options, capture);
  Config config = testing_util::TinyRunConfig(capture, root + "/sequence", 0);
  config.eval.flow = "none";
  config.validation.cameras = {"cam05"};
  config.refine.sigma_hat = 0.04;
  config.refine.scene_lengths.sigma_hat = false;
  config.refine.bias_compensation = true;
  config.refine.keep_input_if_worse = true;
  config.refine.warm_start = true;
  config.refine.sweep.samples = 0;  // A frame without a predecessor starts at zero.
  ASSERT_EQ(RunRefine(config), 0);
  ASSERT_TRUE(Record(config.output.dir, "000000").kept_input);

  Config alone = config;
  alone.output.dir = root + "/alone";
  alone.capture.frames = "1:2";
  ASSERT_EQ(RunRefine(alone), 0);
  const FrameStats after_kept = Record(config.output.dir, "000001");
  const FrameStats first = Record(alone.output.dir, "000001");
  ASSERT_TRUE(std::isfinite(first.energy_start));
  EXPECT_EQ(after_kept.energy_start, first.energy_start);
  EXPECT_EQ(after_kept.kept_input, first.kept_input);
}

}  // namespace
}  // namespace finecap
