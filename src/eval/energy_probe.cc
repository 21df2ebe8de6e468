#include "finecap/eval/energy_probe.h"

#include <algorithm>
#include <cmath>

#include "finecap/refine/frame_reader.h"
#include "finecap/refine/sequence.h"
#include "finecap/util/error.h"
#include "finecap/util/plot.h"

namespace finecap {
namespace {

// The alpha of the largest value, refined by the parabola through it and its two neighbours.
double Optimum(const std::vector<EnergyProbeSample>& samples, double EnergyProbeSample::*value) {
  size_t best = 0;
  for (size_t i = 1; i < samples.size(); ++i) {
    if (samples[i].*value > samples[best].*value) best = i;
  }
  if (best == 0 || best + 1 == samples.size()) return samples[best].alpha;
  const double y0 = samples[best - 1].*value, y1 = samples[best].*value,
               y2 = samples[best + 1].*value;
  const double h = samples[best + 1].alpha - samples[best].alpha;
  const double curvature = y0 - 2.0 * y1 + y2;
  if (curvature >= 0.0) return samples[best].alpha;
  return samples[best].alpha + 0.5 * h * (y0 - y2) / curvature;
}

// `value` of every sample against alpha, scaled to [0, 1].
PlotSeries Normalised(const std::string& title, const std::vector<EnergyProbeSample>& samples,
                      double EnergyProbeSample::*value) {
  PlotSeries series{title, {}, {}};
  double low = samples[0].*value, high = low;
  for (const EnergyProbeSample& s : samples) {
    low = std::min(low, s.*value);
    high = std::max(high, s.*value);
  }
  for (const EnergyProbeSample& s : samples) {
    series.x.push_back(s.alpha);
    series.y.push_back(high > low ? (s.*value - low) / (high - low) : 0.0);
  }
  return series;
}

}  // namespace

void RequireProbeableFrame(const Capture& capture, int frame) {
  Require(frame >= 0 && frame < capture.num_frames(), capture.directory(),
          "frame " + std::to_string(frame) + " does not exist");
  Require(capture.HasTrueSurface(frame), capture.directory(),
          "frame " + capture.frame_name(frame) + " has no ground truth (gt/" +
              capture.frame_name(frame) + ".ply): the probe needs a synthetic capture");
}

EnergyProbe ProbeEnergyAlongTruth(Capture* capture, int frame, const SequenceModel& model,
                                  const ReferenceColors& colors, const RefineOptions& options,
                                  const std::vector<std::string>& held_out_cameras) {
  RequireProbeableFrame(*capture, frame);
  FrameInput input = ReadFrameInput(capture, frame);
  TakeHeldOutViews(held_out_cameras, &input);  // The energy as refinement sees it.
  const PreparedFrame prepared = PrepareFrame(model, colors, input, options);
  const FrameEnergy& energy = *prepared.energy;

  const Eigen::VectorXd truth_all =
      TrueFineGroundTruth(*capture, model, input.coarse, frame).k_true;
  const double bound = energy.layout().bound;
  Eigen::VectorXd truth = energy.UnknownsAtVertices(truth_all);
  for (double& k : truth) k = std::isfinite(k) ? std::clamp(k, -bound, bound) : 0.0;
  EnergyProbe probe;
  probe.frame = capture->frame_name(frame);
  probe.similarity = energy.options().similarity;
  probe.overlap = energy.options().overlap;
  probe.num_surface_gaussians = energy.num_parameters();
  probe.num_pairs = energy.num_pairs();
  probe.rms_truth = std::sqrt(truth.squaredNorm() / std::max<long>(truth.size(), 1));
  for (int step = -5; step <= 15; ++step) {
    EnergyProbeSample sample;
    sample.alpha = 0.1 * step;
    sample.energy =
        energy.Evaluate(sample.alpha * truth, nullptr, &sample.similarity, &sample.quadratic);
    probe.samples.push_back(sample);
  }
  probe.similarity_optimum = Optimum(probe.samples, &EnergyProbeSample::similarity);
  probe.energy_optimum = Optimum(probe.samples, &EnergyProbeSample::energy);
  return probe;
}

void WriteEnergyProbePlot(const EnergyProbe& probe, const std::string& path) {
  PlotOptions plot;
  plot.title = "Energy along k = alpha k_true (" + EnumToString(probe.similarity) + ", frame " +
               probe.frame + ")";
  plot.x_label = "alpha (0 = input surface, 1 = true surface)";
  plot.y_label = "energy, scaled to [0, 1]";
  WriteLinePlot(path,
                {Normalised("E_sim (normalised)", probe.samples, &EnergyProbeSample::similarity),
                 Normalised("E (normalised)", probe.samples, &EnergyProbeSample::energy)},
                plot);
}

}  // namespace finecap
