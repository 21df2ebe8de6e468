// The energy of one frame, E(k) = E_data(k) - E_quad(k): the data terms (data_term.h; today one,
// the similarity: the paper's E_sim or a variant) summed, less the terms quadratic in k
// (quadratic_term.h: the paper's w_reg * E_reg, eq. 3, and the pulls that are not in the paper,
// towards the input and towards the frame before), built from the surface Gaussians, the cameras
// with their image Gaussians and visibility, and the mesh's neighbourhoods. Which terms it holds
// follows from the options alone (src/energy/term_registry.cc). It owns the pair lists, so it is
// built once per frame and then evaluated many times by a solver; it is neither copied nor moved
// (the terms refer to its members).
//
// It is the frame's problem as the solvers see it: the unknowns (layout), the summed value and
// gradient (Evaluate), the data terms with their residual blocks and the capabilities each
// offers, and the quadratic part as pulls and differences. The solvers do not know which terms
// made it.
#ifndef FINECAP_FRAME_ENERGY_H_
#define FINECAP_FRAME_ENERGY_H_

#include <functional>
#include <memory>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <opencv2/core.hpp>

#include "finecap/energy/data_term.h"
#include "finecap/energy/energy_options.h"
#include "finecap/energy/parameter_layout.h"
#include "finecap/energy/quadratic_term.h"
#include "finecap/energy/regularizer.h"
#include "finecap/geometry/neighbourhood.h"
#include "finecap/model/gaussian_pairs.h"
#include "finecap/model/surface_gaussians.h"

namespace finecap {

// One camera of a frame: its pinhole camera, the image Gaussians of its image (not owned), and
// which surface Gaussians it sees (one flag per surface Gaussian).
struct CameraInput {
  Camera camera;
  const ImageGaussians* image = nullptr;
  std::vector<unsigned char> visible;
  // With surface samples (SurfaceSamples): the image itself in the similarity's colour space
  // (CV_32FC3), blurred by ConsensusOptions::sample_blur, and which samples the camera sees (one
  // flag per sample).
  cv::Mat pixels;
  std::vector<unsigned char> samples_visible;
  // With a foreground mask: which samples read only the camera's foreground (one flag per
  // sample); empty when the camera has no mask. A sample off it is left out of the patches this
  // camera compares, not the whole patch (PixelConsensusSimilarity).
  std::vector<unsigned char> samples_on_foreground;
  // With surface samples: per surface Gaussian (as `visible`), the cosine of the angle between
  // the camera's view ray and the normal of the surface the detail stage starts from
  // (ConsensusOptions::view_cosine_power); empty: that of the input surface, at the samples.
  std::vector<double> view_cosines;
};

// Points of the surface about a pixel apart at which a similarity reads the images at their own
// resolution (ConsensusOptions::sample_spacing; pixel_consensus_similarity.h). Each sample lies
// on a face of the mesh and is a blend of the surface Gaussians at its corners.
struct SurfaceSamples {
  Eigen::Matrix3Xd base;     // Positions at k = 0, metres.
  Eigen::Matrix3Xd normals;  // Unit directions they move along: the blended vertex normals.
  // Samples x surface Gaussians: the weights of each sample's blend (its position is the blend of
  // the surface Gaussians' positions; it moves by the blend of their shapes).
  Eigen::SparseMatrix<double, Eigen::RowMajor> weights;
  // patches[s]: the samples with a weight on surface Gaussian s, the one at s itself first.
  std::vector<std::vector<int>> patches;
  // Empty, or one colour per sample in the similarity's colour space, NaN where unknown: the
  // surface's appearance at each sample as another frame showed it (SampleAppearance), compared
  // with by the consensus similarity with ConsensusOptions::shared_appearance. The samples of a
  // mesh of fixed topology are the same points of its faces in every frame.
  Eigen::Matrix3Xd appearance;

  int size() const { return static_cast<int>(base.cols()); }
};

// What an energy with surface samples reads that is the same wherever its surface is: the
// samples, and per camera its pixels and which samples lie on its foreground (CameraInput). An
// energy over the same surface Gaussians prepared anew at another surface (the detail stage's
// next pass) takes them from the one before (FrameEnergy::TakeSampledInput) instead of making
// them again.
struct SampledInput {
  SurfaceSamples samples;
  std::vector<cv::Mat> pixels;
  std::vector<std::vector<unsigned char>> samples_on_foreground;
};

// The bytes the consensus similarity keeps to read its samples faster: the homogeneous pixel of
// each sample read by a patch in a camera and its derivative along the sample's normal (48 bytes
// a read), when they come to at most `max_table_bytes`, else none: each read then projects its
// sample anew, about a quarter slower (a detail-stage evaluation of synth_skirt: 27 against 36
// ms), with the same results. The default, 512 MB, keeps the table of captures of a few
// megapixels (Sceaux at 708 x 532: 7 M reads, 340 MB) and drops it where it would outweigh all
// the rest (Sceaux at 2832 x 2128: 135 M reads, 6.5 GB, against 2.7 GB for everything else).
constexpr double kMaxSampleRayTableBytes = 512e6;
double SampleRayTableBytes(double num_reads, double max_table_bytes = kMaxSampleRayTableBytes);

// The options of the pair lists the energy builds with `options` (gaussian_pairs.h).
PairOptions EnergyPairOptions(const EnergyOptions& options);

class FrameEnergy {
 public:
  // `neighbourhoods` are over the mesh vertices (built with options.reg_rings).
  // With `samples` (not empty; the consensus similarity only), the similarity reads the cameras'
  // pixels at the samples instead of their image Gaussians.
  FrameEnergy(SurfaceGaussians surface, const std::vector<CameraInput>& cameras,
              const VertexNeighbourhoods& neighbourhoods, const EnergyOptions& options,
              SurfaceSamples samples = {});
  FrameEnergy(const FrameEnergy&) = delete;
  FrameEnergy& operator=(const FrameEnergy&) = delete;

  // With samples, hands `energy`'s SampledInput over and frees the rest of it; without, frees it
  // and returns an empty one.
  static SampledInput TakeSampledInput(std::unique_ptr<FrameEnergy> energy);

  int num_parameters() const { return surface_.size(); }
  // The unknowns: num_parameters() displacements within [-k_max, k_max].
  ParameterLayout layout() const { return {num_parameters(), options_.k_max}; }
  const SurfaceGaussians& surface() const { return surface_; }
  const EnergyOptions& options() const { return options_; }
  // The unknowns' values taken from one value per mesh vertex: entry s is the value at surface
  // Gaussian s's vertex (SurfaceGaussians::vertex_ids).
  Eigen::VectorXd UnknownsAtVertices(const Eigen::VectorXd& per_vertex) const;
  // The cameras' pair lists, without their image Gaussian ids, and without the image Gaussians
  // themselves (EnergyView::image null), when no data term reads them after it is built
  // (ReadsPairLists): the image models may then go.
  const std::vector<EnergyView>& views() const { return views_; }

  // The data terms, summed in this order: those of every pass of the solver and, after
  // StartLastPass, those of its last pass.
  int num_data_terms() const { return static_cast<int>(data_terms_.size()); }
  DataTerm& data_term(int i) { return *data_terms_[i]; }
  const DataTerm& data_term(int i) const { return *data_terms_[i]; }
  // Adds `term` to the sum. The pulls stated in the data's units (TermContext::
  // typical_data_curvature) keep the measure taken of the terms the energy was built with, and
  // the pair lists stay as they are.
  void AddDataTerm(std::unique_ptr<DataTerm> term);
  // Adds to the sum the terms that only the solver's last pass needs (today the refined mesh's
  // own term of the detail stage, ConsensusOptions::surface_weight), made now; nothing after
  // the first call. The structure of the residual blocks changes, so a solver builds its problem
  // anew. As with AddDataTerm, the pulls keep the units measured of the terms the energy started
  // with.
  void StartLastPass();
  // Whether every data term is least-squares (DataTerm::IsLeastSquares): then E is minus the
  // least-squares cost, E_data's half sum of squares plus E_quad.
  bool IsLeastSquares() const;
  // Whether some data term reads the pair lists after it is built (DataTerm::ReadsPairLists).
  bool ReadsPairLists() const;
  // Whether some data term changes between passes of the solver (PassHook), and, handing it the
  // surface `k` a pass ended at, changes it.
  bool HasPassHooks() const;
  void EndOfPass(const Eigen::VectorXd& k);

  const Regularizer& regularizer() const { return regularizer_; }
  // The quadratic part, as its terms made it: the pulls on each k_s, gathered into one p_s and
  // t_s per surface Gaussian, and the differences of neighbours.
  const Eigen::VectorXd& pull_curvature() const { return pulls_.curvature(); }
  const Eigen::VectorXd& pull_target() const { return pulls_.target(); }
  const std::vector<Difference>& differences() const { return differences_; }
  // The differences' part of E_quad at k, 1/2 sum root^2 (k_a - k_b)^2, and, unless `gradient` is
  // null, its gradient; and the pulls' part.
  double DifferenceEnergy(const Eigen::VectorXd& k, Eigen::VectorXd* gradient) const;
  double PullEnergy(const Eigen::VectorXd& k) const { return pulls_.Evaluate(k); }
  // c_s, how sure the images are of each k_s (Confidence, input_prior.h); the confidence pull
  // (energy.confidence_prior) holds k_s at the input where it is low.
  const Eigen::VectorXd& confidence() const { return confidence_; }
  // Hands the displacement the frame before was solved with (one per surface Gaussian, NaN where
  // it has none) to the terms that read it, once it is known.
  void TakeFrameBefore(const Eigen::VectorXd& k_before);
  // With samples: the colour each sample shows at the surface displaced by `k` (one per surface
  // Gaussian), averaged over the cameras that see it (NaN where none does); empty without
  // samples. What the next frame compares its patches with (SurfaceSamples::appearance).
  Eigen::Matrix3Xd SampleAppearance(const Eigen::VectorXd& k) const;
  // Evaluated pairs of Gaussians, summed over cameras.
  long num_pairs() const;

  // E at k and, when `gradient` is not null, dE/dk. E_data and E_quad go to the optional outputs.
  double Evaluate(const Eigen::VectorXd& k, Eigen::VectorXd* gradient, double* data = nullptr,
                  double* quadratic = nullptr) const;

 private:
  // H of TermContext::typical_data_curvature, measured at first use; below 0 until then.
  double TypicalDataCurvature();
  // The pulls of every quadratic term, gathered anew.
  void GatherPulls();

  SurfaceGaussians surface_;
  EnergyOptions options_;
  // With samples, what the similarity reads: the samples and the cameras' pixels.
  SurfaceSamples samples_;
  std::vector<CameraInput> sample_cameras_;
  std::vector<EnergyView> views_;
  Regularizer regularizer_;  // Before the data terms: a term may read it.
  std::vector<std::unique_ptr<DataTerm>> data_terms_;
  // Made and summed from StartLastPass on; a term made here may read one made before it.
  std::vector<std::function<std::unique_ptr<DataTerm>()>> last_pass_terms_;
  Eigen::VectorXd confidence_;
  std::vector<std::unique_ptr<QuadraticTerm>> quadratic_terms_;
  Pulls pulls_;
  std::vector<Difference> differences_;
  double typical_data_curvature_ = -1.0;  // Below 0 until measured.
  long num_pairs_ = 0;
};

}  // namespace finecap

#endif  // FINECAP_FRAME_ENERGY_H_
