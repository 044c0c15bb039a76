#include "pipeline/paint/ringed_regions.h"

#include <cstdlib>
#include <numeric>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace fresco {

// Union-find over the 4-neighbour pairs: OpenCV's floodFill grows one region a call, and in a
// textured frame most regions are a pixel or two (tens of thousands of calls a frame).
cv::Mat ColourRegions(const cv::Mat& bgr, int levels, int* count) {
  const int w = bgr.cols, h = bgr.rows;
  std::vector<int> parent(static_cast<size_t>(w) * h);
  std::iota(parent.begin(), parent.end(), 0);
  const auto root = [&](int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  const auto alike = [&](const cv::Vec3b& a, const cv::Vec3b& b) {
    return std::abs(a[0] - b[0]) <= levels && std::abs(a[1] - b[1]) <= levels &&
           std::abs(a[2] - b[2]) <= levels;
  };
  for (int y = 0; y < h; ++y) {
    const cv::Vec3b* row = bgr.ptr<cv::Vec3b>(y);
    const cv::Vec3b* below = y + 1 < h ? bgr.ptr<cv::Vec3b>(y + 1) : nullptr;
    for (int x = 0; x < w; ++x) {
      const int i = y * w + x;
      if (x + 1 < w && alike(row[x], row[x + 1])) parent[root(i)] = root(i + 1);
      if (below && alike(row[x], below[x])) parent[root(i)] = root(i + w);
    }
  }
  cv::Mat labels(h, w, CV_32S);
  std::vector<int> label_of(parent.size(), -1);
  int n = 0;
  int* out = labels.ptr<int>();
  for (int i = 0; i < w * h; ++i) {
    int& l = label_of[root(i)];
    if (l < 0) l = n++;
    out[i] = l;
  }
  *count = n;
  return labels;
}

cv::Mat RingedRegions(const cv::Mat& bgr, const cv::Mat& mask, const cv::Mat& surface,
                      const RingedRegionOptions& options, ColourRegionLabels* kept) {
  const int w = bgr.cols, h = bgr.rows;
  cv::Mat ringed(bgr.size(), CV_8U, cv::Scalar(0));
  if (options.share <= 0 || cv::countNonZero(mask) == 0) return ringed;
  ColourRegionLabels made;
  ColourRegionLabels& labelled = kept ? *kept : made;
  if (labelled.labels.empty()) {
    labelled.labels = ColourRegions(bgr, options.levels, &labelled.count);
    const cv::Mat& regions = labelled.labels;
    labelled.on_boundary = cv::Mat::zeros(bgr.size(), CV_8U);
    labelled.area.assign(labelled.count, 0);
    labelled.boundary.assign(labelled.count, 0);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const int r = regions.at<int>(y, x);
        ++labelled.area[r];
        // Another region's surface pixel next to it: this pixel is on the region's boundary.
        const auto other = [&](int u, int v) {
          return regions.at<int>(v, u) != r && surface.at<uchar>(v, u) != 0;
        };
        if ((x > 0 && other(x - 1, y)) || (x + 1 < w && other(x + 1, y)) ||
            (y > 0 && other(x, y - 1)) || (y + 1 < h && other(x, y + 1))) {
          labelled.on_boundary.at<uchar>(y, x) = 1;
          ++labelled.boundary[r];
        }
      }
  }
  const int count = labelled.count;
  const cv::Mat& regions = labelled.labels;
  const std::vector<int>& area = labelled.area;
  const std::vector<int>& boundary = labelled.boundary;
  // Within two pixels of the mask: the 5 x 5 square without its corners.
  cv::Mat near, reach = cv::Mat::ones(5, 5, CV_8U);
  reach.at<uchar>(0, 0) = reach.at<uchar>(0, 4) = reach.at<uchar>(4, 0) = reach.at<uchar>(4, 4) = 0;
  cv::dilate(mask, near, reach);
  std::vector<int> masked_boundary(count, 0), inside(count, 0);
  for (int y = 0; y < h; ++y) {
    const int* region = regions.ptr<int>(y);
    const uchar* masked = mask.ptr<uchar>(y);
    const uchar* edge = labelled.on_boundary.ptr<uchar>(y);
    const uchar* close = near.ptr<uchar>(y);
    for (int x = 0; x < w; ++x) {
      inside[region[x]] += masked[x] != 0;
      if (edge[x]) masked_boundary[region[x]] += close[x] != 0;
    }
  }
  std::vector<uint8_t> joins(count, 0);
  const double max_px = options.max_share * w * h;
  for (int r = 0; r < count; ++r)
    joins[r] = area[r] >= options.min_px && area[r] <= max_px && inside[r] < area[r] &&
               boundary[r] > 0 && masked_boundary[r] >= options.share * boundary[r];
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (joins[regions.at<int>(y, x)]) ringed.at<uchar>(y, x) = 255;
  return ringed;
}

}  // namespace fresco
