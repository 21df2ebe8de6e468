// The samples at which the consensus similarity reads the images at their own resolution
// (ConsensusOptions::sample_spacing, SurfaceSamples in frame_energy.h): the refined mesh's
// faces split into equal triangles whose sides are about `sample_spacing` pixel footprints long.
#ifndef FINECAP_SRC_REFINE_SURFACE_SAMPLING_H_
#define FINECAP_SRC_REFINE_SURFACE_SAMPLING_H_

#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "finecap/energy/frame_energy.h"
#include "finecap/geometry/mesh.h"
#include "finecap/geometry/neighbourhood.h"
#include "finecap/model/surface_gaussians.h"
#include "finecap/refine/refine.h"

namespace finecap {

// Segments a side that split the mean edge of `mesh` into pieces of at most `spacing` pixel
// footprints (the median over the cameras, as MeasureSceneScale measures it), from 1 to 16. Any
// count, not a power of two: the spacing a user asks for is what the samples get, within a
// segment, and their number (the cost of the detail stage) grows with the square of the count.
int SampleSegments(const Mesh& mesh, const std::vector<Camera>& cameras, double spacing);

// The points of `mesh`'s faces each split into segments^2 equal triangles, as a points x vertices
// matrix of the barycentric weights of each point on its face's corners: the vertices first, each
// with its own id; then the segments - 1 points inside each edge (MeshEdges' order), shared by the
// edge's faces; then the points inside each face. With 2^L segments the points are those of L
// levels of linear subdivision.
Eigen::SparseMatrix<double> SplitFaces(const Mesh& mesh, int segments);

SurfaceSamples SampleSurface(const Mesh& mesh, const Eigen::Matrix3Xd& normals,
                             const SurfaceGaussians& surface,
                             const VertexNeighbourhoods& neighbourhoods, int patch_rings,
                             int segments);

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
