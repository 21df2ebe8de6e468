// The cameras aligned with each other before the detail stage reads them.
//
// A calibration is only as exact as the solver that made it: half a pixel of error in a camera's
// rotation, centre or focal length is common (COLMAP reports reprojection errors of that size),
// and the detail stage compares the cameras' colours at a pixel's spacing, where half a pixel is
// a different texel. On the skirt with the calibration errors of configs/synth_noisy.yaml
// (0.03 degrees of rotation, 2 mm of centre, 0.2 % of focal length: half a pixel to a pixel
// each) the detail recovered falls from 83 % to 53 % (docs/measurements.md, 2026-12-06).
//
// So, per frame and camera, the shift of its principal point that best aligns its colours at the
// surface the surface Gaussians found with the other cameras' mean there, by rounds of
// Lucas-Kanade: in each, every camera reads every sample it sees (and the image's gradient
// there), and moves by half the least-squares step that brings its colours to the others' mean
// (half: the others move too). A shift of the principal point is what a small rotation about the
// camera's x and y axes does to the image, and, for a subject far from the camera compared with
// its depth, what an error of the centre does; it leaves what the frame is compared at (the
// surface) to the solve. The cameras handed back are those the detail stage reads with; the
// images, the surface Gaussians' stage and the held-out scoring keep the calibration as given.
#ifndef FINECAP_SRC_REFINE_CAMERA_ALIGNMENT_H_
#define FINECAP_SRC_REFINE_CAMERA_ALIGNMENT_H_

#include <vector>

#include <Eigen/Core>

#include "finecap/energy/frame_energy.h"

namespace finecap {

// A round's step below this, in pixels, for every camera ends the alignment.
constexpr double kAlignmentTolerancePixels = 0.01;
// The samples the alignment reads at most, spread over the surface: two unknowns a camera need
// far fewer than a frame has (synth_skirt 160,000, Sceaux 470,000, at full resolution 5.7
// million), and 50,000 keep its time within the noise of a frame's and its memory to a few
// megabytes.
constexpr int kMaxAlignmentSamples = 50000;
// The largest step of one round, in pixels: beyond it the linearisation of the image (blurred by
// a fraction of a pixel) says little.
constexpr double kMaxAlignmentStepPixels = 1.0;

// Shifts the principal point of each camera of `cameras` (their `pixels`, `samples_visible` and,
// when not empty, `samples_on_foreground` are read) in at most `max_rounds` rounds, the samples
// at `points` (one column per surface sample; at most kMaxAlignmentSamples of them read). A camera
// that shares too few samples with the others, or whose samples show no gradient, keeps its
// calibration. Returns each camera's shift in pixels (x, y).
std::vector<Eigen::Vector2d> AlignCameras(const Eigen::Matrix3Xd& points, int max_rounds,
                                          std::vector<CameraInput>* cameras);

}  // namespace finecap

#endif  // FINECAP_SRC_REFINE_CAMERA_ALIGNMENT_H_
