// finecap status: which of the configured frames a run folder holds, for a resumed run or the
// final step of a cluster job.
#include <iostream>
#include <vector>

#include "commands/command_util.h"
#include "finecap/commands/commands.h"
#include "finecap/refine/run_folder.h"
#include "finecap/refine/shard.h"

namespace finecap {
namespace {

// "000007" for one frame, "000007 to 000009 (indices 7:10)" for several.
std::string DescribeFrames(const Capture& capture, const FrameRange& missing) {
  const std::string first = capture.frame_name(missing.begin);
  if (missing.size() == 1) return first + " (index " + std::to_string(missing.begin) + ")";
  return first + " to " + capture.frame_name(missing.end - 1) + " (indices " +
         std::to_string(missing.begin) + ":" + std::to_string(missing.end) + ")";
}

// The runs of consecutive frames of `frames` that are not done in `out`.
std::vector<FrameRange> MissingRuns(const Capture& capture, const FrameRange& frames,
                                    const std::string& out, MeshFormat mesh_format) {
  std::vector<FrameRange> runs;
  for (int frame = frames.begin; frame < frames.end; ++frame) {
    if (FrameDone(FrameFilesIn(out, capture.frame_name(frame), mesh_format))) {
      continue;
    }
    if (!runs.empty() && runs.back().end == frame) {
      ++runs.back().end;
    } else {
      runs.push_back({frame, frame + 1});
    }
  }
  return runs;
}

}  // namespace

int RunStatus(const Config& config) {
  const Capture capture = internal::OpenConfiguredCapture(config);
  const FrameRange frames =
      ShardOf(internal::ConfiguredFrames(config, capture), config.runtime.shard);
  const std::string out = internal::RefinedRunFolder(config);
  const std::vector<FrameRange> missing =
      MissingRuns(capture, frames, out, internal::MeshFormatOf(config));
  int missing_count = 0;
  for (const FrameRange& run : missing) missing_count += run.size();

  std::cout << out << ": " << frames.size() - missing_count << " of " << frames.size()
            << " frames done (frames " << frames.begin << ":" << frames.end << ")\n";
  for (const FrameRange& run : missing)
    std::cout << "missing " << DescribeFrames(capture, run) << "\n";
  return missing_count == 0 ? 0 : kStatusIncomplete;
}

}  // namespace finecap
