#include "pipeline/paint/foreground_blobs.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <numeric>
#include <stdexcept>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace fresco {
namespace {

struct Run {
  int row, x0, x1;  // columns x0..x1 (inclusive) of `row` are foreground
};

// The foreground runs of each row, row by row (zero bytes skipped 8 at a time).
void FindRuns(const cv::Mat& raw, std::vector<Run>* runs, std::vector<int>* row_start) {
  runs->clear();
  row_start->assign(raw.rows + 1, 0);
  const int w = raw.cols;
  for (int y = 0; y < raw.rows; ++y) {
    (*row_start)[y] = static_cast<int>(runs->size());
    const uint8_t* p = raw.ptr<uint8_t>(y);
    int x = 0;
    while (x < w) {
      while (x + 8 <= w) {
        uint64_t word;
        std::memcpy(&word, p + x, 8);
        if (word != 0) break;
        x += 8;
      }
      while (x < w && p[x] == 0) ++x;
      if (x == w) break;
      const int x0 = x;
      while (x < w && p[x] != 0) ++x;
      runs->push_back(Run{y, x0, x - 1});
    }
  }
  (*row_start)[raw.rows] = static_cast<int>(runs->size());
}

int Root(std::vector<int>& parent, int i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

void Unite(std::vector<int>& parent, int a, int b) {
  a = Root(parent, a), b = Root(parent, b);
  if (a != b) parent[std::max(a, b)] = std::min(a, b);
}

}  // namespace

int CleanForeground(const cv::Mat& raw, int min_blob_texels, int dilate_texels, cv::Mat* out) {
  if (raw.type() != CV_8U || out->type() != CV_8U || out->size() != raw.size())
    throw std::invalid_argument("CleanForeground: raw and out must be CV_8U of one size");
  std::vector<Run> runs;
  std::vector<int> row_start;
  FindRuns(raw, &runs, &row_start);
  // Blobs: runs joined when they touch across a row, diagonals included (8-connectivity).
  std::vector<int> parent(runs.size());
  std::iota(parent.begin(), parent.end(), 0);
  for (int y = 1; y < raw.rows; ++y) {
    int p = row_start[y - 1];
    const int p_end = row_start[y];
    for (int c = row_start[y]; c < row_start[y + 1]; ++c) {
      // Runs of the row above that end left of this one's reach touch no later run either.
      while (p < p_end && runs[p].x1 + 1 < runs[c].x0) ++p;
      for (int q = p; q < p_end && runs[q].x0 <= runs[c].x1 + 1; ++q) Unite(parent, q, c);
    }
  }
  // Each run's blob (its root), found once; the blobs' areas summed at their roots.
  std::vector<int> area(runs.size(), 0);
  for (size_t i = 0; i < runs.size(); ++i) {
    parent[i] = Root(parent, static_cast<int>(i));
    area[parent[i]] += runs[i].x1 - runs[i].x0 + 1;
  }
  int dropped = 0;
  for (size_t i = 0; i < runs.size(); ++i)
    if (parent[i] == static_cast<int>(i) && area[i] < min_blob_texels) ++dropped;
  // Each kept run, dilated: the ellipse's row dy is one centred interval of half-width
  // half_width[dy + r], so the run grows into that row by as much on either side.
  const int r = std::max(0, dilate_texels);
  std::vector<int> half_width(2 * r + 1, 0);
  if (r > 0) {
    const cv::Mat kernel =
        cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * r + 1, 2 * r + 1));
    for (int i = 0; i <= 2 * r; ++i) {
      const uint8_t* k = kernel.ptr<uint8_t>(i);
      int first = 0;
      while (first <= 2 * r && k[first] == 0) ++first;
      half_width[i] = first > r ? -1 : r - first;  // -1: an empty row (none in OpenCV's)
    }
  }
  for (size_t i = 0; i < runs.size(); ++i) {
    if (area[parent[i]] < min_blob_texels) continue;
    const Run& run = runs[i];
    for (int dy = -r; dy <= r; ++dy) {
      const int y = run.row + dy, hw = half_width[dy + r];
      if (y < 0 || y >= out->rows || hw < 0) continue;
      const int x0 = std::max(0, run.x0 - hw), x1 = std::min(out->cols - 1, run.x1 + hw);
      std::memset(out->ptr<uint8_t>(y) + x0, 255, x1 - x0 + 1);
    }
  }
  return dropped;
}

}  // namespace fresco
