// `fresco rephoto`'s outputs: the figures per left-out frame and their spread (mean, median,
// worst), as JSON and as a Markdown table, and each view beside its photo.
#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "pipeline/rephoto/rephoto_run.h"

namespace fresco {

struct RephotoSpread {
  double mean = 0, median = 0, worst = 0;
};

struct RephotoSummary {
  int frames = 0;  // left-out frames scored
  // PSNR over the frames where pixels were compared (worst: lowest); 1 - NCC, completeness
  // (worst: lowest) and paint wall time (worst: longest) over all.
  RephotoSpread psnr_db, one_minus_ncc, completeness, paint_seconds;
};

RephotoSummary SummarizeRephoto(const RephotoResult& result);

// {"project", "settings", "every", "frames_read", "frames_posed", "frames": [...],
//  "summary": {...}} (pretty-printed).
std::string RephotoToJson(const RephotoResult& result, const std::vector<std::string>& settings,
                          int every, const RephotoSummary& summary);

// One table row per left-out frame, then mean, median and worst (Markdown).
std::string RephotoToMarkdown(const RephotoResult& result, const RephotoSummary& summary);

// The render (left) beside the photo (right), CV_8UC3, with a caption strip naming the
// frame and its figures.
cv::Mat SideBySide(const RephotoFrame& frame, const cv::Mat& rendered_bgr,
                   const cv::Mat& photo_bgr);

}  // namespace fresco
