// A similarity that needs no reference colours: the cameras that see a small patch of the surface
// must agree on what it looks like, up to each camera's gain and offset.
//
// In camera c, a surface Gaussian j displaced by k along its normal shows
// p_jc(k) = sum_i E_ij eta_i / sum_i E_ij, the image model blurred by the projected Gaussian and
// read at its centre (surface_color_similarity.h). The patch of surface Gaussian s is s with its
// one-ring neighbours P(s) on the mesh, all displaced by the same k_s along their own normals: a
// piece of the input surface moved as a whole, as a window is moved in plane-sweep stereo. In each
// camera that sees the whole patch, its colours are normalised per channel, as in a normalised
// cross-correlation,
//
//   z_jc = (p_jc(k_s) - mean_{P(s)} p_c) / sqrt(var_{P(s)} p_c + epsilon^2),
//
// so that a camera's exposure, gain, offset and white balance do not count as disagreement, and
// the residuals ask every camera's normalised patch to equal the cameras' mean,
//
//   r_sjc = w_s (z_jc - mean_c z_jc) / sqrt(n_c),     E_sim = -1/2 sum |r|^2.
//
// This is surface_color with the colour of every Gaussian an unknown eliminated in closed form,
// on patches instead of single colours. w_s is the patch's contrast at the input surface (the
// root mean variance over its cameras, per channel, fixed for the frame): plain cloth, whose
// normalised colours are noise, carries no weight.
//
// Why the patch moves as a whole: with every member at its own k, each member could find a chance
// match of its single blurred colour along its epipolar line (single-pixel stereo), and the
// solver found configurations that agree better than the true surface (measured on synth_skirt:
// refined RMS above the input's). A patch that moves with one k must match as a window. Each block
// then depends on k_s alone, so the least-squares normal equations are diagonal but for the
// regulariser, as for surface_color.
//
// Speed: a member's colour is needed at the k of every patch it belongs to (about seven), so each
// p_jc(k) is tabulated once per frame, with its derivative, at displacements sigma_hat / 2 apart
// over [-k_max, k_max], and read between them by cubic Hermite interpolation (exact at the nodes,
// C1 between them). The energy the solvers see is the interpolated one, and its Jacobians are
// those of the interpolant, exactly. A member's k, and so its node interval and Hermite weights,
// is the same in every camera of the patch: they are computed once per member, and each camera
// only reads its two nodes. What the solvers and the sweep need of a block is its sum of squares,
// gradient and curvature: the robust loss is applied to those sums, and the robust residuals
// themselves are written only for PrepareResiduals. At a node, only the image Gaussians within
// `reach_sigmas` combined standard deviations of the projected Gaussian there count (as
// ImageColorAround counts them): the row's pair list covers its whole path over [-k_max, k_max].
//
// Occlusion and silhouettes: a camera counts for a patch only when it sees every Gaussian of the
// patch (visibility of the input surface), and a patch needs at least `min_cameras` such cameras;
// a Gaussian seen by fewer has no data term and follows the regulariser. A camera's squared
// residuals count cos^p of its view angle at the input surface, relative to the patch's other
// cameras (ConsensusOptions::view_cosine_power): a steep view sees the patch foreshortened.
#ifndef FINECAP_CONSENSUS_SIMILARITY_H_
#define FINECAP_CONSENSUS_SIMILARITY_H_

#include <vector>

#include "energy/terms/consensus/patch_agreement.h"
#include "finecap/energy/data_term.h"
#include "finecap/energy/energy_options.h"
#include "finecap/model/gaussian_overlap.h"
#include "finecap/model/surface_gaussians.h"

namespace finecap {

class ConsensusSimilarity : public PatchAgreementTerm {
 public:
  // Nodes of each colour table for Gaussians of `sigma_hat` over [-k_max, k_max].
  static int NumTableNodes(double sigma_hat, double k_max);

  // `one_rings[s]` lists the surface Gaussians adjacent to s on the mesh (not s itself). `views`
  // must have been built without colour weights; `surface` and `views` must outlive this object.
  ConsensusSimilarity(const SurfaceGaussians& surface, const std::vector<EnergyView>& views,
                      const std::vector<std::vector<int>>& one_rings, OverlapForm form,
                      double k_max, double reach_sigmas, const ConsensusOptions& options);

  // (PatchAgreementTerm: the residuals, summaries and costs. Its block summaries come straight
  // from the residuals, without storing them: a frame's ~0.8 M residuals and as many derivatives,
  // written and read back at every evaluation otherwise. The tables hold all it reads of the
  // pairs.)
  // Each block's sum of squares without storing its residuals. Where every k_s is the same and
  // the patches are flat, as UniformBlockCosts.
  void BlockCosts(const Eigen::VectorXd& k, std::vector<double>* costs) override;
  // With flat patches (no shape set), each pair-list row's colour is interpolated once per
  // displacement instead of once for every patch it belongs to, and each block's residuals are
  // reduced to their sum of squares without being written, for several displacements at a time:
  // the same operations as the residuals' in the same order, so the same costs to the bit.
  void UniformBlockCosts(int num_parameters, const Eigen::VectorXd& displacements,
                         Eigen::MatrixXd* costs) override;

  // The shape of the patches: member j of patch s is read at k_s + shape[j] - shape[s] instead of
  // k_s, so that a patch moves as a piece of the surface `shape` instead of the input surface.
  // One entry per surface Gaussian; zero (the input surface) until set.
  void SetPatchShape(const Eigen::VectorXd& shape) override;

  // Camera c's tabulated colour of pair-list row `row` at k, and dcolour/dk (when not null). At
  // the tables' nodes it is ImageColorOfPairs (surface_color_similarity.h) over the row's image
  // Gaussians within reach there, in single precision; between them a cubic Hermite
  // interpolation.
  Eigen::Vector3d Interpolate(int c, int row, double k, Eigen::Vector3d* derivative) const;

  // The image Gaussians of one pair-list row as the tables' loop reads them: one array per
  // quantity, in single precision, so that the loop runs over several of them at a time.
  struct RowImageGaussians {
    std::vector<float> x, y;
    std::vector<float> variance;         // sigma_i^2.
    std::vector<float> scaled_variance;  // Its share of S: ImageVarianceFactor(form) sigma_i^2.
    std::vector<float> color[3];         // Per channel.

    void Assign(const EnergyView& view, int row, OverlapForm form);
  };

 private:
  // A node's colour and its slope (dcolour/dk times node_step_, the Hermite tangent) side by
  // side: an interpolation reads two neighbouring nodes, 48 contiguous bytes. In single
  // precision: the tables are the similarity's largest part, and colours carry 8 bits.
  struct TableNode {
    Eigen::Vector3f color;
    Eigen::Vector3f slope;
  };
  // The cubic Hermite interpolation at one k, apart from the table it reads: the first node of
  // the interval holding k, and the weights of that node's colour and slope and of the next
  // node's in the colour (`value`) and in dcolour/dk (`derivative`, zero beyond the table, where
  // the colour stays at its end value). Every row of every camera at the same k shares them.
  struct HermiteWeights {
    int node = 0;
    double value[4];
    double derivative[4];
  };
  HermiteWeights HermiteAt(double k) const;
  // weights[0] p0 + weights[1] m0 + weights[2] p1 + weights[3] m1, per channel, of the colours p
  // and slopes m of `nodes[0]` and `nodes[1]`.
  static void Blend(const double weights[4], const TableNode* nodes, double* color) {
    for (int channel = 0; channel < 3; ++channel) {
      color[channel] = weights[0] * nodes[0].color[channel] + weights[1] * nodes[0].slope[channel] +
                       weights[2] * nodes[1].color[channel] + weights[3] * nodes[1].slope[channel];
    }
  }
  // p_jc and dp_jc/dk at the table's nodes, for every row of every camera's pair list.
  void BuildTables(double k_max);
  // The nodes of one row of `view`'s pair list: ImageColorOfPairs over the image Gaussians in
  // reach at each node, with the row's image Gaussians gathered once (into `paired`) instead of
  // once per node.
  void TabulateRow(const EnergyView& view, int row, RowImageGaussians* paired,
                   TableNode* nodes) const;
  // The colours of block b's patch in each of its cameras with every member displaced by k along
  // its own normal (and the patch's shape), interpolated in the tables.
  void PatchColors(int b, double k, double* colors, double* derivatives) const override;
  // Every block's cost, as SummaryAt's squared_norm, with all k_s at each of
  // displacements[0 .. kLanes) and flat patches: costs[b + lane * column_stride]. Every table
  // row's colour at each displacement goes to `lane_colors` (row, channel, lane).
  template <int kLanes>
  void UniformCosts(const double* displacements, double* costs, long column_stride,
                    std::vector<double>* lane_colors) const;
  // Block b's costs at the kLanes displacements of `lane_colors` (every table row's colour at
  // each: row, channel, lane), lane by lane with SummaryAt's operations in its order. `scratch`
  // holds 3 kLanes doubles per row of the block.
  template <int kLanes>
  void UniformCostsOfBlock(int b, const double* lane_colors, double* scratch,
                           double costs[kLanes]) const;

  const SurfaceGaussians& surface_;
  const std::vector<EnergyView>& views_;
  OverlapForm form_;
  double reach_sigmas_;
  // A block's patch members are surface Gaussians, the centre first; its parameter, the centre's
  // k. For each of its cameras in turn, rows_ (from row_begin_[b]) holds every member's table
  // row: its row in that camera's pair list plus the camera's first_row_.
  std::vector<long> row_begin_;
  std::vector<int> rows_;

  // Node g of the tables is at k = node_k0_ + g * node_step_. All cameras' rows in one table:
  // camera c's pair-list row `row` is table row first_row_[c] + row, its node g at
  // table_[(first_row_[c] + row) * num_nodes_ + g].
  double node_k0_ = 0.0, node_step_ = 1.0;
  int num_nodes_ = 0;
  std::vector<int> first_row_;
  std::vector<TableNode> table_;
  Eigen::VectorXd shape_;
  int max_block_rows_ = 0;  // The most table rows a block reads.
};

}  // namespace finecap

#endif  // FINECAP_CONSENSUS_SIMILARITY_H_
