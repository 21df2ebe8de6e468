#include "finecap/refine/frame_reader.h"

#include <algorithm>
#include <exception>
#include <memory>
#include <utility>

#include <omp.h>
#include <pthread.h>

#include "finecap/util/error.h"
#include "finecap/util/threads.h"

namespace finecap {
namespace {

// The message of `failure` when it is an Error (a problem with the input), else empty.
std::string ErrorMessage(const std::exception_ptr& failure) {
  try {
    std::rethrow_exception(failure);
  } catch (const Error& error) {
    return error.what();
  } catch (...) {
    return "";
  }
}

// The calling thread's OpenMP threads for parallel regions, `threads` while in scope.
class ScopedOpenMpThreads {
 public:
  explicit ScopedOpenMpThreads(int threads) : saved_(omp_get_max_threads()) {
    omp_set_num_threads(threads);
  }
  ~ScopedOpenMpThreads() { omp_set_num_threads(saved_); }
  ScopedOpenMpThreads(const ScopedOpenMpThreads&) = delete;
  ScopedOpenMpThreads& operator=(const ScopedOpenMpThreads&) = delete;

 private:
  int saved_;
};

}  // namespace

FrameInput ReadFrameInput(Capture* capture, int frame) {
  return ReadFrameInput(capture, frame, false, nullptr);
}

FrameInput ReadFrameInput(Capture* capture, int frame, bool skip_unreadable,
                          std::vector<SkippedCamera>* skipped) {
  FrameInput input;
  input.coarse = capture->ReadCoarseMesh(frame);
  // Each camera's images come from a source of its own, so they are decoded side by side; the
  // failures are then taken in the rig's order, as one camera after the other would meet them.
  const int num_cameras = capture->num_cameras();
  std::vector<cv::Mat> images(num_cameras), masks(num_cameras);
  const std::vector<std::exception_ptr> failures =
      ParallelForKeepingFailures(num_cameras, [&](int c) {
        images[c] = capture->ReadImage(c, frame);
        masks[c] = capture->ReadMask(c, frame);
      });
  std::string first_error;
  for (int c = 0; c < num_cameras; ++c) {
    const Camera& camera = capture->cameras()[c];
    if (!failures[c]) {
      input.images.push_back(std::move(images[c]));
      if (capture->has_masks()) input.masks.push_back(std::move(masks[c]));
      input.cameras.push_back(camera);
      continue;
    }
    // Only a camera whose image is unreadable (an Error) may be skipped, not a program fault.
    const std::string error = ErrorMessage(failures[c]);
    if (!skip_unreadable || error.empty()) std::rethrow_exception(failures[c]);
    if (first_error.empty()) first_error = error;
    if (skipped != nullptr) skipped->push_back({camera.name, error});
  }
  Require(!input.cameras.empty(), "",
          first_error + " (and no other camera's image of frame " + capture->frame_name(frame) +
              " could be read either)");
  return input;
}

std::vector<CalibratedImage> TakeHeldOutViews(const std::vector<std::string>& held_out,
                                              FrameInput* input) {
  std::vector<CalibratedImage> views;
  const bool modelled = input->image_models.size() == input->images.size();
  const bool masked = !input->masks.empty();
  FrameInput training;
  training.coarse = std::move(input->coarse);
  for (size_t c = 0; c < input->cameras.size(); ++c) {
    const std::string& name = input->cameras[c].name;
    const cv::Mat mask = masked ? input->masks[c] : cv::Mat();
    if (std::find(held_out.begin(), held_out.end(), name) != held_out.end()) {
      views.push_back({input->cameras[c], input->images[c], mask});
    } else {
      training.cameras.push_back(input->cameras[c]);
      training.images.push_back(input->images[c]);
      if (masked) training.masks.push_back(mask);
      if (modelled) training.image_models.push_back(std::move(input->image_models[c]));
    }
  }
  training.image_model_options = input->image_model_options;
  *input = std::move(training);
  Require(!input->cameras.empty(), "SequenceOptions::held_out_cameras",
          "no camera other than the held-out ones could be read");
  return views;
}

std::vector<CalibratedImage> CalibratedImagesOf(const FrameInput& input) {
  std::vector<CalibratedImage> views;
  for (size_t c = 0; c < input.cameras.size(); ++c) {
    views.push_back(
        {input.cameras[c], input.images[c], input.masks.empty() ? cv::Mat() : input.masks[c]});
  }
  return views;
}

FrameReadAhead::FrameReadAhead(Capture* capture, bool skip_unreadable,
                               std::vector<std::string> held_out,
                               std::optional<ImageGaussianOptions> image_options,
                               WorkAhead work_ahead)
    : capture_(capture),
      skip_unreadable_(skip_unreadable),
      held_out_(std::move(held_out)),
      image_options_(std::move(image_options)),
      work_ahead_(std::move(work_ahead)),
      threads_(omp_get_max_threads()) {}

FrameReadAhead::~FrameReadAhead() {
  DropPending();
  if (!thread_.joinable()) return;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    ending_ = true;
  }
  wake_.notify_one();
  thread_.join();
}

void FrameReadAhead::DropPending() {
  for (Pending& pending : pending_) pending.read.wait();
  pending_.clear();
}

void FrameReadAhead::ReadAhead(int frame) {
  if (kept_frame_ == frame) return;
  for (const Pending& pending : pending_) {
    if (pending.frame == frame) return;
  }
  std::packaged_task<Frame()> read([this, frame] { return Read(frame, true); });
  pending_.push_back({frame, read.get_future()});
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    tasks_.push_back(std::move(read));
  }
  wake_.notify_one();
  if (!thread_.joinable()) thread_ = std::thread([this] { Work(); });
}

void FrameReadAhead::Work() {
  // Named, so that a profile tells the frame ahead's work (and that of the OpenMP workers this
  // thread starts, which take its name) from the solve's.
  pthread_setname_np(pthread_self(), "finecap-ahead");
  for (;;) {
    std::packaged_task<Frame()> read;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [this] { return ending_ || !tasks_.empty(); });
      if (tasks_.empty()) return;  // Ending, nothing left.
      read = std::move(tasks_.front());
      tasks_.pop_front();
    }
    read();  // Its exception, if any, goes to its future.
  }
}

void FrameReadAhead::Keep(int frame, Frame read) {
  kept_frame_ = frame;
  kept_ = std::move(read);
}

FrameReadAhead::Frame FrameReadAhead::Take(int frame) {
  const int kept_frame = std::exchange(kept_frame_, -1);
  Frame kept = std::move(kept_);
  kept_ = {};
  if (kept_frame == frame) return kept;
  if (!pending_.empty() && pending_.front().frame == frame) {
    std::future<Frame> read = std::move(pending_.front().read);
    pending_.pop_front();
    return read.get();
  }
  DropPending();  // Reads of other frames.
  return Read(frame, false);
}

FrameReadAhead::Frame FrameReadAhead::Read(int frame, bool ahead) {
  Frame read;
  // In parallel, as the solve it overlaps: on two cores, whichever of the two ends first leaves
  // the other both; but ahead of a solve the images are modelled one at a time, which holds one
  // image's buffers instead of one per thread (a run's peak memory is higher by ~5 MB otherwise,
  // for no speed measured). A frame read while the run waits for it (the reference frame, before
  // the colours) has the cores to itself, and its images are modelled side by side.
  const ScopedOpenMpThreads parallel(threads_);
  read.input = ReadFrameInput(capture_, frame, skip_unreadable_, &read.skipped);
  read.held_out = TakeHeldOutViews(held_out_, &read.input);
  if (image_options_) {
    const ScopedOpenMpThreads modelling(ahead ? 1 : threads_);
    ModelFrameImages(*image_options_, &read.input);
  }
  if (work_ahead_) work_ahead_(frame, &read);
  return read;
}

}  // namespace finecap
