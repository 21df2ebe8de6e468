// finecap synth: a synthetic capture with ground truth, written to output.dir.
#include <iostream>

#include "finecap/commands/commands.h"
#include "finecap/synth/synth.h"
#include "finecap/util/error.h"

namespace finecap {

int RunSynth(const Config& config) {
  Require(!config.output.dir.empty(), "output.dir",
          "no output folder given (set output.dir or pass --out DIR)");
  GenerateSyntheticCapture(config.synth, config.output.dir);
  std::cout << "Synthetic capture written to " << config.output.dir << " ("
            << config.synth.num_frames << " frames, " << config.synth.cameras.count
            << " cameras, ground truth in gt/)\n";
  return 0;
}

}  // namespace finecap
