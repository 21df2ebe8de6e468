// The subcommands of the `finecap` command line. Each takes a fully loaded configuration (the
// command line has already merged the YAML file and the flags), does its job, and returns the
// process exit code. Bad input raises finecap::Error; the command line prints it and exits 1.
#ifndef FINECAP_COMMANDS_H_
#define FINECAP_COMMANDS_H_

#include "finecap/config.h"

namespace finecap {

// Loads the capture, refines the configured frames and writes the results to output.dir.
int RunRefine(const Config& config);

// Generates a synthetic capture with ground truth (section synth) into output.dir.
int RunSynth(const Config& config);

}  // namespace finecap

#endif  // FINECAP_COMMANDS_H_
