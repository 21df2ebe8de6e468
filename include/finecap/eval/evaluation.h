// The figures `finecap eval` computes for one refined frame against the ground truth, and the
// false-colour scale of its error pictures.
//
// Three surfaces are measured, all at the fine vertices and along the unit normals of the
// subdivided input mesh (the refinement's own parameters, displacements k in metres):
//   * the coarse mesh as given: the input as its user gave it, its triangles sampled at the fine
//     vertices (SequenceModel::Interpolate). The baseline: "detail recovered" is relative to it.
//   * the subdivided input mesh (k = 0), where the refinement starts: Loop's smoothing may bring
//     it nearer the truth than the input as given or take it farther away.
//   * the refined mesh.
// Beside each error, its flicker (metrics.h): how much of it changes from one frame to the next.
// Errors are taken over the refined vertices where the estimate and the truth are known. The true
// normal of a vertex is the normal of the subdivided input mesh displaced by the true k (NaN
// counted as 0): the true surface sampled at the vertex's own line, so no ray-cast triangle lookup
// is needed and every normal comes from the same topology.
#ifndef FINECAP_EVAL_EVALUATION_H_
#define FINECAP_EVAL_EVALUATION_H_

#include <string>
#include <vector>

#include <Eigen/Core>

#include "finecap/geometry/mesh.h"
#include "finecap/measure/metrics.h"

namespace finecap {

// What one frame (or a whole sequence, pooled) is evaluated on. All vectors and matrices have one
// entry or column per vertex of the subdivided input mesh.
struct EvaluationSamples {
  Eigen::VectorXd k_refined;  // Refined displacement, metres; NaN where not refined.
  Eigen::VectorXd k_true;     // True displacement, metres; NaN where unknown.
  // Signed distance from the coarse mesh as given to the truth along the same normals, metres
  // (FineGroundTruth::coarse_error); NaN where unknown.
  Eigen::VectorXd coarse_error;
  Eigen::Matrix3Xd normals_coarse;   // Unit normals of the coarse mesh as given (per facet).
  Eigen::Matrix3Xd normals_input;    // Unit normals of the subdivided input mesh.
  Eigen::Matrix3Xd normals_refined;  // Unit normals of the refined mesh.
  Eigen::Matrix3Xd normals_true;     // Unit normals of the input mesh displaced by k_true.
  std::vector<int> all;              // Refined vertex ids: the region every figure is taken over.
  std::vector<int> textured;         // The part of `all` outside the textureless region.
  std::vector<int> textureless;      // The part of `all` inside it.
  // The signed errors of the frame before, one entry per vertex, NaN where unknown; empty when
  // the frame before is not evaluated. The flicker figures compare Errors() with them.
  SignedErrors errors_before;

  // The samples' own signed errors: SignedErrorsOf(k_refined, k_true, coarse_error).
  SignedErrors Errors() const;

  // Appends `other`, offsetting its vertex ids: pooled samples give sequence-wide figures.
  void Append(const EvaluationSamples& other);
};

// The figures of one region: displacement errors in metres (ErrorStats) and mean normal angle
// errors in degrees, of the coarse mesh as given, of the subdivided input (k = 0) and of the
// refinement.
struct RegionFigures {
  ErrorStats coarse;
  ErrorStats subdivided;
  ErrorStats refined;
  double normal_error_coarse_deg = ErrorStats::kNoData;
  double normal_error_subdivided_deg = ErrorStats::kNoData;
  double normal_error_refined_deg = ErrorStats::kNoData;
  // DetailRecovered(refined.rms, coarse.rms), against the input as given: 1 perfect, 0 no gain,
  // < 0 worse.
  double detail_recovered = ErrorStats::kNoData;
  // The flicker of each surface (ComputeFlickers): the change of its signed error since the frame
  // before, over the region's vertices known in both frames; NaN without the frame before.
  FlickerStats flicker;
};

// Figures over all refined vertices and over their textured and textureless parts.
struct EvaluationFigures {
  RegionFigures all, textured, textureless;
};

// Builds the samples of one frame. `coarse` is the coarse mesh as given at the fine vertices
// (SequenceModel::Interpolate), `input` the subdivided input mesh, `refined` the refined mesh (all
// three of one topology), `k_refined`, `k_true` and `coarse_error` as in EvaluationSamples,
// `refined_vertices` the refined vertex ids and `textureless_vertices` the fine ids of the
// textureless region. Throws Error naming `where` when sizes or topologies disagree or an id is
// out of range.
EvaluationSamples MakeEvaluationSamples(const Mesh& coarse, const Mesh& input, const Mesh& refined,
                                        const Eigen::VectorXd& k_refined,
                                        const Eigen::VectorXd& k_true,
                                        const Eigen::VectorXd& coarse_error,
                                        const std::vector<int>& refined_vertices,
                                        const std::vector<int>& textureless_vertices,
                                        const std::string& where);

// The figures of `samples`. The baselines' errors are measured over the same vertices as the
// refinement's: those with a finite refined k.
EvaluationFigures ComputeEvaluationFigures(const EvaluationSamples& samples);

// A false-colour RGB in [0, 1] per entry of `values` (OpenCV's "turbo" map, blue = 0, dark red
// = `max_value` and above); mid grey for a non-finite value. Throws Error unless max_value > 0.
Eigen::Matrix3Xd HeatMapColors(const Eigen::VectorXd& values, double max_value);

}  // namespace finecap

#endif  // FINECAP_EVAL_EVALUATION_H_
