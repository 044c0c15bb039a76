// The distribution of a suite's figures: per family and over all captures, the median and
// the worst of each figure (lowest PSNR, coverage, static texels painted and fps; highest
// 1-NCC and mover leak; mover leak and static texels painted over the captures that have
// movers only). Written as JSON and as a text table.
#pragma once

#include <string>
#include <vector>

#include "pipeline/eval/eval_run.h"

namespace fresco {

struct FigureSpread {
  double median = 0, worst = 0;
  int count = 0;  // captures it is taken over (0: none, e.g. no movers in the family)
};

struct FamilySummary {
  std::string family;  // "all" for the whole suite
  int captures = 0;
  FigureSpread truth_psnr_db, truth_one_minus_ncc, psnr_db, one_minus_ncc, mover_leak, paint_fps,
      coverage;
  // Captures with movers: the static texels painted (CaptureEval::open_coverage; the worst is
  // the lowest).
  FigureSpread static_texels_painted;
  // With EvalOptions::recovery: the share of the PSNR lost to pose noise that is recovered
  // (noisy captures), and truth PSNR against refinement off on captures with exact poses (dB;
  // the worst is the lowest).
  FigureSpread recovered, exact_poses_gain_db;
};

// Families in order of first appearance, then "all".
std::vector<FamilySummary> SummarizeByFamily(const std::vector<CaptureEval>& results);

// {"settings": [...], "captures": [...], "families": [...]} (pretty-printed).
std::string EvalToJson(const std::vector<std::string>& settings,
                       const std::vector<CaptureEval>& results,
                       const std::vector<FamilySummary>& families);

// Per capture one line, then per family median and worst (Markdown tables); where captures
// have movers, a line each on the static scene painted and why movers were; with
// EvalOptions::recovery also what refinement recovers.
std::string EvalToText(const std::vector<CaptureEval>& results,
                       const std::vector<FamilySummary>& families);

}  // namespace fresco
