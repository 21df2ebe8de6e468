// Options of the temporal term (src/energy/terms/temporal/temporal_term.h), the config section
// `energy.temporal`. The fields are documented where Fields() declares them; the comments below
// add what the documentation does not say.
#ifndef FINECAP_ENERGY_TERMS_TEMPORAL_TEMPORAL_OPTIONS_H_
#define FINECAP_ENERGY_TERMS_TEMPORAL_TEMPORAL_OPTIONS_H_

#include "finecap/util/option_fields.h"

namespace finecap {

struct TemporalOptions {
  // The frame before's displacement along its normal is carried to this frame by the input's own
  // motion: the same k on this frame's surface. Read from the saved files of that frame (as
  // refine.warm_start is), so that a resumed run pulls its first frame as an uninterrupted run
  // does; the first frame of a capture, or one whose predecessor is not done (a shard run beside
  // the one before it), is not pulled. Off by default: with the pull a sequence is one chain, so
  // shards run side by side (a Slurm array) would no longer equal one process at their first
  // frames; a single process or shards run in turn get the same result with it.
  double weight = 0.0;

  bool IsOn() const { return weight > 0.0; }
  static const OptionFields<TemporalOptions>& Fields();  // option_fields.h
  void Check() const;
};

}  // namespace finecap

#endif  // FINECAP_ENERGY_TERMS_TEMPORAL_TEMPORAL_OPTIONS_H_
