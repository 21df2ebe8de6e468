#include "model/image_color.h"

#include <vector>

namespace finecap {

Eigen::Vector3d ImageColorAround(const ImageGaussians& image, const ProjectedGaussian& projected,
                                 OverlapForm form, double reach_sigmas) {
  std::vector<int> ids;
  image.FindReaching(projected.mean, projected.sigma, reach_sigmas, &ids);
  internal::ColorAccumulator accumulator(Eigen::Vector3d::Zero());
  for (int i : ids) accumulator.Add(form, projected, image[i], false);
  return accumulator.Mean();
}

}  // namespace finecap
