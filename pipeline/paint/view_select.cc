#include "pipeline/paint/view_select.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

namespace fresco {

cv::Mat DistanceToDepthEdges(const cv::Mat& depth, double depth_rel) {
  CV_Assert(depth.type() == CV_32F);
  cv::Mat not_edge(depth.size(), CV_8U, cv::Scalar(255));
  const float rel = static_cast<float>(depth_rel);
  const auto jump = [rel](float a, float b) {
    const bool fa = std::isfinite(a), fb = std::isfinite(b);
    if (fa != fb) return true;
    return fa && std::abs(a - b) > rel * std::min(a, b);
  };
  for (int y = 0; y < depth.rows; ++y) {
    const float* row = depth.ptr<float>(y);
    const float* below = y + 1 < depth.rows ? depth.ptr<float>(y + 1) : nullptr;
    uint8_t* mark = not_edge.ptr<uint8_t>(y);
    uint8_t* mark_below = below ? not_edge.ptr<uint8_t>(y + 1) : nullptr;
    for (int x = 0; x < depth.cols; ++x) {
      if (x + 1 < depth.cols && jump(row[x], row[x + 1])) mark[x] = mark[x + 1] = 0;
      if (below && jump(row[x], below[x])) mark[x] = mark_below[x] = 0;
    }
  }
  cv::Mat distance;
  cv::distanceTransform(not_edge, distance, cv::DIST_L2, cv::DIST_MASK_3);
  return distance;
}

namespace {

// Runs fn(chunk index, chunk, texel k, texel index) for every valid texel of `warped`, chunks
// in parallel; returns the sum of fn's results (counts) over all texels.
template <class Fn>
int ForEachValidTexel(const BaseBuffer& buffer, const WarpedBuffer& warped, const Fn& fn) {
  const int num_chunks = static_cast<int>(buffer.chunks.size());
  std::vector<int> counts(num_chunks, 0);
  const uint8_t* valid = warped.valid.data;
  cv::parallel_for_(cv::Range(0, num_chunks), [&](const cv::Range& range) {
    for (int c = range.start; c < range.end; ++c) {
      const BaseBuffer::Chunk& chunk = buffer.chunks[c];
      if (!warped.MayBeValid(chunk)) continue;
      for (int k = chunk.begin; k < chunk.end; ++k)
        if (const int idx = buffer.texel_index[k]; valid[idx]) counts[c] += fn(chunk, k, idx);
    }
  });
  int sum = 0;
  for (int n : counts) sum += n;
  return sum;
}

}  // namespace

ViewSelectStats SelectViews(const BaseBuffer& buffer, const ViewSelectInputs& inputs,
                            const SelectOptions& options, const PaintedBuffer& painted,
                            WarpedBuffer* warped, cv::Mat* kept) {
  ViewSelectStats stats;
  const Camera& camera = *inputs.camera;
  const float focal_texel = static_cast<float>(0.5 * (camera.fx + camera.fy) * buffer.texel_size_m);
  const Eigen::Matrix3f R = inputs.cam_from_local.rotation.toRotationMatrix().cast<float>();
  const Eigen::Vector3f t = inputs.cam_from_local.translation.cast<float>();
  const cv::Mat& edges = inputs.edge_distance_px;
  const bool use_edges = !edges.empty() && options.edge_px > 0;
  const bool pinhole = camera.model == LensModel::kPinhole;
  const float fx = static_cast<float>(camera.fx), fy = static_cast<float>(camera.fy);
  const float cx = static_cast<float>(camera.cx), cy = static_cast<float>(camera.cy);
  const float edge_px = static_cast<float>(options.edge_px);
  uint8_t* valid = warped->valid.data;
  float* score = warped->quality.ptr<float>();
  // The pixel a camera point lands on (nearest), or false outside the image.
  const auto pixel_of = [&](const Eigen::Vector3f& p, int* x, int* y) {
    Eigen::Vector2d pixel;
    if (pinhole) {
      if (p.z() <= 0) return false;
      pixel = Eigen::Vector2d(fx * p.x() / p.z() + cx, fy * p.y() / p.z() + cy);
    } else if (!camera.Project(p.cast<double>(), &pixel)) {
      return false;
    }
    *x = static_cast<int>(std::lround(pixel.x()));
    *y = static_cast<int>(std::lround(pixel.y()));
    return *x >= 0 && *y >= 0 && *x < edges.cols && *y < edges.rows;
  };
  // Pass 1: the texels' own scores (no penalty), near-edge flags as the sign.
  stats.near_edge =
      ForEachValidTexel(buffer, *warped, [&](const BaseBuffer::Chunk& chunk, int k, int idx) {
        const Eigen::Vector3f p = R * buffer.PointIn(chunk, k) + t;
        const Eigen::Vector3f n = R * buffer.Normal(k);
        const float cos_view = std::abs(n.dot(p)) / std::max(p.norm(), 1e-12f);
        const float s = focal_texel * cos_view / std::max(p.z(), 1e-9f);
        int x = 0, y = 0;
        const bool near = use_edges && pixel_of(p, &x, &y) && edges.at<float>(y, x) < edge_px;
        score[idx] = near ? -s : s;
        return near ? 1 : 0;
      });
  // The frame's median score over the buffer's valid texels.
  std::vector<float> all;
  all.reserve(warped->visible);
  for (const BaseBuffer::Chunk& chunk : buffer.chunks) {
    if (!warped->MayBeValid(chunk)) continue;
    for (int k = chunk.begin; k < chunk.end; ++k)
      if (const int idx = buffer.texel_index[k]; valid[idx]) all.push_back(std::abs(score[idx]));
  }
  stats.candidates = static_cast<int>(all.size());
  if (all.empty()) return stats;
  std::nth_element(all.begin(), all.begin() + all.size() / 2, all.end());
  const float median = all[all.size() / 2];
  stats.median_score = median;
  // Pass 2: blend, penalise, and keep the stored sample where it scores better.
  const float w = static_cast<float>(options.region_weight);
  const float region = std::pow(std::max(median, 1e-12f), w);
  const float penalty = static_cast<float>(options.edge_penalty);
  const float switch_factor = static_cast<float>(1.0 + options.switch_margin);
  const cv::Vec4b* stored = painted.bgra.ptr<cv::Vec4b>();
  const float* stored_quality = painted.quality.ptr<float>();
  uint8_t* kept_at = nullptr;
  if (kept) {
    *kept = cv::Mat::zeros(warped->valid.size(), CV_8U);
    kept_at = kept->data;
  }
  stats.kept = ForEachValidTexel(buffer, *warped, [&](const BaseBuffer::Chunk&, int, int idx) {
    const float own = score[idx];
    const float a = std::max(std::abs(own), 1e-12f);
    float s = (w == 0.0f   ? a
               : w == 1.0f ? 1.0f
               : w == 0.5f ? std::sqrt(a)
                           : std::pow(a, 1.0f - w)) *
              region;
    if (own < 0) s *= penalty;
    score[idx] = s;
    if (stored[idx][3] == 0 || s > stored_quality[idx] * switch_factor) return 0;
    valid[idx] = 0;  // the stored sample is better: keep it
    if (kept_at) kept_at[idx] = 255;
    return 1;
  });
  return stats;
}

}  // namespace fresco
