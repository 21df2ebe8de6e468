#include "eval/mesh_viewer.h"

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "finecap/eval/html_report.h"
#include "test_meshes.h"
#include "test_util.h"

namespace finecap {
namespace {

using testing_util::ExpectErrorMentions;
using testing_util::MakeTempDir;
using testing_util::WriteText;

size_t Count(const std::string& text, const std::string& part) {
  size_t count = 0;
  for (size_t at = text.find(part); at != std::string::npos; at = text.find(part, at + 1)) ++count;
  return count;
}

// The first match of `pattern`'s group 1 in `html`; empty when none.
std::string Match(const std::string& html, const std::string& pattern) {
  std::smatch match;
  return std::regex_search(html, match, std::regex(pattern)) ? match[1].str() : "";
}

Eigen::Vector3d VectorIn(const std::string& html, const std::string& name) {
  std::istringstream text(Match(html, "\"" + name + "\": \\[([^\\]]*)\\]"));
  Eigen::Vector3d vector;
  char comma;
  text >> vector.x() >> comma >> vector.y() >> comma >> vector.z();
  EXPECT_TRUE(static_cast<bool>(text)) << name;
  return vector;
}

// The positions the viewer's script decodes from `base64`: Uint16 steps over origin + step.
Eigen::Matrix3Xd DecodedPositions(const std::string& base64, const Eigen::Vector3d& origin,
                                  const Eigen::Vector3d& step) {
  const std::string bytes = testing_util::Base64Decode(base64);
  std::vector<uint16_t> steps(bytes.size() / 2);
  std::memcpy(steps.data(), bytes.data(), 2 * steps.size());
  Eigen::Matrix3Xd positions(3, steps.size() / 3);
  for (size_t i = 0; i < steps.size(); ++i) {
    positions(i % 3, i / 3) = origin(i % 3) + step(i % 3) * steps[i];
  }
  return positions;
}

std::string ExpectedFaces(const Mesh& mesh) {
  std::string bytes;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    for (int corner = 0; corner < 3; ++corner) {
      const uint32_t id = static_cast<uint32_t>(mesh.faces(corner, f));
      bytes.append(reinterpret_cast<const char*>(&id), sizeof(id));
    }
  }
  return Base64Encode(bytes);
}

Camera FrontCamera() {
  Camera camera;
  camera.name = "front";
  camera.width = camera.height = 64;
  camera.K << 50, 0, 32, 0, 50, 32, 0, 0, 1;
  camera.t = Eigen::Vector3d(0, 0, 3);  // Looks along +z at the origin from z = -3.
  return camera;
}

// The panels of a capture with ground truth: input, refined coloured by its error, truth.
std::vector<ViewerPanel> Panels() {
  return {{"input", 0xa9b4c4, std::nullopt},
          {"refined", 0xd9bc96, ViewerColorScale{"|k - k_true|", 12.5, "mm"}},
          {"truth", 0xa8c4a2, std::nullopt}};
}

// Input, refined (the input bulged by `bulge` in z, coloured red) and truth (bulged twice as far).
ViewerFrame Frame(const std::string& name, double bulge) {
  const Mesh input = testing_meshes::GridMesh(4, 3);
  ViewerFrame frame{name, {{input, {}}, {input, {}}, {input, {}}}};
  frame.surfaces[1].mesh.vertices.row(2).array() += bulge;
  frame.surfaces[1].vertex_colors = Eigen::Matrix3Xd::Zero(3, input.num_vertices());
  frame.surfaces[1].vertex_colors.row(0).setOnes();
  frame.surfaces[2].mesh.vertices.row(2).array() += 2.0 * bulge;
  return frame;
}

TEST(EvenlySpacedIndicesTest, KeepsTheEndsAndSpreadsTheRest) {
  EXPECT_EQ(EvenlySpacedIndices(3, 5), (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(EvenlySpacedIndices(0, 5), std::vector<int>{});
  EXPECT_EQ(EvenlySpacedIndices(9, 5), (std::vector<int>{0, 2, 4, 6, 8}));
  EXPECT_EQ(EvenlySpacedIndices(100, 5), (std::vector<int>{0, 25, 50, 74, 99}));
  EXPECT_EQ(EvenlySpacedIndices(7, 1), std::vector<int>{0});
  ExpectErrorMentions([] { EvenlySpacedIndices(7, 0); }, {"at least one frame"});
}

TEST(MeshViewerTest, FindsTheLibraryInTheConfiguredFolderFirst) {
  const std::string dir = MakeTempDir("three_js");
  WriteText(dir + "/build/three.min.js", "var THREE = {};");
  WriteText(dir + "/examples/js/controls/OrbitControls.js", "THREE.OrbitControls = 1;");
  ASSERT_EQ(setenv("FINECAP_THREE_JS_DIR", dir.c_str(), 1), 0);
  const std::vector<std::string> paths = ThreeJsSearchPaths();
  ASSERT_FALSE(paths.empty());
  EXPECT_EQ(paths.front(), dir);
  const std::optional<ThreeJsLibrary> library = FindThreeJs();
  ASSERT_TRUE(library.has_value());
  EXPECT_EQ(library->folder, dir);
  EXPECT_EQ(library->three, "var THREE = {};");
  EXPECT_EQ(library->orbit_controls, "THREE.OrbitControls = 1;");
  // A folder without the controls is passed over.
  const std::string partial = MakeTempDir("three_js_partial");
  WriteText(partial + "/build/three.min.js", "var THREE = {};");
  ASSERT_EQ(setenv("FINECAP_THREE_JS_DIR", partial.c_str(), 1), 0);
  const std::optional<ThreeJsLibrary> other = FindThreeJs();
  EXPECT_TRUE(!other.has_value() || other->folder != partial);
  unsetenv("FINECAP_THREE_JS_DIR");
  EXPECT_NE(MissingViewerHtml().find("/usr/share/javascript/three"), std::string::npos);
  EXPECT_NE(MissingViewerHtml().find("libjs-three"), std::string::npos);
}

TEST(MeshViewerTest, EmbedsTheLibraryTheFacesOnceAndEveryFramesPositions) {
  const ThreeJsLibrary library{"/nowhere", "var THREE = {}; // '</script>' in a comment",
                               "THREE.OrbitControls = function () {};"};
  const std::vector<ViewerFrame> frames = {Frame("000000", 0.0), Frame("000004", 0.01)};
  const std::string html = MeshViewerHtml(Panels(), frames, FrontCamera(), library);
  // The library's text cannot end its <script> element early.
  EXPECT_EQ(Count(html, "</script>"), 3u);
  EXPECT_NE(html.find("var THREE = {}; // '<\\/script>'"), std::string::npos);
  EXPECT_NE(html.find("THREE.OrbitControls = function () {};"), std::string::npos);
  EXPECT_EQ(Count(html, ExpectedFaces(frames[0].surfaces[0].mesh)), 1u);
  // Every frame's positions decode to the meshes' within half a quantisation step, 1.5e-5 of the
  // box of all meshes (3 x 2 x 0.02 here).
  const Eigen::Vector3d origin = VectorIn(html, "origin"), step = VectorIn(html, "step");
  EXPECT_LT(step.maxCoeff(), 3.1 / 65535);
  const std::string surface = R"re(\{"positions": "([^"]*)", "colors": "([^"]*)"\})re";
  std::smatch match;
  const std::regex last_frame(R"re("name": "000004", "surfaces": \[)re" + surface + ", " + surface +
                              ", " + surface);
  ASSERT_TRUE(std::regex_search(html, match, last_frame));
  for (int p = 0; p < 3; ++p) {
    SCOPED_TRACE(p);
    const Mesh& mesh = frames[1].surfaces[p].mesh;
    const Eigen::Matrix3Xd decoded = DecodedPositions(match[1 + 2 * p].str(), origin, step);
    ASSERT_EQ(decoded.cols(), mesh.num_vertices());
    EXPECT_LT((decoded - mesh.vertices).cwiseAbs().maxCoeff(), 0.51 * step.maxCoeff());
  }
  // The refined mesh's colours as RGB bytes (red), the others none.
  const std::string colors = testing_util::Base64Decode(match[4].str());
  ASSERT_EQ(colors.size(), 3u * frames[1].surfaces[1].mesh.num_vertices());
  EXPECT_EQ(static_cast<unsigned char>(colors[0]), 255);
  EXPECT_EQ(static_cast<unsigned char>(colors[1]), 0);
  EXPECT_TRUE(match[2].str().empty());
  EXPECT_TRUE(match[6].str().empty());
  const std::string first =
      Match(html, R"re("name": "000000", "surfaces": \[\{"positions": "([^"]*)")re");
  EXPECT_LT((DecodedPositions(first, origin, step) - frames[0].surfaces[0].mesh.vertices)
                .cwiseAbs()
                .maxCoeff(),
            0.51 * step.maxCoeff());
  EXPECT_NE(html.find("<canvas"), std::string::npos);
  EXPECT_NE(html.find("type=\"range\""), std::string::npos);
  // A label per panel, and the colour scale of the refined panel with its top in mm.
  EXPECT_EQ(Count(html, "class=\"viewer-label\""), 3u);
  EXPECT_NE(html.find("data-panel=\"truth\""), std::string::npos);
  EXPECT_EQ(Count(html, "class=\"color-scale\""), 1u);
  EXPECT_NE(html.find("data-high=\"12.5\""), std::string::npos);
  EXPECT_NE(html.find("12.5 mm"), std::string::npos);
  // The view starts on the camera's side of the mesh (z < 0), its up the image's up (-y).
  EXPECT_TRUE(std::regex_search(html, std::regex(R"re("eye": \[[^\]]*, -[0-9.e]+\])re")));
  EXPECT_TRUE(std::regex_search(html, std::regex(R"re("up": \[-?0, -1, -?0\])re")));
}

TEST(MeshViewerTest, RefusesNoFramesAndSurfacesThatDoNotFit) {
  const ThreeJsLibrary library{"/nowhere", "", ""};
  ExpectErrorMentions([&] { MeshViewerHtml(Panels(), {}, FrontCamera(), library); }, {"no frame"});
  ExpectErrorMentions([&] { MeshViewerHtml({}, {Frame("000000", 0.0)}, FrontCamera(), library); },
                      {"no panel"});
  ViewerFrame other = Frame("000001", 0.0);
  other.surfaces[1].mesh = testing_meshes::GridMesh(5, 3);
  other.surfaces[1].vertex_colors.resize(3, 0);
  ExpectErrorMentions(
      [&] {
        MeshViewerHtml(Panels(), {Frame("000000", 0.0), other}, FrontCamera(), library);
      },
      {"000001", "refined", "topology"});
  ViewerFrame missing = Frame("000002", 0.0);
  missing.surfaces.pop_back();
  ExpectErrorMentions([&] { MeshViewerHtml(Panels(), {missing}, FrontCamera(), library); },
                      {"000002", "2 surfaces for 3 panels"});
  ViewerFrame colours = Frame("000003", 0.0);
  colours.surfaces[1].vertex_colors.conservativeResize(3, 2);
  ExpectErrorMentions([&] { MeshViewerHtml(Panels(), {colours}, FrontCamera(), library); },
                      {"000003", "2 vertex colours for 12 vertices"});
}

}  // namespace
}  // namespace finecap
