// The colour the image model shows around a projected surface Gaussian: the image Gaussians'
// colours weighted by their overlap with it (gaussian_overlap.h). The model uses it to colour the
// surface Gaussians from the images; the surface colour similarity (energy) compares it with their
// colours and needs its k-derivative too.
#ifndef FINECAP_SRC_MODEL_IMAGE_COLOR_H_
#define FINECAP_SRC_MODEL_IMAGE_COLOR_H_

#include <Eigen/Core>

#include "finecap/model/gaussian_overlap.h"
#include "finecap/model/image_gaussians.h"

namespace finecap {

// p_sc for one projected surface Gaussian: the overlap-weighted mean colour of the image
// Gaussians within `reach_sigmas` combined standard deviations (zero when there is none).
Eigen::Vector3d ImageColorAround(const ImageGaussians& image, const ProjectedGaussian& projected,
                                 OverlapForm form, double reach_sigmas);

namespace internal {

// Keeps the weighted mean defined where no image Gaussian is in reach (it then tends to the
// `fallback` colour). Overlaps are of the order of sigma^2 ~ 1-100.
constexpr double kEmptyWeight = 1e-9;

// The overlap-weighted mean of image Gaussians' colours, and its k-derivative.
class ColorAccumulator {
 public:
  explicit ColorAccumulator(const Eigen::Vector3d& fallback) : weighted_(kEmptyWeight * fallback) {}

  void Add(OverlapForm form, const ProjectedGaussian& projected, const ImageGaussian& g,
           bool with_derivative) {
    double doverlap = 0.0;
    const double overlap = GaussianOverlap(form, projected, Eigen::Vector2d(g.x, g.y), g.sigma,
                                           with_derivative ? &doverlap : nullptr);
    AddOverlap(overlap, doverlap, g.Color().cast<double>());
  }
  // The same with the overlap and its k-derivative computed by the caller (the consensus tables
  // take what depends only on the surface Gaussian out of their loop over image Gaussians).
  void AddOverlap(double overlap, double doverlap, const Eigen::Vector3d& color) {
    weight_ += overlap;
    weighted_ += overlap * color;
    dweight_ += doverlap;
    dweighted_ += doverlap * color;
  }
  // The same for sums over several image Gaussians: of the overlaps, their k-derivatives, and
  // both times the colours.
  void AddSums(double overlaps, double doverlaps, const Eigen::Vector3d& weighted_colors,
               const Eigen::Vector3d& dweighted_colors) {
    weight_ += overlaps;
    weighted_ += weighted_colors;
    dweight_ += doverlaps;
    dweighted_ += dweighted_colors;
  }
  Eigen::Vector3d Mean() const { return weighted_ / weight_; }
  Eigen::Vector3d MeanDerivative() const { return (dweighted_ - Mean() * dweight_) / weight_; }

 private:
  double weight_ = kEmptyWeight;
  double dweight_ = 0.0;
  Eigen::Vector3d weighted_;
  Eigen::Vector3d dweighted_ = Eigen::Vector3d::Zero();
};

}  // namespace internal
}  // namespace finecap

#endif  // FINECAP_SRC_MODEL_IMAGE_COLOR_H_
