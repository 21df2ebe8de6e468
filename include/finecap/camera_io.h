// Reading and writing a calibrated camera rig in the formats capture set-ups use.
//
// Every reader returns cameras in finecap's convention (see camera.h): metres, x_cam = R*X + t,
// OpenCV axes, centre of the top-left pixel at (0, 0), OpenCV distortion (k1, k2, p1, p2, k3).
// Every reader validates each camera and throws Error naming the file and the problem.
#ifndef FINECAP_CAMERA_IO_H_
#define FINECAP_CAMERA_IO_H_

#include <string>
#include <vector>

#include "finecap/camera.h"

namespace finecap {

// finecap's own cameras.yaml (the file states the convention in a comment at its top).
std::vector<Camera> ReadCamerasYaml(const std::string& path);
void WriteCamerasYaml(const std::vector<Camera>& cameras, const std::string& path);

// A COLMAP text model: `folder`/cameras.txt and `folder`/images.txt. Supports the PINHOLE,
// SIMPLE_PINHOLE, SIMPLE_RADIAL, RADIAL and OPENCV camera models; COLMAP's pixel centres sit at
// +0.5, which the reader converts. Camera names are the image names without their extension.
std::vector<Camera> ReadColmapTextModel(const std::string& folder);

// The OpenCV FileStorage pair intri.yml / extri.yml of ZJU-MoCap and EasyMocap: K_<cam>,
// dist_<cam>, R_<cam> (a rotation vector, or Rot_<cam> as a matrix), T_<cam>.
std::vector<Camera> ReadIntriExtri(const std::string& intri_path, const std::string& extri_path);

// The rig of a capture folder: cameras.yaml if present, else intri.yml + extri.yml, else a COLMAP
// text model in `capture_dir`/sparse (or `capture_dir` itself). Throws Error if none is found.
std::vector<Camera> ReadRig(const std::string& capture_dir);

}  // namespace finecap

#endif  // FINECAP_CAMERA_IO_H_
