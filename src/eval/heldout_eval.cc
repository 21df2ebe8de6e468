#include "eval/heldout_eval.h"

#include <cmath>
#include <sstream>

#include <opencv2/imgproc.hpp>

#include "finecap/refine/frame_reader.h"
#include "util/io_util.h"

namespace finecap {
namespace internal {
namespace {

// NCC from -1 (dark blue) to 1 (dark red), OpenCV's turbo map, where scored; the held-out image
// dimmed to grey elsewhere.
cv::Mat NccPicture(const cv::Mat& ncc, const cv::Mat& image) {
  cv::Mat scaled, picture, grey;
  ncc.convertTo(scaled, CV_8U, 127.5, 127.5);
  cv::applyColorMap(scaled, picture, cv::COLORMAP_TURBO);
  cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  cv::cvtColor(grey / 2, grey, cv::COLOR_GRAY2BGR);
  cv::Mat scored(ncc.size(), CV_8U);
  for (int y = 0; y < ncc.rows; ++y) {
    for (int x = 0; x < ncc.cols; ++x) {
      scored.at<unsigned char>(y, x) = std::isfinite(ncc.at<float>(y, x)) ? 255 : 0;
    }
  }
  grey.copyTo(picture, scored == 0);
  return picture;
}

// Where either warp reached, widened by a margin; the whole view when neither did.
cv::Rect WarpedBox(const HeldOutViewMaps& maps, const cv::Size& size) {
  cv::Mat reached = cv::Mat::zeros(size, CV_8U);
  for (const cv::Mat& warped : maps.warped) {
    cv::Mat grey;
    cv::cvtColor(warped, grey, cv::COLOR_BGR2GRAY);
    reached |= grey > 0;
  }
  const cv::Rect view(cv::Point(0, 0), size);
  const cv::Rect box = cv::boundingRect(reached);
  if (box.empty()) return view;
  const int margin = 8 + std::max(box.width, box.height) / 10;
  return (box - cv::Point(margin, margin) + cv::Size(2 * margin, 2 * margin)) & view;
}

std::string ViewCaption(const std::string& frame_name, const HeldOutViewScore& view) {
  std::ostringstream caption;
  caption.precision(3);
  caption << "Frame " << frame_name << ", held-out camera " << view.camera
          << ": its image | camera " << (view.training.empty() ? "-" : view.training.front())
          << " warped in through the input as given | through the refined mesh | local NCC of "
          << "the input as given | of the refined mesh (mean over " << view.training.size()
          << " training views; blue -1 to dark red 1, grey not scored). NCC "
          << view.surfaces[kHeldOutCoarse].ncc << " (subdivided "
          << view.surfaces[kHeldOutSubdivided].ncc << ") -> " << view.surfaces[kHeldOutRefined].ncc
          << ", MAD " << view.surfaces[kHeldOutCoarse].mad << " (subdivided "
          << view.surfaces[kHeldOutSubdivided].mad << ") -> " << view.surfaces[kHeldOutRefined].mad
          << " grey levels";
  return caption.str();
}

// The labels of the comparison panels, in the order of the held-out picture's parts.
constexpr const char* kPanelLabels[] = {"photo (held out)", "predicted by the input",
                                        "predicted by the refined mesh", "NCC of the input",
                                        "NCC of the refined mesh"};

// The names metrics.json gives the surfaces, in HeldOutSurface order.
constexpr const char* kSurfaceNames[kNumHeldOutSurfaces] = {"input", "subdivided", "refined"};

// "<prefix>ncc_input": ..., the NCC of each surface, then the MAD of each, joined by
// `separator`.
std::string SurfaceJson(const std::vector<SurfaceScore>& surfaces, const std::string& prefix,
                        const std::string& separator) {
  std::vector<std::string> members;
  for (int s = 0; s < kNumHeldOutSurfaces; ++s) {
    members.push_back("\"" + prefix + "ncc_" + kSurfaceNames[s] +
                      "\": " + JsonNumber(surfaces[s].ncc));
  }
  for (int s = 0; s < kNumHeldOutSurfaces; ++s) {
    members.push_back("\"" + prefix + "mad_" + kSurfaceNames[s] +
                      "\": " + JsonNumber(surfaces[s].mad));
  }
  std::string json = members.front();
  for (size_t m = 1; m < members.size(); ++m) json += "," + separator + members[m];
  return json;
}

std::vector<TableCell> ScoreRow(const std::string& name, const std::string& training,
                                const std::vector<SurfaceScore>& surfaces) {
  return {name,
          training,
          surfaces[kHeldOutCoarse].ncc,
          surfaces[kHeldOutSubdivided].ncc,
          surfaces[kHeldOutRefined].ncc,
          surfaces[kHeldOutCoarse].mad,
          surfaces[kHeldOutSubdivided].mad,
          surfaces[kHeldOutRefined].mad};
}

}  // namespace

HeldOutFrame EvaluateHeldOutFrame(const std::vector<std::string>& held_out_cameras,
                                  const HeldOutOptions& options, const std::string& frame_name,
                                  FrameInput frame, const Mesh& coarse, const Mesh& input,
                                  const Mesh& refined, const std::string& eval_dir,
                                  bool keep_panels,
                                  std::vector<std::pair<std::string, std::string>>* pictures) {
  const std::vector<CalibratedImage> held_out = TakeHeldOutViews(held_out_cameras, &frame);
  std::vector<HeldOutViewMaps> maps;
  HeldOutFrame result;
  result.frame = frame_name;
  result.score = ScoreHeldOutViews(CalibratedImagesOf(frame), held_out, {&coarse, &input, &refined},
                                   options, &maps);
  for (size_t h = 0; h < held_out.size(); ++h) {
    const cv::Mat& image = held_out[h].image;
    const cv::Rect box = WarpedBox(maps[h], image.size());
    const HeldOutViewMaps& view = maps[h];
    const std::vector<cv::Mat> parts = {image(box), view.warped[kHeldOutCoarse](box),
                                        view.warped[kHeldOutRefined](box),
                                        NccPicture(view.ncc[kHeldOutCoarse], image)(box),
                                        NccPicture(view.ncc[kHeldOutRefined], image)(box)};
    cv::Mat picture;
    cv::hconcat(parts, picture);
    const std::string path =
        eval_dir + "/heldout_" + frame_name + "_" + held_out[h].camera.name + ".png";
    WritePng(path, picture);
    const std::string caption = ViewCaption(frame_name, result.score.views[h]);
    pictures->push_back({path, caption});
    if (keep_panels) {
      std::vector<ReportPanel> panels;
      for (size_t p = 0; p < parts.size(); ++p)
        panels.push_back({kPanelLabels[p], parts[p].clone()});
      result.panels.push_back(std::move(panels));
      result.captions.push_back(caption);
    }
  }
  return result;
}

std::vector<SurfaceScore> PooledHeldOutScore(const std::vector<HeldOutFrame>& frames) {
  std::vector<SurfaceScore> pooled(kNumHeldOutSurfaces, SurfaceScore{std::nan(""), std::nan("")});
  for (int s = 0; s < kNumHeldOutSurfaces; ++s) {
    double ncc = 0.0, mad = 0.0;
    int ncc_count = 0, mad_count = 0;
    for (const HeldOutFrame& frame : frames) {
      for (const HeldOutViewScore& view : frame.score.views) {
        if (std::isfinite(view.surfaces[s].ncc)) ncc += view.surfaces[s].ncc, ++ncc_count;
        if (std::isfinite(view.surfaces[s].mad)) mad += view.surfaces[s].mad, ++mad_count;
      }
    }
    if (ncc_count > 0) pooled[s].ncc = ncc / ncc_count;
    if (mad_count > 0) pooled[s].mad = mad / mad_count;
  }
  return pooled;
}

std::string HeldOutPooledJson(const std::vector<HeldOutFrame>& frames, const std::string& indent) {
  return SurfaceJson(PooledHeldOutScore(frames), "heldout_", indent);
}

std::string HeldOutFrameJson(const HeldOutFrame& frame) {
  std::ostringstream json;
  json << "{" << SurfaceJson(frame.score.mean, "", " ") << ", \"views\": [";
  for (size_t h = 0; h < frame.score.views.size(); ++h) {
    const HeldOutViewScore& view = frame.score.views[h];
    json << (h == 0 ? "" : ", ") << "{\"camera\": " << JsonString(view.camera)
         << ", \"training\": [";
    for (size_t t = 0; t < view.training.size(); ++t) {
      json << (t == 0 ? "" : ", ") << JsonString(view.training[t]);
    }
    json << "], " << SurfaceJson(view.surfaces, "", " ") << ", \"ncc_pixels\": " << view.ncc_pixels
         << ", \"common_pixels\": " << view.common_pixels << "}";
  }
  json << "]}";
  return json.str();
}

void AddHeldOutSection(const std::vector<HeldOutFrame>& frames, const HeldOutOptions& options,
                       HtmlReport* report) {
  std::ostringstream text;
  text << "Each held-out image against the " << options.neighbours
       << " nearest training views warped into it through the input as given (the coarse mesh), "
          "through its subdivision and through the refined mesh (z-buffered: points a training "
          "view does not see are left out), over the pixels all three cover: local normalised "
          "cross-correlation of grey levels in "
       << options.window << "x" << options.window
       << " windows (higher is better; windows of the held-out image with a standard deviation "
          "below "
       << options.min_std
       << " grey levels are not scored) and mean absolute difference in grey levels (lower is "
          "better). Means over the training views, then over the views. No ground truth needed.";
  report->AddParagraph(text.str());
  std::vector<std::vector<TableCell>> rows = {ScoreRow("all", "", PooledHeldOutScore(frames))};
  for (const HeldOutFrame& frame : frames) {
    rows.push_back(ScoreRow("frame " + frame.frame, "", frame.score.mean));
    for (const HeldOutViewScore& view : frame.score.views) {
      std::string training;
      for (const std::string& name : view.training)
        training += (training.empty() ? "" : " ") + name;
      rows.push_back(
          ScoreRow("frame " + frame.frame + ", " + view.camera, training, view.surfaces));
    }
  }
  report->AddTable({"", "training views", "NCC input", "NCC subdivided", "NCC refined", "MAD input",
                    "MAD subdivided", "MAD refined"},
                   rows, "Held-out photo-consistency, pooled, per frame and per held-out view");
  bool any_panels = false;
  for (const HeldOutFrame& frame : frames) any_panels = any_panels || !frame.panels.empty();
  if (!any_panels) return;
  report->AddParagraph(
      "Each held-out photo beside what the input as given and the refined mesh predict there: the "
      "nearest training view warped into the held-out camera through each mesh. Where a mesh is "
      "right, its prediction matches the photo and its NCC map is red; where it is wrong, the "
      "warped texture shifts and the map turns blue.");
  report->AddRawHtml(ColorScaleHtml("local NCC", -1.0, 1.0, ""));
  for (const HeldOutFrame& frame : frames) {
    for (size_t v = 0; v < frame.panels.size(); ++v) {
      report->AddPanelRow("held-out frame " + frame.frame + ", " + frame.score.views[v].camera,
                          frame.panels[v], frame.captions[v]);
    }
  }
}

}  // namespace internal
}  // namespace finecap
