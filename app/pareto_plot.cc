#include "app/pareto_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <opencv2/imgproc.hpp>

namespace fresco {

std::vector<size_t> ParetoFront(const std::vector<ParetoPoint>& points) {
  std::vector<size_t> front;
  for (size_t i = 0; i < points.size(); ++i) {
    bool dominated = false;
    for (size_t j = 0; j < points.size() && !dominated; ++j) {
      const bool no_worse = points[j].fps >= points[i].fps && points[j].psnr_db >= points[i].psnr_db;
      const bool better = points[j].fps > points[i].fps || points[j].psnr_db > points[i].psnr_db;
      dominated = j != i && no_worse && better;
    }
    if (!dominated) front.push_back(i);
  }
  std::sort(front.begin(), front.end(),
            [&](size_t a, size_t b) { return points[a].fps < points[b].fps; });
  return front;
}

cv::Mat DrawPareto(const std::vector<ParetoPoint>& points, const std::string& title) {
  const int width = 1000, height = 640, left = 80, right = 30, top = 50, bottom = 60;
  cv::Mat image(height, width, CV_8UC3, cv::Scalar(255, 255, 255));
  const auto text = [&](const std::string& s, cv::Point at, double scale, cv::Scalar colour) {
    cv::putText(image, s, at, cv::FONT_HERSHEY_SIMPLEX, scale, colour, 1, cv::LINE_AA);
  };
  text(title, {left, 30}, 0.6, cv::Scalar(0, 0, 0));
  if (points.empty()) return image;
  double fps_max = 0, psnr_min = 1e9, psnr_max = -1e9;
  for (const ParetoPoint& p : points) {
    fps_max = std::max(fps_max, p.fps);
    psnr_min = std::min(psnr_min, p.psnr_db);
    psnr_max = std::max(psnr_max, p.psnr_db);
  }
  fps_max = std::max(1.0, std::ceil(fps_max * 1.1 / 5) * 5);
  psnr_min = std::floor(psnr_min - 1), psnr_max = std::ceil(psnr_max + 1);
  const auto to_pixel = [&](double fps, double psnr) {
    return cv::Point(left + static_cast<int>((width - left - right) * fps / fps_max),
                     height - bottom -
                         static_cast<int>((height - top - bottom) * (psnr - psnr_min) /
                                          (psnr_max - psnr_min)));
  };
  const cv::Scalar axis(80, 80, 80), grid(225, 225, 225);
  char label[64];
  for (int i = 0; i <= 5; ++i) {  // grid and ticks
    const double fps = fps_max * i / 5, psnr = psnr_min + (psnr_max - psnr_min) * i / 5;
    cv::line(image, to_pixel(fps, psnr_min), to_pixel(fps, psnr_max), grid);
    cv::line(image, to_pixel(0, psnr), to_pixel(fps_max, psnr), grid);
    std::snprintf(label, sizeof label, "%.0f", fps);
    text(label, to_pixel(fps, psnr_min) + cv::Point(-8, 20), 0.45, axis);
    std::snprintf(label, sizeof label, "%.1f", psnr);
    text(label, to_pixel(0, psnr) + cv::Point(-50, 5), 0.45, axis);
  }
  cv::rectangle(image, to_pixel(0, psnr_max), to_pixel(fps_max, psnr_min), axis);
  text("frames per second (end to end)", {width / 2 - 120, height - 15}, 0.5, axis);
  text("PSNR dB (held-out frames)", {8, top - 8}, 0.45, axis);
  const std::vector<size_t> front = ParetoFront(points);
  for (size_t k = 1; k < front.size(); ++k)
    cv::line(image, to_pixel(points[front[k - 1]].fps, points[front[k - 1]].psnr_db),
             to_pixel(points[front[k]].fps, points[front[k]].psnr_db), cv::Scalar(0, 0, 220), 2,
             cv::LINE_AA);
  // Labels: the front's first, then the others; a label that would overlap one already
  // drawn becomes the point's row number in bench.json ("#3").
  std::vector<size_t> order = front;
  for (size_t i = 0; i < points.size(); ++i)
    if (std::find(front.begin(), front.end(), i) == front.end()) order.push_back(i);
  std::vector<cv::Rect> placed;
  for (size_t i : order) {
    const bool on_front = std::find(front.begin(), front.end(), i) != front.end();
    const cv::Point at = to_pixel(points[i].fps, points[i].psnr_db);
    const cv::Scalar colour = on_front ? cv::Scalar(0, 0, 220) : cv::Scalar(120, 120, 120);
    cv::circle(image, at, 5, colour, cv::FILLED, cv::LINE_AA);
    // The full label to the right (or left) of the point; if that overlaps a label already
    // drawn, the row number at the first free place around the point.
    char number[24];
    std::snprintf(number, sizeof number, "#%zu", i);
    const std::string candidates[2] = {points[i].label, number};
    bool drawn = false;
    for (const std::string& label : candidates) {
      int baseline = 0;
      const cv::Size size = cv::getTextSize(label, cv::FONT_HERSHEY_SIMPLEX, 0.4, 1, &baseline);
      const bool fits_right = at.x + 8 + size.width < width - 4;
      const cv::Point offsets[4] = {{fits_right ? 8 : -8 - size.width, -6},
                                    {fits_right ? 8 : -8 - size.width, 16},
                                    {-8 - size.width, -6},
                                    {-8 - size.width, 16}};
      for (int k = 0; k < (label == number ? 4 : 1) && !drawn; ++k) {
        const cv::Point origin = at + offsets[k];
        const cv::Rect box(origin.x, origin.y - size.height, size.width, size.height + baseline);
        if (std::any_of(placed.begin(), placed.end(),
                        [&](const cv::Rect& r) { return (r & box).area() > 0; }))
          continue;
        placed.push_back(box);
        text(label, origin, 0.4, on_front ? cv::Scalar(0, 0, 160) : cv::Scalar(90, 90, 90));
        drawn = true;
      }
      if (drawn) break;
    }
  }
  return image;
}

}  // namespace fresco
