// Line plots rendered to PNG by gnuplot, for the evaluation report (error per frame, energy per
// iteration, solvers side by side).
#ifndef FINECAP_UTIL_PLOT_H_
#define FINECAP_UTIL_PLOT_H_

#include <string>
#include <vector>

namespace finecap {

// One named curve of a line plot. `x` and `y` have the same length; a non-finite value leaves a
// gap in the curve (e.g. a frame with no ground truth).
struct PlotSeries {
  std::string name;  // Legend entry; any text, shown literally.
  std::vector<double> x;
  std::vector<double> y;
};

struct PlotOptions {
  // Title above the plot and axis labels; any text, shown literally (no gnuplot markup).
  // Default: empty (none drawn).
  std::string title;
  std::string x_label;
  std::string y_label;
  // Logarithmic y axis, for errors or energies spanning decades; points with y <= 0 are then
  // left out by gnuplot. Default false.
  bool log_y = false;
  // Size of the PNG image in pixels, each in [16, 16384]. Default 800 x 500.
  int width = 800;
  int height = 500;
  // The gnuplot program: a name looked up in PATH, or a path. Default "gnuplot".
  std::string gnuplot = "gnuplot";

  // Throws Error naming the invalid field.
  void Check() const;
};

// The PNG terminal `gnuplot` offers: "pngcairo" (antialiased) when available, else "png". Asks
// gnuplot once per program per process and remembers the answer. Throws Error when gnuplot
// cannot be run.
std::string PngTerminal(const std::string& gnuplot = "gnuplot");

// Draws every series as lines with points in one plot with a legend and writes it to
// `png_path` atomically (see atomic_file.h). The data and all text reach gnuplot as a script on
// its standard input; no shell is involved, so any title or name is safe. Throws Error naming
// `png_path` when there is no series, a series is empty or its x and y differ in length, or
// gnuplot is missing or fails (with gnuplot's own message).
void WriteLinePlot(const std::string& png_path, const std::vector<PlotSeries>& series,
                   const PlotOptions& options = PlotOptions());

}  // namespace finecap

#endif  // FINECAP_UTIL_PLOT_H_
