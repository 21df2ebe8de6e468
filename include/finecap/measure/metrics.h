// Error statistics of a refined displacement against ground truth, and of normals against true
// normals: the numbers `finecap eval` reports per frame and per region (all vertices, textured,
// textureless).
#ifndef FINECAP_MEASURE_METRICS_H_
#define FINECAP_MEASURE_METRICS_H_

#include <limits>
#include <vector>

#include <Eigen/Core>

namespace finecap {

// Statistics of the absolute errors |estimate - truth| over the entries where both are finite.
// All values are in the unit of the inputs (metres for a displacement k). When no entry counts
// (an empty region, or only NaN), `count` is 0 and every statistic is NaN: "no data", which a
// table shows as such rather than as a perfect 0.
struct ErrorStats {
  static constexpr double kNoData = std::numeric_limits<double>::quiet_NaN();

  int count = 0;              // Entries used: both values finite.
  double rms = kNoData;       // sqrt(mean(e^2)).
  double mean_abs = kNoData;  // mean(|e|).
  double p95_abs = kNoData;   // 95th percentile of |e| (see Percentile).
  double max_abs = kNoData;   // max(|e|).

  bool empty() const { return count == 0; }
};

// The `percent`-th percentile (0..100) of the finite entries of `values`, interpolated linearly
// between order statistics (rank percent/100 * (n - 1), numpy's default). Non-finite entries are
// ignored; NaN when no finite entry is left. Throws Error unless 0 <= percent <= 100.
double Percentile(std::vector<double> values, double percent);

// ErrorStats over every entry. Throws Error when the two vectors differ in size.
ErrorStats ComputeErrorStats(const Eigen::VectorXd& estimate, const Eigen::VectorXd& truth);

// ErrorStats over the entries listed in `indices` (a region, e.g. the textured vertices); a
// repeated index counts twice. Throws Error when the vectors differ in size or an index is
// outside [0, size).
ErrorStats ComputeErrorStats(const Eigen::VectorXd& estimate, const Eigen::VectorXd& truth,
                             const std::vector<int>& indices);

// A frame's signed errors along the normals of its subdivided input mesh, one entry per fine
// vertex, in the unit of the displacements (metres), NaN where unknown: of the coarse mesh as
// given, of its subdivision (k = 0) and of the refined mesh (k - k_true).
struct SignedErrors {
  Eigen::VectorXd coarse;
  Eigen::VectorXd subdivided;
  Eigen::VectorXd refined;

  bool empty() const { return refined.size() == 0; }
};

// The signed errors of a frame whose refined displacement is `k`, whose true displacement is
// `k_true` and whose coarse mesh as given lies `coarse_error` from the truth along the same
// normals (FineGroundTruth). All three are NaN where `k` is: the baselines are measured over the
// vertices the refinement gave a value, as every error figure is. Throws Error when the sizes
// differ.
SignedErrors SignedErrorsOf(const Eigen::VectorXd& k, const Eigen::VectorXd& k_true,
                            const Eigen::VectorXd& coarse_error);

// The flicker of a surface from one frame to the next: ErrorStats of the change of its signed
// error per vertex, `now - before` (two frames of one topology), over the entries of `indices`
// where both are finite; its rms is the flicker figure. A steady error, however large, has none:
// it is the part of the error that moves from frame to frame, which shows as shimmer when the
// sequence is played. Throws Error as ComputeErrorStats does.
ErrorStats ComputeFlicker(const Eigen::VectorXd& before, const Eigen::VectorXd& now,
                          const std::vector<int>& indices);

// The flicker of each of the three surfaces between two frames' SignedErrors. An empty `before`
// (the frame before has no errors: not refined, or no truth) gives empty stats (NaN).
struct FlickerStats {
  ErrorStats coarse;
  ErrorStats subdivided;
  ErrorStats refined;
};
FlickerStats ComputeFlickers(const SignedErrors& before, const SignedErrors& now,
                             const std::vector<int>& indices);

// The share of the coarse input's error that refinement removed: 1 - rms_refined / rms_coarse.
// 1 is a perfect recovery, 0 no gain, negative a refinement that made things worse. NaN when
// rms_coarse is not a positive finite number (there was no detail to recover).
double DetailRecovered(double rms_refined, double rms_coarse);

// Mean angle between corresponding columns of `estimate` and `truth`, in degrees (0..180).
// Columns need not be exactly unit length; a pair where either vector is zero or non-finite is
// skipped. NaN when no pair is left. Throws Error when the matrices differ in size.
double MeanAngularErrorDegrees(const Eigen::Matrix3Xd& estimate, const Eigen::Matrix3Xd& truth);

}  // namespace finecap

#endif  // FINECAP_MEASURE_METRICS_H_
