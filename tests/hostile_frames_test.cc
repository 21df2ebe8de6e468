// Damaged frames through `finecap refine` on a tiny synthetic capture: a missing camera folder, a
// video shorter than the mesh sequence, an unreadable image; each stops with an Error naming the
// file or folder, or, with capture.skip_unreadable_cameras, refines the frame without the camera
// and lists it in the frame's stats record.
#include <filesystem>
#include <sstream>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "finecap/commands/commands.h"
#include "finecap/config/config.h"
#include "finecap/refine/frame_stats.h"
#include "finecap/synth/synth.h"
#include "test_util.h"
#include "tiny_synth.h"

namespace finecap {
namespace {

namespace fs = std::filesystem;
using testing_util::ExpectErrorMentions;
using testing_util::FileBytes;
using testing_util::MakeTempDir;
using testing_util::WriteText;

// A tiny capture of `frames` frames (cameras cam00 and cam01) in <root>/capture.
std::string MakeCapture(const std::string& root, int frames) {
  SynthOptions options = testing_util::TinySynthOptions();
  options.num_frames = frames;
  GenerateSyntheticCapture(options, root + "/capture");
  return root + "/capture";
}

Config FastConfig(const std::string& capture, const std::string& out) {
  return testing_util::TinyRunConfig(capture, out, 2);
}

// Replaces images/<camera>/ by videos/<camera>.avi holding its first `frames` images.
void ImagesToShortVideo(const std::string& capture, const std::string& camera, int frames) {
  fs::create_directories(capture + "/videos");
  const std::string folder = capture + "/images/" + camera;
  cv::VideoWriter writer(capture + "/videos/" + camera + ".avi",
                         cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 25.0, cv::Size(64, 64));
  ASSERT_TRUE(writer.isOpened());
  for (int f = 0; f < frames; ++f) {
    std::ostringstream name;
    name << folder << "/" << std::setw(6) << std::setfill('0') << f << ".png";
    writer.write(cv::imread(name.str()));
  }
  writer.release();
  fs::remove_all(folder);
}

// The first half of a PNG: its header decodes, its data does not.
void TruncateImage(const std::string& path) {
  const std::string bytes = FileBytes(path);
  WriteText(path, bytes.substr(0, bytes.size() / 2));
}

std::vector<FrameStats> ReadStatsLines(const std::string& path) {
  std::istringstream lines(FileBytes(path));
  std::vector<FrameStats> records;
  int number = 0;
  for (std::string line; std::getline(lines, line);) {
    records.push_back(ParseFrameStats(line, path + " line " + std::to_string(++number)));
  }
  return records;
}

TEST(HostileFrames, MissingCameraFolderIsNamedAndNothingIsCreated) {
  const std::string root = MakeTempDir("missing_camera");
  const std::string capture = MakeCapture(root, 1);
  fs::remove_all(capture + "/images/cam01");
  ExpectErrorMentions([&] { RunRefine(FastConfig(capture, root + "/out")); },
                      {capture, "camera cam01", "images/cam01/", "videos/cam01.*"});
  EXPECT_FALSE(fs::exists(root + "/out"));
}

TEST(HostileFrames, VideoShorterThanTheMeshSequenceIsNamedWithTheFrame) {
  const std::string root = MakeTempDir("short_video");
  const std::string capture = MakeCapture(root, 3);
  ImagesToShortVideo(capture, "cam01", 2);
  ExpectErrorMentions([&] { RunRefine(FastConfig(capture, root + "/out")); },
                      {capture + "/videos/cam01.avi", "no frame 2", "shorter than the 3 frames"});
  // The frames before it are complete; the one that failed left nothing.
  EXPECT_TRUE(fs::exists(root + "/out/meshes/000001.ply"));
  EXPECT_FALSE(fs::exists(root + "/out/meshes/000002.ply"));
  EXPECT_FALSE(fs::exists(root + "/out/frames/000002.json"));
}

TEST(HostileFrames, UnreadableImageStopsTheRunNamingTheFile) {
  const std::string root = MakeTempDir("truncated");
  const std::string capture = MakeCapture(root, 2);
  TruncateImage(capture + "/images/cam01/000001.png");
  ExpectErrorMentions([&] { RunRefine(FastConfig(capture, root + "/out")); },
                      {capture + "/images/cam01/000001.png", "cannot decode"});
  EXPECT_FALSE(fs::exists(root + "/out/meshes/000001.ply"));
  EXPECT_EQ(ReadStatsLines(root + "/out/stats.jsonl").size(), 1u);
}

TEST(HostileFrames, SkipUnreadableCamerasRefinesWithoutThemAndListsThem) {
  const std::string root = MakeTempDir("skip");
  const std::string capture = MakeCapture(root, 3);
  TruncateImage(capture + "/images/cam01/000001.png");
  ImagesToShortVideo(capture, "cam00", 2);  // cam00 has no frame 2.
  Config config = FastConfig(capture, root + "/out");
  config.capture.skip_unreadable_cameras = true;
  ASSERT_EQ(RunRefine(config), 0);
  const std::vector<FrameStats> records = ReadStatsLines(root + "/out/stats.jsonl");
  ASSERT_EQ(records.size(), 3u);
  EXPECT_EQ(records[0].skipped_cameras, std::vector<std::string>{});
  EXPECT_EQ(records[1].skipped_cameras, std::vector<std::string>{"cam01"});
  EXPECT_EQ(records[2].skipped_cameras, std::vector<std::string>{"cam00"});
  for (const char* frame : {"000000", "000001", "000002"}) {
    EXPECT_TRUE(fs::exists(root + "/out/meshes/" + frame + ".ply")) << frame;
  }
  // A frame refined with one camera has fewer pairs of Gaussians than one with both.
  EXPECT_LT(records[1].pairs, records[0].pairs);
  EXPECT_GT(records[1].pairs, 0);
}

TEST(HostileFrames, SkipUnreadableCamerasStillStopsWhenNoCameraIsLeft) {
  const std::string root = MakeTempDir("skip_all");
  const std::string capture = MakeCapture(root, 2);
  TruncateImage(capture + "/images/cam00/000001.png");
  TruncateImage(capture + "/images/cam01/000001.png");
  Config config = FastConfig(capture, root + "/out");
  config.capture.skip_unreadable_cameras = true;
  ExpectErrorMentions([&] { RunRefine(config); }, {capture + "/images/cam00/000001.png",
                                                   "no other camera's image", "frame 000001"});
  EXPECT_FALSE(fs::exists(root + "/out/meshes/000001.ply"));
}

TEST(HostileFrames, SkipKeyDefaultsToFalse) {
  EXPECT_FALSE(LoadConfig("", {}).capture.skip_unreadable_cameras);
  EXPECT_TRUE(LoadConfig("", {{"capture.skip_unreadable_cameras", "true", "--set"}})
                  .capture.skip_unreadable_cameras);
}

}  // namespace
}  // namespace finecap
