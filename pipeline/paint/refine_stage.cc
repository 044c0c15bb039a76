// The refine stage (paint_stages.h): each buffer seen registered in 2D to what it already
// holds and warped again (§3.5), the pose corrected through all buffers' matches, registered
// frames anchoring the buffers' offsets (refine_alignment.h, refine_pose.h,
// refine_anchor.h). Off unless pipeline.refine.mode; `auto` measures the misalignment while
// it decides.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <string>

#include <opencv2/core/utility.hpp>

#include "pipeline/paint/paint_session.h"
#include "pipeline/paint/stage_clock.h"

namespace fresco {
namespace {

// A frame that refinement could not register keeps out of painted texels only when its
// matches show it misaligned by more than this (texels): otherwise it paints as it would
// without refinement. Keeping every unregistered frame out froze each texel at its first
// sample wherever matches were too few (short sequences, small frames: -4.8 dB on a 30-frame
// street with perfect poses, docs/results.md "Evaluation suite"). Perfect poses measure
// 0.15-0.45 texels there, 0.5 degree of noise about 2.
constexpr double kKeepOutMisalignmentPx = 1.0;

// The part of an RMS residual `before` that a correction leaving `after` removes.
double ExplainedPx(double before, double after) {
  return std::sqrt(std::max(0.0, before * before - after * after));
}

}  // namespace

void PaintSession::RefineStage(FrameWork* work) {
  frame_camera_ = work->camera;
  frame_cam_from_local_ = work->cam_from_local;
  if (options_.refine.mode == RefineMode::kOff) return;
  const bool measure_only = refine_auto_.deciding();
  if (measure_only || work->number % options_.refine.every_n_frames == 0) {
    work->report->stages.push_back(
        RefineAlignment(work->seen, work->debug, measure_only, &work->report->refine));
    if (measure_only) work->measured_misalignment_px = frame_explained_px_;
  } else {  // not registered this frame: it only fills what the buffers lack
    for (size_t b = 0; b < set_.buffers.size(); ++b)
      if (work->seen[b]) KeepOutOfPainted(b, warped_[b].valid_box);
  }
}

void PaintSession::KeepOutOfPainted(size_t b, const cv::Rect& roi) {
  if (roi.empty()) return;
  cv::Mat alpha;
  cv::extractChannel(painted_[b].bgra(roi), alpha, 3);
  warped_[b].valid(roi).setTo(0, alpha);
}

// One buffer's refinement: register, warp again, anchor; what the stage reports about it.
struct PaintSession::BufferRefinement {
  RefineEstimate estimate;
  bool from_pose = false;  // the correction was derived from the frame's corrected pose
  bool moved = false, kept_out = false;
  double estimate_ms = 0, rewarp_ms = 0, anchor_ms = 0;
  std::map<std::string, cv::Mat> images;
};

void PaintSession::EstimateBuffer(size_t b, bool debug, BufferRefinement* r) {
  const WarpedBuffer& w = warped_[b];
  const PaintedBuffer& painted = painted_[b];
  RefineEstimate& e = r->estimate;
  const auto t0 = std::chrono::steady_clock::now();
  e = EstimateRefinement(w.bgr, w.valid, painted.bgra, options_.refine, w.valid_box);
  r->estimate_ms = MsSince(t0);
  if (debug && e.inliers > 0)
    r->images["residual_before_b" + std::to_string(b)] =
        ResidualHeatMap(w.bgr, w.valid, painted.bgra, e.region);
}

void PaintSession::FinishBuffer(size_t b, bool debug, BufferRefinement* r) {
  WarpedBuffer& w = warped_[b];
  PaintedBuffer& painted = painted_[b];
  RefineEstimate& e = r->estimate;
  const std::string suffix = "_b" + std::to_string(b);
  auto t0 = std::chrono::steady_clock::now();
  w.valid_box = ApplyRefinement(e, w.valid_box, &w.bgr, &w.valid, &w.quality);
  r->rewarp_ms = MsSince(t0);
  t0 = std::chrono::steady_clock::now();
  // A registered frame is a sample of the buffer's offset (refine_anchor.h).
  AnchorMove move;
  const bool sample = options_.refine.anchor && e.registered;
  cv::Mat in_view, measured;
  if (sample) {
    in_view = TilesSet(anchors_[b], w.valid, w.valid_box);
    if (r->from_pose) {  // the pose's correction holds wherever the frame sees the buffer
      measured = in_view;
    } else {  // a homography fitted to this buffer's matches holds where they are
      std::vector<cv::Point2f> inliers_at;
      for (size_t i = 0; i < e.to.size(); ++i)
        if (e.inlier[i]) inliers_at.push_back(e.to[i]);
      measured = TilesAt(anchors_[b], inliers_at);
    }
  }
  if (sample && AddAnchorSample(e.buffer_from_warped, measured, in_view, options_.refine,
                                &anchors_[b], &move)) {
    MovePaintedBuffer(move, anchors_[b], &painted);
    // The frame, registered to the buffer before the move, moves with it.
    const int margin = static_cast<int>(std::ceil(e.correction_px)) + 2;
    const cv::Rect within =
        cv::Rect(w.valid_box.x - margin, w.valid_box.y - margin, w.valid_box.width + 2 * margin,
                 w.valid_box.height + 2 * margin) &
        cv::Rect(0, 0, w.valid.cols, w.valid.rows);
    MoveWarpedImages(move, within, &w.bgr, &w.valid, &w.quality);
    w.valid_box = within;  // valid texels may have moved by up to the margin
    // Every stream's model of the buffer moves with it (a stream's set made later starts
    // in the moved buffer).
    if (!background_.empty() && TakeBackgroundMove(&anchors_[b], &move))
      for (std::vector<BufferBackground>& models : background_)
        if (!models.empty()) models[b].Move(set_.buffers[b], move.roi, move.field);
    r->moved = true;
  }
  r->anchor_ms = MsSince(t0);
  const bool misaligned = (e.inliers > 0 && e.residual_before_px > kKeepOutMisalignmentPx) ||
                          frame_misalignment_px_ > kKeepOutMisalignmentPx;
  if (!e.registered && !e.region.empty() && misaligned) {
    // Not registered and seen misaligned: it may fill what the buffer lacks but not overwrite
    // registered texels (which all lie in the region: it bounds where the frame and the
    // buffer overlap).
    KeepOutOfPainted(b, e.region);
    r->kept_out = true;
  }
  if (debug) {
    r->images["matches" + suffix] = DrawRefinementMatches(w.bgr, e);
    if (e.inliers > 0)
      r->images["residual_after" + suffix] =
          ResidualHeatMap(w.bgr, w.valid, painted.bgra, e.region);
  }
}

void PaintSession::CorrectThroughPose(const std::vector<size_t>& todo,
                                      const std::vector<size_t>& fresh, bool measure_only,
                                      std::vector<BufferRefinement>* results, StageReport* report) {
  const auto start = std::chrono::steady_clock::now();
  std::vector<PoseMatch> matches;
  for (size_t i = 0; i < todo.size(); ++i)
    AppendPoseMatches(set_.buffers[todo[i]], *frame_camera_, frame_cam_from_local_,
                      (*results)[i].estimate, &matches);
  const PoseCorrection pose =
      EstimatePoseCorrection(matches, *frame_camera_, frame_cam_from_local_, options_.refine);
  report->metrics["pose_matches"] = pose.matches;
  report->metrics["pose_inliers"] = pose.inliers;
  report->metrics["pose_residual_before_px"] = pose.residual_before_px;
  report->metrics["pose_residual_after_px"] = pose.residual_after_px;
  report->metrics["pose_rotation_deg"] =
      Rigid3d::AxisAngleFromQuaternion(pose.delta.rotation).norm() * 180.0 / M_PI;
  report->metrics["pose_translation_m"] = pose.delta.translation.norm();
  report->metrics["pose_model_" + pose.model] = 1;
  report->notes["pose"] = pose.applied ? pose.model : "no pose correction: " + pose.fallback;
  if (pose.inliers > 0) {
    frame_misalignment_px_ = pose.residual_before_px;
    frame_explained_px_ = ExplainedPx(pose.residual_before_px, pose.residual_after_px);
  }
  if (!pose.applied || measure_only) return;  // the buffers keep their own 2D estimates
  const Rigid3d corrected = pose.delta * frame_cam_from_local_;
  results->resize(todo.size() + fresh.size());
  for (size_t i = 0; i < results->size(); ++i) {
    const size_t b = i < todo.size() ? todo[i] : fresh[i - todo.size()];
    RefineEstimate& e = (*results)[i].estimate;
    const cv::Rect& box = warped_[b].valid_box;
    cv::Matx33d H;
    if (!BufferCorrectionFromPose(set_.buffers[b], *frame_camera_, frame_cam_from_local_, corrected,
                                  box, &H)) {
      continue;  // keeps its own estimate
    }
    e.buffer_from_warped = H;
    (*results)[i].from_pose = true;
    e.model = MotionModel::kHomography;
    e.registered = true;
    e.correction_px = LargestDisplacement(H, box);
    e.applied = e.correction_px >= options_.refine.min_correction_px;
    e.fallback = e.applied ? "" : "none needed (below min_correction_px)";
    e.residual_after_px = InlierResidualPx(e, H);
  }
  report->metrics["pose_ms"] = MsSince(start);
}

// Refinement measuring for its `auto` decision registers at most about this many texels a
// frame (the largest buffers seen, whole).
constexpr long long kMeasureTexels = 300000;

StageReport PaintSession::RefineAlignment(const std::vector<bool>& seen, bool debug,
                                          bool measure_only, RefineFigures* figures) {
  const auto start = std::chrono::steady_clock::now();
  StageReport report;
  report.name = "refine";
  frame_misalignment_px_ = -1;
  frame_explained_px_ = -1;
  std::vector<size_t> todo, fresh;
  for (size_t b = 0; b < set_.buffers.size(); ++b) {
    if (seen[b] && painted_[b].painted_surface_texels > 0)
      todo.push_back(b);
    else if (seen[b])
      fresh.push_back(b);
  }
  if (measure_only) {
    // Measuring needs a sample, not every buffer: the largest regions seen, up to about a
    // 640x480 frame's texels (a photo of a large mesh sees several times that).
    std::stable_sort(todo.begin(), todo.end(), [&](size_t a, size_t b) {
      return warped_[a].valid_box.area() > warped_[b].valid_box.area();
    });
    long long area = 0;
    size_t kept = 0;
    while (kept < todo.size() && area < kMeasureTexels)
      area += warped_[todo[kept++]].valid_box.area();
    todo.resize(kept);
    std::sort(todo.begin(), todo.end());
  }
  // Buffers are independent: one per thread, the largest regions first so that the threads
  // finish together (longest processing time first).
  std::vector<BufferRefinement> results(todo.size());
  const auto for_each_buffer = [&](void (PaintSession::*step)(size_t, bool, BufferRefinement*)) {
    std::vector<int> order(todo.size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
      return warped_[todo[a]].valid_box.area() > warped_[todo[b]].valid_box.area();
    });
    cv::parallel_for_(
        cv::Range(0, static_cast<int>(order.size())),
        [&](const cv::Range& range) {
          for (int i = range.start; i < range.end; ++i)
            (this->*step)(todo[order[i]], debug, &results[order[i]]);
        },
        static_cast<double>(order.size()));
  };
  if (options_.refine.pose) {  // every buffer's matches first, then one pose for all
    for_each_buffer(&PaintSession::EstimateBuffer);
    CorrectThroughPose(todo, fresh, measure_only, &results, &report);
    if (results.size() > todo.size()) todo.insert(todo.end(), fresh.begin(), fresh.end());
    if (!measure_only) for_each_buffer(&PaintSession::FinishBuffer);
  } else {  // each buffer on its own; the frame's misalignment pooled over their inliers
    for_each_buffer(&PaintSession::EstimateBuffer);
    double before_sq = 0, after_sq = 0;
    int pooled = 0;
    for (const BufferRefinement& r : results) {
      const RefineEstimate& e = r.estimate;
      before_sq += e.inliers * e.residual_before_px * e.residual_before_px;
      after_sq += e.inliers * e.residual_after_px * e.residual_after_px;
      pooled += e.inliers;
    }
    if (pooled > 0) {
      frame_misalignment_px_ = std::sqrt(before_sq / pooled);
      frame_explained_px_ = ExplainedPx(frame_misalignment_px_, std::sqrt(after_sq / pooled));
    }
    if (!measure_only) for_each_buffer(&PaintSession::FinishBuffer);
  }

  int refined = 0, fell_back = 0, corners = 0, matches = 0, inliers = 0, ambiguous = 0, moved = 0,
      unregistered_kept_out = 0;
  double before_sq = 0, after_sq = 0, correction = 0;
  double estimate_ms = 0, rewarp_ms = 0, anchor_ms = 0;
  std::map<std::string, int> models, reasons;
  for (size_t i = 0; i < todo.size(); ++i) {
    const RefineEstimate& e = results[i].estimate;
    report.images.merge(results[i].images);
    estimate_ms += results[i].estimate_ms;
    rewarp_ms += results[i].rewarp_ms;
    anchor_ms += results[i].anchor_ms;
    moved += results[i].moved;
    unregistered_kept_out += results[i].kept_out;
    corners += e.corners, matches += e.matches, inliers += e.inliers, ambiguous += e.ambiguous;
    before_sq += e.inliers * e.residual_before_px * e.residual_before_px;
    after_sq += e.inliers * e.residual_after_px * e.residual_after_px;
    if (e.applied && !measure_only) {
      ++refined;
      ++models[MotionModelName(e.model)];
      correction = std::max(correction, e.correction_px);
    } else {
      ++fell_back;
      ++reasons[e.fallback];
    }
    if (debug)
      report.notes["buffer" + std::to_string(todo[i])] =
          (e.applied ? MotionModelName(e.model) : "no correction: " + e.fallback) + " (" +
          std::to_string(e.inliers) + "/" + std::to_string(e.matches) + " inliers)";
  }
  report.metrics["buffers_refined"] = refined;
  report.metrics["buffers_not_refined"] = fell_back;
  report.metrics["corners"] = corners;
  report.metrics["matches"] = matches;
  report.metrics["inliers"] = inliers;
  report.metrics["ambiguous_matches"] = ambiguous;  // dropped: repetitive texture
  // RMS over all inliers, texels: identity before, the chosen corrections after.
  if (inliers > 0) {
    figures->residual_before_px = std::sqrt(before_sq / inliers);
    figures->residual_after_px = std::sqrt(after_sq / inliers);
  }
  figures->PutInto(&report);
  report.metrics["correction_px"] = correction;
  report.metrics["buffers_moved"] = moved;
  report.metrics["buffers_unregistered"] = unregistered_kept_out;
  // Thread time summed over the buffers (they run in parallel): corners, matching and
  // fitting; warping the frame again; consensus and buffer moves.
  report.metrics["estimate_ms"] = estimate_ms;
  report.metrics["rewarp_ms"] = rewarp_ms;
  report.metrics["anchor_ms"] = anchor_ms;  // consensus anchoring moved them this frame
  for (const auto& [model, n] : models) report.metrics["model_" + model] = n;
  std::string why;
  for (const auto& [reason, n] : reasons)
    why += (why.empty() ? "" : "; ") + reason + " x" + std::to_string(n);
  if (!why.empty()) report.notes["not refined"] = why;
  if (measure_only) report.notes["not refined"] = "measured only (refine.mode auto, deciding)";
  report.wall_ms = MsSince(start);
  return report;
}

}  // namespace fresco
