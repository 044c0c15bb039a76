#include "calib/pictures.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <opencv2/imgproc.hpp>

namespace fresco::calib {
namespace {

cv::Scalar ViewColour(size_t v) {
  cv::Mat hsv(1, 1, CV_8UC3, cv::Scalar((v * 47) % 180, 200, 220)), bgr;
  cv::cvtColor(hsv, bgr, cv::COLOR_HSV2BGR);
  const cv::Vec3b c = bgr.at<cv::Vec3b>(0, 0);
  return cv::Scalar(c[0], c[1], c[2]);
}

std::string Text(const char* format, double value) {
  char buffer[96];
  std::snprintf(buffer, sizeof(buffer), format, value);
  return buffer;
}

// Scale so that the imager fits in `max_side` pixels.
double CanvasScale(const CalibrationRun& run, int max_side) {
  return std::min(1.0, max_side / double(std::max(run.width, run.height)));
}

}  // namespace

cv::Mat DrawResiduals(const CalibrationRun& run) {
  const SolveResult& fit = run.Chosen().fit;
  const double s = CanvasScale(run, 900);
  const int w = static_cast<int>(run.width * s), h = static_cast<int>(run.height * s);
  const int bars_h = 200, top = 30;
  cv::Mat canvas(top + bars_h + h + 40, std::max(w, 400), CV_8UC3, cv::Scalar(255, 255, 255));
  double max_rms = 1e-9;
  for (const ViewFit& v : fit.views) max_rms = std::max(max_rms, v.rms_px);
  const double bar_w = canvas.cols / double(fit.views.size());
  for (size_t v = 0; v < fit.views.size(); ++v) {
    const int bh = static_cast<int>(fit.views[v].rms_px / max_rms * (bars_h - 20));
    cv::rectangle(canvas, cv::Point(int(v * bar_w) + 1, top + bars_h - bh),
                  cv::Point(int((v + 1) * bar_w) - 1, top + bars_h), ViewColour(v), cv::FILLED);
    if (fit.views[v].outliers > 0)
      cv::putText(canvas, std::to_string(fit.views[v].outliers),
                  cv::Point(int(v * bar_w) + 1, top + bars_h - bh - 3), cv::FONT_HERSHEY_PLAIN, 0.8,
                  cv::Scalar(0, 0, 255));
  }
  cv::putText(canvas,
              "per-image RMS (max " + Text("%.3f px", max_rms) + "), model " +
                  run.Chosen().short_name + ", all " + Text("%.3f px", fit.rms_px) +
                  "; red numbers: outliers",
              cv::Point(5, 20), cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  const int y0 = top + bars_h + 10;
  cv::rectangle(canvas, cv::Rect(0, y0, w, h), cv::Scalar(0, 0, 0));
  const double magnify = 0.1 * w / std::max(3 * fit.rms_px, 1e-3);  // 3 sigma = 10 % of width
  for (size_t v = 0; v < run.views.size(); ++v)
    for (size_t k = 0; k < run.views[v].corners.size(); ++k) {
      const Eigen::Vector2d& q = run.views[v].corners[k].pixel;
      const Eigen::Vector2d& r = fit.views[v].residual_px[k];
      const cv::Point a(int(q.x() * s), y0 + int(q.y() * s));
      const cv::Point b(int(q.x() * s + r.x() * magnify), y0 + int(q.y() * s + r.y() * magnify));
      cv::line(canvas, a, b, fit.views[v].outlier[k] ? cv::Scalar(0, 0, 255) : ViewColour(v), 1,
               cv::LINE_AA);
    }
  cv::putText(canvas, "residual vectors on the imager, x" + Text("%.0f", magnify / s),
              cv::Point(5, y0 + h + 25), cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(0, 0, 0), 1,
              cv::LINE_AA);
  return canvas;
}

cv::Mat DrawCoverage(const CalibrationRun& run) {
  const SolveResult* fit = run.choice.chosen >= 0 ? &run.Chosen().fit : nullptr;
  const double s = CanvasScale(run, 900);
  const int w = static_cast<int>(run.width * s), h = static_cast<int>(run.height * s);
  cv::Mat canvas(h + 30, w, CV_8UC3, cv::Scalar(255, 255, 255));
  constexpr int kCols = kCoverageCols, kRows = kCoverageRows;
  const std::vector<bool> seen = CoverageCells(run.views, run.width, run.height);
  for (int j = 0; j < kRows; ++j)
    for (int i = 0; i < kCols; ++i) {
      const cv::Rect cell(i * w / kCols, j * h / kRows, w / kCols, h / kRows);
      if (!seen[j * kCols + i]) cv::rectangle(canvas, cell, cv::Scalar(200, 200, 255), cv::FILLED);
      cv::rectangle(canvas, cell, cv::Scalar(220, 220, 220));
    }
  for (size_t v = 0; v < run.views.size(); ++v)
    for (size_t k = 0; k < run.views[v].corners.size(); ++k) {
      const cv::Point p(int(run.views[v].corners[k].pixel.x() * s),
                        int(run.views[v].corners[k].pixel.y() * s));
      if (fit && fit->views[v].outlier[k])
        cv::drawMarker(canvas, p, cv::Scalar(0, 0, 255), cv::MARKER_CROSS, 8, 2);
      else
        cv::circle(canvas, p, 2, ViewColour(v), cv::FILLED, cv::LINE_AA);
    }
  // Images rejected: where their tags were read (a view lost, and the part of the imager it
  // would have covered).
  int lost = 0;
  for (const ViewDetection& d : run.detections) {
    lost += !d.used && !d.tag_centres.empty();
    if (d.used) continue;
    for (const Eigen::Vector2d& c : d.tag_centres)
      cv::drawMarker(canvas, cv::Point(int(c.x() * s), int(c.y() * s)), cv::Scalar(0, 140, 255),
                     cv::MARKER_TILTED_CROSS, 10, 2);
  }
  cv::putText(
      canvas,
      "coverage " + Text("%.0f %%", 100 * CoverageFraction(run.views, run.width, run.height)) +
          " of 16x12 cells, " + std::to_string(run.views.size()) + " images; shaded: no corner" +
          (lost ? "; orange x: tags of " + std::to_string(lost) + " rejected images" : ""),
      cv::Point(5, h + 20), cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  return canvas;
}

cv::Mat DrawUncertainty(const CalibrationRun& run) {
  const UncertaintyMap& u = run.uncertainty;
  if (u.max_px <= 0 || u.cols <= 0) return cv::Mat();
  const double s = 900.0 / std::max(run.width, run.height);  // this one may be enlarged
  const int w = static_cast<int>(run.width * s), h = static_cast<int>(run.height * s);
  const int bar_h = 50, text_h = 50;
  cv::Mat canvas(h + bar_h + text_h, std::max(w, 900), CV_8UC3, cv::Scalar(255, 255, 255));
  // Logarithmic colour scale between "nice" levels around the map's smallest and largest value.
  const std::vector<double> levels = {0.001, 0.002, 0.005, 0.01, 0.02, 0.05, 0.1, 0.2,
                                      0.5,   1,     2,     5,    10,   20,   50,  100};
  double min_value = u.max_px;
  for (double v : u.stdev_px)
    if (v > 0) min_value = std::min(min_value, v);
  double lo = levels.front(), hi = levels.back();
  for (double l : levels)
    if (l <= min_value) lo = l;
  for (auto it = levels.rbegin(); it != levels.rend(); ++it)
    if (*it >= u.max_px) hi = *it;
  if (hi <= lo) hi = lo * 10;
  const double log_lo = std::log10(lo), log_span = std::log10(hi) - log_lo;
  cv::Mat values(u.rows, u.cols, CV_32F);
  for (int j = 0; j < u.rows; ++j)
    for (int i = 0; i < u.cols; ++i)
      values.at<float>(j, i) = static_cast<float>(std::max(lo, u.At(i, j)));
  cv::Mat big, logs, scaled, heat;
  cv::resize(values, big, cv::Size(w, h), 0, 0, cv::INTER_LINEAR);
  cv::log(big, logs);
  logs.convertTo(scaled, CV_8U, 255.0 / (log_span * std::log(10.0)), -255.0 * log_lo / log_span);
  cv::applyColorMap(scaled, heat, cv::COLORMAP_VIRIDIS);
  heat.copyTo(canvas(cv::Rect(0, 0, w, h)));
  for (double l : levels) {  // labelled contours, the label where the line is furthest inside
    if (l <= lo || l >= hi) continue;
    cv::Mat above = big > l, padded;  // padded: the mask's own edge falls outside the canvas
    cv::copyMakeBorder(above, padded, 1, 1, 1, 1, cv::BORDER_REPLICATE);
    std::vector<std::vector<cv::Point>> contours;
    cv::findContours(padded, contours, cv::RETR_LIST, cv::CHAIN_APPROX_NONE, cv::Point(-1, -1));
    cv::drawContours(canvas, contours, -1, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
    cv::Point at(-1, -1);
    int best = 20;
    for (const auto& c : contours)
      for (const cv::Point& p : c) {
        const int inside = std::min({p.x, p.y, w - 1 - p.x, h - 1 - p.y});
        if (inside > best) best = inside, at = p;
      }
    if (at.x >= 0)
      cv::putText(canvas, Text("%g px", l), at + cv::Point(3, -3), cv::FONT_HERSHEY_SIMPLEX, 0.45,
                  cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  }
  for (const BoardView& v : run.views)
    for (const CornerObservation& c : v.corners)
      cv::circle(canvas, cv::Point(int(c.pixel.x() * s), int(c.pixel.y() * s)), 1,
                 cv::Scalar(0, 0, 0), cv::FILLED);
  for (int x = 0; x < w; ++x) {  // colour bar, log scale
    cv::Mat one(1, 1, CV_8U, cv::Scalar(255.0 * x / w)), colour;
    cv::applyColorMap(one, colour, cv::COLORMAP_VIRIDIS);
    const cv::Vec3b c = colour.at<cv::Vec3b>(0, 0);
    cv::line(canvas, cv::Point(x, h + 8), cv::Point(x, h + 25), cv::Scalar(c[0], c[1], c[2]));
  }
  for (double l : levels) {
    if (l < lo || l > hi) continue;
    const int x = static_cast<int>((std::log10(l) - log_lo) / log_span * (w - 1));
    cv::line(canvas, cv::Point(x, h + 25), cv::Point(x, h + 30), cv::Scalar(0, 0, 0));
    cv::putText(canvas, Text("%g", l), cv::Point(std::clamp(x - 10, 0, w - 40), h + 44),
                cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  }
  const std::string line1 = "projection uncertainty, px (1-sigma, worst direction) of " +
                            run.Chosen().short_name + " for points at " +
                            Text("%.2f m", u.range_m) + ", corner noise " +
                            Text("%.3f px", u.sigma_px);
  const std::string line2 = "centre " + Text("%.3f px", u.centre_px) +
                            ", where observed (median) " + Text("%.3f px", u.median_observed_px) +
                            ", max " + Text("%.3f px", u.max_px) + "; black dots: observed corners";
  cv::putText(canvas, line1, cv::Point(5, h + bar_h + 18), cv::FONT_HERSHEY_SIMPLEX, 0.5,
              cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  cv::putText(canvas, line2, cv::Point(5, h + bar_h + 40), cv::FONT_HERSHEY_SIMPLEX, 0.5,
              cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  return canvas;
}

cv::Mat DrawDetections(const cv::Mat& image, const std::vector<CornerObservation>& corners,
                       const ViewFit* fit) {
  cv::Mat canvas;
  if (image.channels() == 1)
    cv::cvtColor(image, canvas, cv::COLOR_GRAY2BGR);
  else
    canvas = image.clone();
  const int r = std::max(3, canvas.cols / 160);
  for (size_t k = 0; k + 1 < corners.size(); ++k)  // the detection order, as OpenCV draws it
    cv::line(canvas, cv::Point(int(corners[k].pixel.x()), int(corners[k].pixel.y())),
             cv::Point(int(corners[k + 1].pixel.x()), int(corners[k + 1].pixel.y())),
             cv::Scalar(255, 160, 0), 1, cv::LINE_AA);
  for (size_t k = 0; k < corners.size(); ++k) {
    const cv::Point p(int(corners[k].pixel.x()), int(corners[k].pixel.y()));
    if (fit && fit->outlier[k])
      cv::drawMarker(canvas, p, cv::Scalar(0, 0, 255), cv::MARKER_CROSS, 3 * r, 2);
    else
      cv::circle(canvas, p, r, k == 0 ? cv::Scalar(0, 0, 255) : cv::Scalar(0, 220, 0), 2,
                 cv::LINE_AA);
  }
  const std::string label = std::to_string(corners.size()) + " corners" +
                            (fit ? ", RMS " + Text("%.3f px", fit->rms_px) : std::string());
  cv::putText(canvas, label, cv::Point(8, 24), cv::FONT_HERSHEY_SIMPLEX, 0.7, cv::Scalar(0, 0, 0),
              3, cv::LINE_AA);
  cv::putText(canvas, label, cv::Point(8, 24), cv::FONT_HERSHEY_SIMPLEX, 0.7,
              cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  return canvas;
}

}  // namespace fresco::calib
