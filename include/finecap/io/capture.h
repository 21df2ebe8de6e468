// A capture folder: the calibrated rig, the synchronized images of each camera, the coarse mesh
// of each frame and, for synthetic captures, the ground truth.
//
//   capture/
//     cameras.yaml (or intri.yml + extri.yml, a Calib.toml, or a COLMAP model; see camera_io.h)
//     images/<camera>/<frame>.png|.jpg|.jpeg   or   videos/<camera>.<ext>
//     meshes/<frame>.<ply|obj|off|...>          coarse mesh per frame, one topology
//     masks/<camera>/<frame>.png|.jpg|.jpeg     optional: foreground masks, non-zero on the
//                                               subject (or mask/<camera>/..., the layout of
//                                               ZJU-MoCap and EasyMocap); every camera has one
//                                               per frame
//     mask.txt                                  optional: vertex ids to refine (vertex_mask.h)
//     gt/<frame>.ply                            optional: the true (fine) surface of that frame
//     gt/<frame>_k.txt                          optional: per coarse vertex, the true displacement
//                                               along its coarse normal, metres, one a line ("nan"
//                                               where unknown)
//     gt/textureless.txt                        optional: coarse vertex ids of the textureless
//     region
//
// Frames are named by the mesh file stems (hidden files, e.g. unfinished writes, are ignored),
// sorted numerically when every stem is a number (`2` before `10`), else as text.
//
// A COLMAP workspace is a capture too. With a COLMAP model, a camera with neither images/<camera>/
// nor videos/<camera>.* takes the image that posed it, images/NAME (COLMAP's flat layout, where
// NAME is `cam03.jpg` and the camera `cam03`): one image per camera, so the capture holds one
// frame. Its mesh is the one given to Open, else meshes/ as above, else, in COLMAP's undistorted
// dense/0/ folder, the one meshed-*.ply there (meshed-poisson.ply, meshed-delaunay.ply). Its masks,
// when it has a masks/ folder, are COLMAP's: masks/NAME.png (masks/cam03.jpg.png), where a camera
// has no masks/<camera>/ folder.
#ifndef FINECAP_CAPTURE_H_
#define FINECAP_CAPTURE_H_

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "finecap/geometry/camera.h"
#include "finecap/geometry/mesh.h"
#include "finecap/io/frame_source.h"

namespace finecap {

class Capture {
 public:
  // Opens and checks `dir` cheaply, so that a broken capture fails before any work: the folder
  // exists; the rig reads and every camera is valid (an intri/extri rig without image sizes gets
  // them from each camera's first image); there is at least one mesh and the first one is a valid
  // mesh; every camera has images/<camera>/ or videos/<camera>.* (or, from a COLMAP model, the
  // image it names); the first image of every camera decodes and has the camera's size; with a
  // masks/ (or mask/) folder, every camera has a folder there and its first mask decodes and has
  // the camera's size; mask.txt and gt/textureless.txt, when present, hold valid ids. Later frames
  // are checked when read. Throws Error naming the file and the problem. `mesh`, when not empty,
  // is the coarse mesh of a one-frame capture, named after its stem, instead of meshes/ or a
  // meshed-*.ply (a relative path is from the working directory).
  static Capture Open(const std::string& dir, const std::string& mesh = "");

  Capture(Capture&&) = default;
  Capture& operator=(Capture&&) = default;

  const std::string& directory() const { return directory_; }

  // The cameras of the images ReadImage returns: the rig's, with distortion zero (images are
  // undistorted on load, same K).
  const std::vector<Camera>& cameras() const { return cameras_; }
  // The cameras as calibrated, lens distortion included.
  const std::vector<Camera>& rig() const { return rig_; }
  // What the rig was read from, e.g. "cameras.yaml" (ReadRig).
  const std::string& rig_source() const { return rig_source_; }
  int num_cameras() const { return static_cast<int>(cameras_.size()); }

  int num_frames() const { return static_cast<int>(frame_names_.size()); }
  const std::string& frame_name(int frame) const;
  const std::vector<std::string>& frame_names() const { return frame_names_; }
  // The coarse mesh file of `frame`, for messages about it.
  const std::string& mesh_path(int frame) const;

  // The coarse mesh of `frame`, validated and with the topology of frame 0. Throws Error naming
  // the file otherwise.
  Mesh ReadCoarseMesh(int frame) const;
  int num_coarse_vertices() const { return first_mesh_.num_vertices(); }

  // The undistorted image of camera `camera_index` at `frame`: CV_8UC3 BGR of the camera's size.
  // Not const: a camera's video decoder moves along. Reading different cameras from different
  // threads is safe; reading one camera from two threads is not.
  cv::Mat ReadImage(int camera_index, int frame);

  // Whether the capture has foreground masks (masks/ or mask/).
  bool has_masks() const { return !mask_sources_.empty(); }
  // The undistorted foreground mask of camera `camera_index` at `frame`: CV_8UC1 of the camera's
  // size, 255 on the subject and 0 on the background (MakeMaskFolderSource); empty when the
  // capture has no masks. Thread safety as ReadImage's.
  cv::Mat ReadMask(int camera_index, int frame);

  // The sorted vertex ids of mask.txt; empty when the capture has no mask (refine every vertex).
  const std::vector<int>& vertex_mask() const { return vertex_mask_; }
  bool has_vertex_mask() const { return has_vertex_mask_; }

  // True when the capture has a gt/ folder. Which files it holds is per frame:
  bool has_ground_truth() const { return has_ground_truth_; }
  bool HasTrueSurface(int frame) const;
  bool HasTrueDisplacement(int frame) const;
  // gt/<frame>.ply: the true surface (any topology). Throws Error naming the file when absent.
  Mesh ReadTrueSurface(int frame) const;
  // gt/<frame>_k.txt: one true displacement (metres) per coarse vertex, NaN where unknown.
  // Throws Error naming the file (and line) when absent, malformed, infinite or of the wrong
  // length.
  Eigen::VectorXd ReadTrueDisplacement(int frame) const;
  // gt/textureless.txt, sorted; empty when absent.
  const std::vector<int>& textureless_vertices() const { return textureless_vertices_; }

 private:
  Capture() = default;

  void ReadCameras(const std::vector<std::string>& colmap_images);
  void FindFrames(const std::string& mesh);
  void FindFramesInMeshFolder();
  void FindColmapMesh();
  std::string FindCameraStream(const Camera& camera, const std::string& colmap_image) const;
  void OpenFrameSources();
  void OpenMaskSources();
  void RequireCamera(int camera_index) const;
  void ReadOptionalFiles();
  void RequireFrame(int frame) const;
  std::string GroundTruthPath(int frame, const std::string& suffix) const;

  std::string directory_;
  std::string rig_source_;
  std::vector<Camera> rig_;      // As calibrated, distortion included.
  std::vector<Camera> cameras_;  // rig_ undistorted.
  std::vector<std::string> frame_names_;
  std::vector<std::string> mesh_paths_;
  Mesh first_mesh_;
  std::vector<std::string> streams_;  // Per camera, its image folder, video or single image.
  // Per camera, the name of its one image in a COLMAP model (relative to images/) when it is
  // read from COLMAP's flat layout; empty otherwise.
  std::vector<std::string> flat_image_names_;
  std::vector<std::unique_ptr<FrameSource>> sources_;
  // Per camera, its image of frame 0, decoded as the capture opened to check it: the first
  // ReadImage of that frame takes it instead of decoding it again, and a read of any other frame
  // drops it.
  std::vector<cv::Mat> first_images_;
  std::vector<std::unique_ptr<FrameSource>> mask_sources_;  // Empty without masks.
  std::vector<int> vertex_mask_;
  bool has_vertex_mask_ = false;
  bool has_ground_truth_ = false;
  std::vector<int> textureless_vertices_;
};

}  // namespace finecap

#endif  // FINECAP_CAPTURE_H_
