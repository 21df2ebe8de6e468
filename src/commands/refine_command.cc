// finecap refine: every configured frame of a capture (of this shard), refined into output.dir.
#include "commands/command_util.h"
#include "finecap/commands/commands.h"
#include "finecap/refine/shard.h"

namespace finecap {

int RunRefine(const Config& configured) {
  Capture capture = internal::OpenConfiguredCapture(configured);
  const FrameRange frames =
      ShardOf(internal::ConfiguredFrames(configured, capture), configured.runtime.shard);
  const Config config = internal::WithSceneLengths(configured, capture, "refine");
  // Created by the run, once its memory forecast has been found to fit.
  const std::string out = internal::CheckOutputFolder(config, capture);
  internal::RefineConfiguredSequence(config, frames, out, "refine", &capture);
  return 0;
}

}  // namespace finecap
