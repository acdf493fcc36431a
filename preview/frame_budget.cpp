#include "preview/frame_budget.h"

namespace pxf {

bool step_fits_display_frame(double used_ms, bool fresh, double next_ms, double budget_ms) {
  return fresh || used_ms + next_ms <= budget_ms;
}

}  // namespace pxf
