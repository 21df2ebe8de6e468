#include "finecap/energy/terms/temporal/temporal_options.h"

namespace finecap {

const OptionFields<TemporalOptions>& TemporalOptions::Fields() {
  static const OptionFields<TemporalOptions> fields = [] {
    OptionFields<TemporalOptions> f;
    f.AddDouble("weight", &TemporalOptions::weight,
                "Strength of a pull of k towards the frame before's solved k (temporal "
                "coherence), in units of the median data curvature (not in the paper; 0: off; 0.3 "
                "recommended).",
                0.0, 1e6);
    return f;
  }();
  return fields;
}

void TemporalOptions::Check() const { Fields().CheckValues(*this, "TemporalOptions::"); }

}  // namespace finecap
