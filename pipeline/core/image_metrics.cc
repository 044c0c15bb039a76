#include "pipeline/core/image_metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <opencv2/imgproc.hpp>

namespace fresco {

double PsnrDb(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask) {
  CV_Assert(a.size() == b.size() && a.type() == b.type() && a.depth() == CV_8U);
  double sum_sq = 0.0;
  long long count = 0;
  const int channels = a.channels();
  for (int y = 0; y < a.rows; ++y) {
    const uint8_t* pa = a.ptr<uint8_t>(y);
    const uint8_t* pb = b.ptr<uint8_t>(y);
    const uint8_t* pm = mask.empty() ? nullptr : mask.ptr<uint8_t>(y);
    for (int x = 0; x < a.cols; ++x) {
      if (pm && !pm[x]) continue;
      for (int c = 0; c < channels; ++c) {
        const double d = double(pa[x * channels + c]) - double(pb[x * channels + c]);
        sum_sq += d * d;
      }
      count += channels;
    }
  }
  if (count == 0) return std::numeric_limits<double>::quiet_NaN();
  const double mse = sum_sq / count;
  if (mse == 0.0) return std::numeric_limits<double>::infinity();
  return 10.0 * std::log10(255.0 * 255.0 / mse);
}

double OneMinusNcc(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask) {
  CV_Assert(a.size() == b.size() && a.type() == b.type());
  cv::Mat ga = a, gb = b;
  if (a.channels() == 3) cv::cvtColor(a, ga, cv::COLOR_BGR2GRAY), cv::cvtColor(b, gb, cv::COLOR_BGR2GRAY);
  if (a.channels() == 4) cv::cvtColor(a, ga, cv::COLOR_BGRA2GRAY), cv::cvtColor(b, gb, cv::COLOR_BGRA2GRAY);
  double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
  long long n = 0;
  for (int y = 0; y < ga.rows; ++y) {
    const uint8_t* pa = ga.ptr<uint8_t>(y);
    const uint8_t* pb = gb.ptr<uint8_t>(y);
    const uint8_t* pm = mask.empty() ? nullptr : mask.ptr<uint8_t>(y);
    for (int x = 0; x < ga.cols; ++x) {
      if (pm && !pm[x]) continue;
      const double va = pa[x], vb = pb[x];
      sa += va, sb += vb, saa += va * va, sbb += vb * vb, sab += va * vb;
      ++n;
    }
  }
  if (n == 0) return std::numeric_limits<double>::quiet_NaN();
  const double cov = sab / n - (sa / n) * (sb / n);
  const double var_a = saa / n - (sa / n) * (sa / n), var_b = sbb / n - (sb / n) * (sb / n);
  if (var_a <= 1e-12 || var_b <= 1e-12) return std::numeric_limits<double>::quiet_NaN();
  return 1.0 - cov / std::sqrt(var_a * var_b);
}

double LocalOneMinusNcc(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask, int window) {
  CV_Assert(a.size() == b.size() && a.type() == b.type() && mask.size() == a.size() &&
            mask.type() == CV_8U && window >= 1);
  cv::Mat ga = a, gb = b;
  if (a.channels() == 3) cv::cvtColor(a, ga, cv::COLOR_BGR2GRAY), cv::cvtColor(b, gb, cv::COLOR_BGR2GRAY);
  if (a.channels() == 4) cv::cvtColor(a, ga, cv::COLOR_BGRA2GRAY), cv::cvtColor(b, gb, cv::COLOR_BGRA2GRAY);
  cv::Mat fa, fb;
  ga.convertTo(fa, CV_64F);
  gb.convertTo(fb, CV_64F);
  const cv::Size box(window, window);
  cv::Mat mean_a, mean_b, mean_aa, mean_bb, mean_ab;
  cv::blur(fa, mean_a, box);
  cv::blur(fb, mean_b, box);
  cv::blur(fa.mul(fa), mean_aa, box);
  cv::blur(fb.mul(fb), mean_bb, box);
  cv::blur(fa.mul(fb), mean_ab, box);
  cv::Mat inside;  // pixels whose whole box is in the mask (beyond the image border counts as
                   // in: boxes there see the image reflected, as the means do)
  cv::erode(mask != 0, inside, cv::Mat::ones(window, window, CV_8U));
  double sum = 0;
  long long n = 0;
  for (int y = 0; y < a.rows; ++y) {
    const uint8_t* m = inside.ptr<uint8_t>(y);
    for (int x = 0; x < a.cols; ++x) {
      if (!m[x]) continue;
      const double ma = mean_a.at<double>(y, x), mb = mean_b.at<double>(y, x);
      const double va = mean_aa.at<double>(y, x) - ma * ma;
      const double vb = mean_bb.at<double>(y, x) - mb * mb;
      const double cov = mean_ab.at<double>(y, x) - ma * mb;
      sum += 1.0 - cov / std::sqrt(std::max(va * vb, 1e-6));
      ++n;
    }
  }
  return n > 0 ? sum / n : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace fresco
