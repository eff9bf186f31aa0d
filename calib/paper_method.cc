#include "calib/paper_method.h"

#include "data/error.h"

namespace kincal {

// Placeholder until the direct search lands: refuses instead of pretending.
FitSummary FitPaperObjective(const std::vector<Measurement>&,
                             const PaperOptions&, ModelState*) {
  throw InputError("--method paper is not available in this build yet");
}

}  // namespace kincal
