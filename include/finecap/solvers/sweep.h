// A starting point for the solvers, found the way plane-sweep stereo finds depth: the data term
// is evaluated for every surface Gaussian at a few displacements spanning [-k_max, k_max] (all
// at once, since each evaluation moves every Gaussian by the same k), the per-Gaussian costs are
// smoothed over the mesh's neighbours so that a single colour coincidence cannot win, and each
// Gaussian starts at its best displacement. The local solvers then start inside the right basin
// instead of at k = 0, where the nearest optimum of a textured surface is often a wrong one (the
// paper's "risk of returning local maxima").
//
// Each Gaussian looks for its best displacement in a window of its own, which starts a few
// sigma_hat wide and doubles only while the lowest cost inside it sits at one of its ends and the
// curve falls further beyond that end: a minimum inside the window is kept even when a lower one
// lies farther away. A wide range then costs time but no longer draws Gaussians to the chance
// coincidences of colour far from the input (the Middlebury temple's held-out NCC fell from 0.67
// to 0.63 between ranges of 8.3 and 16.6 mm when every Gaussian took its lowest sample), while a
// Gaussian whose curve keeps falling still reaches as far as the range allows.
#ifndef FINECAP_SWEEP_H_
#define FINECAP_SWEEP_H_

#include <limits>

#include <Eigen/Core>

#include "finecap/energy/frame_energy.h"
#include "finecap/util/option_fields.h"

namespace finecap {

// The plane sweep's options. The fields are documented where Fields() declares them
// (docs/configuration.md: refine.sweep); the comments below add what the documentation does not
// say.
struct SweepOptions {
  // The bounds of `samples` when the sweep is on: fewer than 3 displacements would not include
  // k = 0 and both signs.
  static constexpr int kMinSamples = 3;
  static constexpr int kMaxSamples = 1000;

  // Displacements in [-k_max, k_max]. 33: with the consensus similarity's tabulated colours a
  // sample costs little, and a start from the best displacement of each patch reaches inputs
  // farther from the truth (the temple's visual hull).
  int samples = 33;
  int smoothing_rounds = 4;
  // The first window of each Gaussian, in sigma_hat each side of the input (4.2 mm on the temple,
  // 40 mm on synth_skirt, 137 mm on Sceaux); 0: the whole range at once (each Gaussian takes its
  // lowest sample).
  double window_sigmas = 8.0;
  // The samples are at most this many sigma_hat apart (more than `samples` on a wide range), so
  // that a window resolves the same minima whatever the range; 0: `samples` alone.
  double max_step_sigmas = 0.5;
  // A refinement doubles its frame's range (EnergyOptions::k_max) while more than this share of
  // the surface Gaussians is limited by it (SweepResult::share_at_ends), at most `max_widenings`
  // times and up to EnergyOptions' largest k_max. With the windows a wider range no longer costs
  // accuracy, so the range can follow this evidence; the share falls steeply once the range
  // stops truncating (the temple: 10.8 % at 4.15 mm, 1.7 % at 8.3 mm, 0.27 % at 16.6 mm,
  // 0.04 % at 33 mm; Sceaux: 2.9 % at 50 mm, 0.76 % at 101 mm, 0.29 % at 203 mm; synth_skirt:
  // 5.4 % at 12 mm, 0.02 % at 24 mm).
  double widen_share = 0.01;
  int max_widenings = 4;
  // A refinement that did not widen narrows its frame's range to the narrowest of its halvings,
  // down to sigma_hat, in whose outer half fewer than this share of the surface Gaussians (those
  // refined with confidence) find their lowest cost (SweepResult::reach). A range far wider than
  // the input's error adds nothing a Gaussian needs and keeps the few that find a chance
  // coincidence of colour far off (synth_skirt_exact: one to three Gaussians a frame beyond
  // 12 mm, each centimetres from the truth). The share is small only where the range is wide:
  // 0.01-0.03 % on synth_skirt_exact at 24 mm and 0.02 % on the smoothed input, against 1.1 % on
  // the temple at 16.6 mm and on Sceaux at 203 mm, 3.5 % on synth_skirt and 2.2 % on the smoothed
  // input at 12 mm.
  double narrow_share = 0.002;
  // The detail stage's own sweep (SweepAround), in sigma_hat: its half-width and its step.
  // Where the surface Gaussians' stage ends, the images hold detail finer than its Gaussians'
  // width, and the detail stage's solver, whose patches read the images at their own resolution,
  // only descends into the nearest of its minima; a few displacements tried around the start
  // find the best one nearby (synth_skirt_exact 49.6 -> 50.0 %, synth_noisy 68.8 -> 70.4 %, the
  // temple's held-out NCC 0.7236 -> 0.7250; docs/measurements.md). Wider is not better: 8
  // sigma_hat each side starts many Gaussians at chance agreements of colour. Off (0) with
  // `samples` 0 or no solver iteration, so that an input scored as given stays as given.
  double detail_range_sigmas = 0.5;
  double detail_step_sigmas = 0.25;
  // Rounds of averaging the detail sweep's costs over the neighbours, counted as
  // `smoothing_rounds` are. Fewer than the plane sweep's: its displacements span a pixel or two,
  // not the whole range, and the patches it costs read the images at their own resolution.
  int detail_smoothing_rounds = 1;
  // A surface Gaussian that at most two cameras see within VisibilityOptions::
  // max_view_angle_deg starts at the input instead of at its best displacement when that
  // displacement's uniqueness (SweepResult::uniqueness) is below this. Two cameras 90 degrees
  // apart (a four-camera rig) see a printed or finely textured cloth match itself at several
  // displacements, and a solve started at a chance one ends there: synth_skirt printed, four
  // cameras, ended 6.9 % worse than its input over frames 0-2. With three cameras or more the
  // others break such ties, and there a low uniqueness mostly means a wide range's far minima (the
  // temple's visual hull), which the windowed search already passes by: the rule is not applied
  // (applied to every Gaussian, the temple's held-out NCC fell from 0.725 to 0.711). Chosen between
  // 0.3, after which one frame of the printed skirt stayed worse than its input, and 0.5, which
  // cost the temple 0.004 (docs/measurements.md, 2026-12-07). 0: never.
  double min_uniqueness = 0.4;

  static const OptionFields<SweepOptions>& Fields();  // option_fields.h
  void Check() const;
};

// The sample Gaussian's window search chooses on its cost curve `costs` at `displacements`
// (ascending): the lowest sample within `window` of k = 0, the window doubled while that sample
// is at one of its ends and a sample up to twice as far beyond that end costs less.
// `searched`, when not null, is set to the window's half-width at the end.
int WindowedMinimum(const Eigen::Ref<const Eigen::RowVectorXd>& costs,
                    const Eigen::Ref<const Eigen::VectorXd>& displacements, double window,
                    double* searched = nullptr);

// How clearly the displacement `chosen` stands out on the cost curve `costs` at `displacements`:
// (c_2 - c_chosen) / (c_median - c_chosen), with c_2 the lowest cost of the samples more than
// `distinct` away from it, clamped to [0, 1]. 0: another displacement, a distinct minimum, costs
// as little (or less: the windowed search may keep a nearer one), or half the curve is as low; 1:
// nothing else comes close, or no sample lies that far (nothing to confuse it with).
double CostUniqueness(const Eigen::Ref<const Eigen::RowVectorXd>& costs,
                      const Eigen::Ref<const Eigen::VectorXd>& displacements, int chosen,
                      double distinct, double searched);

// A sweep's start and what it says about its range.
struct SweepResult {
  Eigen::VectorXd k;  // One entry per surface Gaussian, metres.
  // The share of the Gaussians (those whose curve is flat counted too) refined with confidence
  // (FrameEnergy::confidence() at least 0.5) whose window grew to the whole range and whose best
  // sample is at one of its ends: where the range, not the images, limits them.
  double share_at_ends = 0.0;
  // How far from k = 0 the best displacements of all but SweepOptions::narrow_share of the
  // Gaussians refined with confidence (whose curve is not flat) lie: a range whose half reaches as
  // far would limit fewer than that share of them. Counted among those Gaussians alone, so that a
  // frame whose cameras can decide few of its Gaussians narrows no more readily than one whose
  // cameras decide them all; infinite when there is none (nothing says that the range is too
  // wide).
  double reach = std::numeric_limits<double>::infinity();
  // Per Gaussian, the CostUniqueness of its start on its smoothed cost curve, distinct minima
  // kDistinctMinimumSigmas sigma_hat apart, averaged over the neighbours as the costs are
  // (SweepOptions::smoothing_rounds); 1 where the curve is flat.
  Eigen::VectorXd uniqueness;
};

// Two minima of a cost curve count as distinct this many sigma_hat apart: a surface Gaussian's
// own minimum is about as wide as the Gaussian.
constexpr double kDistinctMinimumSigmas = 2.0;

SweepResult Sweep(FrameEnergy* energy, const SweepOptions& options);

// The starting k (one entry per surface Gaussian, metres). The cost of a Gaussian at a
// displacement is the sum of squares of the residual blocks it belongs to, shared equally
// among the block's parameters.
Eigen::VectorXd SweepInitialization(FrameEnergy* energy, const SweepOptions& options);

// The start of the detail stage's first pass (SweepOptions::detail_range_sigmas): each Gaussian s
// tries the displacements k_s + d, d evenly spaced over [-range, range] at most `step` apart
// (every Gaussian moved by the same d at once, as the plane sweep moves them), costed by the data
// terms that offer sweep costs; the costs are averaged over `smoothing_rounds` rounds of mesh
// neighbours, and s moves to its lowest, refined to the vertex of the parabola through it and
// its neighbours, within the energy's bound. A Gaussian whose costs are all equal stays at k_s.
Eigen::VectorXd SweepAround(FrameEnergy* energy, const Eigen::VectorXd& k, double range,
                            double step, int smoothing_rounds);

}  // namespace finecap

#endif  // FINECAP_SWEEP_H_
