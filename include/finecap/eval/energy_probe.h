// The configured energy along the line from the input surface to the true one, k = alpha * k_true,
// on a frame with ground truth: the diagnostic by which every change to the energy is judged. An
// energy that describes the images well peaks at alpha = 1; one that prefers flatter surfaces
// peaks below it.
#ifndef FINECAP_EVAL_ENERGY_PROBE_H_
#define FINECAP_EVAL_ENERGY_PROBE_H_

#include <string>
#include <vector>

#include "finecap/energy/energy_options.h"
#include "finecap/io/capture.h"
#include "finecap/model/surface_gaussians.h"
#include "finecap/refine/refine.h"

namespace finecap {

// The energy and its two parts at one alpha, E = E_sim - E_quad (frame_energy.h).
struct EnergyProbeSample {
  double alpha = 0.0;
  double energy = 0.0;
  double similarity = 0.0;
  double quadratic = 0.0;  // The terms quadratic in k: smoothness (w_reg E_reg) and pulls.
};

struct EnergyProbe {
  std::string frame;  // The capture's name of the frame.
  SimilarityType similarity = EnergyOptions().similarity;
  OverlapForm overlap = OverlapForm::kExact;
  int num_surface_gaussians = 0;
  long num_pairs = 0;
  double rms_truth = 0.0;  // RMS of k_true over the surface Gaussians, metres.
  // alpha from -0.5 to 1.5 in steps of 0.1.
  std::vector<EnergyProbeSample> samples;
  // The alpha of the largest value, refined by the parabola through it and its two neighbours.
  double similarity_optimum = 0.0;
  double energy_optimum = 0.0;
};

// Throws Error unless frame `frame` of `capture` exists and has ground truth.
void RequireProbeableFrame(const Capture& capture, int frame);

// Probes frame `frame` of `capture`, which must have ground truth, with the energy that
// refinement would build for it: `options`, the reference colours `colors`, and the images of
// every camera but `held_out_cameras`. k_true is the true displacement clamped to +-k_max (0 where
// a vertex has none). Throws Error as RequireProbeableFrame does, or on unreadable input.
EnergyProbe ProbeEnergyAlongTruth(Capture* capture, int frame, const SequenceModel& model,
                                  const ReferenceColors& colors, const RefineOptions& options,
                                  const std::vector<std::string>& held_out_cameras);

// Writes the probe's similarity and energy, each scaled to [0, 1], against alpha as a PNG plot
// at `path` (plot.h: needs gnuplot).
void WriteEnergyProbePlot(const EnergyProbe& probe, const std::string& path);

}  // namespace finecap

#endif  // FINECAP_EVAL_ENERGY_PROBE_H_
