#include "pipeline/paint/refine_alignment.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

namespace fresco {
namespace {

cv::Mat Grey(const cv::Mat& image) {
  cv::Mat grey;
  cv::cvtColor(image, grey, image.channels() == 4 ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGR2GRAY);
  return grey;
}

cv::Point2d Apply(const cv::Matx33d& H, const cv::Point2d& p) {
  const double w = H(2, 0) * p.x + H(2, 1) * p.y + H(2, 2);
  return {(H(0, 0) * p.x + H(0, 1) * p.y + H(0, 2)) / w,
          (H(1, 0) * p.x + H(1, 1) * p.y + H(1, 2)) / w};
}

double SumSquared(const cv::Matx33d& H, const std::vector<cv::Point2f>& from,
                  const std::vector<cv::Point2f>& to) {
  double sum = 0;
  for (size_t i = 0; i < from.size(); ++i) {
    const cv::Point2d d = Apply(H, from[i]) - cv::Point2d(to[i]);
    sum += d.dot(d);
  }
  return sum;
}

int NumParams(MotionModel m) {
  switch (m) {
    case MotionModel::kNone:
      return 0;
    case MotionModel::kTranslation:
      return 2;
    case MotionModel::kSimilarity:
      return 4;
    case MotionModel::kAffine:
      return 6;
    case MotionModel::kHomography:
      return 8;
  }
  return 0;
}

// Least squares fit of `model` to the matches (coordinates centred on `centre` for
// conditioning). Returns false when the system is degenerate.
bool FitModel(MotionModel model, const std::vector<cv::Point2f>& from,
              const std::vector<cv::Point2f>& to, const cv::Point2d& centre, cv::Matx33d* H) {
  const int n = static_cast<int>(from.size());
  const cv::Matx33d shift(1, 0, -centre.x, 0, 1, -centre.y, 0, 0, 1);
  const cv::Matx33d unshift(1, 0, centre.x, 0, 1, centre.y, 0, 0, 1);
  cv::Matx33d M = cv::Matx33d::eye();
  if (model == MotionModel::kNone) {
    *H = M;
    return true;
  }
  if (model == MotionModel::kTranslation) {
    cv::Point2d t(0, 0);
    for (int i = 0; i < n; ++i) t += cv::Point2d(to[i] - from[i]);
    M(0, 2) = t.x / n;
    M(1, 2) = t.y / n;
    *H = M;
    return n > 0;
  }
  if (model == MotionModel::kHomography) {
    std::vector<cv::Point2f> a(n), b(n);
    for (int i = 0; i < n; ++i) {
      a[i] = from[i] - cv::Point2f(centre);
      b[i] = to[i] - cv::Point2f(centre);
    }
    const cv::Mat h = cv::findHomography(a, b, 0);
    if (h.empty()) return false;
    *H = unshift * cv::Matx33d(h) * shift;
    return true;
  }
  // Similarity: x' = a x - b y + tx, y' = b x + a y + ty; affine: six free parameters.
  const bool similarity = model == MotionModel::kSimilarity;
  const int k = similarity ? 4 : 6;
  cv::Mat A(2 * n, k, CV_64F, cv::Scalar(0)), rhs(2 * n, 1, CV_64F);
  for (int i = 0; i < n; ++i) {
    const double x = from[i].x - centre.x, y = from[i].y - centre.y;
    double* r0 = A.ptr<double>(2 * i);
    double* r1 = A.ptr<double>(2 * i + 1);
    if (similarity) {
      r0[0] = x, r0[1] = -y, r0[2] = 1;
      r1[0] = y, r1[1] = x, r1[3] = 1;
    } else {
      r0[0] = x, r0[1] = y, r0[2] = 1;
      r1[3] = x, r1[4] = y, r1[5] = 1;
    }
    rhs.at<double>(2 * i) = to[i].x - centre.x;
    rhs.at<double>(2 * i + 1) = to[i].y - centre.y;
  }
  // Through the normal equations (k x k): OpenCV hands an SVD of 25 rows or more to LAPACK
  // when built with it, whose last bits then depend on where its buffers lie in memory
  // (refinement must give the same result every run); its own small SVD does not.
  cv::Mat p;
  if (!cv::solve(A, rhs, p, cv::DECOMP_SVD | cv::DECOMP_NORMAL)) return false;
  const double* q = p.ptr<double>();
  if (similarity)
    M = cv::Matx33d(q[0], -q[1], q[2], q[1], q[0], q[3], 0, 0, 1);
  else
    M = cv::Matx33d(q[0], q[1], q[2], q[3], q[4], q[5], 0, 0, 1);
  *H = unshift * M * shift;
  return true;
}

// The checks a correction must pass; "" when it does.
std::string Check(const cv::Matx33d& H, const cv::Rect& region, const RefineOptions& options,
                  double* correction_px) {
  const cv::Matx22d A(H(0, 0) / H(2, 2), H(0, 1) / H(2, 2), H(1, 0) / H(2, 2), H(1, 1) / H(2, 2));
  if (cv::determinant(A) <= 0) return "fit would flip the image";
  cv::Mat w;
  cv::SVD::compute(cv::Mat(A), w);
  const double s1 = w.at<double>(0), s2 = w.at<double>(1);
  const double limit = options.max_scale_change;
  if (s1 > 1 + limit || s2 < 1 - limit) return "fit would scale or shear the image";
  *correction_px = 0;
  const cv::Point2d corners[4] = {{double(region.x), double(region.y)},
                                  {double(region.br().x), double(region.y)},
                                  {double(region.br().x), double(region.br().y)},
                                  {double(region.x), double(region.br().y)}};
  for (const cv::Point2d& c : corners) {
    const cv::Point2d m = Apply(H, c);
    if (!std::isfinite(m.x) || !std::isfinite(m.y)) return "fit is not finite";
    *correction_px = std::max(*correction_px, cv::norm(m - c));
  }
  if (*correction_px > options.search_px) return "correction larger than the search window";
  return "";
}

// Repetitive texture: whether another place of the search window matches the template nearly
// as well as the best, so that the best (or the tracker's nearest) may be a period off.
// `ssd`: the template's SSD over the window (TM_SQDIFF), `best` its minimum. Nearly as good:
// a local minimum at least 2 texels from the best (not a slope of the best's own basin) whose
// excess over the best is below kAmbiguity of the median excess (what a mismatch costs here).
constexpr double kAmbiguity = 0.25;
bool Ambiguous(const cv::Mat& ssd, const cv::Point& best) {
  const float least = ssd.at<float>(best);
  std::vector<float> values(ssd.begin<float>(), ssd.end<float>());
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  const double limit = least + kAmbiguity * (values[values.size() / 2] - least);
  for (int y = 0; y < ssd.rows; ++y) {
    for (int x = 0; x < ssd.cols; ++x) {
      const float v = ssd.at<float>(y, x);
      if (v > limit || std::max(std::abs(x - best.x), std::abs(y - best.y)) < 2) continue;
      bool minimum = true;
      for (int dy = -1; dy <= 1 && minimum; ++dy)
        for (int dx = -1; dx <= 1 && minimum; ++dx) {
          const cv::Point n(x + dx, y + dy);
          if (n.x >= 0 && n.y >= 0 && n.x < ssd.cols && n.y < ssd.rows && ssd.at<float>(n) < v)
            minimum = false;
        }
      if (minimum) return true;
    }
  }
  return false;
}

// Matches by the paper: SSD of a (2w+1)^2 template in a +-search window, integer texels.
// Ambiguous matches are counted in `ambiguous`, not kept.
void MatchSsd(const cv::Mat& grey_w, const cv::Mat& grey_b, const cv::Mat& overlap,
              const std::vector<cv::Point2f>& corners, const RefineOptions& options,
              std::vector<cv::Point2f>* from, std::vector<cv::Point2f>* to, int* ambiguous) {
  const int w = options.window_px, s = options.search_px;
  const cv::Rect image(0, 0, grey_w.cols, grey_w.rows);
  for (const cv::Point2f& c : corners) {
    const cv::Point p(cvRound(c.x), cvRound(c.y));
    const cv::Rect templ(p.x - w, p.y - w, 2 * w + 1, 2 * w + 1);
    const cv::Rect search(p.x - w - s, p.y - w - s, 2 * (w + s) + 1, 2 * (w + s) + 1);
    if ((templ & image) != templ || (search & image) != search) continue;
    cv::Mat ssd;
    cv::matchTemplate(grey_b(search), grey_w(templ), ssd, cv::TM_SQDIFF);
    cv::Point best;
    cv::minMaxLoc(ssd, nullptr, nullptr, &best);
    const cv::Point2f found(static_cast<float>(search.x + best.x + w),
                            static_cast<float>(search.y + best.y + w));
    if (!overlap.at<uchar>(cvRound(found.y), cvRound(found.x))) continue;
    if (Ambiguous(ssd, best)) {
      ++*ambiguous;
      continue;
    }
    from->push_back(cv::Point2f(p));
    to->push_back(found);
  }
}

// Whether the template of the corner at `p` matches the buffer ambiguously within the
// +-search window (clipped to the image).
bool AmbiguousAt(const cv::Mat& grey_w, const cv::Mat& grey_b, const cv::Point& p,
                 const RefineOptions& options) {
  const int w = options.window_px, s = options.search_px;
  const cv::Rect image(0, 0, grey_w.cols, grey_w.rows);
  const cv::Rect templ(p.x - w, p.y - w, 2 * w + 1, 2 * w + 1);
  const cv::Rect search =
      cv::Rect(p.x - w - s, p.y - w - s, 2 * (w + s) + 1, 2 * (w + s) + 1) & image;
  if ((templ & image) != templ) return false;
  cv::Mat ssd;
  cv::matchTemplate(grey_b(search), grey_w(templ), ssd, cv::TM_SQDIFF);
  cv::Point best;
  cv::minMaxLoc(ssd, nullptr, nullptr, &best);
  return Ambiguous(ssd, best);
}

// Pyramidal Lucas-Kanade (coarse to fine, sub-texel) with a forward-backward check. The
// tracker converges to the nearest copy of a repetitive texture: the template of up to
// kAmbiguitySamples matches (evenly spread over the tracked ones; each check is a full SSD
// search) is compared over the search window; ambiguous ones are counted in `ambiguous`
// (out of `checked`) and not kept.
constexpr int kAmbiguitySamples = 24;
void MatchLk(const cv::Mat& grey_w, const cv::Mat& grey_b, const cv::Mat& overlap,
             const std::vector<cv::Point2f>& corners, const RefineOptions& options,
             std::vector<cv::Point2f>* from, std::vector<cv::Point2f>* to, int* ambiguous,
             int* checked) {
  if (corners.empty()) return;
  std::vector<cv::Point2f> forward, backward;
  std::vector<uchar> ok_f, ok_b;
  std::vector<float> err;
  const cv::Size window(2 * options.window_px + 1, 2 * options.window_px + 1);
  const cv::TermCriteria stop(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 30, 0.01);
  // Both pyramids once, for both directions.
  std::vector<cv::Mat> pyramid_w, pyramid_b;
  const int levels_w =
      cv::buildOpticalFlowPyramid(grey_w, pyramid_w, window, options.pyramid_levels);
  const int levels_b =
      cv::buildOpticalFlowPyramid(grey_b, pyramid_b, window, options.pyramid_levels);
  const int levels = std::min(levels_w, levels_b);
  cv::calcOpticalFlowPyrLK(pyramid_w, pyramid_b, corners, forward, ok_f, err, window, levels, stop);
  cv::calcOpticalFlowPyrLK(pyramid_b, pyramid_w, forward, backward, ok_b, err, window, levels,
                           stop);
  std::vector<size_t> tracked;  // corners the tracker followed both ways into the overlap
  for (size_t i = 0; i < corners.size(); ++i) {
    if (!ok_f[i] || !ok_b[i]) continue;
    if (cv::norm(backward[i] - corners[i]) > 0.5) continue;  // not the same texture both ways
    if (cv::norm(forward[i] - corners[i]) > options.search_px) continue;
    const cv::Point q(cvRound(forward[i].x), cvRound(forward[i].y));
    if (q.x < 0 || q.y < 0 || q.x >= overlap.cols || q.y >= overlap.rows || !overlap.at<uchar>(q))
      continue;
    tracked.push_back(i);
  }
  const size_t n = tracked.size();
  const size_t samples = std::min<size_t>(n, kAmbiguitySamples);
  size_t next_sample = 0;  // sample k is tracked[k * n / samples]
  for (size_t j = 0; j < n; ++j) {
    const size_t i = tracked[j];
    if (next_sample < samples && j == next_sample * n / samples) {
      ++next_sample;
      ++*checked;
      if (AmbiguousAt(grey_w, grey_b, cv::Point(cvRound(corners[i].x), cvRound(corners[i].y)),
                      options)) {
        ++*ambiguous;
        continue;
      }
    }
    from->push_back(corners[i]);
    to->push_back(forward[i]);
  }
}

// Corners of the warped frame within `corner_mask`: Harris at full resolution for the
// paper's mode, else Shi-Tomasi at half resolution (4x fewer texels): the positions only
// seed the tracker, which refines them at full resolution.
std::vector<cv::Point2f> FindCorners(const cv::Mat& grey_w, const cv::Mat& corner_mask,
                                     const RefineOptions& options) {
  std::vector<cv::Point2f> corners;
  if (options.mode == RefineMode::kPaper) {  // Harris, full resolution
    cv::goodFeaturesToTrack(grey_w, corners, options.max_corners, 0.01, options.window_px,
                            corner_mask, 3, options.mode == RefineMode::kPaper, 0.04);
  } else {
    cv::Mat half, half_mask;
    cv::pyrDown(grey_w, half);
    cv::resize(corner_mask, half_mask, half.size(), 0, 0, cv::INTER_NEAREST);
    cv::goodFeaturesToTrack(half, corners, options.max_corners, 0.01,
                            std::max(1, options.window_px / 2), half_mask, 3, false);
    for (cv::Point2f& c : corners) c *= 2.0f;
  }
  return corners;
}

// Collinear (or clustered) corners cannot fix more than a translation reliably: false for
// those; else true with the points' mean in `centre`.
bool WellSpread(std::vector<cv::Point2f>* from, cv::Point2d* centre) {
  cv::Mat points(static_cast<int>(from->size()), 2, CV_32F, from->data());
  cv::Mat covariance, mean;
  cv::calcCovarMatrix(points, covariance, mean,
                      cv::COVAR_NORMAL | cv::COVAR_ROWS | cv::COVAR_SCALE);
  cv::Mat eigen;
  cv::eigen(covariance, eigen);
  const double spread_min = std::sqrt(std::max(0.0, eigen.at<double>(1)));
  const double spread_max = std::sqrt(std::max(0.0, eigen.at<double>(0)));
  if (spread_min < 2.0 || spread_min < 0.05 * spread_max) return false;
  *centre = cv::Point2d(mean.at<double>(0), mean.at<double>(1));
  return true;
}

// Inliers: the paper takes every match; the robust mode, RANSAC on the most general model
// allowed.
std::vector<uchar> FindInliers(const std::vector<cv::Point2f>& from,
                               const std::vector<cv::Point2f>& to, MotionModel most_general,
                               const RefineOptions& options) {
  std::vector<uchar> inlier(from.size(), 1);
  if (options.mode != RefineMode::kRobust) return inlier;
  cv::Mat mask;
  if (most_general == MotionModel::kHomography)
    cv::findHomography(from, to, cv::RANSAC, options.ransac_px, mask, 2000, 0.999);
  else if (most_general == MotionModel::kAffine)
    cv::estimateAffine2D(from, to, mask, cv::RANSAC, options.ransac_px);
  else if (most_general == MotionModel::kSimilarity)
    cv::estimateAffinePartial2D(from, to, mask, cv::RANSAC, options.ransac_px);
  if (!mask.empty()) {
    for (size_t i = 0; i < inlier.size(); ++i) inlier[i] = mask.at<uchar>(static_cast<int>(i));
  } else {  // translation: within the threshold of the median displacement
    std::vector<float> dx, dy;
    for (size_t i = 0; i < from.size(); ++i)
      dx.push_back(to[i].x - from[i].x), dy.push_back(to[i].y - from[i].y);
    std::nth_element(dx.begin(), dx.begin() + dx.size() / 2, dx.end());
    std::nth_element(dy.begin(), dy.begin() + dy.size() / 2, dy.end());
    const cv::Point2f median(dx[dx.size() / 2], dy[dy.size() / 2]);
    for (size_t i = 0; i < from.size(); ++i)
      inlier[i] = cv::norm(to[i] - from[i] - median) <= options.ransac_px;
  }
  return inlier;
}

// The model: the paper's affine, or the one BIC prefers among those allowed (each one's
// BIC noted in `e`). False when the paper's fit is degenerate.
bool ChooseModel(const std::vector<cv::Point2f>& in_from, const std::vector<cv::Point2f>& in_to,
                 const cv::Point2d& centre, MotionModel most_general, const RefineOptions& options,
                 RefineEstimate* e, cv::Matx33d* best_H) {
  *best_H = cv::Matx33d::eye();
  MotionModel best = MotionModel::kNone;
  if (options.mode == RefineMode::kPaper) {
    if (!FitModel(MotionModel::kAffine, in_from, in_to, centre, best_H)) return false;
    best = MotionModel::kAffine;
  } else {
    // BIC with a noise floor (0.05 texel) so that exact data does not favour a model by log(0).
    const double n2 = 2.0 * e->inliers;
    double best_bic = std::numeric_limits<double>::infinity();
    for (int m = 0; m <= static_cast<int>(most_general); ++m) {
      const MotionModel model = static_cast<MotionModel>(m);
      cv::Matx33d H;
      if (!FitModel(model, in_from, in_to, centre, &H)) continue;
      const double rss = SumSquared(H, in_from, in_to);
      const double bic = n2 * std::log(rss / n2 + 0.05 * 0.05) + NumParams(model) * std::log(n2);
      e->bic[MotionModelName(model)] = bic;
      if (bic < best_bic) best_bic = bic, best = model, *best_H = H;
    }
  }
  e->model = best;
  return true;
}

// The matches between the warped frame and the buffer in the overlap (`region` of the
// image), moved into image coordinates; how many were checked for ambiguity in `checked`.
void MatchRegion(const cv::Mat& grey_w, const cv::Mat& grey_b, const cv::Mat& overlap,
                 const std::vector<cv::Point2f>& corners, const RefineOptions& options,
                 RefineEstimate* e, std::vector<cv::Point2f>* from, std::vector<cv::Point2f>* to,
                 int* checked) {
  if (options.mode == RefineMode::kPaper) {
    MatchSsd(grey_w, grey_b, overlap, corners, options, from, to, &e->ambiguous);
    *checked = e->ambiguous + static_cast<int>(from->size());
  } else {
    MatchLk(grey_w, grey_b, overlap, corners, options, from, to, &e->ambiguous, checked);
  }
  e->matches = static_cast<int>(from->size());
  const cv::Point2f offset(static_cast<float>(e->region.x), static_cast<float>(e->region.y));
  for (auto& p : *from) p += offset;
  for (auto& p : *to) p += offset;
}

// Takes the model `H` when its correction passes the checks, and applies it when it is
// large enough to matter.
void Accept(const cv::Matx33d& H, const RefineOptions& options, RefineEstimate* e) {
  const std::string problem = Check(H, e->region, options, &e->correction_px);
  if (!problem.empty()) {
    e->fallback = problem;
    e->residual_after_px = e->residual_before_px;
    return;
  }
  e->buffer_from_warped = H;
  e->registered = true;
  if (e->correction_px < options.min_correction_px) {
    e->fallback = "none needed (below min_correction_px)";
    return;
  }
  e->applied = true;
}

}  // namespace

std::string MotionModelName(MotionModel model) {
  switch (model) {
    case MotionModel::kNone:
      return "none";
    case MotionModel::kTranslation:
      return "translation";
    case MotionModel::kSimilarity:
      return "similarity";
    case MotionModel::kAffine:
      return "affine";
    case MotionModel::kHomography:
      return "homography";
  }
  return "?";
}

double InlierResidualPx(const RefineEstimate& estimate, const cv::Matx33d& H) {
  std::vector<cv::Point2f> from, to;
  for (size_t i = 0; i < estimate.from.size(); ++i) {
    if (!estimate.inlier[i]) continue;
    from.push_back(estimate.from[i]);
    to.push_back(estimate.to[i]);
  }
  return from.empty() ? 0 : std::sqrt(SumSquared(H, from, to) / from.size());
}

RefineEstimate EstimateRefinement(const cv::Mat& warped_bgr, const cv::Mat& warped_valid,
                                  const cv::Mat& buffer_bgra, const RefineOptions& options,
                                  cv::Rect within) {
  RefineEstimate e;
  if (options.mode == RefineMode::kOff) {
    e.fallback = "off";
    return e;
  }
  // Where the frame and the painted buffer overlap; work in that region only.
  if (within.empty()) within = cv::Rect(0, 0, warped_valid.cols, warped_valid.rows);
  cv::Mat alpha;
  cv::extractChannel(buffer_bgra(within), alpha, 3);
  const cv::Mat overlap_within = warped_valid(within) & (alpha == 255);
  e.region = cv::boundingRect(overlap_within) + within.tl();
  const int min_side = 4 * options.window_px + 2;
  if (e.region.width < min_side || e.region.height < min_side) {
    e.fallback = "too little painted overlap";
    return e;
  }
  const cv::Mat overlap = overlap_within(e.region - within.tl());
  const cv::Mat grey_w = Grey(warped_bgr(e.region)), grey_b = Grey(buffer_bgra(e.region));
  cv::Mat corner_mask;
  cv::erode(overlap, corner_mask, cv::Mat(), cv::Point(-1, -1), options.window_px + 1);
  const std::vector<cv::Point2f> corners = FindCorners(grey_w, corner_mask, options);
  e.corners = static_cast<int>(corners.size());
  if (e.corners < options.min_inliers) {
    e.fallback = "too few corners (textureless?)";
    return e;
  }
  std::vector<cv::Point2f> from, to;
  int checked = 0;  // matches checked for ambiguity
  MatchRegion(grey_w, grey_b, overlap, corners, options, &e, &from, &to, &checked);
  e.from = from;
  e.to = to;
  e.inlier.assign(from.size(), 1);
  // Most matches ambiguous: the texture repeats within the search window, and the few left
  // (near the region's edges, where a copy may lie outside) cannot be told from a period off.
  if (2 * e.ambiguous > checked) {
    e.fallback = "repetitive texture: matches ambiguous within the search window";
    e.inlier.assign(from.size(), 0);  // nor for the pose (refine_pose.h)
    return e;
  }
  if (e.matches < options.min_inliers) {
    e.fallback = "too few matches";
    return e;
  }
  cv::Point2d centre;
  if (!WellSpread(&from, &centre)) {
    e.fallback = "corners (nearly) collinear";
    return e;
  }

  const MotionModel most_general =
      static_cast<MotionModel>(static_cast<int>(options.max_model) + 1);
  const std::vector<uchar> inlier = FindInliers(from, to, most_general, options);
  std::vector<cv::Point2f> in_from, in_to;
  for (size_t i = 0; i < from.size(); ++i)
    if (inlier[i]) in_from.push_back(from[i]), in_to.push_back(to[i]);
  e.inlier = inlier;
  e.inliers = static_cast<int>(in_from.size());
  if (e.inliers < options.min_inliers) {
    e.fallback = "too few inliers (repeated texture or movers?)";
    return e;
  }
  e.residual_before_px = std::sqrt(SumSquared(cv::Matx33d::eye(), in_from, in_to) / e.inliers);

  cv::Matx33d best_H;
  if (!ChooseModel(in_from, in_to, centre, most_general, options, &e, &best_H)) {
    e.fallback = "degenerate fit";
    return e;
  }
  e.residual_after_px = std::sqrt(SumSquared(best_H, in_from, in_to) / e.inliers);
  if (e.model == MotionModel::kNone) {
    e.fallback = "none needed (model selection)";
    e.registered = true;
    return e;
  }
  Accept(best_H, options, &e);
  return e;
}

cv::Rect ApplyRefinement(const RefineEstimate& estimate, const cv::Rect& within,
                         cv::Mat* warped_bgr, cv::Mat* warped_valid, cv::Mat* warped_quality) {
  if (!estimate.applied) return within;
  const int margin = static_cast<int>(std::ceil(estimate.correction_px)) + 2;
  const cv::Rect image(0, 0, warped_bgr->cols, warped_bgr->rows);
  const cv::Rect box = within.empty() ? image : within;
  const auto grow = [&](const cv::Rect& r) {
    return cv::Rect(r.x - margin, r.y - margin, r.width + 2 * margin, r.height + 2 * margin) &
           image;
  };
  const cv::Rect roi = grow(box), source = grow(roi);
  // dst (roi coordinates) = to_roi * buffer_from_warped * from_source * src (source coordinates).
  const cv::Matx33d M = cv::Matx33d(1, 0, -roi.x, 0, 1, -roi.y, 0, 0, 1) *
                        estimate.buffer_from_warped *
                        cv::Matx33d(1, 0, source.x, 0, 1, source.y, 0, 0, 1);
  const cv::Mat bgr = (*warped_bgr)(source).clone(), valid = (*warped_valid)(source).clone(),
                quality = (*warped_quality)(source).clone();
  cv::Mat out_bgr, out_valid, out_quality;
  cv::warpPerspective(bgr, out_bgr, M, roi.size(), cv::INTER_CUBIC, cv::BORDER_REPLICATE);
  cv::warpPerspective(valid, out_valid, M, roi.size(), cv::INTER_NEAREST, cv::BORDER_CONSTANT);
  cv::warpPerspective(quality, out_quality, M, roi.size(), cv::INTER_NEAREST, cv::BORDER_CONSTANT);
  cv::erode(out_valid, out_valid, cv::Mat());
  out_bgr.copyTo((*warped_bgr)(roi));
  out_valid.copyTo((*warped_valid)(roi));
  out_quality.copyTo((*warped_quality)(roi));
  return roi;
}

cv::Mat DrawRefinementMatches(const cv::Mat& warped_bgr, const RefineEstimate& estimate) {
  cv::Mat out = warped_bgr.clone();
  for (size_t i = 0; i < estimate.from.size(); ++i) {
    const cv::Scalar colour = estimate.inlier[i] ? cv::Scalar(0, 220, 0) : cv::Scalar(0, 0, 255);
    // Displacements are small: drawn 5x longer.
    const cv::Point2f tip = estimate.from[i] + 5.0f * (estimate.to[i] - estimate.from[i]);
    cv::circle(out, estimate.from[i], 3, colour, 1, cv::LINE_AA);
    cv::line(out, estimate.from[i], tip, colour, 1, cv::LINE_AA);
  }
  cv::rectangle(out, estimate.region, cv::Scalar(255, 200, 0), 1);
  return out;
}

cv::Mat ResidualHeatMap(const cv::Mat& warped_bgr, const cv::Mat& warped_valid,
                        const cv::Mat& buffer_bgra, const cv::Rect& region) {
  const cv::Rect r = region & cv::Rect(0, 0, warped_bgr.cols, warped_bgr.rows);
  if (r.empty()) return cv::Mat();
  std::vector<cv::Mat> channels;
  cv::split(buffer_bgra(r), channels);
  const cv::Mat overlap = warped_valid(r) & (channels[3] == 255);
  cv::Mat diff, scaled, heat;
  cv::absdiff(Grey(warped_bgr(r)), Grey(buffer_bgra(r)), diff);
  diff.convertTo(scaled, CV_8U, 4.0);  // 64 grey levels = full scale
  cv::applyColorMap(scaled, heat, cv::COLORMAP_INFERNO);
  heat.setTo(cv::Scalar(40, 40, 40), ~overlap);
  return heat;
}

}  // namespace fresco
