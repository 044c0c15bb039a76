#include "pipeline/rephoto/rephoto_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>

#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "pipeline/paint/auto_modes.h"

namespace fresco {
namespace {

using json = nlohmann::json;

// Mean, median and worst of the finite values (`higher_is_worse`: the worst is the largest).
RephotoSpread Spread(const std::vector<RephotoFrame>& frames,
                     const std::function<double(const RephotoFrame&)>& figure,
                     bool higher_is_worse) {
  std::vector<double> v;
  for (const RephotoFrame& f : frames)
    if (const double x = figure(f); std::isfinite(x)) v.push_back(x);
  RephotoSpread s;
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  for (double x : v) s.mean += x / n;
  s.median = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
  s.worst = higher_is_worse ? v.back() : v.front();
  return s;
}

json SpreadJson(const RephotoSpread& s) {
  return {{"mean", s.mean}, {"median", s.median}, {"worst", s.worst}};
}

// NaN as JSON null.
json Number(double x) { return std::isfinite(x) ? json(x) : json(nullptr); }

}  // namespace

RephotoSummary SummarizeRephoto(const RephotoResult& result) {
  RephotoSummary s;
  const std::vector<RephotoFrame>& f = result.frames;
  s.frames = static_cast<int>(f.size());
  s.psnr_db = Spread(
      f, [](const RephotoFrame& r) { return r.psnr_db; }, false);
  s.one_minus_ncc = Spread(
      f, [](const RephotoFrame& r) { return r.one_minus_ncc; }, true);
  s.completeness = Spread(
      f, [](const RephotoFrame& r) { return r.completeness; }, false);
  s.paint_seconds = Spread(
      f, [](const RephotoFrame& r) { return r.paint_seconds; }, true);
  return s;
}

std::string RephotoToJson(const RephotoResult& result, const std::vector<std::string>& settings,
                          int every, const RephotoSummary& summary) {
  json frames = json::array();
  for (const RephotoFrame& f : result.frames) {
    frames.push_back({{"name", f.name},
                      {"counter", f.counter},
                      {"stream", f.stream},
                      {"psnr_db", Number(f.psnr_db)},
                      {"one_minus_ncc", f.one_minus_ncc},
                      {"completeness", f.completeness},
                      {"image_coverage", f.image_coverage},
                      {"pixels", f.pixels},
                      {"frames_painted", f.frames_painted},
                      {"view_layers", f.view_layers},
                      {"paint_seconds", f.paint_seconds},
                      {"auto", json::parse(AutoDecisionsJson(f.decisions))}});
  }
  const json doc = {{"project", result.project},
                    {"settings", settings},
                    {"every", every},
                    {"frames_read", result.frames_read},
                    {"frames_posed", result.frames_posed},
                    {"frames", frames},
                    {"summary",
                     {{"frames", summary.frames},
                      {"psnr_db", SpreadJson(summary.psnr_db)},
                      {"one_minus_ncc", SpreadJson(summary.one_minus_ncc)},
                      {"completeness", SpreadJson(summary.completeness)},
                      {"paint_seconds", SpreadJson(summary.paint_seconds)}}}};
  return doc.dump(2) + "\n";
}

std::string RephotoToMarkdown(const RephotoResult& result, const RephotoSummary& summary) {
  std::string text = "Virtual rephotography of " + result.project + ": " +
                     std::to_string(summary.frames) + " frames left out in turn (of " +
                     std::to_string(result.frames_posed) + " with poses)\n\n";
  text +=
      "| frame | PSNR dB | 1 - NCC | completeness | image covered | painted from | paint s |\n"
      "|---|---|---|---|---|---|---|\n";
  char line[256];
  for (const RephotoFrame& f : result.frames) {
    std::snprintf(line, sizeof line, "| %s | %.2f | %.3f | %.3f | %.3f | %d | %.1f |\n",
                  f.name.c_str(), f.psnr_db, f.one_minus_ncc, f.completeness, f.image_coverage,
                  f.frames_painted, f.paint_seconds);
    text += line;
  }
  const auto row = [&](const char* label, double RephotoSpread::*field) {
    std::snprintf(line, sizeof line, "| **%s** | %.2f | %.3f | %.3f | | | %.1f |\n", label,
                  summary.psnr_db.*field, summary.one_minus_ncc.*field, summary.completeness.*field,
                  summary.paint_seconds.*field);
    text += line;
  };
  row("mean", &RephotoSpread::mean);
  row("median", &RephotoSpread::median);
  row("worst", &RephotoSpread::worst);
  return text;
}

cv::Mat SideBySide(const RephotoFrame& frame, const cv::Mat& rendered_bgr,
                   const cv::Mat& photo_bgr) {
  const int caption_px = std::max(24, photo_bgr.rows / 30);
  cv::Mat out(photo_bgr.rows + caption_px, 2 * photo_bgr.cols, CV_8UC3, cv::Scalar::all(0));
  rendered_bgr.copyTo(out(cv::Rect(0, caption_px, photo_bgr.cols, photo_bgr.rows)));
  photo_bgr.copyTo(out(cv::Rect(photo_bgr.cols, caption_px, photo_bgr.cols, photo_bgr.rows)));
  char text[200];
  std::snprintf(text, sizeof text, "%s  painted from the others: %.2f dB, 1-NCC %.3f | photo",
                frame.name.c_str(), frame.psnr_db, frame.one_minus_ncc);
  const double scale = caption_px / 40.0;
  cv::putText(out, text, cv::Point(8, caption_px * 3 / 4), cv::FONT_HERSHEY_SIMPLEX, scale,
              cv::Scalar::all(255), std::max(1, caption_px / 20), cv::LINE_AA);
  return out;
}

}  // namespace fresco
