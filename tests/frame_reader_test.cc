#include "finecap/refine/frame_reader.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <mutex>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "finecap/io/capture.h"
#include "finecap/util/error.h"
#include "test_util.h"
#include "tiny_synth.h"

namespace finecap {
namespace {

namespace fs = std::filesystem;

// Records the frames the work ahead was done on, in the order it started on them, and how many
// ran at once at most.
class WorkLog {
 public:
  FrameReadAhead::WorkAhead Callback() {
    return [this](int frame, FrameReadAhead::Frame*) {
      const int running = ++running_;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        most_at_once_ = std::max(most_at_once_, running);
        frames_.push_back(frame);
      }
      // Long enough for a read started beside this one to be caught running.
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      --running_;
    };
  }
  std::vector<int> frames() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return frames_;
  }
  int most_at_once() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return most_at_once_;
  }

 private:
  std::atomic<int> running_{0};
  mutable std::mutex mutex_;
  int most_at_once_ = 0;
  std::vector<int> frames_;
};

class FrameReadAheadTest : public ::testing::Test {
 protected:
  void SetUp() override {
    directory_ = testing_util::MakeTempDir("frame_read_ahead");
    SynthOptions options = testing_util::TinySynthOptions();
    options.num_frames = 3;
    GenerateSyntheticCapture(options, directory_);
  }

  // Whether `read` holds frame `frame` of the capture as ReadFrameInput reads it.
  ::testing::AssertionResult IsFrame(Capture* capture, const FrameReadAhead::Frame& read,
                                     int frame) {
    const FrameInput expected = ReadFrameInput(capture, frame);
    if (read.input.coarse.vertices != expected.coarse.vertices) {
      return ::testing::AssertionFailure() << "another frame's mesh";
    }
    if (read.input.images.size() != expected.images.size()) {
      return ::testing::AssertionFailure() << read.input.images.size() << " images";
    }
    return ::testing::AssertionSuccess();
  }

  std::string directory_;
};

TEST_F(FrameReadAheadTest, ReadsTheFramesAskedForInOrderOneAtATime) {
  Capture capture = Capture::Open(directory_);
  WorkLog log;
  FrameReadAhead reader(&capture, false, {}, std::nullopt, log.Callback());
  reader.ReadAhead(1);
  reader.ReadAhead(2);
  reader.ReadAhead(1);  // Asked for already: not read twice.
  const FrameReadAhead::Frame first = reader.Take(1);
  EXPECT_TRUE(reader.ReadsAhead());
  const FrameReadAhead::Frame second = reader.Take(2);
  EXPECT_FALSE(reader.ReadsAhead());
  EXPECT_TRUE(IsFrame(&capture, first, 1));
  EXPECT_TRUE(IsFrame(&capture, second, 2));
  EXPECT_EQ(log.frames(), (std::vector<int>{1, 2}));
  EXPECT_EQ(log.most_at_once(), 1);
}

TEST_F(FrameReadAheadTest, TakingAFrameBehindAnotherReadsItAgain) {
  Capture capture = Capture::Open(directory_);
  WorkLog log;
  FrameReadAhead reader(&capture, false, {}, std::nullopt, log.Callback());
  reader.ReadAhead(0);
  reader.ReadAhead(1);
  const FrameReadAhead::Frame read = reader.Take(1);  // Frame 0 is dropped, unused.
  EXPECT_TRUE(IsFrame(&capture, read, 1));
  EXPECT_EQ(log.frames(), (std::vector<int>{0, 1, 1}));
}

// A read that fails does not hold up the one asked for after it: its error comes from Take.
TEST_F(FrameReadAheadTest, AFailedReadLetsTheNextOneRun) {
  Capture capture = Capture::Open(directory_);
  const std::string camera = capture.cameras().front().name;
  const fs::path image =
      fs::path(directory_) / "images" / camera / (capture.frame_name(1) + ".png");
  ASSERT_TRUE(fs::exists(image));
  testing_util::WriteText(image.string(), "not a PNG");
  WorkLog log;
  FrameReadAhead reader(&capture, false, {}, std::nullopt, log.Callback());
  reader.ReadAhead(1);
  reader.ReadAhead(2);
  EXPECT_THROW(reader.Take(1), Error);
  const FrameReadAhead::Frame read = reader.Take(2);
  EXPECT_TRUE(IsFrame(&capture, read, 2));
  EXPECT_EQ(log.frames(), (std::vector<int>{2}));
}

}  // namespace
}  // namespace finecap
