#include "pipeline/paint/buffer_preview.h"

#include <algorithm>
#include <string>

#include <opencv2/imgproc.hpp>

namespace fresco {

cv::Mat BufferContactSheet(const std::vector<PaintedBuffer>& buffers, int max_width,
                           int cell_height) {
  const int gap = 8;
  // Lay cells out in rows, left to right.
  struct Cell {
    cv::Rect rect;
    int buffer;
  };
  std::vector<Cell> cells;
  int x = gap, y = gap, row_height = 0, width = 0;
  for (size_t b = 0; b < buffers.size(); ++b) {
    const cv::Mat& bgra = buffers[b].bgra;
    if (bgra.empty()) continue;
    int h = cell_height;
    int w = std::max(1, bgra.cols * h / std::max(1, bgra.rows));
    if (w > max_width - 2 * gap) {  // very wide buffer: fit the width instead
      w = max_width - 2 * gap;
      h = std::max(1, bgra.rows * w / std::max(1, bgra.cols));
    }
    if (x + w + gap > max_width && x > gap) {
      x = gap;
      y += row_height + gap;
      row_height = 0;
    }
    cells.push_back({cv::Rect(x, y, w, h), static_cast<int>(b)});
    x += w + gap;
    row_height = std::max(row_height, h);
    width = std::max(width, x);
  }
  cv::Mat sheet(std::max(1, y + row_height + gap), std::max(1, width), CV_8UC3,
                cv::Scalar(40, 40, 40));
  for (const Cell& cell : cells) {
    cv::Mat scaled;
    cv::resize(buffers[cell.buffer].bgra, scaled, cell.rect.size(), 0, 0, cv::INTER_AREA);
    cv::Mat out = sheet(cell.rect);
    for (int r = 0; r < scaled.rows; ++r) {
      for (int c = 0; c < scaled.cols; ++c) {
        const cv::Vec4b p = scaled.at<cv::Vec4b>(r, c);
        const uchar check = ((r / 8 + c / 8) % 2) ? 150 : 110;  // never painted
        const float a = p[3] / 255.0f;
        for (int k = 0; k < 3; ++k)
          out.at<cv::Vec3b>(r, c)[k] = static_cast<uchar>(a * p[k] + (1 - a) * check + 0.5f);
      }
    }
    cv::putText(sheet, std::to_string(cell.buffer), cell.rect.tl() + cv::Point(6, 22),
                cv::FONT_HERSHEY_SIMPLEX, 0.7, cv::Scalar(0, 0, 0), 3, cv::LINE_AA);
    cv::putText(sheet, std::to_string(cell.buffer), cell.rect.tl() + cv::Point(6, 22),
                cv::FONT_HERSHEY_SIMPLEX, 0.7, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  }
  return sheet;
}

}  // namespace fresco
