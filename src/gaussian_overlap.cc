#include "finecap/gaussian_overlap.h"

#include "finecap/error.h"

namespace finecap {

OverlapForm ParseOverlapForm(const std::string& name) {
  if (name == "printed") return OverlapForm::kPrinted;
  if (name == "exact") return OverlapForm::kExact;
  if (name == "patch") return OverlapForm::kPatch;
  throw Error("energy.overlap", "'" + name + "' is not one of: printed, exact, patch");
}

}  // namespace finecap
