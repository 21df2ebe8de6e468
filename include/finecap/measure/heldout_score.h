// Photo-consistency in views left out of the refinement: the measure that needs no ground truth.
//
// A held-out camera's image was never seen by the refinement. If a surface is right, the images
// of the cameras that were used, carried into the held-out view through that surface, look like
// the held-out image; if it is wrong, they land on the wrong pixels. For each held-out view h:
//
//   1. Each surface is rendered into h (depth and face ids, render.h), and every pixel it covers
//      is back-projected to its surface point X.
//   2. The `neighbours` training views nearest to h (by the distance of their camera centres,
//      ties to the lower index) are warped into h: X is projected into training view t, kept when
//      it lies inside t's image and is not occluded there (its depth in t is at most
//      depth_tolerance_px pixel footprints behind the surface's own depth map of t at the nearest
//      pixel), and t's image is sampled bilinearly there.
//      With masks, only the subject is scored: a held-out pixel on its view's background is not
//      measured, nor is a surface point whose bilinear read in t blends a pixel of t's
//      background (the
//      backgrounds of different cameras need not agree, and are not what the surfaces explain).
//   3. Scores are measured over the pixels that *every* surface passed to (covered in h and
//      visible in t for each surface), so that all surfaces are scored on the same pixels:
//        * NCC: local normalised cross-correlation of grey levels in window x window squares,
//          per pixel, whose whole window lies in that common set; pixels whose held-out window
//          has a standard deviation below `min_std` are left out (no structure to correlate; a
//          flat patch would correlate with noise), and a warped window with no variance scores 0.
//        * MAD: mean absolute difference of grey levels (0-255) over the common set.
//      The figures of one held-out view are the means over its training views (those with any
//      measured pixel); the figures of all views, the means over the held-out views.
//
// Grey, not per channel: the texture of real objects lies mostly in brightness (plaster, skin,
// plain cloth), where the channels of a colour camera correlate almost perfectly; per-channel
// NCC would count the same signal three times and add the noise of dim channels. NCC is
// insensitive to gain and offset between cameras (exposure, white balance); MAD is not and shows
// them.
//
// No files are read or written here; the caller supplies cameras, undistorted images and meshes.
#ifndef FINECAP_MEASURE_HELDOUT_SCORE_H_
#define FINECAP_MEASURE_HELDOUT_SCORE_H_

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "finecap/geometry/camera.h"
#include "finecap/geometry/mesh.h"
#include "finecap/util/option_fields.h"

namespace finecap {

// The held-out score's options. The fields are documented where Fields() declares them
// (docs/configuration.md: validation).
struct HeldOutOptions {
  int neighbours = 4;
  int window = 7;  // Odd: a window has a centre pixel.
  double min_std = 2.0;
  // A pixel footprint is depth / focal, at the nearest pixel: scale-free, and wide enough for
  // surfaces seen at up to ~70 degrees.
  double depth_tolerance_px = 3.0;

  static const OptionFields<HeldOutOptions>& Fields();  // option_fields.h
  // Throws Error naming the field (HeldOutOptions::window) of a value out of range.
  void Check() const;
};

// One view: a pinhole camera (distortion zero), its 8-bit BGR image of its size and, optionally,
// its foreground mask (CV_8UC1 of the same size, zero on the background; empty: all foreground).
struct CalibratedImage {
  Camera camera;
  cv::Mat image;
  cv::Mat mask{};  // Initialised, so that {camera, image} needs no third member.
};

// The figures of one surface in one held-out view (or pooled over views). NaN when nothing was
// measured (no common pixels, or every window too flat).
struct SurfaceScore {
  double ncc = 0.0;
  double mad = 0.0;
};

struct HeldOutViewScore {
  std::string camera;                  // The held-out camera's name.
  std::vector<std::string> training;   // The training cameras warped in, nearest first.
  std::vector<SurfaceScore> surfaces;  // One per surface, in the caller's order.
  long ncc_pixels = 0;                 // NCC samples over all training views.
  long common_pixels = 0;              // MAD samples over all training views.
};

// Optional pictures of one held-out view, for reports: the nearest training view warped in
// through each surface (BGR, black where the warp did not reach) and each surface's NCC map, the
// mean over the training views (CV_32F, NaN where not scored).
struct HeldOutViewMaps {
  std::vector<cv::Mat> warped;
  std::vector<cv::Mat> ncc;
};

struct HeldOutScore {
  std::vector<HeldOutViewScore> views;  // In the order of `held_out`.
  std::vector<SurfaceScore> mean;       // Per surface, the means over the views.
};

// Scores every surface of `surfaces` (meshes of any topology; e.g. the input and the refined
// mesh) in every view of `held_out`, warping the views of `training` in as described above.
// When `maps` is given it receives one HeldOutViewMaps per held-out view. Throws Error when
// `training` or `surfaces` is empty, an image is not 8-bit BGR of its camera's size, a mask is
// neither empty nor CV_8UC1 of that size, or the options are invalid.
HeldOutScore ScoreHeldOutViews(const std::vector<CalibratedImage>& training,
                               const std::vector<CalibratedImage>& held_out,
                               const std::vector<const Mesh*>& surfaces,
                               const HeldOutOptions& options,
                               std::vector<HeldOutViewMaps>* maps = nullptr);

// Indices into `cameras` of the `count` cameras whose centres lie nearest to `target`'s, nearest
// first (ties to the lower index); fewer when there are fewer cameras.
std::vector<int> NearestCameras(const Camera& target, const std::vector<Camera>& cameras,
                                int count);

}  // namespace finecap

#endif  // FINECAP_MEASURE_HELDOUT_SCORE_H_
