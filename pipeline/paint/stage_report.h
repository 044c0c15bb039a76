// Plain structs every pipeline stage fills for each frame: wall time, named metrics and,
// when asked, debug images. The CLI (metrics.json, stages/) and the GUI's stage panels both
// read these; the pipeline never calls either.
//
// Figures that other code reads back as data (the time-offset estimation, the app's
// misalignment and refinement plots) are typed fields (PaintFigures, RefineFigures): a
// rename does not compile, where a string key would silently read NaN. The stage's
// `metrics` map shows them too (panels, metrics.json), made from the typed struct.
#pragma once

#include <limits>
#include <map>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace fresco {

struct StageReport {
  std::string name;                        // "depth", "warp", "paint", ...
  double wall_ms = 0.0;
  std::map<std::string, double> metrics;   // e.g. {"texels_visible", 12345}
  std::map<std::string, cv::Mat> images;   // debug images (BGR or gray), only when asked
  std::map<std::string, std::string> notes;  // words: chosen model, why no correction, ...
};

// The paint stage's figures read back as data.
struct PaintFigures {
  // Mean |grey difference| between the frame and what the buffers held, where both exist
  // (grey levels, 0..255): a cheap misalignment signal (pose error, time offset, exposure
  // change, movers). NaN when nothing was compared.
  double difference_to_buffer = std::numeric_limits<double>::quiet_NaN();

  // Shows the figures in the paint stage's metrics (the names are the fields').
  void PutInto(StageReport* paint) const {
    paint->metrics["difference_to_buffer"] = difference_to_buffer;
  }
};

// The refine stage's figures read back as data (when the stage ran).
struct RefineFigures {
  // RMS residual over all inliers, texels: with no correction (before) and with the chosen
  // corrections (after). NaN when nothing was matched.
  double residual_before_px = std::numeric_limits<double>::quiet_NaN();
  double residual_after_px = std::numeric_limits<double>::quiet_NaN();

  void PutInto(StageReport* refine) const {
    refine->metrics["residual_before_px"] = residual_before_px;
    refine->metrics["residual_after_px"] = residual_after_px;
  }
};

struct FrameReport {
  int frame = -1;
  std::string name;
  bool painted = false;          // false when skipped (no pose, update_every, ...)
  std::string skipped_reason;    // why not painted
  std::vector<StageReport> stages;
  double total_ms = 0.0;
  PaintFigures paint;    // when painted
  RefineFigures refine;  // when the refine stage ran (Stage("refine") != nullptr)

  StageReport* Stage(const std::string& name) {
    for (auto& s : stages)
      if (s.name == name) return &s;
    return nullptr;
  }
  const StageReport* Stage(const std::string& name) const {
    for (const auto& s : stages)
      if (s.name == name) return &s;
    return nullptr;
  }
};

}  // namespace fresco
