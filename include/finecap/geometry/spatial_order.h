// An order of points in which neighbours in space are mostly neighbours in the order too, so that
// a loop over them in that order reads memory (the images they project into, the data of nearby
// points) that the loop's last steps left in the caches.
#ifndef FINECAP_GEOMETRY_SPATIAL_ORDER_H_
#define FINECAP_GEOMETRY_SPATIAL_ORDER_H_

#include <vector>

#include <Eigen/Core>

namespace finecap {

// The indices of `points` sorted along the Z-order (Morton) curve through their bounding box,
// 21 bits per axis; ties (points closer than the box's size / 2^21) keep their index order.
// Non-finite points go last, in index order.
std::vector<int> SpatialOrder(const Eigen::Matrix3Xd& points);

}  // namespace finecap

#endif  // FINECAP_GEOMETRY_SPATIAL_ORDER_H_
