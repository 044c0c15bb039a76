#include "ui/core/job_estimate.h"

#include <cmath>
#include <cstdio>

namespace fresco {

std::string DurationText(double seconds) {
  if (!(seconds >= 0)) return "?";
  const long total = std::lround(seconds);
  char text[40];
  if (total < 60) {
    std::snprintf(text, sizeof(text), "%ld s", total);
  } else if (total < 3600) {
    std::snprintf(text, sizeof(text), "%ld:%02ld", total / 60, total % 60);
  } else {
    std::snprintf(text, sizeof(text), "%ld:%02ld:%02ld", total / 3600, total / 60 % 60, total % 60);
  }
  return text;
}

double RemainingSeconds(double elapsed_s, double fraction) {
  if (!(elapsed_s >= 1.0) || !(fraction >= 0.01)) return -1.0;
  if (fraction >= 1.0) return 0.0;
  return elapsed_s * (1.0 - fraction) / fraction;
}

std::string ElapsedAndRemainingText(double elapsed_s, double fraction) {
  std::string text = DurationText(elapsed_s) + " elapsed";
  const double remaining = RemainingSeconds(elapsed_s, fraction);
  // At the end "about 0 s left" would stand while what follows the last step runs: the job
  // is finishing.
  if (remaining >= kFinishingBelowSeconds)
    text += ", about " + DurationText(remaining) + " left";
  else if (remaining >= 0)
    text += ", finishing";
  return text;
}

}  // namespace fresco
