#include "pipeline/poses/verify_report.h"

#include <algorithm>
#include <cmath>

#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "pipeline/core/atomic_file.h"
#include "pipeline/core/image_io.h"

namespace fresco {
namespace {

using nlohmann::json;

// One panel: values along the sequence, the threshold dashed, flags red.
void DrawPanel(cv::Mat& image, const cv::Rect& area, const VerifyResult& result, bool rotation) {
  const cv::Scalar kAxis(60, 60, 60), kLine(180, 90, 0), kFlag(0, 0, 220), kMissing(170, 170, 170);
  const double threshold = rotation ? result.rotation_threshold_deg : result.position_threshold_m;
  double top = 2.0 * threshold;
  for (const FrameVerdict& v : result.frames) {
    if (v.has_given && v.registered) {
      top = std::max(top, 1.1 * (rotation ? v.rotation_error_deg : v.position_error_m));
    }
  }
  const int n = std::max<int>(1, static_cast<int>(result.frames.size()));
  auto x_of = [&](int i) { return area.x + static_cast<int>((i + 0.5) * area.width / n); };
  auto y_of = [&](double value) {
    return area.y + area.height - static_cast<int>(std::min(value, top) / top * area.height);
  };
  cv::rectangle(image, area, kAxis, 1);
  for (int x = area.x; x < area.x + area.width; x += 12) {
    cv::line(image, {x, y_of(threshold)}, {std::min(x + 6, area.x + area.width), y_of(threshold)},
             kFlag, 1);
  }
  cv::Point previous(-1, -1);
  for (int i = 0; i < static_cast<int>(result.frames.size()); ++i) {
    const FrameVerdict& v = result.frames[i];
    if (!v.has_given || !v.registered) {
      cv::line(image, {x_of(i), area.y + area.height - 6}, {x_of(i), area.y + area.height},
               kMissing, 2);
      previous = {-1, -1};
      continue;
    }
    const cv::Point p(x_of(i), y_of(rotation ? v.rotation_error_deg : v.position_error_m));
    if (previous.x >= 0) cv::line(image, previous, p, kLine, 1, cv::LINE_AA);
    cv::circle(image, p, v.flagged ? 5 : 2, v.flagged ? kFlag : kLine, cv::FILLED, cv::LINE_AA);
    previous = p;
  }
  char label[160];
  std::snprintf(label, sizeof(label), "%s (max shown %.3g %s, threshold %.3g)",
                rotation ? "rotation error, deg" : "position error, m", top, rotation ? "deg" : "m",
                threshold);
  cv::putText(image, label, {area.x + 4, area.y + 16}, cv::FONT_HERSHEY_SIMPLEX, 0.45, kAxis, 1,
              cv::LINE_AA);
}

}  // namespace

std::string VerifyJsonText(const VerifyResult& result, const ColmapRunResult& run) {
  json frames = json::array();
  for (const FrameVerdict& v : result.frames) {
    json f = {{"name", v.name}, {"has_given_pose", v.has_given}, {"registered", v.registered}};
    if (v.has_given && v.registered) {
      f["rotation_error_deg"] = v.rotation_error_deg;
      f["position_error_m"] = v.position_error_m;
      f["judged_locally"] = v.judged_locally;
      f["fit_rotation_error_deg"] = v.fit_rotation_error_deg;
      f["fit_position_error_m"] = v.fit_position_error_m;
      f["inlier"] = v.inlier;
      f["given_centre_m"] = {v.given_centre_m.x(), v.given_centre_m.y(), v.given_centre_m.z()};
      f["colmap_centre_m"] = {v.colmap_centre_m.x(), v.colmap_centre_m.y(), v.colmap_centre_m.z()};
    } else {
      f["rotation_error_deg"] = nullptr;
      f["position_error_m"] = nullptr;
    }
    f["flagged"] = v.flagged;
    f["follows_drift"] = v.follows_drift;
    f["borderline"] = v.borderline;
    if (v.judged_locally) {
      f["rotation_uncertainty_deg"] = v.rotation_uncertainty_deg;
      f["position_uncertainty_m"] = v.position_uncertainty_m;
    }
    if (v.relative_rotation_deg >= 0) f["relative_rotation_deg"] = v.relative_rotation_deg;
    if (v.observations >= 0) f["observations"] = v.observations;
    f["weak_support"] = v.weak_support;
    if (v.drift_tolerance > 0) {
      f["drift_tolerance_deg"] = v.drift_tolerance * result.rotation_threshold_deg;
    }
    frames.push_back(f);
  }
  const Sim3d& s = result.world_from_colmap;
  json steps = json::object();
  for (const auto& [name, seconds] : run.step_seconds) steps[name] = seconds;
  json out = {
      {"frames", frames},
      {"registered", result.registered},
      {"compared", result.compared},
      {"flagged", result.flagged},
      {"borderline", result.borderline},
      {"scene_size_m", result.scene_size_m},
      {"thresholds",
       {{"rotation_deg", result.rotation_threshold_deg},
        {"position_m", result.position_threshold_m}}},
      {"alignment",
       {{"world_from_colmap",
         {{"scale", s.scale},
          {"rotation_wxyz", {s.rotation.w(), s.rotation.x(), s.rotation.y(), s.rotation.z()}},
          {"translation_m", {s.translation.x(), s.translation.y(), s.translation.z()}}}},
        {"scale", s.scale},
        {"inliers", result.global_inliers},
        {"agreeing", result.global_agreeing},
        {"weak", result.weak_alignment},
        {"rotation_from", result.rotation_from},
        {"centres",
         {{"collinear", result.centres.collinear},
          {"spread_ratio", result.centres.spread_ratio},
          {"rms_m", result.centres.rms_m}}},
        {"local_windows", result.windows}}},
      {"drift",
       {{"detected", result.disagreement.Drifts()},
        {"smooth_frames", result.disagreement.smooth},
        {"disagreeing_frames", result.disagreement.disagreeing},
        {"first", result.drift_first},
        {"last", result.drift_last},
        {"followed", result.drift_followed},
        {"judged_locally", result.judged_locally},
        {"following_frames", result.following_drift},
        {"widened_frames", result.widened},
        {"widest_tolerance_deg", result.widest_tolerance_deg}}},
      {"weak_support",
       {{"frames", result.weak_support},
        {"median_observations", result.median_observations},
        {"fraction", result.weak_support_fraction}}},
      {"notes", VerifyNotes(result)},
      {"agreement_unflagged",
       {{"frames", result.unflagged},
        {"median_rotation_error_deg", result.median_rotation_error_deg},
        {"max_rotation_error_deg", result.max_unflagged_rotation_error_deg},
        {"median_position_error_m", result.median_position_error_m},
        {"max_position_error_m", result.max_unflagged_position_error_m}}},
      {"colmap",
       {{"program", run.program},
        {"models", run.models},
        {"matcher", run.matcher},
        {"seconds", run.seconds},
        {"step_seconds", steps}}},
  };
  return out.dump(2) + "\n";
}

Status WriteVerifyReport(const VerifyResult& result, const ColmapRunResult& run,
                         const std::string& json_path, const std::string& plot_path) {
  cv::Mat plot(440, 900, CV_8UC3, cv::Scalar(255, 255, 255));
  DrawPanel(plot, cv::Rect(40, 20, 840, 180), result, true);
  DrawPanel(plot, cv::Rect(40, 225, 840, 180), result, false);
  char footer[200];
  std::snprintf(footer, sizeof(footer),
                "%d frames, %d registered, %d compared, %d flagged (red); grey: no comparison",
                static_cast<int>(result.frames.size()), result.registered, result.compared,
                result.flagged);
  cv::putText(plot, footer, {40, 428}, cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(60, 60, 60), 1,
              cv::LINE_AA);
  FRESCO_RETURN_IF_ERROR(WriteImageAtomic(plot_path, plot));
  return WriteFileAtomic(json_path, VerifyJsonText(result, run));
}

}  // namespace fresco
