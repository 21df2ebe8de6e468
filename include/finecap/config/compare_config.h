// The `compare` section of a config: the variants of the refinement that `finecap compare` runs
// side by side on the same frames of the same capture, each a set of config overrides on top of
// the rest of the config.
//
//   compare:
//     reference: ceres            # the variant whose time the others are divided by
//     variants:
//       - name: ceres             # also the name of its output folder, output.dir/ceres/
//       - name: gradient_ascent
//         set: {solver.type: gradient_ascent, solver.max_iterations: 150}
//
// `set` is a mapping of config keys (dotted, or nested as in the file) to values; every key and
// value is checked against the config schema when the config is read, so a wrong key is an error
// naming the config file and the variant.
#ifndef FINECAP_CONFIG_COMPARE_CONFIG_H_
#define FINECAP_CONFIG_COMPARE_CONFIG_H_

#include <string>
#include <utility>
#include <vector>

namespace finecap {

// One variant of a comparison.
struct CompareVariant {
  // Name in tables, plots and the output folder: letters, digits, '_', '-', '.'; not starting
  // with '.'; unique within a comparison.
  std::string name;
  // Config key (dotted path) and value (YAML text), applied in order on top of the config.
  std::vector<std::pair<std::string, std::string>> settings;
  // Where the variant was given, for errors, e.g. "configs/x.yaml: key 'compare.variants',
  // variant 'lbfgs'".
  std::string source;
};

struct CompareConfig {
  // The variants, in the order of the tables. Default: none (`finecap compare` then refuses to
  // run).
  std::vector<CompareVariant> variants;
  // Name of the variant whose median time per frame the others' are divided by; "" = the first
  // variant whose solver is gradient_ascent (the paper's), or the first variant when none is.
  // Default "".
  std::string reference;

  // Throws Error when `reference` names no variant or two variants share a name.
  void Check() const;
};

// Keys a variant may not set: they say what is compared and where it goes, which all variants
// share (capture.*, output.dir, compare.*).
bool IsSharedComparisonKey(const std::string& path);

}  // namespace finecap

#endif  // FINECAP_CONFIG_COMPARE_CONFIG_H_
