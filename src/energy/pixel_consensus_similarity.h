// The consensus similarity (consensus_similarity.h) read at the images' own resolution.
//
// ConsensusSimilarity compares, in every camera that sees a patch, the colours of the patch's
// surface Gaussians: one colour per mesh vertex, blurred by a Gaussian of several pixels. Where
// the mesh is coarser than the images (a photogrammetry or scanner mesh seen by photos of a few
// megapixels, or any mesh seen close up), the images hold detail between the vertices that such
// a patch cannot see, and finer meshes only add unknowns that the same blurred colours cannot
// tell apart.
//
// Here the patch of surface Gaussian s is a set of surface samples about a pixel apart: the
// points of the refined mesh's faces around s (SurfaceSamples), each displaced along its
// interpolated normal by s's own k, read in each camera at their projection by bilinear
// interpolation of the image, blurred beforehand by a Gaussian of `blur` pixels so that the
// interpolant is smooth at the scale of the samples' spacing. The residuals are then the
// consensus similarity's: per camera and channel the patch's colours are normalised as in a
// normalised cross-correlation, each camera's against the cameras' mean, weighted by the patch's
// contrast at the input surface, under Cauchy's loss (patch_agreement.h). The unknowns stay one
// k per surface Gaussian: the samples only read the images finer.
//
// A camera counts for a patch when it sees every sample of it (visibility of the input surface),
// and a patch needs at least `min_cameras` such cameras. Colours are computed when asked, from
// the images, without tables: a sample is read at the k of the two or three patches it belongs
// to, and a bilinear read costs less than a table's Hermite interpolation.
#ifndef FINECAP_SRC_ENERGY_PIXEL_CONSENSUS_SIMILARITY_H_
#define FINECAP_SRC_ENERGY_PIXEL_CONSENSUS_SIMILARITY_H_

#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <opencv2/core.hpp>

#include "finecap/energy/energy_options.h"
#include "finecap/energy/frame_energy.h"
#include "finecap/energy/similarity.h"

namespace finecap {

class PixelConsensusSimilarity : public SimilarityTerm {
 public:
  // `samples` and `cameras` must outlive this object; `cameras[c].samples_visible` has one flag
  // per sample and `cameras[c].pixels` is the camera's image in the similarity's colour space
  // (CV_32FC3), blurred (ConsensusOptions::sample_blur).
  PixelConsensusSimilarity(const SurfaceSamples& samples, const std::vector<CameraInput>& cameras,
                           const ConsensusOptions& options);

  double Evaluate(const Eigen::VectorXd& k, Eigen::VectorXd* gradient) const override;
  const std::vector<ResidualBlock>& residual_blocks() const override { return blocks_; }
  void PrepareResiduals(const Eigen::VectorXd& k, bool with_jacobians) override;
  void BlockResiduals(int block, double* residuals, double* jacobian) const override;
  // Each block's summary straight from its residuals, without storing them.
  void PrepareBlockSummaries(const Eigen::VectorXd& k) override;
  // Each block's sum of squares without storing its residuals.
  void BlockCosts(const Eigen::VectorXd& k, std::vector<double>* costs) override;
  bool IsLeastSquares() const override { return true; }
  bool ReadsPairLists() const override { return false; }
  // The patches' shape, one entry per surface Gaussian, carried to the samples by
  // SurfaceSamples::weights: sample j of patch s is read at k_s + shape_j - shape_s.
  bool ShapesPatches() const override { return true; }
  void SetPatchShape(const Eigen::VectorXd& shape) override;

  // Camera c's colour of sample j displaced by k along its normal, and dcolour/dk when
  // `derivative` is not null.
  Eigen::Vector3d SampleColor(int c, int j, double k, Eigen::Vector3d* derivative) const;

 private:
  int PatchSize(int b) const { return patch_begin_[b + 1] - patch_begin_[b]; }
  int NumCameras(int b) const { return camera_begin_[b + 1] - camera_begin_[b]; }
  // The colours of block b's patch in each of its cameras (camera after camera, sample after
  // sample, channel after channel) with the patch displaced by k, and their k-derivatives when
  // `derivatives` is not null.
  void PatchColors(int b, double k, double* colors, double* derivatives) const;
  void PlainResiduals(int b, double k, double* residuals, double* jacobian) const;
  double LossScale(int b) const;
  BlockSummary SummaryAt(int b, double k, bool with_derivatives) const;

  const SurfaceSamples& samples_;
  const std::vector<CameraInput>& cameras_in_;
  ConsensusOptions options_;
  double scale_;  // 1 / sqrt(n_c).

  std::vector<ResidualBlock> blocks_;
  // Block b's samples (its own first) are members_[patch_begin_[b] ..), its cameras
  // cameras_[camera_begin_[b] ..).
  std::vector<int> patch_begin_, members_, camera_begin_, cameras_;
  std::vector<Eigen::Vector3d> weights_;
  Eigen::VectorXd shape_;            // Per sample.
  Eigen::VectorXd parameter_shape_;  // Per surface Gaussian.

  std::vector<long> residual_begin_;
  std::vector<double> residuals_, jacobians_;
};

}  // namespace finecap

#endif  // FINECAP_SRC_ENERGY_PIXEL_CONSENSUS_SIMILARITY_H_
