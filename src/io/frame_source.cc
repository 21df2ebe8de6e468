#include "finecap/io/frame_source.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <map>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "finecap/util/error.h"
#include "util/image_codec.h"
#include "util/io_util.h"
#include "util/opencv_extras.h"

namespace finecap {
namespace {

namespace fs = std::filesystem;

std::string SizeText(int width, int height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

void RequireCameraSize(const cv::Mat& image, const Camera& camera, const std::string& where) {
  Require(image.cols == camera.width && image.rows == camera.height, where,
          "is " + SizeText(image.cols, image.rows) + " but camera " + camera.name + " is " +
              SizeText(camera.width, camera.height));
}

// A JPEG ends with the EOI marker FF D9. libjpeg decodes a truncated file with a mere warning,
// filling the rest grey, so the marker is looked for in the file's tail (entropy-coded data never
// holds FF D9; an EXIF thumbnail's EOI sits near the start, not in the tail).
bool JpegHasEndMarker(const std::string& bytes) {
  const size_t tail_start = bytes.size() > 4096 ? bytes.size() - 4096 : 0;
  return bytes.find("\xFF\xD9", tail_start) != std::string::npos;
}

bool IsJpeg(const std::string& bytes) { return bytes.compare(0, 2, "\xFF\xD8") == 0; }

// Decodes the bytes of the image file `path` to 8-bit BGR, refusing empty, truncated and
// undecodable files.
cv::Mat DecodeImageBytes(const std::string& bytes, const std::string& path) {
  Require(!bytes.empty(), path, "the image file is empty (0 bytes)");
  Require(!IsJpeg(bytes) || JpegHasEndMarker(bytes), path,
          "the JPEG image is truncated (no end marker)");
  return internal::DecodeImage(bytes, path);
}

cv::Mat DecodeImageFile(const std::string& path) {
  return DecodeImageBytes(internal::ReadWholeFile(path), path);
}

bool IsImageExtension(std::string extension) {
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension == ".png" || extension == ".jpg" || extension == ".jpeg";
}

// A decoded mask as 0 (background) and 255 (foreground). A PNG stores labels exactly, so any
// non-zero value is foreground (ZJU-MoCap's masks are 0 and 1); a JPEG's compression leaves
// small non-zero values in the background, so there foreground is above half the range.
cv::Mat ForegroundOf(const cv::Mat& bgr, bool lossy) {
  cv::Mat channels[3], brightest;
  cv::split(bgr, channels);
  brightest = cv::max(cv::max(channels[0], channels[1]), channels[2]);
  return brightest > (lossy ? 127 : 0);
}

// The images of a folder, found by frame name: listed once so that a frame costs no directory
// scan. Names are matched exactly, else by numeric value (`12.png` for frame `000012`).
class ImageFolderIndex {
 public:
  explicit ImageFolderIndex(const std::string& folder) : folder_(folder) {
    std::error_code error;
    Require(fs::is_directory(folder, error), folder, "image folder not found");
    for (const fs::directory_entry& entry : fs::directory_iterator(folder, error)) {
      const fs::path& path = entry.path();
      if (!entry.is_regular_file(error) || !IsImageExtension(path.extension().string())) continue;
      const std::string stem = path.stem().string();
      by_stem_.emplace(stem, path.string());
      int number = 0;
      if (internal::ParseInt(stem, &number)) by_number_.emplace(number, path.string());
    }
  }

  std::string Find(const std::string& frame_name) const {
    const auto exact = by_stem_.find(frame_name);
    if (exact != by_stem_.end()) return exact->second;
    int number = 0;
    if (internal::ParseInt(frame_name, &number)) {
      const auto numeric = by_number_.find(number);
      if (numeric != by_number_.end()) return numeric->second;
    }
    throw Error(folder_, "no image for frame '" + frame_name + "' (looked for " + frame_name +
                             ".png, .jpg and .jpeg)");
  }

 private:
  std::string folder_;
  std::map<std::string, std::string> by_stem_;
  std::map<int, std::string> by_number_;
};

// Removes the lens distortion with maps computed once per camera; keeps K.
class Undistorter {
 public:
  explicit Undistorter(const Camera& camera) {
    if (!camera.HasDistortion()) return;
    cv::Mat K(3, 3, CV_64F);
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) K.at<double>(r, c) = camera.K(r, c);
    }
    const std::vector<double> distortion(camera.distortion.begin(), camera.distortion.end());
    const cv::Size size(camera.width, camera.height);
    if (camera.K(0, 1) == 0.0) {
      cv::initUndistortRectifyMap(K, distortion, cv::Mat(), K, size, CV_16SC2, map1_, map2_);
      return;
    }
    // OpenCV's maps leave out the skew of the distorted image (they take u = fx xd + cx): adding
    // skew * yd, with yd = (v - cy) / fy read off the map itself, puts it back exactly.
    cv::Mat map_x, map_y;
    cv::initUndistortRectifyMap(K, distortion, cv::Mat(), K, size, CV_32FC1, map_x, map_y);
    const double skew_per_row = camera.K(0, 1) / camera.K(1, 1);
    map_x += skew_per_row * (map_y - camera.K(1, 2));
    cv::convertMaps(map_x, map_y, map1_, map2_, CV_16SC2);
  }

  // `interpolation`: cv::INTER_LINEAR for images, cv::INTER_NEAREST for masks (whose values
  // are labels, not intensities).
  cv::Mat Apply(const cv::Mat& image, int interpolation = cv::INTER_LINEAR) const {
    if (map1_.empty()) return image;
    cv::Mat undistorted;
    cv::remap(image, undistorted, map1_, map2_, interpolation, cv::BORDER_CONSTANT);
    return undistorted;
  }

 private:
  cv::Mat map1_, map2_;
};

void RequireFrameInRange(int frame, int num_frames, const std::string& where) {
  Require(frame >= 0 && frame < num_frames, where,
          "frame " + std::to_string(frame) + " is outside [0, " + std::to_string(num_frames) + ")");
}

// The mask at `path` of `camera`, undistorted by `undistorter` (ForegroundOf;
// MakeMaskFolderSource).
cv::Mat ReadMaskFile(const std::string& path, const Camera& camera,
                     const Undistorter& undistorter) {
  const std::string bytes = internal::ReadWholeFile(path);
  const cv::Mat mask = ForegroundOf(DecodeImageBytes(bytes, path), IsJpeg(bytes));
  Require(mask.cols == camera.width && mask.rows == camera.height, path,
          "the mask is " + SizeText(mask.cols, mask.rows) + " but camera " + camera.name +
              "'s images are " + SizeText(camera.width, camera.height));
  return undistorter.Apply(mask, cv::INTER_NEAREST);
}

// The images of a folder, or its masks (ForegroundOf), one frame at a time.
class ImageFolderSource : public FrameSource {
 public:
  enum class Content { kImages, kMasks };

  ImageFolderSource(const std::string& folder, const std::vector<std::string>& frame_names,
                    const Camera& camera, Content content)
      : folder_(folder),
        index_(folder),
        frame_names_(frame_names),
        camera_(camera),
        undistorter_(camera),
        content_(content) {}

  cv::Mat Read(int frame) override {
    RequireFrameInRange(frame, num_frames(), folder_);
    const std::string path = index_.Find(frame_names_[frame]);
    if (content_ == Content::kMasks) return ReadMaskFile(path, camera_, undistorter_);
    const cv::Mat image = DecodeImageFile(path);
    RequireCameraSize(image, camera_, path);
    return undistorter_.Apply(image);
  }

  int num_frames() const override { return static_cast<int>(frame_names_.size()); }

 private:
  std::string folder_;
  ImageFolderIndex index_;
  std::vector<std::string> frame_names_;
  Camera camera_;
  Undistorter undistorter_;
  Content content_;
};

// One image file, the only frame: COLMAP's flat images/NAME layout, or its mask masks/NAME.png.
class ImageFileSource : public FrameSource {
 public:
  ImageFileSource(const std::string& path, const Camera& camera, bool mask = false)
      : path_(path), camera_(camera), undistorter_(camera), mask_(mask) {}

  cv::Mat Read(int frame) override {
    RequireFrameInRange(frame, num_frames(), path_);
    if (mask_) return ReadMaskFile(path_, camera_, undistorter_);
    const cv::Mat image = DecodeImageFile(path_);
    RequireCameraSize(image, camera_, path_);
    return undistorter_.Apply(image);
  }

  int num_frames() const override { return 1; }

 private:
  std::string path_;
  Camera camera_;
  Undistorter undistorter_;
  bool mask_;
};

bool IsImageFile(const std::string& path) {
  std::error_code error;
  return fs::is_regular_file(path, error) && IsImageExtension(fs::path(path).extension().string());
}

// The video at `path` through the OpenCV extras (src/util/opencv_extras.h), which are loaded
// here, by the first video a run opens.
std::unique_ptr<internal::VideoReader> OpenVideo(const std::string& path) {
  internal::RequireFile(path);
  std::unique_ptr<internal::VideoReader> video =
      internal::LoadOpenCvExtras("video input (" + path + ")").open_video(path);
  Require(video != nullptr, path, "cannot be opened as a video");
  return video;
}

// Forward jumps up to this many frames decode the frames in between instead of seeking: exact
// for every codec, and cheaper than a seek to the previous key frame.
constexpr int kMaxFramesDecodedToSkip = 32;

class VideoSource : public FrameSource {
 public:
  VideoSource(const std::string& path, int num_frames, const Camera& camera)
      : path_(path),
        num_frames_(num_frames),
        camera_(camera),
        undistorter_(camera),
        capture_(OpenVideo(path)) {}

  cv::Mat Read(int frame) override {
    RequireFrameInRange(frame, num_frames_, path_);
    MoveTo(frame);
    cv::Mat image;
    Require(capture_->Read(&image) && !image.empty(), path_, TooShort(frame));
    next_frame_ = frame + 1;
    RequireCameraSize(image, camera_, path_ + " (frame " + std::to_string(frame) + ")");
    return undistorter_.Apply(image);
  }

  int num_frames() const override { return num_frames_; }

 private:
  void MoveTo(int frame) {
    if (frame < next_frame_ || frame > next_frame_ + kMaxFramesDecodedToSkip) {
      capture_->Seek(frame);
      next_frame_ = frame;
    }
    for (; next_frame_ < frame; ++next_frame_) {
      Require(capture_->Grab(), path_, TooShort(next_frame_));
    }
  }

  std::string TooShort(int frame) const {
    return "the video has no frame " + std::to_string(frame) + ": it is shorter than the " +
           std::to_string(num_frames_) + " frames asked";
  }

  std::string path_;
  int num_frames_;
  Camera camera_;
  Undistorter undistorter_;
  std::unique_ptr<internal::VideoReader> capture_;
  int next_frame_ = 0;  // The frame the next capture_->Read() returns.
};

}  // namespace

std::unique_ptr<FrameSource> MakeImageFolderSource(const std::string& folder,
                                                   const std::vector<std::string>& frame_names,
                                                   const Camera& camera) {
  camera.Validate(folder);
  return std::make_unique<ImageFolderSource>(folder, frame_names, camera,
                                             ImageFolderSource::Content::kImages);
}

std::unique_ptr<FrameSource> MakeMaskFolderSource(const std::string& folder,
                                                  const std::vector<std::string>& frame_names,
                                                  const Camera& camera) {
  camera.Validate(folder);
  return std::make_unique<ImageFolderSource>(folder, frame_names, camera,
                                             ImageFolderSource::Content::kMasks);
}

std::unique_ptr<FrameSource> MakeMaskFileSource(const std::string& path, const Camera& camera) {
  camera.Validate(path);
  return std::make_unique<ImageFileSource>(path, camera, true);
}

std::unique_ptr<FrameSource> MakeVideoSource(const std::string& path, int num_frames,
                                             const Camera& camera) {
  camera.Validate(path);
  return std::make_unique<VideoSource>(path, num_frames, camera);
}

std::unique_ptr<FrameSource> OpenFrameSource(const std::string& path,
                                             const std::vector<std::string>& frame_names,
                                             const Camera& camera) {
  std::error_code error;
  Require(fs::exists(path, error), path, "no images or video found here");
  if (fs::is_directory(path, error)) return MakeImageFolderSource(path, frame_names, camera);
  if (IsImageFile(path)) {
    Require(
        frame_names.size() == 1, path,
        "a single image holds one frame, not the " + std::to_string(frame_names.size()) + " asked");
    camera.Validate(path);
    return std::make_unique<ImageFileSource>(path, camera);
  }
  return MakeVideoSource(path, static_cast<int>(frame_names.size()), camera);
}

cv::Size ReadFirstFrameSize(const std::string& path, const std::vector<std::string>& frame_names) {
  Require(!frame_names.empty(), path, "no frames to read");
  std::error_code error;
  if (fs::is_directory(path, error)) {
    return DecodeImageFile(ImageFolderIndex(path).Find(frame_names[0])).size();
  }
  if (IsImageFile(path)) return DecodeImageFile(path).size();
  cv::Mat image;
  Require(OpenVideo(path)->Read(&image) && !image.empty(), path, "the video has no frames");
  return image.size();
}

}  // namespace finecap
