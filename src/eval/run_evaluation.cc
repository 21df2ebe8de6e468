#include "finecap/eval/run_evaluation.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <optional>
#include <sstream>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "eval/heldout_eval.h"
#include "eval/mesh_viewer.h"
#include "finecap/eval/html_report.h"
#include "finecap/geometry/render.h"
#include "finecap/io/mesh_io.h"
#include "finecap/refine/frame_reader.h"
#include "finecap/refine/sequence.h"
#include "finecap/util/atomic_file.h"
#include "finecap/util/error.h"
#include "finecap/util/plot.h"
#include "util/io_util.h"

namespace finecap {
namespace {

namespace fs = std::filesystem;

// |k - k_true| per vertex; NaN where either is unknown.
Eigen::VectorXd AbsoluteErrors(const EvaluationSamples& samples) {
  return (samples.k_refined - samples.k_true).cwiseAbs();
}

// The part of the eval camera's view that shows the subject: the bounding box of both meshes'
// footprints, widened by a margin; the whole view when neither is seen. A studio camera sees the
// subject small, and uncropped pictures would show mostly background.
cv::Rect SubjectBox(const Camera& camera, const Mesh& input, const Mesh& refined) {
  const cv::Rect view(0, 0, camera.width, camera.height);
  const cv::Mat seen = (RenderDepth(camera, input).triangle_ids >= 0) |
                       (RenderDepth(camera, refined).triangle_ids >= 0);
  const cv::Rect box = cv::boundingRect(seen);
  if (box.empty()) return view;
  const int margin = 8 + std::max(box.width, box.height) / 10;
  return (box - cv::Point(margin, margin) + cv::Size(2 * margin, 2 * margin)) & view;
}

// Input image | normals of the input | normals of the refined mesh (the paper's Figure 4), all
// cut to `box`.
cv::Mat SideBySidePicture(const cv::Mat& image, const Camera& camera, const Mesh& input,
                          const Mesh& refined, const cv::Rect& box) {
  cv::Mat picture;
  cv::hconcat(std::vector<cv::Mat>{image(box), RenderNormals(camera, input)(box),
                                   RenderNormals(camera, refined)(box)},
              picture);
  return picture;
}

// The length of `flow` in false colour (OpenCV's turbo map, blue 0 to dark red `max_px`) where
// `mask` is set, and the image dimmed to grey elsewhere.
cv::Mat FlowLengthPicture(const cv::Mat& flow, const cv::Mat& mask, const cv::Mat& image,
                          double max_px) {
  std::vector<cv::Mat> components;
  cv::split(flow, components);
  cv::Mat length, scaled, picture, grey;
  cv::magnitude(components[0], components[1], length);
  length.convertTo(scaled, CV_8U, 255.0 / max_px);
  cv::applyColorMap(scaled, picture, cv::COLORMAP_TURBO);
  cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  cv::cvtColor(grey / 2, grey, cv::COLOR_GRAY2BGR);
  grey.copyTo(picture, mask == 0);
  return picture;
}

// 95th percentile of the flow length over the mask; 1 px when there is none.
double FlowLengthScale(const cv::Mat& flow, const cv::Mat& mask) {
  std::vector<double> lengths;
  for (int y = 0; y < flow.rows; ++y) {
    for (int x = 0; x < flow.cols; ++x) {
      const cv::Vec2f vector = flow.at<cv::Vec2f>(y, x);
      if (mask.at<unsigned char>(y, x)) lengths.push_back(std::hypot(vector[0], vector[1]));
    }
  }
  const double scale = Percentile(lengths, 95.0);
  return scale > 0.0 ? scale : 1.0;
}

// Writes the flow length of the input | of the refined mesh, one scale for both, cut to `box`, to
// `path`; returns its caption.
std::string WriteFlowPicture(const FlowFields& fields, const cv::Mat& image, const cv::Rect& box,
                             const std::string& path) {
  const double max_px = FlowLengthScale(fields.coarse, fields.mask);
  cv::Mat both;
  cv::hconcat(FlowLengthPicture(fields.coarse, fields.mask, image, max_px)(box),
              FlowLengthPicture(fields.refined, fields.mask, image, max_px)(box), both);
  internal::WritePng(path, both);
  std::ostringstream caption;
  caption.precision(3);
  caption << "optical flow length from the render of the input | of the refined mesh to the "
          << "image, blue 0 to dark red " << max_px
          << " px (95th percentile of the input's); grey: not measured";
  return caption.str();
}

// What the optical-flow figures need, prepared once per run from the reference frame.
struct FlowSetup {
  OpticalFlowOptions options;
  std::vector<int> cameras;           // The cameras the flow is measured in.
  ProjectiveTexture input_texture;    // From the reference frame's subdivided input mesh.
  ProjectiveTexture refined_texture;  // From its refined mesh, or the input's (see source).
  RefinedFlowTexture refined_texture_source = RefinedFlowTexture::kInputReferenceMesh;
  std::vector<unsigned char> faces_to_measure;
};

// The texture of `mesh`, a surface of the reference frame `reference`, from that frame's images,
// with the camera choice and visibility of that surface.
ProjectiveTexture TextureFromSurface(const Mesh& mesh, const FrameInput& reference,
                                     const VisibilityOptions& visibility) {
  const Eigen::Matrix3Xd normals = ComputeVertexNormals(mesh);
  return MakeProjectiveTexture(
      mesh, normals, reference.cameras, reference.images,
      ComputeFrameVisibility(mesh, normals, reference.cameras, visibility, 0));
}

// The textures of the reference frame's subdivided input mesh and of its refined mesh (when
// `refined_reference` has it; else the input's paints both) from its images (see
// flow_evaluation.h for why each its own, and why not the saved reference colours), over the
// faces of refined vertices the input's texture covers.
FlowSetup PrepareFlow(const RunEvaluationOptions& options, const SequenceModel& model,
                      const std::optional<RefinedFrame>& refined_reference, Capture* capture) {
  FlowSetup setup;
  setup.options = options.flow;
  for (int c = 0; c < capture->num_cameras(); ++c) {
    if (options.flow_in_all_cameras || c == options.camera) setup.cameras.push_back(c);
  }
  Require(options.reference_frame < capture->num_frames(), "RunEvaluationOptions::reference_frame",
          "frame " + std::to_string(options.reference_frame) + " does not exist in " +
              capture->directory());
  const FrameInput reference = ReadFrameInput(capture, options.reference_frame);
  const Mesh fine = model.Subdivide(reference.coarse);
  const VisibilityOptions& visibility = options.refine.visibility;
  setup.input_texture = TextureFromSurface(fine, reference, visibility);
  setup.faces_to_measure = FacesToMeasure(fine, setup.input_texture, model.refined_vertices());
  setup.refined_texture = setup.input_texture;
  if (!refined_reference) return setup;
  Require(refined_reference->index == options.reference_frame, refined_reference->files.mesh,
          "is not the refined mesh of the reference frame " +
              capture->frame_name(options.reference_frame));
  const Mesh refined = ReadMesh(refined_reference->files.mesh);
  RequireSameTopology(fine, refined, refined_reference->files.mesh);
  setup.refined_texture = TextureFromSurface(refined, reference, visibility);
  FillUntexturedFaces(setup.input_texture, &setup.refined_texture);
  setup.refined_texture_source = RefinedFlowTexture::kRefinedReferenceMesh;
  return setup;
}

// The flow figures of one frame, the cameras' pixels pooled; `eval_fields` receives the flow
// fields of camera `eval_camera`.
FlowComparison MeasureFrameFlow(const FlowSetup& setup, int frame, const Mesh& input,
                                const Mesh& refined, int eval_camera, Capture* capture,
                                FlowFields* eval_fields) {
  FlowComparison frame_flow;
  for (int c : setup.cameras) {
    const Camera& camera = capture->cameras()[c];
    frame_flow.Add(CompareFlow(camera, capture->ReadImage(c, frame), input, setup.input_texture,
                               refined, setup.refined_texture, setup.faces_to_measure,
                               setup.options,
                               capture->directory() + ": flow in camera " + camera.name +
                                   ", frame " + capture->frame_name(frame),
                               c == eval_camera ? eval_fields : nullptr));
  }
  return frame_flow;
}

// What the sequence figures and the report collect while the frames are evaluated.
struct EvaluationRun {
  std::vector<std::string> names;
  std::vector<double> frame_indices;
  std::vector<EvaluationFigures> figures;
  std::vector<FlowComparison> flows;  // Per frame; empty sums when flow is not measured.
  FlowComparison pooled_flow;
  std::optional<RefinedFlowTexture> refined_flow_texture;  // None when flow is not measured.
  std::vector<internal::HeldOutFrame> heldout;  // Per frame; empty without validation.cameras.
  std::vector<int> panel_frames;  // Frame indices whose held-out comparison panels are shown.
  EvaluationSamples pooled;
  std::vector<std::pair<std::string, std::string>> pictures;  // Path, caption.
  // The signed errors of the frame evaluated last, which the frame after it (index
  // `next_index`) measures its flicker against.
  int next_index = -1;
  SignedErrors errors_before_next;
};

void EvaluateFrame(const RefinedFrame& frame, const RunEvaluationOptions& options,
                   const SequenceModel& model, const std::vector<int>& textureless,
                   const FlowSetup* flow, const std::string& eval_dir, Capture* capture,
                   EvaluationRun* run) {
  const Mesh coarse = capture->ReadCoarseMesh(frame.index);
  const Mesh input = model.Subdivide(coarse);
  const Mesh refined = ReadMesh(frame.files.mesh);
  const Eigen::VectorXd k = ReadDisplacement(frame.files.displacement, input.num_vertices());
  FineGroundTruth truth = TrueFineGroundTruth(*capture, model, coarse, frame.index);
  if (truth.empty()) {
    truth.k_true = truth.coarse_error = Eigen::VectorXd::Constant(k.size(), ErrorStats::kNoData);
  }
  EvaluationSamples samples = MakeEvaluationSamples(
      model.Interpolate(coarse), input, refined, k, truth.k_true, truth.coarse_error,
      model.refined_vertices(), textureless, frame.files.mesh);
  if (frame.index == run->next_index) samples.errors_before = run->errors_before_next;
  run->next_index = frame.index + 1;
  run->errors_before_next = samples.Errors();
  const EvaluationFigures figures = ComputeEvaluationFigures(samples);
  run->names.push_back(frame.name);
  run->frame_indices.push_back(frame.index);
  run->figures.push_back(figures);
  run->pooled.Append(samples);
  FlowFields fields;
  run->flows.push_back(
      flow ? MeasureFrameFlow(*flow, frame.index, input, refined, options.camera, capture, &fields)
           : FlowComparison());
  run->pooled_flow.Add(run->flows.back());
  if (!options.held_out_cameras.empty()) {
    run->heldout.push_back(internal::EvaluateHeldOutFrame(
        options.held_out_cameras, options.held_out_score, frame.name,
        ReadFrameInput(capture, frame.index), coarse, input, refined, eval_dir,
        std::find(run->panel_frames.begin(), run->panel_frames.end(), frame.index) !=
            run->panel_frames.end(),
        &run->pictures));
  }
  const Camera& camera = capture->cameras()[options.camera];
  const cv::Mat image = capture->ReadImage(options.camera, frame.index);
  const cv::Rect box = SubjectBox(camera, input, refined);
  const std::string prefix = "Frame " + frame.name + ", camera " + camera.name + ": ";
  const std::string picture = eval_dir + "/frame_" + frame.name + ".png";
  internal::WritePng(picture, SideBySidePicture(image, camera, input, refined, box));
  run->pictures.push_back({picture, prefix + "image, normals of the input, normals refined"});
  if (!fields.mask.empty()) {
    const std::string flow_path = eval_dir + "/flow_" + frame.name + ".png";
    run->pictures.push_back({flow_path, prefix + WriteFlowPicture(fields, image, box, flow_path)});
  }
  const double scale = figures.all.coarse.p95_abs;
  if (!(scale > 0.0)) return;  // No ground truth (or no detail): no error to colour.
  SurfaceAppearance heat;
  heat.vertex_colors = HeatMapColors(AbsoluteErrors(samples), scale);
  const std::string heat_path = eval_dir + "/error_" + frame.name + ".png";
  internal::WritePng(heat_path, RenderColor(camera, refined, heat)(box));
  std::ostringstream caption;
  caption.precision(3);
  caption << prefix << "|k - k_true| on the refined mesh, blue 0 to dark red " << 1000.0 * scale
          << " mm (95th percentile of the input's error); grey unknown";
  run->pictures.push_back({heat_path, caption.str()});
}

double Millimetres(double metres) { return 1000.0 * metres; }

std::string RegionJson(const RegionFigures& region) {
  using internal::JsonNumber;
  std::ostringstream json;
  json << "{\"vertices\": " << region.refined.count
       << ", \"rms_coarse_mm\": " << JsonNumber(Millimetres(region.coarse.rms))
       << ", \"rms_subdivided_mm\": " << JsonNumber(Millimetres(region.subdivided.rms))
       << ", \"rms_refined_mm\": " << JsonNumber(Millimetres(region.refined.rms))
       << ", \"mean_abs_coarse_mm\": " << JsonNumber(Millimetres(region.coarse.mean_abs))
       << ", \"mean_abs_subdivided_mm\": " << JsonNumber(Millimetres(region.subdivided.mean_abs))
       << ", \"mean_abs_refined_mm\": " << JsonNumber(Millimetres(region.refined.mean_abs))
       << ", \"p95_abs_coarse_mm\": " << JsonNumber(Millimetres(region.coarse.p95_abs))
       << ", \"p95_abs_subdivided_mm\": " << JsonNumber(Millimetres(region.subdivided.p95_abs))
       << ", \"p95_abs_refined_mm\": " << JsonNumber(Millimetres(region.refined.p95_abs))
       << ", \"detail_recovered\": " << JsonNumber(region.detail_recovered)
       << ", \"flicker_coarse_mm\": " << JsonNumber(Millimetres(region.flicker.coarse.rms))
       << ", \"flicker_subdivided_mm\": " << JsonNumber(Millimetres(region.flicker.subdivided.rms))
       << ", \"flicker_refined_mm\": " << JsonNumber(Millimetres(region.flicker.refined.rms))
       << ", \"normal_error_coarse_deg\": " << JsonNumber(region.normal_error_coarse_deg)
       << ", \"normal_error_subdivided_deg\": " << JsonNumber(region.normal_error_subdivided_deg)
       << ", \"normal_error_refined_deg\": " << JsonNumber(region.normal_error_refined_deg) << "}";
  return json.str();
}

std::string FiguresJson(const EvaluationFigures& figures) {
  return "{\"all\": " + RegionJson(figures.all) +
         ", \"textured\": " + RegionJson(figures.textured) +
         ", \"textureless\": " + RegionJson(figures.textureless) + "}";
}

// The mean flow lengths of the input and the refined mesh and the improvement, as JSON members
// (null when not measured).
std::string FlowJson(const FlowComparison& flow, const std::string& separator) {
  using internal::JsonNumber;
  return "\"flow_coarse_px\": " + JsonNumber(flow.coarse.mean_px()) + "," + separator +
         "\"flow_refined_px\": " + JsonNumber(flow.refined.mean_px()) + "," + separator +
         "\"flow_improvement_percent\": " + JsonNumber(flow.improvement_percent());
}

// The headline figures (all refined vertices, the sequence pooled) at the top level, then the
// regions of the sequence and of every frame.
std::string MetricsJson(const EvaluationRun& run, const EvaluationFigures& sequence) {
  using internal::JsonNumber;
  const RegionFigures& all = sequence.all;
  std::ostringstream json;
  json << "{\n  \"rms_coarse_mm\": " << JsonNumber(Millimetres(all.coarse.rms))
       << ",\n  \"rms_subdivided_mm\": " << JsonNumber(Millimetres(all.subdivided.rms))
       << ",\n  \"rms_refined_mm\": " << JsonNumber(Millimetres(all.refined.rms))
       << ",\n  \"detail_recovered\": " << JsonNumber(all.detail_recovered)
       << ",\n  \"flicker_coarse_mm\": " << JsonNumber(Millimetres(all.flicker.coarse.rms))
       << ",\n  \"flicker_subdivided_mm\": " << JsonNumber(Millimetres(all.flicker.subdivided.rms))
       << ",\n  \"flicker_refined_mm\": " << JsonNumber(Millimetres(all.flicker.refined.rms))
       << ",\n  \"normal_error_coarse_deg\": " << JsonNumber(all.normal_error_coarse_deg)
       << ",\n  \"normal_error_subdivided_deg\": " << JsonNumber(all.normal_error_subdivided_deg)
       << ",\n  \"normal_error_refined_deg\": " << JsonNumber(all.normal_error_refined_deg)
       << ",\n  " << FlowJson(run.pooled_flow, "\n  ") << ",\n  \"flow_refined_texture\": "
       << (run.refined_flow_texture
               ? internal::JsonString(RefinedFlowTextureName(*run.refined_flow_texture))
               : std::string("null"))
       << ",\n  " << internal::HeldOutPooledJson(run.heldout, "\n  ")
       << ",\n  \"sequence\": " << FiguresJson(sequence) << ",\n  \"frames\": [";
  for (size_t i = 0; i < run.names.size(); ++i) {
    json << (i == 0 ? "\n    " : ",\n    ") << "{\"frame\": " << internal::JsonString(run.names[i])
         << ", " << FlowJson(run.flows[i], " ") << ", \"heldout\": "
         << (run.heldout.empty() ? "null" : internal::HeldOutFrameJson(run.heldout[i]))
         << ", \"figures\": " << FiguresJson(run.figures[i]) << "}";
  }
  json << "\n  ]\n}\n";
  return json.str();
}

// One curve of a figure over the frames.
PlotSeries SeriesOverFrames(const std::string& name, const EvaluationRun& run,
                            double (*figure)(const EvaluationFigures&)) {
  PlotSeries series{name, run.frame_indices, {}};
  for (const EvaluationFigures& figures : run.figures) series.y.push_back(figure(figures));
  return series;
}

bool AnyFinite(const PlotSeries& series) {
  for (double y : series.y) {
    if (std::isfinite(y)) return true;
  }
  return false;
}

// The mean flow lengths of the input and the refined mesh over the frames (the paper's
// Figure 6), when flow was measured; returns its path and caption.
std::vector<std::pair<std::string, std::string>> WriteFlowPlot(const EvaluationRun& run,
                                                               const std::string& eval_dir) {
  PlotSeries input{"input", run.frame_indices, {}};
  PlotSeries refined{"refined", run.frame_indices, {}};
  for (const FlowComparison& flow : run.flows) {
    input.y.push_back(flow.coarse.mean_px());
    refined.y.push_back(flow.refined.mean_px());
  }
  if (!AnyFinite(input)) return {};
  PlotOptions options;
  options.x_label = "frame";
  options.title = "Mean optical flow between the textured model's render and the image";
  options.y_label = "pixels";
  const std::string path = eval_dir + "/flow.png";
  WriteLinePlot(path, {input, refined}, options);
  return {{path, "Optical flow over the frames (the paper's Figure 6)"}};
}

// The flicker of each surface and the refined error over the frames at `path`, when some frame
// has a flicker figure; whether it did.
bool WriteFlickerPlot(const EvaluationRun& run, const std::string& path) {
  const std::vector<PlotSeries> flicker = {
      SeriesOverFrames(
          "flicker input", run,
          [](const EvaluationFigures& f) { return Millimetres(f.all.flicker.coarse.rms); }),
      SeriesOverFrames(
          "flicker subdivided", run,
          [](const EvaluationFigures& f) { return Millimetres(f.all.flicker.subdivided.rms); }),
      SeriesOverFrames(
          "flicker refined", run,
          [](const EvaluationFigures& f) { return Millimetres(f.all.flicker.refined.rms); }),
      SeriesOverFrames("error refined", run,
                       [](const EvaluationFigures& f) { return Millimetres(f.all.refined.rms); })};
  if (!AnyFinite(flicker[2])) return false;
  PlotOptions options;
  options.x_label = "frame";
  options.title = "RMS change of the signed error since the frame before, and the refined error";
  options.y_label = "mm";
  WriteLinePlot(path, flicker, options);
  return true;
}

// The plots over the frames (error, normal error, flicker), when there is ground truth to plot;
// returns their paths.
std::vector<std::pair<std::string, std::string>> WritePlots(const EvaluationRun& run,
                                                            const std::string& eval_dir) {
  const std::vector<PlotSeries> rms = {
      SeriesOverFrames("input", run,
                       [](const EvaluationFigures& f) { return Millimetres(f.all.coarse.rms); }),
      SeriesOverFrames(
          "subdivided", run,
          [](const EvaluationFigures& f) { return Millimetres(f.all.subdivided.rms); }),
      SeriesOverFrames("refined", run,
                       [](const EvaluationFigures& f) { return Millimetres(f.all.refined.rms); })};
  const std::vector<PlotSeries> normals = {
      SeriesOverFrames("input", run,
                       [](const EvaluationFigures& f) { return f.all.normal_error_coarse_deg; }),
      SeriesOverFrames(
          "subdivided", run,
          [](const EvaluationFigures& f) { return f.all.normal_error_subdivided_deg; }),
      SeriesOverFrames("refined", run,
                       [](const EvaluationFigures& f) { return f.all.normal_error_refined_deg; })};
  if (!AnyFinite(rms[0])) return {};
  PlotOptions options;
  options.x_label = "frame";
  options.title = "RMS of |k - k_true| over the refined vertices";
  options.y_label = "mm";
  WriteLinePlot(eval_dir + "/rms.png", rms, options);
  options.title = "Mean angle between vertex normals and the true normals";
  options.y_label = "degrees";
  WriteLinePlot(eval_dir + "/normal_error.png", normals, options);
  std::vector<std::pair<std::string, std::string>> plots = {
      {eval_dir + "/rms.png", "Displacement error over the frames"},
      {eval_dir + "/normal_error.png", "Normal error over the frames"}};
  if (WriteFlickerPlot(run, eval_dir + "/flicker.png")) {
    plots.push_back({eval_dir + "/flicker.png", "Flicker over the frames, beside the error"});
  }
  return plots;
}

std::vector<TableCell> TableRow(const std::string& name, const RegionFigures& region) {
  return {name,
          region.refined.count,
          Millimetres(region.coarse.rms),
          Millimetres(region.subdivided.rms),
          Millimetres(region.refined.rms),
          Millimetres(region.flicker.coarse.rms),
          Millimetres(region.flicker.subdivided.rms),
          Millimetres(region.flicker.refined.rms),
          Millimetres(region.coarse.mean_abs),
          Millimetres(region.refined.mean_abs),
          Millimetres(region.coarse.p95_abs),
          Millimetres(region.refined.p95_abs),
          100.0 * region.detail_recovered,
          region.normal_error_coarse_deg,
          region.normal_error_subdivided_deg,
          region.normal_error_refined_deg};
}

std::vector<TableCell> FlowTableRow(const std::string& name, const FlowComparison& flow) {
  return {name, flow.coarse.mean_px(), flow.refined.mean_px(), flow.improvement_percent()};
}

// The optical-flow figures: the sequence first, then every frame.
void AddFlowTable(const EvaluationRun& run, HtmlReport* report) {
  std::vector<std::vector<TableCell>> rows = {FlowTableRow("sequence", run.pooled_flow)};
  for (size_t i = 0; i < run.names.size(); ++i) {
    rows.push_back(FlowTableRow(run.names[i], run.flows[i]));
  }
  report->AddParagraph(
      "Mean length of the optical flow from a render of the model, textured from the reference "
      "frame's images, to the input image, over the pixels where the model shows refined "
      "vertices (no ground truth needed; the paper's section 7). Improvement: 100 (input - "
      "refined) / input. n/a: not measured (no flow evaluation).");
  if (run.refined_flow_texture == RefinedFlowTexture::kRefinedReferenceMesh) {
    report->AddParagraph(
        "Each mesh is textured from its own surface in the reference frame: the input mesh from "
        "the reference frame's input mesh, the refined mesh from its refined mesh.");
  } else if (run.refined_flow_texture == RefinedFlowTexture::kInputReferenceMesh) {
    report->AddParagraph(
        "The reference frame is not refined in this run folder: the texture of the reference "
        "frame's input mesh paints both meshes, so wherever the input is wrong in the reference "
        "frame the refined mesh's flow is overstated.");
  }
  report->AddTable({"", "flow input px", "flow refined px", "improvement %"}, rows,
                   "Optical flow, the sequence pooled and per frame");
}

// eval/flow.csv: one line per frame, the figures of the flow table.
void WriteFlowCsv(const EvaluationRun& run, const std::string& path) {
  std::ostringstream csv;
  csv.precision(10);
  csv << "frame,flow_coarse_px,flow_refined_px,flow_improvement_percent\n";
  for (size_t i = 0; i < run.names.size(); ++i) {
    const FlowComparison& flow = run.flows[i];
    csv << run.names[i] << ',' << flow.coarse.mean_px() << ',' << flow.refined.mean_px() << ','
        << flow.improvement_percent() << '\n';
  }
  WriteTextFileAtomically(path, csv.str());
}

// Frames the report's 3D view offers: enough to see the motion, few enough to keep the report
// small (each adds every panel's positions).
constexpr int kViewerFrames = 5;

// The report's 3D view of up to kViewerFrames frames, evenly spaced over the evaluated ones, seen
// first from the eval camera: the subdivided input mesh, the refined mesh and, where the capture
// has ground truth, the refined mesh coloured by |k - k_true| (the scale's top `error_scale`, the
// sequence's 95th percentile of the input's error) and the true surface (the subdivided input
// displaced by the true k along its normals, where the truth is known; the input elsewhere); and,
// from runs that wrote it, the refined mesh coloured by its confidence (confidence/<frame>.txt:
// where it is low, too few cameras saw the surface well and refine held it near the input). Where
// three.js is absent a note takes its place and a warning goes to stderr: the report is still
// written.
std::string ViewerHtml(const std::vector<RefinedFrame>& frames, const SequenceModel& model,
                       const Camera& camera, double error_scale, Capture* capture,
                       EvaluationObserver* observer) {
  const std::optional<ThreeJsLibrary> library = FindThreeJs();
  if (!library) {
    observer->ViewerUnavailable();
    return MissingViewerHtml();
  }
  const std::vector<int> shown_indices =
      EvenlySpacedIndices(static_cast<int>(frames.size()), kViewerFrames);
  // Truth is shown only when every shown frame has it, so that the panels stay the same.
  bool with_truth = error_scale > 0.0;
  for (int i : shown_indices) with_truth = with_truth && capture->HasTrueSurface(frames[i].index);
  std::vector<ViewerPanel> panels = {{"input", 0xa9b4c4, std::nullopt}};
  if (with_truth) {
    panels.push_back({"refined, coloured by its error", 0xd9bc96,
                      ViewerColorScale{"|k - k_true|", Millimetres(error_scale), "mm"}});
    panels.push_back({"truth", 0xa8c4a2, std::nullopt});
  } else {
    panels.push_back({"refined", 0xd9bc96, std::nullopt});
  }
  bool with_confidence = true;
  for (int i : shown_indices) {
    with_confidence = with_confidence && fs::is_regular_file(frames[i].files.confidence);
  }
  if (with_confidence) {
    panels.push_back({"refined, coloured by confidence", 0xd9bc96,
                      ViewerColorScale{"confidence (0: held near the input)", 1.0, ""}});
  }
  std::vector<ViewerFrame> shown;
  for (int i : shown_indices) {
    const RefinedFrame& frame = frames[i];
    const Mesh coarse = capture->ReadCoarseMesh(frame.index);
    ViewerFrame viewed{frame.name,
                       {{model.Subdivide(coarse), {}}, {ReadMesh(frame.files.mesh), {}}}};
    if (with_truth) {
      const Mesh& input = viewed.surfaces[0].mesh;
      const Eigen::VectorXd k_true =
          TrueFineGroundTruth(*capture, model, coarse, frame.index).k_true;
      const Eigen::VectorXd k = ReadDisplacement(frame.files.displacement, input.num_vertices());
      viewed.surfaces[1].vertex_colors = HeatMapColors((k - k_true).cwiseAbs(), error_scale);
      Mesh truth = input;
      const Eigen::Matrix3Xd normals = ComputeVertexNormals(input);
      for (int v = 0; v < input.num_vertices(); ++v) {
        if (v < k_true.size() && std::isfinite(k_true[v])) {
          truth.vertices.col(v) += k_true[v] * normals.col(v);
        }
      }
      viewed.surfaces.push_back({std::move(truth), {}});
    }
    if (with_confidence) {
      const Mesh& refined = viewed.surfaces[1].mesh;
      const Eigen::VectorXd confidence =
          ReadConfidence(frame.files.confidence, refined.num_vertices());
      viewed.surfaces.push_back({refined, HeatMapColors(confidence, 1.0)});
    }
    shown.push_back(std::move(viewed));
  }
  return MeshViewerHtml(panels, shown, camera, *library);
}

// One section of the report: its heading and what fills it. The report is the list of its
// sections (ReportSections), in order; a new kind of figure is one more entry there.
struct ReportSection {
  std::string heading;
  std::function<void(HtmlReport*)> fill;
};

// What the report's sections are made of.
struct ReportContent {
  const EvaluationRun& run;
  const EvaluationFigures& sequence;
  const HeldOutOptions& heldout_options;
  std::vector<std::pair<std::string, std::string>> plots;
  std::vector<std::pair<std::string, std::string>> flow_plots;
  std::string viewer_html;
};

void AddFiguresSection(const ReportContent& content, HtmlReport* report) {
  const std::vector<std::string> header = {"",
                                           "vertices",
                                           "RMS input mm",
                                           "RMS subdivided mm",
                                           "RMS refined mm",
                                           "flicker input mm",
                                           "flicker subdivided mm",
                                           "flicker refined mm",
                                           "mean input mm",
                                           "mean refined mm",
                                           "p95 input mm",
                                           "p95 refined mm",
                                           "detail recovered %",
                                           "normal error input deg",
                                           "normal error subdivided deg",
                                           "normal error refined deg"};
  report->AddParagraph(
      "Distances to the ground truth along the normals of the subdivided input mesh, over the "
      "refined vertices, of the input as given (the coarse mesh's triangles sampled at the fine "
      "vertices), of its Loop subdivision (where refinement starts, k of 0) and of the refined "
      "mesh (k - k_true). Detail recovered: 1 - RMS refined / RMS input, against the input as "
      "given. Flicker: the RMS of the change of the signed error (refined minus true) from the "
      "frame before, over the vertices known in both frames, what shows as shimmer when the "
      "sequence is played; a steady error has none. True normals: the subdivided input mesh "
      "displaced by the true k. n/a: no ground truth, an empty region or, for the flicker, no "
      "frame before.");
  const EvaluationFigures& sequence = content.sequence;
  report->AddTable(header,
                   {TableRow("all", sequence.all), TableRow("textured", sequence.textured),
                    TableRow("textureless", sequence.textureless)},
                   "The whole sequence, vertices of all frames pooled");
  std::vector<std::vector<TableCell>> frame_rows;
  for (size_t i = 0; i < content.run.names.size(); ++i) {
    frame_rows.push_back(TableRow(content.run.names[i], content.run.figures[i].all));
  }
  report->AddTable(header, frame_rows, "Per frame, all refined vertices");
}

// The report's sections, top to bottom; a section with nothing to show is left out.
std::vector<ReportSection> ReportSections(const ReportContent& content) {
  std::vector<ReportSection> sections;
  if (content.sequence.all.refined.count > 0) {
    sections.push_back({"Figures", [&](HtmlReport* r) { AddFiguresSection(content, r); }});
  } else {
    // Tables of n/a would say less than this.
    sections.push_back({"Figures", [](HtmlReport* r) {
                          r->AddParagraph(
                              "No ground truth: the capture has no true surface for the evaluated "
                              "frames, so no error against it is measured. The held-out cameras "
                              "(validation.cameras) and the optical flow measure the result "
                              "without one.");
                        }});
  }
  sections.push_back({"3D view", [&](HtmlReport* r) { r->AddRawHtml(content.viewer_html); }});
  if (!content.run.heldout.empty()) {
    sections.push_back({"Held-out cameras", [&](HtmlReport* r) {
                          internal::AddHeldOutSection(content.run.heldout, content.heldout_options,
                                                      r);
                        }});
  }
  sections.push_back({"Optical flow", [&](HtmlReport* r) {
                        AddFlowTable(content.run, r);
                        for (const auto& [plot, caption] : content.flow_plots)
                          r->AddImageFile(plot, caption);
                      }});
  if (!content.plots.empty()) {
    sections.push_back({"Over the frames", [&](HtmlReport* r) {
                          for (const auto& [plot, caption] : content.plots)
                            r->AddImageFile(plot, caption);
                        }});
  }
  sections.push_back({"Pictures", [&](HtmlReport* r) {
                        for (const auto& [picture, caption] : content.run.pictures)
                          r->AddImageFile(picture, caption);
                      }});
  return sections;
}

void WriteReport(const ReportContent& content, const std::string& path) {
  HtmlReport report("finecap evaluation");
  for (const ReportSection& section : ReportSections(content)) {
    report.AddSection(section.heading);
    section.fill(&report);
  }
  report.Write(path);
}

}  // namespace

const char* RefinedFlowTextureName(RefinedFlowTexture texture) {
  switch (texture) {
    case RefinedFlowTexture::kRefinedReferenceMesh:
      return "refined_reference_mesh";
    case RefinedFlowTexture::kInputReferenceMesh:
      return "input_reference_mesh";
  }
  return "unknown";
}

const OptionFields<RunEvaluationOptions>& RunEvaluationOptions::Fields() {
  static const OptionFields<RunEvaluationOptions> fields = [] {
    OptionFields<RunEvaluationOptions> f;
    f.AddInt("camera", &RunEvaluationOptions::camera,
             "finecap eval: index of the camera whose view the per-frame pictures show.", 0);
    return f;
  }();
  return fields;
}

void RunEvaluationOptions::Check() const {
  refine.Check();
  held_out_score.Check();
  if (measure_flow) flow.Check();
  Fields().CheckValues(*this, "RunEvaluationOptions::");
  // The run's reference frame, as the sequence declares it.
  internal::CheckDeclaredNumber(reference_frame, SequenceOptions::Fields().Field("reference_frame"),
                                "RunEvaluationOptions::reference_frame");
}

RunEvaluation EvaluateRun(Capture* capture, const std::vector<RefinedFrame>& frames,
                          const std::optional<RefinedFrame>& refined_reference,
                          const RunEvaluationOptions& options, const std::string& folder,
                          EvaluationObserver* observer) {
  options.Check();
  Require(options.camera < capture->num_cameras(), "RunEvaluationOptions::camera",
          std::to_string(options.camera) + " is not a camera of " + capture->directory() +
              ", which has " + std::to_string(capture->num_cameras()));
  EvaluationObserver silent;
  if (observer == nullptr) observer = &silent;
  fs::create_directories(folder);
  const SequenceModel model(capture->ReadCoarseMesh(0), capture->vertex_mask(), options.refine,
                            capture->directory() + "/meshes");
  const std::vector<int> textureless = model.SubdivideIds(capture->textureless_vertices());
  std::optional<FlowSetup> flow;
  if (options.measure_flow) {
    flow = PrepareFlow(options, model, refined_reference, capture);
    if (!refined_reference)
      observer->RefinedReferenceUnavailable(capture->frame_name(options.reference_frame));
  }
  EvaluationRun run;
  if (flow) run.refined_flow_texture = flow->refined_texture_source;
  // The held-out comparison panels of the frames the 3D view shows.
  for (int i : EvenlySpacedIndices(static_cast<int>(frames.size()), kViewerFrames)) {
    run.panel_frames.push_back(frames[i].index);
  }
  for (const RefinedFrame& frame : frames) {
    EvaluateFrame(frame, options, model, textureless, flow ? &*flow : nullptr, folder, capture,
                  &run);
    observer->FrameEvaluated(frame.name);
  }
  RunEvaluation result;
  result.sequence = ComputeEvaluationFigures(run.pooled);
  result.flow_measured = flow.has_value();
  result.flow = run.pooled_flow;
  result.refined_flow_texture = run.refined_flow_texture.value_or(result.refined_flow_texture);
  if (!run.heldout.empty()) result.heldout = internal::PooledHeldOutScore(run.heldout);
  result.metrics = folder + "/metrics.json";
  result.report = folder + "/report.html";
  WriteTextFileAtomically(result.metrics, MetricsJson(run, result.sequence));
  WriteFlowCsv(run, folder + "/flow.csv");
  WriteReport({run, result.sequence, options.held_out_score, WritePlots(run, folder),
               WriteFlowPlot(run, folder),
               ViewerHtml(frames, model, capture->cameras()[options.camera],
                          result.sequence.all.coarse.p95_abs, capture, observer)},
              result.report);
  return result;
}

}  // namespace finecap
