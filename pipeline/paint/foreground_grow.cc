#include "pipeline/paint/foreground_grow.h"

#include <cstdlib>
#include <vector>

namespace fresco {

int GrowForegroundByColour(const cv::Mat& bgr, const cv::Mat& valid, int levels, int reach,
                           cv::Mat* foreground) {
  if (levels <= 0 || reach <= 0 || foreground->empty()) return 0;
  const int w = foreground->cols, h = foreground->rows;
  // Breadth first from every flagged texel at once; each added texel remembers its seed's
  // colour (so the flag does not drift along a gradient) and its distance.
  struct Item {
    int x, y, seed_x, seed_y, steps;
  };
  std::vector<Item> queue;
  for (int y = 0; y < h; ++y) {
    const uint8_t* r = foreground->ptr<uint8_t>(y);
    for (int x = 0; x < w; ++x)
      if (r[x]) queue.push_back({x, y, x, y, 0});
  }
  int added = 0;
  constexpr int kDx[4] = {1, -1, 0, 0}, kDy[4] = {0, 0, 1, -1};
  for (size_t head = 0; head < queue.size(); ++head) {
    const Item item = queue[head];
    if (item.steps >= reach) continue;
    const cv::Vec3b seed = bgr.at<cv::Vec3b>(item.seed_y, item.seed_x);
    for (int d = 0; d < 4; ++d) {
      const int x = item.x + kDx[d], y = item.y + kDy[d];
      if (x < 0 || y < 0 || x >= w || y >= h) continue;
      uint8_t& flag = foreground->at<uint8_t>(y, x);
      if (flag || !valid.at<uint8_t>(y, x)) continue;
      const cv::Vec3b s = bgr.at<cv::Vec3b>(y, x);
      if (std::abs(s[0] - seed[0]) > levels || std::abs(s[1] - seed[1]) > levels ||
          std::abs(s[2] - seed[2]) > levels)
        continue;
      flag = 255;
      ++added;
      queue.push_back({x, y, item.seed_x, item.seed_y, item.steps + 1});
    }
  }
  return added;
}

}  // namespace fresco
