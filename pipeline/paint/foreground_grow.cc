#include "pipeline/paint/foreground_grow.h"

#include <cstdint>
#include <cstdlib>
#include <vector>

namespace fresco {

int GrowForegroundByColour(const cv::Mat& bgr, const cv::Mat& valid, int levels, int reach,
                           cv::Mat* foreground) {
  if (levels <= 0 || reach <= 0 || foreground->empty()) return 0;
  const int w = foreground->cols, h = foreground->rows;
  CV_Assert(w <= 65535 && h <= 65535 && bgr.size() == foreground->size() &&
            valid.size() == foreground->size());
  // Breadth first from every flagged texel at once; each added texel carries its seed's
  // colour (so the flag does not drift along a gradient) and its distance.
  struct Item {
    uint16_t x, y;
    uint8_t b, g, r;
    int steps;
  };
  std::vector<Item> queue;
  queue.reserve(1024);
  for (int y = 0; y < h; ++y) {
    const uint8_t* flags = foreground->ptr<uint8_t>(y);
    const uint8_t* colour = bgr.ptr<uint8_t>(y);
    for (int x = 0; x < w; ++x)
      if (flags[x])
        queue.push_back({static_cast<uint16_t>(x), static_cast<uint16_t>(y), colour[3 * x],
                         colour[3 * x + 1], colour[3 * x + 2], 0});
  }
  uint8_t* const flag0 = foreground->data;
  const uint8_t* const valid0 = valid.data;
  const uint8_t* const bgr0 = bgr.data;
  const size_t flag_step = foreground->step, valid_step = valid.step, bgr_step = bgr.step;
  int added = 0;
  // Neighbours in the order +x, -x, +y, -y (the order decides which seed claims a texel).
  for (size_t head = 0; head < queue.size(); ++head) {
    const Item item = queue[head];
    if (item.steps >= reach) continue;
    const auto visit = [&](int x, int y) {
      uint8_t* flag = flag0 + y * flag_step + x;
      if (*flag || !valid0[y * valid_step + x]) return;
      const uint8_t* s = bgr0 + y * bgr_step + 3 * x;
      if (std::abs(s[0] - item.b) > levels || std::abs(s[1] - item.g) > levels ||
          std::abs(s[2] - item.r) > levels)
        return;
      *flag = 255;
      ++added;
      queue.push_back({static_cast<uint16_t>(x), static_cast<uint16_t>(y), item.b, item.g, item.r,
                       item.steps + 1});
    };
    const int x = item.x, y = item.y;
    if (x + 1 < w) visit(x + 1, y);
    if (x > 0) visit(x - 1, y);
    if (y + 1 < h) visit(x, y + 1);
    if (y > 0) visit(x, y - 1);
  }
  return added;
}

}  // namespace fresco
