#include "finecap/util/plot.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <mutex>
#include <sstream>

#include "finecap/util/atomic_file.h"
#include "finecap/util/error.h"
#include "util/io_util.h"

extern char** environ;

namespace finecap {
namespace {

// A uniquely named empty file in the system temp folder, removed when this goes out of scope.
class ScratchFile {
 public:
  explicit ScratchFile(const std::string& stem) {
    std::string pattern =
        (std::filesystem::temp_directory_path() / ("finecap-" + stem + "-XXXXXX")).string();
    const int fd = mkstemp(pattern.data());
    Require(fd >= 0, pattern, std::string("cannot create a temporary file: ") + strerror(errno));
    close(fd);
    path_ = pattern;
  }
  ~ScratchFile() { std::remove(path_.c_str()); }
  ScratchFile(const ScratchFile&) = delete;
  ScratchFile& operator=(const ScratchFile&) = delete;

  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

struct GnuplotRun {
  int exit_status = 0;  // 0 on success.
  std::string output;   // What gnuplot printed (errors, warnings, `print`).
};

void WaitForChild(pid_t child, const std::string& program, int* status) {
  while (waitpid(child, status, 0) < 0) {
    Require(errno == EINTR, program, std::string("cannot wait for gnuplot: ") + strerror(errno));
  }
}

// Runs `program` with `script` on its standard input; stdout and stderr are both captured.
// The script goes through a file rather than a pipe so that a chatty gnuplot cannot deadlock
// against a parent still writing the script.
GnuplotRun RunGnuplot(const std::string& program, const std::string& script) {
  ScratchFile script_file("plot-script"), output_file("plot-output");
  WriteTextFileAtomically(script_file.path(), script);

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, script_file.path().c_str(), O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, output_file.path().c_str(),
                                   O_WRONLY | O_TRUNC, 0);
  posix_spawn_file_actions_adddup2(&actions, STDERR_FILENO, STDOUT_FILENO);
  std::string program_argument = program;
  char* argv[] = {program_argument.data(), nullptr};
  pid_t child = 0;
  const int spawn_error = posix_spawnp(&child, program.c_str(), &actions, nullptr, argv, environ);
  posix_spawn_file_actions_destroy(&actions);
  Require(spawn_error == 0, program,
          std::string("cannot run gnuplot: ") + strerror(spawn_error) +
              " (install gnuplot, e.g. the gnuplot-nox package)");

  int status = 0;
  WaitForChild(child, program, &status);
  GnuplotRun run;
  run.exit_status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  run.output = internal::ReadWholeFile(output_file.path());
  return run;
}

std::string Trimmed(const std::string& text) {
  const size_t first = text.find_first_not_of(" \t\r\n");
  if (first == std::string::npos) return "";
  return text.substr(first, text.find_last_not_of(" \t\r\n") - first + 1);
}

std::string DetectPngTerminal(const std::string& gnuplot) {
  const GnuplotRun run = RunGnuplot(gnuplot, "print GPVAL_TERMINALS\n");
  Require(run.exit_status == 0, gnuplot,
          "gnuplot cannot list its terminals: " + Trimmed(run.output));
  std::istringstream terminals(run.output);
  std::string terminal;
  while (terminals >> terminal) {
    if (terminal == "pngcairo") return terminal;
  }
  return "png";
}

// Letters, digits and punctuation that mean nothing to gnuplot, judged without the locale.
bool IsPlainAscii(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
         (c != '\0' && std::strchr(" .,-_/:()+=", c) != nullptr);
}

// `text` as a gnuplot double-quoted string in which every character but letters, digits and a
// few harmless punctuation marks is an octal escape. Gnuplot splits command lines at ';' and
// expands backquotes before it parses strings, so quotes, ';' or '`' must not appear raw at
// all; UTF-8 passes through byte by byte. A NUL or line break becomes a space.
std::string GnuplotString(const std::string& text) {
  std::string quoted = "\"";
  for (char c : text) {
    const unsigned char byte = static_cast<unsigned char>(c);
    if (c == '\0' || c == '\n' || c == '\r') {
      quoted += ' ';
    } else if (IsPlainAscii(c)) {
      quoted += c;
    } else {
      char escape[5];
      std::snprintf(escape, sizeof(escape), "\\%03o", byte);
      quoted += escape;
    }
  }
  return quoted + "\"";
}

std::string GnuplotNumber(double value) {
  if (!std::isfinite(value)) return "NaN";
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.17g", value);
  return buffer;
}

void CheckSeries(const std::string& png_path, const std::vector<PlotSeries>& series) {
  Require(!series.empty(), png_path, "no series to plot");
  for (const PlotSeries& s : series) {
    Require(s.x.size() == s.y.size(), png_path,
            "series '" + s.name + "' has " + std::to_string(s.x.size()) + " x values but " +
                std::to_string(s.y.size()) + " y values");
    Require(!s.x.empty(), png_path, "series '" + s.name + "' has no points");
  }
}

// Each series becomes an inline data block $series<i>, so no data file is needed.
void AppendDataBlocks(const std::vector<PlotSeries>& series, std::ostringstream* script) {
  for (size_t i = 0; i < series.size(); ++i) {
    *script << "$series" << i << " << EOD\n";
    for (size_t p = 0; p < series[i].x.size(); ++p) {
      *script << GnuplotNumber(series[i].x[p]) << ' ' << GnuplotNumber(series[i].y[p]) << '\n';
    }
    *script << "EOD\n";
  }
}

std::string PlotScript(const std::string& output_path, const std::vector<PlotSeries>& series,
                       const PlotOptions& options) {
  std::ostringstream script;
  // noenhanced: titles are shown literally instead of being read as gnuplot text markup.
  script << "set terminal " << PngTerminal(options.gnuplot) << " size " << options.width << ','
         << options.height << " noenhanced\n"
         << "set output " << GnuplotString(output_path) << '\n'
         << "set title " << GnuplotString(options.title) << '\n'
         << "set xlabel " << GnuplotString(options.x_label) << '\n'
         << "set ylabel " << GnuplotString(options.y_label) << '\n'
         << "set datafile missing NaN\n"
         << "set key below\n"
         << "set grid\n";
  if (options.log_y) script << "set logscale y\n";
  AppendDataBlocks(series, &script);
  script << "plot";
  for (size_t i = 0; i < series.size(); ++i) {
    script << (i == 0 ? " " : ", ") << "$series" << i
           << " using 1:2 with linespoints pointsize 0.6 title " << GnuplotString(series[i].name);
  }
  script << "\nunset output\n";
  return script.str();
}

}  // namespace

void PlotOptions::Check() const {
  const std::string where = "plot options";
  Require(width >= 16 && width <= 16384, where,
          "width " + std::to_string(width) + " is outside [16, 16384] pixels");
  Require(height >= 16 && height <= 16384, where,
          "height " + std::to_string(height) + " is outside [16, 16384] pixels");
  Require(!gnuplot.empty(), where, "the gnuplot program is empty");
}

std::string PngTerminal(const std::string& gnuplot) {
  static std::mutex mutex;
  static std::map<std::string, std::string> terminal_of_program;
  std::lock_guard<std::mutex> lock(mutex);
  auto found = terminal_of_program.find(gnuplot);
  if (found == terminal_of_program.end()) {
    found = terminal_of_program.emplace(gnuplot, DetectPngTerminal(gnuplot)).first;
  }
  return found->second;
}

void WriteLinePlot(const std::string& png_path, const std::vector<PlotSeries>& series,
                   const PlotOptions& options) {
  options.Check();
  CheckSeries(png_path, series);
  WriteFileAtomically(png_path, [&](const std::string& temporary_path) {
    try {
      const GnuplotRun run =
          RunGnuplot(options.gnuplot, PlotScript(temporary_path, series, options));
      Require(run.exit_status == 0, png_path,
              "gnuplot failed (exit status " + std::to_string(run.exit_status) +
                  "): " + Trimmed(run.output));
      std::error_code error;
      Require(std::filesystem::file_size(temporary_path, error) > 0 && !error, png_path,
              "gnuplot wrote no image: " + Trimmed(run.output));
    } catch (const Error& error) {
      // Failures of gnuplot itself name the program; the caller wants the output file.
      const std::string message = error.what();
      if (message.rfind(png_path, 0) == 0) throw;
      throw Error(png_path, message);
    }
  });
}

}  // namespace finecap
