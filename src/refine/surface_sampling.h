// The samples at which the consensus similarity reads the images at their own resolution
// (ConsensusOptions::sample_spacing, SurfaceSamples in frame_energy.h): the refined mesh's
// faces split linearly until their edges are about `sample_spacing` pixel footprints long.
#ifndef FINECAP_SRC_REFINE_SURFACE_SAMPLING_H_
#define FINECAP_SRC_REFINE_SURFACE_SAMPLING_H_

#include <vector>

#include <Eigen/Core>

#include "finecap/energy/frame_energy.h"
#include "finecap/geometry/mesh.h"
#include "finecap/geometry/neighbourhood.h"
#include "finecap/model/surface_gaussians.h"
#include "finecap/refine/refine.h"

namespace finecap {

// Levels of linear subdivision that bring the mean edge of `mesh` to at most `spacing` pixel
// footprints (the median over the cameras, as MeasureSceneScale measures it), at most 4.
int SampleLevels(const Mesh& mesh, const std::vector<Camera>& cameras, double spacing);

// The samples of `mesh` (with unit vertex normals `normals`) after `levels` of linear
// subdivision, blended from the surface Gaussians of `surface` (its vertex_ids are vertices of
// `mesh`; a sample of a face none of whose corners is a surface Gaussian keeps no weight). The
// patch of a surface Gaussian holds the samples of the faces around it and, for `patch_rings`
// above 1, around its neighbours up to patch_rings - 1 edges away (`neighbourhoods`, over the
// vertices of `mesh`, must reach that far).
SurfaceSamples SampleSurface(const Mesh& mesh, const Eigen::Matrix3Xd& normals,
                             const SurfaceGaussians& surface,
                             const VertexNeighbourhoods& neighbourhoods, int patch_rings,
                             int levels);

// Which samples a camera sees, from which surface Gaussians it sees (one flag each): a sample is
// seen when every surface Gaussian it is blended from is. (A face whose corners a camera sees is
// seen whole but where a smaller occluder covers its inside, which the visibility of vertices
// misses as well.)
std::vector<unsigned char> SampleVisibility(const SurfaceSamples& samples,
                                            const std::vector<unsigned char>& surface_visible);

// Each camera's image in `space`, blurred by a Gaussian of `blur` pixels (none when 0), as the
// samples read it (CameraInput::pixels); with masks, its background black before the blur
// (ForegroundImages).
std::vector<cv::Mat> SampledImages(const FrameInput& input, ColorSpace space, double blur);

}  // namespace finecap

#endif  // FINECAP_SRC_REFINE_SURFACE_SAMPLING_H_
