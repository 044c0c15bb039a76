#include "pipeline/paint/seam_levelling.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace fresco {
namespace {

// Values this far from black and saturation carry the colour (as the exposure fit's).
constexpr int kMinUsableValue = 4, kMaxUsableValue = 251;

const std::array<float, 256>& LogTable() {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> t{};
    for (int i = 0; i < 256; ++i) t[i] = std::log(static_cast<float>(std::max(i, 1)));
    return t;
  }();
  return table;
}

float MedianOf(std::vector<float>* v) {
  auto mid = v->begin() + v->size() / 2;
  std::nth_element(v->begin(), mid, v->end());
  return *mid;
}

// The grid of cells over the warped buffer's valid box.
struct CellGrid {
  cv::Rect box;
  int cell = 1;        // texels a side
  int gx = 0, gy = 0;  // cells across and down
  int Cells() const { return gx * gy; }
};

// Per cell and channel, log(stored / sample) over the kept texels (trusted stored samples,
// values away from black and saturation, ratios within max_log_ratio of 1).
std::vector<std::vector<float>> CellRatios(const PaintedBuffer& painted, const cv::Mat& kept,
                                           const WarpedBuffer& warped, const CellGrid& grid,
                                           float max_log) {
  const cv::Rect& box = grid.box;
  const int cell = grid.cell, gx = grid.gx;
  const int width = warped.bgr.cols;
  const cv::Vec3b* sample = warped.bgr.ptr<cv::Vec3b>();
  const cv::Vec4b* stored = painted.bgra.ptr<cv::Vec4b>();
  const float* stored_quality = painted.quality.ptr<float>();
  const std::array<float, 256>& log_of = LogTable();
  const uint8_t* keeps = kept.data;
  std::vector<std::vector<float>> ratios(3 * static_cast<size_t>(grid.Cells()));
  for (int y = box.y; y < box.br().y; ++y) {
    const int cy = (y - box.y) / cell;
    for (int x = box.x; x < box.br().x; ++x) {
      const int idx = y * width + x;
      if (!keeps[idx] || stored[idx][3] == 0 || !(stored_quality[idx] > 0.0f)) continue;
      float d[3];
      bool usable = true;
      for (int c = 0; c < 3 && usable; ++c) {
        const int s = sample[idx][c], o = stored[idx][c];
        usable = s >= kMinUsableValue && s <= kMaxUsableValue && o >= kMinUsableValue &&
                 o <= kMaxUsableValue;
        d[c] = log_of[o] - log_of[s];
        usable = usable && std::abs(d[c]) <= max_log;
      }
      if (!usable) continue;
      const size_t at = 3 * static_cast<size_t>(cy * gx + (x - box.x) / cell);
      for (int c = 0; c < 3; ++c) ratios[at + c].push_back(d[c]);
    }
  }
  return ratios;
}

// Cells without a value take their measured (or earlier filled) neighbours' mean, for
// `rounds` rounds. set: per cell, 0 unset, 1 measured, 2 + round filled.
void FillCells(const CellGrid& grid, int rounds, std::vector<float>* value, std::vector<int>* set,
               SeamLevelStats* stats) {
  const int gx = grid.gx, gy = grid.gy;
  for (int round = 0; round < rounds; ++round) {
    const std::vector<int> before = *set;
    for (int cy = 0; cy < gy; ++cy)
      for (int cx = 0; cx < gx; ++cx) {
        const int i = cy * gx + cx;
        if (before[i] != 0) continue;
        float sum[3] = {0, 0, 0};
        int n = 0;
        const int neighbours[4][2] = {{cx - 1, cy}, {cx + 1, cy}, {cx, cy - 1}, {cx, cy + 1}};
        for (const auto& nb : neighbours) {
          if (nb[0] < 0 || nb[1] < 0 || nb[0] >= gx || nb[1] >= gy) continue;
          const int j = nb[1] * gx + nb[0];
          if (before[j] == 0) continue;
          for (int c = 0; c < 3; ++c) sum[c] += (*value)[3 * j + c];
          ++n;
        }
        if (n == 0) continue;
        for (int c = 0; c < 3; ++c) (*value)[3 * i + c] = sum[c] / static_cast<float>(n);
        (*set)[i] = 2 + round;
        ++stats->cells_filled;
      }
  }
}

// Each valid sample times the gain interpolated between the cells' centres, drawn towards 1
// linearly with the texel's distance from the nearest kept texel (1 at fade_texels).
void ApplyGains(const CellGrid& grid, const std::vector<float>& gain, const cv::Mat& kept,
                int fade_texels, WarpedBuffer* warped) {
  const cv::Rect& box = grid.box;
  const int gx = grid.gx, gy = grid.gy;
  const int width = warped->bgr.cols;
  const uint8_t* valid = warped->valid.data;
  cv::Vec3b* sample = warped->bgr.ptr<cv::Vec3b>();
  // (City-block distances, in bytes where the fade is short: a fraction of the cost.)
  cv::Mat not_kept = kept(box) == 0, distance;
  if (fade_texels < 255)
    cv::distanceTransform(not_kept, distance, cv::DIST_L1, 3, CV_8U);
  else
    cv::distanceTransform(not_kept, distance, cv::DIST_L1, 3, CV_32F);
  const bool bytes = distance.type() == CV_8U;
  const float inv_fade = 1.0f / static_cast<float>(fade_texels);
  const float inv_cell = 1.0f / static_cast<float>(grid.cell);
  for (int y = box.y; y < box.br().y; ++y) {
    const float fy = std::clamp((static_cast<float>(y - box.y) + 0.5f) * inv_cell - 0.5f, 0.0f,
                                static_cast<float>(gy - 1));
    const int y0 = std::min(static_cast<int>(fy), gy - 1), y1 = std::min(y0 + 1, gy - 1);
    const float ay = fy - static_cast<float>(y0);
    for (int x = box.x; x < box.br().x; ++x) {
      const int idx = y * width + x;
      if (!valid[idx]) continue;
      const float d = bytes ? static_cast<float>(distance.at<uint8_t>(y - box.y, x - box.x))
                            : distance.at<float>(y - box.y, x - box.x);
      const float fade = 1.0f - d * inv_fade;
      if (fade <= 0.0f) continue;
      const float fx = std::clamp((static_cast<float>(x - box.x) + 0.5f) * inv_cell - 0.5f, 0.0f,
                                  static_cast<float>(gx - 1));
      const int x0 = std::min(static_cast<int>(fx), gx - 1), x1 = std::min(x0 + 1, gx - 1);
      const float ax = fx - static_cast<float>(x0);
      const float w00 = (1 - ax) * (1 - ay), w10 = ax * (1 - ay), w01 = (1 - ax) * ay,
                  w11 = ax * ay;
      const int c00 = 3 * (y0 * gx + x0), c10 = 3 * (y0 * gx + x1), c01 = 3 * (y1 * gx + x0),
                c11 = 3 * (y1 * gx + x1);
      for (int c = 0; c < 3; ++c) {
        const float g = 1.0f + fade * (w00 * gain[c00 + c] + w10 * gain[c10 + c] +
                                       w01 * gain[c01 + c] + w11 * gain[c11 + c] - 1.0f);
        sample[idx][c] = cv::saturate_cast<uint8_t>(static_cast<float>(sample[idx][c]) * g);
      }
    }
  }
}

}  // namespace

SeamLevelStats LevelSeams(const PaintedBuffer& painted, const cv::Mat& kept,
                          const SeamLevelOptions& options, WarpedBuffer* warped) {
  SeamLevelStats stats;
  const cv::Rect box = warped->valid_box;
  if (box.empty() || kept.size() != warped->bgr.size() || kept.type() != CV_8U ||
      painted.bgra.size() != warped->bgr.size())
    return stats;
  CellGrid grid;
  grid.box = box;
  grid.cell = std::max(1, options.cell_texels);
  grid.gx = (box.width + grid.cell - 1) / grid.cell;
  grid.gy = (box.height + grid.cell - 1) / grid.cell;
  const int cells = grid.Cells();
  std::vector<std::vector<float>> ratios =
      CellRatios(painted, kept, *warped, grid, static_cast<float>(options.max_log_ratio));

  // The measured cells' medians; the others filled from their neighbours.
  std::vector<float> value(3 * static_cast<size_t>(cells), 0.0f);
  std::vector<int> set(cells, 0);  // 0 unset, 1 measured, 2 + round filled
  for (int i = 0; i < cells; ++i) {
    std::vector<float>* r = &ratios[3 * static_cast<size_t>(i)];
    if (static_cast<int>(r->size()) < options.min_samples) continue;
    set[i] = 1;
    ++stats.cells_measured;
    for (int c = 0; c < 3; ++c) {
      value[3 * i + c] = MedianOf(&ratios[3 * static_cast<size_t>(i) + c]);
      stats.abs_log_sum += std::abs(value[3 * i + c]);
    }
  }
  if (stats.cells_measured == 0) return stats;
  FillCells(grid, options.fill_cells, &value, &set, &stats);

  std::vector<float> gain(value.size());
  for (size_t k = 0; k < value.size(); ++k) gain[k] = std::exp(value[k]);
  ApplyGains(grid, gain, kept, std::max(1, options.fade_texels), warped);
  return stats;
}

}  // namespace fresco
