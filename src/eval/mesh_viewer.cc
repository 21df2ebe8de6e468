#include "eval/mesh_viewer.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <limits>
#include <sstream>

#include "finecap/eval/html_report.h"
#include "finecap/util/error.h"
#include "util/io_util.h"

namespace finecap {
namespace {

namespace fs = std::filesystem;

constexpr char kThreeFile[] = "build/three.min.js";
constexpr char kOrbitControlsFile[] = "examples/js/controls/OrbitControls.js";

// Positions are quantised to 16 bits over the box of all shown meshes: a step of 1.5e-5 of the
// box (0.01 mm on a 0.7 m skirt), far below the detail, at half the size of Float32.
constexpr int kQuantisationLevels = 65535;

// The vertical field of view the viewer starts with, degrees; the mesh fills most of it.
constexpr double kFieldOfViewDeg = 30.0;

// The viewer's page part: the canvas (one part per panel, one camera), the panels' labels (added
// by MarkupOf), the colour scales and the frame slider.
constexpr char kViewerMarkupStart[] = R"html(<div class="finecap-viewer" id="finecap-viewer">
<div style="position: relative;">
<canvas style="width: 100%; height: 520px; display: block; border: 1px solid #ccd;
  background: #f4f4f8;"></canvas>
)html";
constexpr char kViewerMarkupEnd[] =
    R"html(<p class="viewer-controls">Frame <input type="range" min="0" value="0" step="1" style="width: 40%;">
<span class="viewer-frame"></span>. Drag to orbit, right-drag to pan, wheel to zoom; the panels
share one camera.</p>
<p class="viewer-note" style="color: #a33;"></p>
</div>
)html";

// Decodes the data, builds one scene with every panel's mesh and draws each into its part of the
// canvas. The directional light hangs off the camera (above and to the left of the view
// direction), so folds stay shaded from any orbit; the hemisphere light keeps the far side
// readable. A panel with vertex colours multiplies them into its shading.
constexpr char kViewerScript[] = R"js(
(function () {
  const data = FINECAP_VIEWER_DATA;
  const root = document.getElementById("finecap-viewer");
  const canvas = root.querySelector("canvas");
  const slider = root.querySelector("input");
  const frameLabel = root.querySelector(".viewer-frame");
  function bytes(base64) {
    const text = atob(base64);
    const array = new Uint8Array(text.length);
    for (let i = 0; i < text.length; ++i) array[i] = text.charCodeAt(i);
    return array.buffer;
  }
  let renderer;
  try {
    renderer = new THREE.WebGLRenderer({canvas: canvas, antialias: true,
                                        preserveDrawingBuffer: true});
  } catch (error) {
    root.querySelector(".viewer-note").textContent =
        "This browser cannot draw the 3D view (WebGL): " + error.message;
    return;
  }
  const faces = new THREE.BufferAttribute(new Uint32Array(bytes(data.faces)), 1);
  function positions(base64) {
    const quantised = new Uint16Array(bytes(base64));
    const result = new Float32Array(quantised.length);
    for (let i = 0; i < quantised.length; ++i) {
      result[i] = data.origin[i % 3] + data.step[i % 3] * quantised[i];
    }
    return result;
  }
  function colours(base64) {
    if (!base64) return null;
    const rgb = new Uint8Array(bytes(base64));
    const result = new Float32Array(rgb.length);
    for (let i = 0; i < rgb.length; ++i) result[i] = rgb[i] / 255;
    return result;
  }
  const frames = data.frames.map(frame => ({name: frame.name,
      surfaces: frame.surfaces.map(surface => ({positions: positions(surface.positions),
                                                colours: colours(surface.colors)}))}));
  const count = frames[0].surfaces[0].positions.length;
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0xf4f4f8);
  scene.add(new THREE.HemisphereLight(0xffffff, 0x606070, 0.5));
  const camera = new THREE.PerspectiveCamera(data.fov, 1, data.near, data.far);
  camera.up.fromArray(data.up);
  camera.position.fromArray(data.eye);
  const light = new THREE.DirectionalLight(0xffffff, 0.9);
  light.position.set(-0.6, 0.8, 0.3);
  light.target.position.set(0, 0, -1);
  camera.add(light);
  camera.add(light.target);
  scene.add(camera);
  function makeMesh(panel) {
    const geometry = new THREE.BufferGeometry();
    geometry.setIndex(faces);
    geometry.setAttribute("position", new THREE.BufferAttribute(new Float32Array(count), 3));
    geometry.setAttribute("color", new THREE.BufferAttribute(new Float32Array(count), 3));
    const material = new THREE.MeshStandardMaterial({color: panel.color, roughness: 0.9,
                                                     metalness: 0.0, side: THREE.DoubleSide});
    const mesh = new THREE.Mesh(geometry, material);
    scene.add(mesh);
    return mesh;
  }
  const meshes = data.panels.map(makeMesh);
  function render() {
    const width = canvas.clientWidth, height = canvas.clientHeight;
    renderer.setPixelRatio(window.devicePixelRatio || 1);
    renderer.setSize(width, height, false);
    camera.aspect = width / meshes.length / height;
    camera.updateProjectionMatrix();
    renderer.setScissorTest(true);
    meshes.forEach((shown, index) => {
      meshes.forEach(mesh => { mesh.visible = mesh === shown; });
      // Whole device pixels, each part starting where the one before ends: no column left
      // undrawn at any pixel ratio.
      const ratio = renderer.getPixelRatio();
      const left = Math.round(index * width * ratio / meshes.length) / ratio;
      const right = Math.round((index + 1) * width * ratio / meshes.length) / ratio;
      renderer.setViewport(left, 0, right - left, height);
      renderer.setScissor(left, 0, right - left, height);
      renderer.render(scene, camera);
    });
  }
  function showFrame(index) {
    const frame = frames[index];
    frame.surfaces.forEach((surface, i) => {
      const mesh = meshes[i], geometry = mesh.geometry;
      geometry.attributes.position.array.set(surface.positions);
      geometry.attributes.position.needsUpdate = true;
      const coloured = surface.colours !== null;
      if (coloured) {
        geometry.attributes.color.array.set(surface.colours);
        geometry.attributes.color.needsUpdate = true;
      }
      if (mesh.material.vertexColors !== coloured) {
        mesh.material.vertexColors = coloured;
        mesh.material.color.set(coloured ? 0xffffff : data.panels[i].color);
        mesh.material.needsUpdate = true;
      }
      geometry.computeVertexNormals();
      geometry.computeBoundingSphere();
    });
    frameLabel.textContent = frame.name + " (" + (index + 1) + " of " + frames.length + ")";
    render();
  }
  const controls = new THREE.OrbitControls(camera, canvas);
  controls.target.fromArray(data.target);
  controls.update();
  controls.addEventListener("change", render);
  window.addEventListener("resize", render);
  slider.max = frames.length - 1;
  slider.value = frames.length - 1;
  slider.addEventListener("input", () => showFrame(Number(slider.value)));
  showFrame(frames.length - 1);
})();
)js";

bool IsFile(const std::string& path) {
  std::error_code error;
  return fs::is_regular_file(path, error);
}

// Keeps a script's text from ending the <script> element it is placed in.
std::string ScriptSafe(std::string script) {
  for (size_t at = script.find("</"); at != std::string::npos; at = script.find("</", at + 3)) {
    script.replace(at, 2, "<\\/");
  }
  return script;
}

template <typename Value>
std::string Base64Of(const std::vector<Value>& values) {
  std::string bytes(values.size() * sizeof(Value), '\0');
  // An empty vector's data() may be null, which memcpy must not be given even for no bytes.
  if (!bytes.empty()) std::memcpy(bytes.data(), values.data(), bytes.size());
  return Base64Encode(bytes);
}

// The box every frame's positions are quantised over: its low corner and the step per axis.
struct Quantisation {
  Eigen::Vector3d origin;
  Eigen::Vector3d step;
};

Quantisation QuantisationOf(const std::vector<ViewerFrame>& frames) {
  Eigen::Vector3d low = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d high = -low;
  for (const ViewerFrame& frame : frames) {
    for (const ViewerSurface& surface : frame.surfaces) {
      low = low.cwiseMin(surface.mesh.vertices.rowwise().minCoeff());
      high = high.cwiseMax(surface.mesh.vertices.rowwise().maxCoeff());
    }
  }
  return {low, ((high - low) / kQuantisationLevels).cwiseMax(1e-12)};
}

// The vertex positions (x, y, z per vertex) as little-endian Uint16 steps over the box, base64.
std::string PositionsBase64(const Mesh& mesh, const Quantisation& box) {
  std::vector<uint16_t> positions(3 * mesh.num_vertices());
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    for (int axis = 0; axis < 3; ++axis) {
      const double steps = (mesh.vertices(axis, v) - box.origin(axis)) / box.step(axis);
      positions[3 * v + axis] =
          static_cast<uint16_t>(std::clamp(std::lround(steps), 0L, long{kQuantisationLevels}));
    }
  }
  return Base64Of(positions);
}

// The vertex colours as RGB bytes, base64; empty when there are none.
std::string ColorsBase64(const Eigen::Matrix3Xd& colors) {
  std::vector<uint8_t> bytes(3 * colors.cols());
  for (Eigen::Index v = 0; v < colors.cols(); ++v) {
    for (int channel = 0; channel < 3; ++channel) {
      const double value = std::isfinite(colors(channel, v)) ? colors(channel, v) : 0.5;
      bytes[3 * v + channel] =
          static_cast<uint8_t>(std::lround(255.0 * std::clamp(value, 0.0, 1.0)));
    }
  }
  return Base64Of(bytes);
}

// The panels' labels over their parts of the canvas, then the canvas' end and the colour scales.
std::string PanelMarkup(const std::vector<ViewerPanel>& panels) {
  std::string markup;
  const size_t count = panels.size();
  for (size_t i = 0; i < count; ++i) {
    markup += "<div class=\"viewer-label\" data-panel=\"" + EscapeHtml(panels[i].label) +
              "\" style=\"position: absolute; top: 6px; left: calc(" +
              std::to_string(100.0 * i / count) + "% + 10px); font-weight: bold;\">" +
              EscapeHtml(panels[i].label) + "</div>\n";
  }
  markup += "</div>\n";
  for (const ViewerPanel& panel : panels) {
    if (panel.scale) {
      markup += ColorScaleHtml(panel.label + ": " + panel.scale->title, 0.0, panel.scale->max_value,
                               panel.scale->unit);
    }
  }
  return markup;
}

std::string FacesBase64(const Mesh& mesh) {
  std::vector<uint32_t> faces(3 * mesh.num_faces());
  for (int f = 0; f < mesh.num_faces(); ++f) {
    for (int corner = 0; corner < 3; ++corner) {
      faces[3 * f + corner] = static_cast<uint32_t>(mesh.faces(corner, f));
    }
  }
  return Base64Of(faces);
}

std::string JsonVector(const Eigen::Vector3d& vector) {
  return "[" + internal::JsonNumber(vector.x()) + ", " + internal::JsonNumber(vector.y()) + ", " +
         internal::JsonNumber(vector.z()) + "]";
}

// The start view: from the camera's side, at the distance that fits the mesh's bounding sphere.
std::string ViewJson(const Mesh& mesh, const Camera& camera) {
  const Eigen::Vector3d low = mesh.vertices.rowwise().minCoeff();
  const Eigen::Vector3d high = mesh.vertices.rowwise().maxCoeff();
  const Eigen::Vector3d centre = 0.5 * (low + high);
  const double radius = std::max(0.5 * (high - low).norm(), 1e-9);
  Eigen::Vector3d direction = camera.Center() - centre;
  if (!(direction.norm() > 0.0)) direction = -camera.R.row(2).transpose();
  const double half_angle = 0.5 * kFieldOfViewDeg * M_PI / 180.0;
  const double distance = 0.85 * radius / std::sin(half_angle);
  const Eigen::Vector3d eye = centre + distance * direction.normalized();
  const Eigen::Vector3d up = -camera.R.row(1).transpose();  // Image y points down.
  return "\"eye\": " + JsonVector(eye) + ", \"target\": " + JsonVector(centre) +
         ", \"up\": " + JsonVector(up) + ", \"fov\": " + internal::JsonNumber(kFieldOfViewDeg) +
         ", \"near\": " + internal::JsonNumber(distance / 100.0) +
         ", \"far\": " + internal::JsonNumber(100.0 * distance);
}

}  // namespace

std::vector<std::string> ThreeJsSearchPaths() {
  std::vector<std::string> paths;
  if (const char* configured = std::getenv("FINECAP_THREE_JS_DIR"); configured && *configured) {
    paths.push_back(configured);
  }
  paths.push_back("/usr/share/javascript/three");
  paths.push_back("/usr/local/share/javascript/three");
  return paths;
}

std::optional<ThreeJsLibrary> FindThreeJs() {
  for (const std::string& folder : ThreeJsSearchPaths()) {
    const std::string three = folder + "/" + kThreeFile;
    const std::string controls = folder + "/" + kOrbitControlsFile;
    if (IsFile(three) && IsFile(controls)) {
      return ThreeJsLibrary{folder, internal::ReadWholeFile(three),
                            internal::ReadWholeFile(controls)};
    }
  }
  return std::nullopt;
}

std::vector<int> EvenlySpacedIndices(int count, int max_frames) {
  Require(max_frames >= 1, "mesh viewer",
          "at least one frame must be shown, not " + std::to_string(max_frames));
  std::vector<int> indices;
  if (count <= max_frames) {
    for (int i = 0; i < count; ++i) indices.push_back(i);
    return indices;
  }
  if (max_frames == 1) return {0};
  for (int i = 0; i < max_frames; ++i) {
    indices.push_back(
        static_cast<int>(std::lround(static_cast<double>(i) * (count - 1) / (max_frames - 1))));
  }
  return indices;
}

std::string MeshViewerHtml(const std::vector<ViewerPanel>& panels,
                           const std::vector<ViewerFrame>& frames, const Camera& camera,
                           const ThreeJsLibrary& library) {
  Require(!panels.empty(), "mesh viewer", "no panel to show");
  Require(!frames.empty(), "mesh viewer", "no frame to show");
  Require(!frames.front().surfaces.empty(), "mesh viewer",
          "frame " + frames.front().name + " has no surface");
  const Mesh& first = frames.front().surfaces.front().mesh;
  for (const ViewerFrame& frame : frames) {
    Require(frame.surfaces.size() == panels.size(), "mesh viewer",
            "frame " + frame.name + " has " + std::to_string(frame.surfaces.size()) +
                " surfaces for " + std::to_string(panels.size()) + " panels");
    for (size_t p = 0; p < panels.size(); ++p) {
      const ViewerSurface& surface = frame.surfaces[p];
      Require(HasSameTopology(surface.mesh, first), "mesh viewer",
              "frame " + frame.name + ", panel " + panels[p].label +
                  ": the meshes do not share one topology");
      Require(surface.vertex_colors.cols() == 0 ||
                  surface.vertex_colors.cols() == surface.mesh.num_vertices(),
              "mesh viewer",
              "frame " + frame.name + ", panel " + panels[p].label + ": " +
                  std::to_string(surface.vertex_colors.cols()) + " vertex colours for " +
                  std::to_string(surface.mesh.num_vertices()) + " vertices");
    }
  }
  const Quantisation box = QuantisationOf(frames);
  std::ostringstream data;
  data << "{\"faces\": \"" << FacesBase64(first) << "\", " << ViewJson(first, camera)
       << ", \"origin\": " << JsonVector(box.origin) << ", \"step\": " << JsonVector(box.step)
       << ", \"panels\": [";
  for (size_t p = 0; p < panels.size(); ++p) {
    data << (p == 0 ? "" : ", ") << "{\"label\": " << internal::JsonString(panels[p].label)
         << ", \"color\": " << (panels[p].color & 0xffffff) << "}";
  }
  data << "], \"frames\": [";
  for (size_t i = 0; i < frames.size(); ++i) {
    data << (i == 0 ? "" : ", ") << "{\"name\": " << internal::JsonString(frames[i].name)
         << ", \"surfaces\": [";
    for (size_t p = 0; p < frames[i].surfaces.size(); ++p) {
      const ViewerSurface& surface = frames[i].surfaces[p];
      data << (p == 0 ? "" : ", ") << "{\"positions\": \"" << PositionsBase64(surface.mesh, box)
           << "\", \"colors\": \"" << ColorsBase64(surface.vertex_colors) << "\"}";
    }
    data << "]}";
  }
  data << "]}";
  std::string script = kViewerScript;
  const std::string placeholder = "FINECAP_VIEWER_DATA";
  script.replace(script.find(placeholder), placeholder.size(), data.str());
  return std::string(kViewerMarkupStart) + PanelMarkup(panels) + kViewerMarkupEnd + "<script>" +
         ScriptSafe(library.three) + "</script>\n" + "<script>" +
         ScriptSafe(library.orbit_controls) + "</script>\n<script>" + ScriptSafe(script) +
         "</script>\n";
}

std::string MissingViewerHtml() {
  std::string folders;
  for (const std::string& folder : ThreeJsSearchPaths()) {
    folders += (folders.empty() ? "" : ", ") + folder;
  }
  return "<p class=\"viewer-note\">No 3D view: three.js was not found when this report was "
         "written (looked for " +
         EscapeHtml(std::string(kThreeFile) + " and " + kOrbitControlsFile + " in " + folders) +
         "). Install Debian's libjs-three, or set FINECAP_THREE_JS_DIR, and run finecap eval "
         "again.</p>\n";
}

}  // namespace finecap
