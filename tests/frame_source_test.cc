#include "finecap/io/frame_source.h"

#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "finecap/util/error.h"
#include "test_util.h"

namespace finecap {
namespace {

using testing_util::ExpectErrorMentions;
using testing_util::MakeTempDir;
using testing_util::WriteText;

Camera MakeSmallCamera(int width, int height) {
  Camera camera;
  camera.name = "cam0";
  camera.width = width;
  camera.height = height;
  camera.K << 150.0, 0.0, 0.5 * (width - 1), 0.0, 150.0, 0.5 * (height - 1), 0.0, 0.0, 1.0;
  camera.t = Eigen::Vector3d(0, 0, 2);
  return camera;
}

cv::Mat UniformImage(int width, int height, int level) {
  return cv::Mat(height, width, CV_8UC3, cv::Scalar(level, 255 - level, level / 2));
}

// Intensity-weighted centre of the bright pixels of a grey blob image.
Eigen::Vector2d BrightCentroid(const cv::Mat& image) {
  cv::Mat grey;
  cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  double sum = 0, sx = 0, sy = 0;
  for (int y = 0; y < grey.rows; ++y) {
    for (int x = 0; x < grey.cols; ++x) {
      const double w = std::max(0, grey.at<uchar>(y, x) - 20);
      sum += w, sx += w * x, sy += w * y;
    }
  }
  return Eigen::Vector2d(sx / sum, sy / sum);
}

// A Gaussian blob centred at `centre`: its centroid is `centre` to a small fraction of a pixel.
cv::Mat BlobImage(int width, int height, const Eigen::Vector2d& centre) {
  cv::Mat image(height, width, CV_8UC3);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const double d2 = std::pow(x - centre.x(), 2) + std::pow(y - centre.y(), 2);
      const auto level = cv::saturate_cast<uchar>(255.0 * std::exp(-d2 / (2 * 2.0 * 2.0)));
      image.at<cv::Vec3b>(y, x) = cv::Vec3b(level, level, level);
    }
  }
  return image;
}

// Plain OpenCV distortion; the rational and thin-prism models; and a skew, which OpenCV's maps
// leave out and the undistorter puts back.
class UndistortionTest : public ::testing::TestWithParam<int> {};

TEST_P(UndistortionTest, UndistortsToTheUndistortedCamerasProjection) {
  const std::string dir = MakeTempDir("frames");
  Camera camera = MakeSmallCamera(200, 160);
  camera.distortion = {-0.35, 0.1, 0.002, -0.003, 0.0};
  if (GetParam() == 1) {
    camera.distortion = {-0.3,  0.08, 0.002, -0.003, 0.01,   0.05,
                         -0.02, 0.01, 0.004, -0.001, -0.003, 0.002};
  }
  if (GetParam() == 2) camera.K(0, 1) = 4.0;
  const Eigen::Vector3d point(0.9, 0.6, 0.0);  // Near the corner, where distortion is large.
  const Eigen::Vector2d distorted = camera.Project(point);
  const Eigen::Vector2d ideal = camera.Undistorted().Project(point);
  ASSERT_GT((distorted - ideal).norm(), 5.0);  // The test means something.
  cv::imwrite(dir + "/0.png", BlobImage(200, 160, distorted));

  const cv::Mat image = MakeImageFolderSource(dir, {"0"}, camera)->Read(0);
  ASSERT_EQ(image.type(), CV_8UC3);
  EXPECT_LT((BrightCentroid(image) - ideal).norm(), 0.3);
}

INSTANTIATE_TEST_SUITE_P(Models, UndistortionTest, ::testing::Values(0, 1, 2));

TEST(FrameSourceTest, ImageFolderMatchesFrameNamesExactlyOrByNumber) {
  const std::string dir = MakeTempDir("frames");
  cv::imwrite(dir + "/000000.png", UniformImage(32, 24, 10));
  cv::imwrite(dir + "/7.JPG", UniformImage(32, 24, 200));
  cv::imwrite(dir + "/000002.jpeg", UniformImage(32, 24, 100));
  const auto source =
      MakeImageFolderSource(dir, {"000000", "000007", "000002", "000009"}, MakeSmallCamera(32, 24));
  ASSERT_EQ(source->num_frames(), 4);
  EXPECT_NEAR(cv::mean(source->Read(1))[0], 200, 3);
  EXPECT_NEAR(cv::mean(source->Read(0))[0], 10, 1);
  EXPECT_NEAR(cv::mean(source->Read(2))[0], 100, 3);
  ExpectErrorMentions([&] { source->Read(3); }, {dir, "no image for frame '000009'"});
  ExpectErrorMentions([&] { source->Read(4); }, {dir, "outside [0, 4)"});
}

TEST(FrameSourceTest, BadImagesNameTheFileAndProblem) {
  const std::string dir = MakeTempDir("frames");
  const Camera camera = MakeSmallCamera(80, 60);
  cv::imwrite(dir + "/0.png", UniformImage(64, 48, 50));
  WriteText(dir + "/1.png", "");
  std::vector<uchar> png, jpg;
  cv::Mat noise(60, 80, CV_8UC3);
  cv::randu(noise, 0, 255);
  cv::imencode(".png", noise, png);
  cv::imencode(".jpg", noise, jpg);
  WriteText(dir + "/2.png", std::string(png.begin(), png.begin() + png.size() / 2));
  WriteText(dir + "/3.jpg", std::string(jpg.begin(), jpg.begin() + jpg.size() * 3 / 4));
  WriteText(dir + "/4.png", "not an image at all\n");
  const auto source = MakeImageFolderSource(dir, {"0", "1", "2", "3", "4"}, camera);
  ExpectErrorMentions([&] { source->Read(0); },
                      {dir + "/0.png", "is 64x48 but camera cam0 is 80x60"});
  ExpectErrorMentions([&] { source->Read(1); }, {dir + "/1.png", "empty (0 bytes)"});
  ExpectErrorMentions([&] { source->Read(2); }, {dir + "/2.png", "cannot decode"});
  ExpectErrorMentions([&] { source->Read(3); }, {dir + "/3.jpg", "truncated"});
  ExpectErrorMentions([&] { source->Read(4); }, {dir + "/4.png", "cannot decode"});
}

// Writes `levels.size()` uniform frames with Motion-JPEG, the codec OpenCV always has.
std::string WriteVideo(const std::string& dir, const std::vector<int>& levels) {
  const std::string path = dir + "/cam0.avi";
  cv::VideoWriter writer(path, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 25.0, cv::Size(32, 24));
  EXPECT_TRUE(writer.isOpened());
  for (int level : levels) writer.write(UniformImage(32, 24, level));
  return path;
}

TEST(FrameSourceTest, VideoReadsInOrderAndSeeks) {
  const std::vector<int> levels = {10, 50, 90, 130, 170, 210};
  const std::string path = WriteVideo(MakeTempDir("frames"), levels);
  const auto source =
      OpenFrameSource(path, std::vector<std::string>(6, "x"), MakeSmallCamera(32, 24));
  ASSERT_EQ(source->num_frames(), 6);
  for (int frame : {0, 1, 2, 5, 1, 3, 0, 4}) {
    EXPECT_NEAR(cv::mean(source->Read(frame))[0], levels[frame], 4) << frame;
  }
}

TEST(FrameSourceTest, VideoShorterThanAskedAndWrongSizeAreNamed) {
  const std::string path = WriteVideo(MakeTempDir("frames"), {10, 50, 90});
  const auto source = MakeVideoSource(path, 5, MakeSmallCamera(32, 24));
  EXPECT_NO_THROW(source->Read(2));
  ExpectErrorMentions([&] { source->Read(3); }, {"cam0.avi", "no frame 3", "shorter than the 5"});
  const auto wrong = MakeVideoSource(path, 3, MakeSmallCamera(40, 24));
  ExpectErrorMentions([&] { wrong->Read(0); }, {"cam0.avi", "is 32x24 but camera cam0 is 40x24"});
  EXPECT_EQ(ReadFirstFrameSize(path, {"0"}), cv::Size(32, 24));
}

TEST(FrameSourceTest, MissingInputsAreNamed) {
  const std::string dir = MakeTempDir("frames");
  ExpectErrorMentions([&] { OpenFrameSource(dir + "/cam9.mp4", {"0"}, MakeSmallCamera(8, 8)); },
                      {"cam9.mp4", "no images or video"});
  WriteText(dir + "/fake.mp4", "not a video");
  ExpectErrorMentions([&] { OpenFrameSource(dir + "/fake.mp4", {"0"}, MakeSmallCamera(8, 8)); },
                      {"fake.mp4", "cannot be opened as a video"});
}

}  // namespace
}  // namespace finecap
