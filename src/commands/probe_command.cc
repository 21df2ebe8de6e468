// finecap probe: the configured energy along k = alpha * k_true on a frame with ground truth.
// An energy that describes the images well peaks at alpha = 1; one that prefers flatter surfaces
// peaks below it. Every change to the energy is judged by this diagnostic.
#include <stdlib.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>

#include "commands/command_util.h"
#include "finecap/commands/commands.h"
#include "finecap/util/error.h"
#include "finecap/util/plot.h"

namespace finecap {
namespace {

struct ProbeSample {
  double alpha = 0.0;
  double energy = 0.0;
  double similarity = 0.0;
  double regularization = 0.0;
};

// The alpha of the largest value, refined by the parabola through it and its two neighbours.
double Optimum(const std::vector<ProbeSample>& samples, double ProbeSample::*value) {
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

// The folder of --out (output.dir); without one, a new folder under the system's temporary
// folder ($TMPDIR, else /tmp): the probe's plot and reference colours are a diagnostic, and the
// current directory is the user's, not the probe's. A new folder each run, so that reference
// colours cached for another capture are never reused.
std::string ProbeOutputFolder(const Config& config, const Capture& capture) {
  if (!config.output.dir.empty()) return internal::PrepareOutputFolder(config, capture);
  std::error_code error;
  const std::filesystem::path temp = std::filesystem::temp_directory_path(error);
  Require(!error, "TMPDIR",
          "no temporary folder for the probe's files (" + error.message() + "): pass --out DIR");
  std::string folder = (temp / "finecap-probe-XXXXXX").string();
  Require(mkdtemp(folder.data()) != nullptr, folder,
          std::string("cannot create the probe's folder: ") + std::strerror(errno) +
              " (pass --out DIR)");
  std::printf("probe: no --out given, writing into %s\n", folder.c_str());
  return folder;
}

}  // namespace

int RunProbe(const Config& configured, int frame_index) {
  Capture capture = internal::OpenConfiguredCapture(configured);
  const Config config = internal::WithSceneLengths(configured, capture, "probe");
  const int frame = frame_index >= 0 ? frame_index : capture.num_frames() - 1;
  Require(frame < capture.num_frames(), "--frame",
          "frame " + std::to_string(frame) + " does not exist in " + capture.directory());
  Require(capture.HasTrueSurface(frame), capture.directory(),
          "frame " + capture.frame_name(frame) + " has no ground truth (gt/" +
              capture.frame_name(frame) + ".ply): the probe needs a synthetic capture");
  const SequenceModel model(capture.ReadCoarseMesh(0), capture.vertex_mask(), config.refine,
                            capture.directory() + "/meshes");
  const std::string out = ProbeOutputFolder(config, capture);
  const ReferenceColors colors = internal::ConfiguredReferenceColors(config, model, &capture, out);
  FrameInput input = ReadFrameInput(&capture, frame);
  TakeHeldOutViews(config.validation.cameras, &input);  // The energy as refine sees it.
  PreparedFrame prepared = PrepareFrame(model, colors, input, config.refine);
  const FrameEnergy& energy = *prepared.energy;

  const Eigen::VectorXd truth_all = TrueFineDisplacement(capture, model, input.coarse, frame);
  Eigen::VectorXd truth(energy.num_parameters());
  for (int s = 0; s < truth.size(); ++s) {
    const double k = truth_all[energy.surface().vertex_ids[s]];
    truth[s] =
        std::isfinite(k) ? std::clamp(k, -energy.options().k_max, energy.options().k_max) : 0.0;
  }
  std::printf(
      "probe: frame %s, similarity %s (%s overlap), %d surface Gaussians, %ld pairs, "
      "RMS of k_true %.2f mm\n",
      capture.frame_name(frame).c_str(), EnumToString(energy.options().similarity).c_str(),
      EnumToString(energy.options().overlap).c_str(), energy.num_parameters(), energy.num_pairs(),
      1000.0 * std::sqrt(truth.squaredNorm() / std::max<long>(truth.size(), 1)));
  std::printf("%8s %16s %16s %16s\n", "alpha", "E", "E_sim", "E_reg");
  std::vector<ProbeSample> samples;
  for (int step = -5; step <= 15; ++step) {
    ProbeSample sample;
    sample.alpha = 0.1 * step;
    sample.energy =
        energy.Evaluate(sample.alpha * truth, nullptr, &sample.similarity, &sample.regularization);
    std::printf("%8.2f %16.8g %16.8g %16.8g\n", sample.alpha, sample.energy, sample.similarity,
                sample.regularization);
    samples.push_back(sample);
  }

  PlotSeries similarity{"E_sim (normalised)", {}, {}}, total{"E (normalised)", {}, {}};
  const auto normalise = [&](double ProbeSample::*value, PlotSeries* series) {
    double low = samples[0].*value, high = low;
    for (const ProbeSample& s : samples)
      low = std::min(low, s.*value), high = std::max(high, s.*value);
    for (const ProbeSample& s : samples) {
      series->x.push_back(s.alpha);
      series->y.push_back(high > low ? (s.*value - low) / (high - low) : 0.0);
    }
  };
  normalise(&ProbeSample::similarity, &similarity);
  normalise(&ProbeSample::energy, &total);
  PlotOptions plot;
  plot.title = "Energy along k = alpha k_true (" + EnumToString(energy.options().similarity) +
               ", frame " + capture.frame_name(frame) + ")";
  plot.x_label = "alpha (0 = input surface, 1 = true surface)";
  plot.y_label = "energy, scaled to [0, 1]";
  const std::string plot_path = out + "/probe_" + capture.frame_name(frame) + ".png";
  WriteLinePlot(plot_path, {similarity, total}, plot);
  std::printf("plot: %s\n", plot_path.c_str());
  std::printf("similarity_alpha_optimum: %.3f\n", Optimum(samples, &ProbeSample::similarity));
  std::printf("alpha_optimum: %.3f\n", Optimum(samples, &ProbeSample::energy));
  return 0;
}

}  // namespace finecap
