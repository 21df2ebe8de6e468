// An interactive 3D view for the HTML report: a frame's meshes side by side in panels (the input,
// the refined mesh, the truth where there is one, ...), lit so that folds read, one orbiting
// camera for all, and a slider over a few frames. A panel may colour its mesh per vertex (the
// refined mesh by its error against the truth) and then shows the colour scale beside it. The page
// embeds three.js (and its OrbitControls) as text, so the report still refers to nothing outside
// itself and opens offline.
//
// three.js is found at run time, never fetched: the first folder of ThreeJsSearchPaths() that
// holds both build/three.min.js and examples/js/controls/OrbitControls.js (Debian's
// `libjs-three` installs them under /usr/share/javascript/three). Where none does, the viewer's
// place in the report holds a note saying how to get it.
#ifndef FINECAP_EVAL_MESH_VIEWER_H_
#define FINECAP_EVAL_MESH_VIEWER_H_

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "finecap/geometry/camera.h"
#include "finecap/geometry/mesh.h"

namespace finecap {

// The two scripts the viewer needs, as text.
struct ThreeJsLibrary {
  std::string folder;          // Where they were found.
  std::string three;           // build/three.min.js.
  std::string orbit_controls;  // examples/js/controls/OrbitControls.js (the non-module build).
};

// The folders searched for three.js, in order: $FINECAP_THREE_JS_DIR when set (e.g. the
// node_modules/three folder of `npm install three@0.147`, the last release with examples/js), then
// /usr/share/javascript/three (Debian's libjs-three) and /usr/local/share/javascript/three.
std::vector<std::string> ThreeJsSearchPaths();

// The library from the first folder of ThreeJsSearchPaths() that holds both files; nullopt when
// none does.
std::optional<ThreeJsLibrary> FindThreeJs();

// The colours of a panel's vertices as a scale: OpenCV's turbo map (HeatMapColors, evaluation.h)
// from blue at 0 to dark red at `max_value`, in `unit`, shown under the view with `title`.
struct ViewerColorScale {
  std::string title;
  double max_value = 1.0;
  std::string unit;
};

// One panel of the view, the same in every frame: its label, the plain colour of its mesh, and
// the scale of its vertex colours when its frames give them.
struct ViewerPanel {
  std::string label;
  uint32_t color = 0xa9b4c4;  // 0xRRGGBB.
  std::optional<ViewerColorScale> scale;
};

// What a panel shows in one frame: a mesh and, optionally, an RGB colour in [0, 1] per vertex
// (no columns: the panel's plain colour).
struct ViewerSurface {
  Mesh mesh;
  Eigen::Matrix3Xd vertex_colors;
};

// One frame of the viewer: one surface per panel, all of one topology (the fine mesh's).
struct ViewerFrame {
  std::string name;
  std::vector<ViewerSurface> surfaces;
};

// At most `max_frames` indices into [0, count), evenly spaced and including the first and last;
// all of them when count <= max_frames. Throws Error unless max_frames >= 1.
std::vector<int> EvenlySpacedIndices(int count, int max_frames);

// The viewer as an HTML fragment (a canvas divided into one part per panel, their labels, the
// colour scales, a slider and its script). `panels` and `frames` must be non-empty, every frame
// must have a surface per panel, all of one topology, and vertex colours, where given, one per
// vertex (Error otherwise). The view starts from `camera`'s centre, looking at the first frame's
// first mesh's centre with the camera's up direction, so it first shows what that camera saw; it
// shows the last frame, where the slider ends. The faces are embedded once (little-endian Uint32,
// base64), each mesh's positions as little-endian Uint16 steps over the box of all shown meshes (a
// step of 1/65535 of the box per axis: half the size of Float32, far finer than folds), vertex
// colours as RGB bytes.
std::string MeshViewerHtml(const std::vector<ViewerPanel>& panels,
                           const std::vector<ViewerFrame>& frames, const Camera& camera,
                           const ThreeJsLibrary& library);

// The note that takes the viewer's place when three.js is absent, naming the folders searched.
std::string MissingViewerHtml();

}  // namespace finecap

#endif  // FINECAP_EVAL_MESH_VIEWER_H_
