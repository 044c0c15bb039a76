// Plain structs every pipeline stage fills for each frame: wall time, named metrics and,
// when asked, debug images. The CLI (metrics.json, stages/) and the GUI's stage panels both
// read these; the pipeline never calls either.
#pragma once

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

struct FrameReport {
  int frame = -1;
  std::string name;
  bool painted = false;          // false when skipped (no pose, update_every, ...)
  std::string skipped_reason;    // why not painted
  std::vector<StageReport> stages;
  double total_ms = 0.0;

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
