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
// and a patch needs at least `min_cameras` such cameras. Its squared residuals count cos^p of its
// view angle relative to the patch's other cameras (ConsensusOptions::view_cosine_power): a steep
// view sees the patch foreshortened. With ConsensusOptions::shared_appearance
// and the samples' appearance (SurfaceSamples::appearance) known on all of a patch, that
// appearance is one more view of the patch, normalised and compared as a camera's colours are
// (it does not move with k): the surface's colours do not change from frame to frame while its
// shape does, so a patch that two cameras see gets a third comparison, and one that a single
// camera sees is compared at all. It counts towards `min_cameras` as a camera does, but a patch
// still needs a camera: the appearance alone says nothing about k. The normalisation takes out
// the patch's gain and offset, which the shading of a surface that changed shape moves. Colours are
// computed when asked, from the images, without tables: a sample is read at the k of the two or
// three patches it belongs to, and a bilinear read costs less than a table's Hermite interpolation.
#ifndef FINECAP_SRC_ENERGY_PIXEL_CONSENSUS_SIMILARITY_H_
#define FINECAP_SRC_ENERGY_PIXEL_CONSENSUS_SIMILARITY_H_

#include <vector>

#include <Eigen/Core>

#include "energy/terms/consensus/patch_agreement.h"
#include "finecap/energy/energy_options.h"
#include "finecap/energy/frame_energy.h"

namespace finecap {

// The colour each of `samples` shows at the surface displaced by `shape` (one entry per sample,
// along its normal), averaged over the cameras of `cameras` that see it and, with masks, have it
// on their foreground; NaN where none does. `cameras` as PixelConsensusSimilarity takes them.
Eigen::Matrix3Xd SeenAppearance(const SurfaceSamples& samples,
                                const std::vector<CameraInput>& cameras,
                                const Eigen::VectorXd& shape);

class PixelConsensusSimilarity : public PatchAgreementTerm {
 public:
  // `samples` and `cameras` must outlive this object; `cameras[c].samples_visible` has one flag
  // per sample and `cameras[c].pixels` is the camera's image in the similarity's colour space
  // (CV_32FC3), blurred (ConsensusOptions::sample_blur).
  // The reads' rays are kept when they come to at most `max_ray_table_bytes`
  // (SampleRayTableBytes).
  PixelConsensusSimilarity(const SurfaceSamples& samples, const std::vector<CameraInput>& cameras,
                           const ConsensusOptions& options,
                           double max_ray_table_bytes = kMaxSampleRayTableBytes);

  // The patches' shape, one entry per surface Gaussian, carried to the samples by
  // SurfaceSamples::weights: sample j of patch s is read at k_s + shape_j - shape_s.
  void SetPatchShape(const Eigen::VectorXd& shape) override;

  // Block b's colours in its cameras (camera after camera, member after member, channel after
  // channel) with member m of its patch at displacement member_k[m] along its normal, whatever
  // the patch's shape, and, when `derivatives` is not null, each colour's derivative in its own
  // member's displacement: the reads of a term that moves the samples otherwise
  // (SurfaceConsensusSimilarity).
  void ReadPatch(int b, const double* member_k, double* colors, double* derivatives) const;

 private:
  void PatchColors(int b, double k, double* colors, double* derivatives) const override;
  // The cameras that compare `patch` (ascending) and the samples of it they compare: the cameras
  // that see the whole patch, and of its samples those on the foreground of each of them
  // (CameraInput::samples_on_foreground); with no masks, every camera that sees it, on all of it.
  void ComparablePart(const std::vector<int>& patch, std::vector<int>* seen_by,
                      std::vector<int>* members) const;
  // Sets rays_ for every block's reads, when they fit within `max_table_bytes`.
  void ProjectReads(double max_table_bytes);

  // Whether the patch's members all have a known appearance (SurfaceSamples::appearance).
  bool AppearanceKnown(const std::vector<int>& members) const;
  // The weights of the cameras `seen_by` of `patch` (ConsensusOptions::view_cosine_power), at
  // CameraInput::view_cosines or, without them, at the patch's own sample; none with power 0.
  std::vector<double> CameraWeightsOf(int patch, const std::vector<int>& seen_by) const;

  const SurfaceSamples& samples_;
  const std::vector<CameraInput>& cameras_;
  // The camera index that stands for the samples' appearance in a patch's cameras: after every
  // camera, so that a patch's cameras stay ascending.
  int appearance_view_;
  // Per camera, K [R | t]: the homogeneous pixel of a world point (the images are undistorted).
  std::vector<Eigen::Matrix<double, 3, 4>> projections_;
  // A sample read by a camera: its homogeneous pixel at the input surface and that pixel's
  // derivative along the sample's normal, so that a read moved by k costs three multiply-adds
  // before the division instead of two matrix products. Per block, camera after camera, member
  // after member (the order of PatchColors), from read_begin_[b]; none is read for the
  // appearance's view. Laid out in the order the evaluation reads them, they stream from memory,
  // where the samples' positions and normals were gathered from all over theirs.
  // Empty when the reads are too many to keep (SampleRayTableBytes): each read then projects
  // its sample itself (RayOf), with the same arithmetic and so the same bits.
  struct SampleRay {
    Eigen::Vector3d at_zero;
    Eigen::Vector3d direction;
  };
  SampleRay RayOf(int camera, int sample) const;
  std::vector<SampleRay> rays_;
  std::vector<long> read_begin_;
  Eigen::VectorXd shape_;            // Per sample.
  Eigen::VectorXd parameter_shape_;  // Per surface Gaussian.
};

}  // namespace finecap

#endif  // FINECAP_SRC_ENERGY_PIXEL_CONSENSUS_SIMILARITY_H_
