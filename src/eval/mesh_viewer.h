// An interactive 3D view of the input and the refined meshes for the HTML report: the two meshes
// of a frame side by side, lit so that folds read, one orbiting camera for both, and a slider
// over a few frames. The page embeds three.js (and its OrbitControls) as text, so the report
// still refers to nothing outside itself and opens offline.
//
// three.js is found at run time, never fetched: the first folder of ThreeJsSearchPaths() that
// holds both build/three.min.js and examples/js/controls/OrbitControls.js (Debian's
// `libjs-three` installs them under /usr/share/javascript/three). Where none does, the viewer's
// place in the report holds a note saying how to get it.
#ifndef FINECAP_EVAL_MESH_VIEWER_H_
#define FINECAP_EVAL_MESH_VIEWER_H_

#include <optional>
#include <string>
#include <vector>

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

// One frame of the viewer: the subdivided input mesh and the refined mesh (same faces).
struct ViewerFrame {
  std::string name;
  Mesh input;
  Mesh refined;
};

// At most `max_frames` indices into [0, count), evenly spaced and including the first and last;
// all of them when count <= max_frames. Throws Error unless max_frames >= 1.
std::vector<int> EvenlySpacedIndices(int count, int max_frames);

// The viewer as an HTML fragment (a canvas, a slider and its script). `frames` must be non-empty
// and share one topology (Error otherwise). The view starts from `camera`'s centre, looking at the
// first input mesh's centre with the camera's up direction, so it first shows what that camera
// saw; it shows the last frame, where the slider ends. The faces are embedded once (little-endian
// Uint32, base64), each mesh's positions as little-endian Uint16 steps over the box of all shown
// meshes (a step of 1/65535 of the box per axis: half the size of Float32, far finer than folds).
std::string MeshViewerHtml(const std::vector<ViewerFrame>& frames, const Camera& camera,
                           const ThreeJsLibrary& library);

// The note that takes the viewer's place when three.js is absent, naming the folders searched.
std::string MissingViewerHtml();

}  // namespace finecap

#endif  // FINECAP_EVAL_MESH_VIEWER_H_
