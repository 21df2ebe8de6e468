#include "util/opencv_extras.h"

#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "finecap/util/error.h"
#include "test_util.h"

namespace finecap {
namespace {

using internal::LoadOpenCvExtras;
using internal::LoadOpenCvExtrasFrom;
using internal::OpenCvExtrasCandidates;
using testing_util::ExpectErrorMentions;

TEST(OpenCvExtrasTest, TheBuiltLibraryLoadsAndServesDeepFlow) {
  const std::vector<std::string> candidates = OpenCvExtrasCandidates();
  ASSERT_FALSE(candidates.empty());
  EXPECT_EQ(std::filesystem::path(candidates[0]).filename(), "libfinecap_opencv_extras.so");
  const internal::OpenCvExtras& extras = LoadOpenCvExtras("the test");
  ASSERT_NE(extras.open_video, nullptr);
  ASSERT_NE(extras.deep_flow, nullptr);
  const cv::Mat still(32, 48, CV_8UC1, cv::Scalar(90));
  const cv::Mat flow = extras.deep_flow(still, still);
  EXPECT_EQ(flow.type(), CV_32FC2);
  EXPECT_EQ(flow.size(), still.size());
}

TEST(OpenCvExtrasTest, AMissingOrForeignLibraryNamesItselfAndWhatNeededIt) {
  ExpectErrorMentions(
      [] {
        LoadOpenCvExtrasFrom({"/nonexistent/libfinecap_opencv_extras.so"},
                             "video input (videos/cam0.mp4)");
      },
      {"libfinecap_opencv_extras.so", "video input (videos/cam0.mp4)",
       "/nonexistent/libfinecap_opencv_extras.so"});
  // A library that loads but is not the extras: refused by its missing entry point.
  ExpectErrorMentions([] { LoadOpenCvExtrasFrom({"libz.so.1"}, "optical flow by DeepFlow"); },
                      {"optical flow by DeepFlow", "libz.so.1: no finecap_opencv_extras_v1"});
}

TEST(OpenCvExtrasTest, AnUnopenableVideoGivesNoReader) {
  const std::string dir = testing_util::MakeTempDir("extras");
  testing_util::WriteText(dir + "/fake.mp4", "not a video");
  EXPECT_EQ(LoadOpenCvExtras("the test").open_video(dir + "/fake.mp4"), nullptr);
}

}  // namespace
}  // namespace finecap
