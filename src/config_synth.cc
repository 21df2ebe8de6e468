#include "finecap/config.h"

namespace finecap {

void AddSynthKeys(SynthOptions* /*options*/, ConfigSchema* /*schema*/) {}

}  // namespace finecap
