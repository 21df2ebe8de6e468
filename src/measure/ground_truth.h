// Ground truth of a synthetic capture, measured the way the refinement moves vertices: the
// signed distance from each vertex, along its normal, to the true surface.
#ifndef FINECAP_MEASURE_GROUND_TRUTH_H_
#define FINECAP_MEASURE_GROUND_TRUTH_H_

#include <Eigen/Core>

#include "finecap/geometry/mesh.h"

namespace finecap {

// For every vertex v: the t with |t| <= max_distance nearest 0 such that
// vertices.col(v) + t * normals.col(v) lies on `truth`; NaN where the line misses it.
Eigen::VectorXd TrueDisplacementAlongNormals(const Eigen::Matrix3Xd& vertices,
                                             const Eigen::Matrix3Xd& normals, const Mesh& truth,
                                             double max_distance);

}  // namespace finecap

#endif  // FINECAP_MEASURE_GROUND_TRUTH_H_
