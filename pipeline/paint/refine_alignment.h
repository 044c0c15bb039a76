// Texture alignment refinement (paper §3.5): tracked poses are never exact, so the frame,
// warped into a base buffer through the model (frame_warp.h), is registered to what the
// buffer already holds with a 2D transform and warped again before painting.
//
// Two methods:
//  - kPaper: the paper's. Harris corners on the warped frame, SSD matching in a search
//    window of the buffer (integer texels), least-squares affine over all matches.
//  - kRobust (default): corners (Shi-Tomasi), pyramidal Lucas-Kanade (coarse to fine,
//    sub-texel) with a forward-backward check, RANSAC, and motion-model selection: none,
//    translation, similarity, affine or homography, each fitted to the inliers and chosen
//    by BIC (residual against parameters), so a frame gets only the model it needs.
// Both fall back to no correction, with the reason, when there are too few or collinear
// corners, when the fit would shrink, stretch or flip the image, or when the correction is
// larger than the search window. Repetitive texture: a match whose template matches nearly as
// well elsewhere in the search window (a period away) is dropped; when most are, the buffer
// gets no correction ("repetitive texture: ...") rather than one a period off.
//
// Coordinates: texel (column, row) of the buffer; buffer_from_warped maps a position in the
// warped frame to where it belongs in the buffer (eq. 6, with a homography as the most
// general case).
#pragma once

#include <map>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "pipeline/core/project.h"

namespace fresco {

enum class MotionModel { kNone, kTranslation, kSimilarity, kAffine, kHomography };
std::string MotionModelName(MotionModel model);

struct RefineEstimate {
  bool applied = false;  // a correction was estimated and passed every check
  bool registered = false;  // applied, or the matches showed no correction is needed
  std::string fallback;  // why not, when not ("too few corners", ...)
  MotionModel model = MotionModel::kNone;
  // The correction measured (also when too small to apply: registered but not applied).
  cv::Matx33d buffer_from_warped = cv::Matx33d::eye();
  int corners = 0, matches = 0, inliers = 0;
  // Matches dropped because another place in the search window matched nearly as well
  // (repetitive texture: the nearest copy may be a period off). Paper mode checks every
  // match; robust mode a sample of the tracked ones (kAmbiguitySamples).
  int ambiguous = 0;
  double residual_before_px = 0;      // RMS over inliers, identity
  double residual_after_px = 0;       // RMS over inliers, chosen model
  double correction_px = 0;           // largest displacement of the region's corners
  std::map<std::string, double> bic;  // per model tried (lower is better)
  // For debug images: matched positions (warped -> buffer) and which are inliers.
  std::vector<cv::Point2f> from, to;
  std::vector<uchar> inlier;
  cv::Rect region;  // where the warped frame and the painted buffer overlap
};

// RMS distance (texels) between H(from) and `to` over the estimate's inliers; 0 without any.
double InlierResidualPx(const RefineEstimate& estimate, const cv::Matx33d& H);

// `warped_bgr`, `warped_valid`: the frame warped into the buffer (CV_8UC3, CV_8U);
// `buffer_bgra`: the buffer as painted so far (alpha 255 = painted); `within` (optional):
// bounds every valid warped texel (WarpedBuffer::valid_box), so that only it is scanned.
RefineEstimate EstimateRefinement(const cv::Mat& warped_bgr, const cv::Mat& warped_valid,
                                  const cv::Mat& buffer_bgra, const RefineOptions& options,
                                  cv::Rect within = cv::Rect());

// Warps the frame's buffer images again with the estimate (bgr bicubic; valid and quality
// nearest, valid eroded by a texel so that no sample blends with unseen texels). Only
// `within` (every valid texel: WarpedBuffer::valid_box; empty = everywhere) plus a margin is
// touched: the correction applies to the whole frame, also where the buffer is unpainted.
// Returns what now bounds every valid texel (`within`, grown by the margin when applied).
cv::Rect ApplyRefinement(const RefineEstimate& estimate, const cv::Rect& within, cv::Mat* warped_bgr,
                     cv::Mat* warped_valid, cv::Mat* warped_quality);

// Debug images: the warped frame with its corners and matches drawn (inliers green,
// outliers red), and a heat map of |grey difference| between the warped frame and the
// buffer over the region (before or after the correction).
cv::Mat DrawRefinementMatches(const cv::Mat& warped_bgr, const RefineEstimate& estimate);
cv::Mat ResidualHeatMap(const cv::Mat& warped_bgr, const cv::Mat& warped_valid,
                        const cv::Mat& buffer_bgra, const cv::Rect& region);

}  // namespace fresco
