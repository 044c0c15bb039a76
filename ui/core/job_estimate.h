// How long a job has run and how long it may still take, for the panels' progress lines
// (calibration solve, COLMAP's steps, the New project bootstrap, seeking): the remaining time
// is extrapolated from the fraction done so far, assuming the rest goes at the same pace.
// Plain text from plain numbers: no clock is read here (the callers pass the elapsed time).
#pragma once

#include <string>

namespace fresco {

// "12 s", "3:07" (minutes:seconds) or "1:02:03"; negative or NaN: "?".
std::string DurationText(double seconds);

// The seconds left of a job `fraction` done (0..1) after `elapsed_s`: elapsed * (1 - f) / f;
// -1 when it cannot be told yet (under 1 % done or under a second elapsed).
double RemainingSeconds(double elapsed_s, double fraction);

// Under this many seconds left a job is finishing: no estimate is shown (never "about 0 s
// left").
inline constexpr double kFinishingBelowSeconds = 0.5;

// "1:23 elapsed, about 2:10 left"; "1:23 elapsed, finishing" at the end (all done, or under
// kFinishingBelowSeconds left); "1:23 elapsed" when the remaining time cannot be told yet.
std::string ElapsedAndRemainingText(double elapsed_s, double fraction);

}  // namespace fresco
