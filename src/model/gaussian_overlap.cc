#include "finecap/model/gaussian_overlap.h"

namespace finecap {

const std::vector<EnumName<OverlapForm>>& EnumNames(OverlapForm) {
  static const std::vector<EnumName<OverlapForm>> names = {{OverlapForm::kPrinted, "printed"},
                                                           {OverlapForm::kExact, "exact"},
                                                           {OverlapForm::kPatch, "patch"}};
  return names;
}

}  // namespace finecap
