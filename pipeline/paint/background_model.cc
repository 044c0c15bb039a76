#include "pipeline/paint/background_model.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstring>
#include <utility>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "pipeline/paint/foreground_blobs.h"
#include "pipeline/paint/foreground_grow.h"

namespace fresco {

int GainStride(long long visible) {
  constexpr long long kSamples = 65536;
  return 4 * static_cast<int>(std::max(1LL, visible / (4 * kSamples)));
}

float GainHistogram::MedianGain(long long min_samples) const {
  if (count < min_samples) return 1.0f;
  long long seen = 0;
  for (int i = 0; i < kBins; ++i) {
    seen += bins[i];
    if (2 * seen >= count) return std::exp2(-2.0f + 4.0f * (i + 0.5f) / kBins);
  }
  return 1.0f;
}

// What one chunk of texels found (reduced after the parallel loop: deterministic).
struct BufferBackground::ChunkStats {
  int observed = 0, foreground = 0, warming = 0;
  int x_min = INT_MAX, y_min = INT_MAX, x_max = -1, y_max = -1;  // foreground texels
};

void BufferBackground::Init(const BaseBuffer& buffer, const BackgroundOptions& options) {
  options_ = options;
  robust_.Clear();
  average_.clear();
  if (options.mode == BackgroundMode::kRobust) robust_.Assign(buffer.NumTexels());
  if (options.mode == BackgroundMode::kAverage) average_.assign(buffer.NumTexels(), AverageTexel{});
  raw_ = cv::Mat::zeros(buffer.height, buffer.width, CV_8U);
  raw_set_.assign(buffer.chunks.size(), 0);
}

namespace {
// The texel pairs (k, from) by which a field moves texels: the texel at q (in `roi`) takes
// the state of the texel nearest to q + field(q - roi.tl()), when there is one.
std::vector<std::pair<int, int>> MovedTexels(const BaseBuffer& buffer,
                                             const std::vector<int>& texel_at, const cv::Rect& roi,
                                             const cv::Mat& field) {
  std::vector<std::pair<int, int>> moved;
  for (int y = roi.y; y < roi.br().y; ++y) {
    const cv::Vec2f* f = field.ptr<cv::Vec2f>(y - roi.y);
    for (int x = roi.x; x < roi.br().x; ++x) {
      const int k = texel_at[static_cast<size_t>(y) * buffer.width + x];
      const int sx = x + static_cast<int>(std::lround(f[x - roi.x][0]));
      const int sy = y + static_cast<int>(std::lround(f[x - roi.x][1]));
      if (k < 0 || (sx == x && sy == y)) continue;
      if (sx < 0 || sy < 0 || sx >= buffer.width || sy >= buffer.height) continue;
      const int from = texel_at[static_cast<size_t>(sy) * buffer.width + sx];
      if (from >= 0) moved.emplace_back(k, from);
    }
  }
  return moved;
}
}  // namespace

void BufferBackground::Move(const BaseBuffer& buffer, const cv::Rect& roi, const cv::Mat& field) {
  if (texel_at_.empty()) {
    texel_at_.assign(static_cast<size_t>(buffer.width) * buffer.height, -1);
    for (int k = 0; k < buffer.NumTexels(); ++k) texel_at_[buffer.texel_index[k]] = k;
  }
  const std::vector<std::pair<int, int>> moved = MovedTexels(buffer, texel_at_, roi, field);
  if (!robust_.empty()) robust_.Move(moved);
  if (average_.empty()) return;
  std::vector<AverageTexel> read(moved.size());  // all read before any is written
  for (size_t i = 0; i < moved.size(); ++i) read[i] = average_[moved[i].second];
  for (size_t i = 0; i < moved.size(); ++i) average_[moved[i].first] = read[i];
}

void BufferBackground::AccumulateGain(const BaseBuffer& buffer, const WarpedBuffer& warped,
                                      int stride, GainHistogram* histogram) const {
  if (robust_.empty()) return;
  const uint8_t* valid = warped.valid.data;
  const cv::Vec3b* src = warped.bgr.ptr<cv::Vec3b>();
  constexpr float kBinsPerLog2 = GainHistogram::kBins / 4.0f;
  for (const BaseBuffer::Chunk& chunk : buffer.chunks) {
    if (!warped.MayBeValid(chunk)) continue;
    for (int k = (chunk.begin + stride - 1) / stride * stride; k < chunk.end; k += stride) {
      const int idx = buffer.texel_index[k];
      if (!valid[idx] || robust_.samples[k] == 0) continue;
      const float model = (robust_.mean[0][0][k] + robust_.mean[0][1][k] + robust_.mean[0][2][k]) *
                          (1.0f / kRobustMeanScale);
      const float sample = static_cast<float>(src[idx][0] + src[idx][1] + src[idx][2]);
      if (model < 30.0f || sample < 30.0f) continue;  // too dark for a ratio
      const int bin = static_cast<int>((std::log2(sample / model) + 2.0f) * kBinsPerLog2);
      ++histogram->bins[std::clamp(bin, 0, GainHistogram::kBins - 1)];
      ++histogram->count;
    }
  }
}

namespace {

// A chunk's texels are classified in runs (a chunk is one run: at most a tile's texels).
constexpr int kRunMax = BaseBuffer::kTileTexels * BaseBuffer::kTileTexels;

// One run of texels: where it is and how it is read (a full tile's texels are runs of the
// buffer's rows, BaseBuffer::Chunk::full: read and written a row at a time; otherwise one at
// a time through texel_index).
struct TexelSpan {
  const BaseBuffer& buffer;
  const BaseBuffer::Chunk& chunk;
  int begin = 0, n = 0;
  bool rows = false;

  const int32_t* Index() const { return buffer.texel_index.data() + begin; }
  int TileWidth() const { return chunk.x1 - chunk.x0; }
  size_t RowOf(int r) const { return static_cast<size_t>(chunk.y0 + r) * buffer.width + chunk.x0; }
};

// A run's samples (robust: divided by the gain) and what classifying them found.
struct TexelRun {
  alignas(32) float x[3][kRunMax];
  alignas(32) uint8_t sampled[kRunMax], foreground[kRunMax], warm_up[kRunMax];
  alignas(32) float distance2[kRunMax];
};

// The robust model's input: each texel's sample divided by the gain, and whether it has one.
void GatherSamples(const TexelSpan& span, const WarpedBuffer& warped, float inv_gain,
                   TexelRun* run) {
  const uint8_t* valid = warped.valid.data;
  if (span.rows) {
    const int tile_w = span.TileWidth();
    for (int r = 0, i = 0; i < span.n; ++r, i += tile_w) {
      const size_t row = span.RowOf(r);
      const uint8_t* v = valid + row;
      const uint8_t* p = warped.bgr.data + 3 * row;
      for (int c = 0; c < tile_w; ++c) {
        run->sampled[i + c] = v[c] != 0;
        run->x[0][i + c] = p[3 * c] * inv_gain;
        run->x[1][i + c] = p[3 * c + 1] * inv_gain;
        run->x[2][i + c] = p[3 * c + 2] * inv_gain;
      }
    }
    return;
  }
  const cv::Vec3b* src = warped.bgr.ptr<cv::Vec3b>();
  const int32_t* index = span.Index();
  for (int i = 0; i < span.n; ++i) {
    const int idx = index[i];
    const cv::Vec3b s = src[idx];
    run->sampled[i] = valid[idx] != 0;
    for (int c = 0; c < 3; ++c) run->x[c][i] = s[c] * inv_gain;
  }
}

// The average model: training texels learn (and paint provisionally); trained ones are
// foreground where a channel differs from their mean by more than average_threshold.
void ClassifyAverage(const TexelSpan& span, const WarpedBuffer& warped,
                     const BackgroundOptions& options,
                     std::vector<BufferBackground::AverageTexel>* average, TexelRun* run) {
  const uint8_t* valid = warped.valid.data;
  const cv::Vec3b* src = warped.bgr.ptr<cv::Vec3b>();
  const int32_t* index = span.Index();
  const float threshold = static_cast<float>(options.average_threshold);
  for (int i = 0; i < span.n; ++i) {
    const int idx = index[i];
    run->sampled[i] = valid[idx] != 0;
    run->foreground[i] = run->warm_up[i] = 0;
    run->distance2[i] = 0;
    if (!run->sampled[i]) continue;
    const cv::Vec3b s = src[idx];
    BufferBackground::AverageTexel& t = (*average)[span.begin + i];
    if (t.count < options.training_frames) {  // training: learn, paint provisionally
      for (int c = 0; c < 3; ++c) t.sum[c] += s[c];
      ++t.count;
      run->warm_up[i] = 1;
    } else {
      float largest = 0;
      for (int c = 0; c < 3; ++c) {
        const float e = s[c] - static_cast<float>(t.sum[c]) / t.count;
        largest = std::max(largest, std::abs(e));
        run->distance2[i] += e * e * (1.0f / 3.0f);
      }
      run->foreground[i] = largest > threshold;
    }
  }
}

// The run's foreground and warming texels into the masks `raw` and `warming` (buffer size).
void WriteRunMasks(const TexelSpan& span, const TexelRun& run, uint8_t* raw, uint8_t* warming) {
  if (span.rows) {
    const int tile_w = span.TileWidth();
    for (int r = 0, i = 0; i < span.n; ++r, i += tile_w) {
      std::memcpy(raw + span.RowOf(r), run.foreground + i, tile_w);
      std::memcpy(warming + span.RowOf(r), run.warm_up + i, tile_w);
    }
    return;
  }
  const int32_t* index = span.Index();
  for (int i = 0; i < span.n; ++i) {
    raw[index[i]] = run.foreground[i];
    warming[index[i]] = run.warm_up[i];
  }
}

}  // namespace

void BufferBackground::Classify(const BaseBuffer& buffer, const WarpedBuffer& warped, float gain,
                                bool debug, const BaseBuffer::Chunk& chunk, ChunkStats* stats,
                                BackgroundFrame* frame) {
  uint8_t* raw = raw_.data;
  uint8_t* warming = frame->warming.data;
  uint8_t* difference = debug ? frame->difference.data : nullptr;
  // The samples of a run of texels gathered (robust: divided by the gain), then classified
  // together (a chunk is one run: at most a tile's texels).
  TexelRun run;
  RobustUpdateParams params;
  params.k2 = static_cast<float>(options_.sigma_threshold * options_.sigma_threshold);
  params.min_var = static_cast<float>(options_.min_sigma * options_.min_sigma);
  params.window = options_.window_frames;
  params.warmup = options_.warmup_frames;
  params.majority = static_cast<float>(options_.majority);
  const float inv_gain = 1.0f / gain;
  for (int begin = chunk.begin; begin < chunk.end; begin += kRunMax) {
    const int n = std::min(kRunMax, chunk.end - begin);
    const TexelSpan span{buffer, chunk, begin, n, chunk.full && n == chunk.end - chunk.begin};
    if (options_.mode == BackgroundMode::kRobust) {
      GatherSamples(span, warped, inv_gain, &run);
      UpdateRobustTexels(params, begin, n, run.x[0], run.x[1], run.x[2], run.sampled, &robust_,
                         run.foreground, run.warm_up, run.distance2);
    } else {
      ClassifyAverage(span, warped, options_, &average_, &run);
    }
    // foreground and warm_up are 0 or 1, and 0 where not sampled.
    int observed = 0, warm = 0, fore = 0;
    for (int i = 0; i < n; ++i) {
      observed += run.sampled[i];
      warm += run.warm_up[i];
      fore += run.foreground[i];
      run.foreground[i] = static_cast<uint8_t>(-run.foreground[i]);  // 0 or 255
      run.warm_up[i] = static_cast<uint8_t>(-run.warm_up[i]);
    }
    WriteRunMasks(span, run, raw, warming);
    if (difference) {
      const int32_t* index = span.Index();
      for (int i = 0; i < n; ++i)
        if (run.sampled[i])
          difference[index[i]] = cv::saturate_cast<uint8_t>(2.0f * std::sqrt(run.distance2[i]));
    }
    stats->observed += observed, stats->warming += warm, stats->foreground += fore;
    // The foreground's bounds, to the tile (Clean works on a region around them: a larger
    // one holds the same foreground and gives the same mask).
    if (fore > 0) {
      stats->x_min = std::min(stats->x_min, chunk.x0);
      stats->x_max = std::max(stats->x_max, chunk.x1 - 1);
      stats->y_min = std::min(stats->y_min, chunk.y0);
      stats->y_max = std::max(stats->y_max, chunk.y1 - 1);
    }
  }
}

void BufferBackground::Clean(const cv::Rect& roi, BackgroundFrame* frame) {
  cv::Mat out = frame->foreground(roi);  // all zero: cleared for this frame
  frame->blobs_removed +=
      CleanForeground(raw_(roi), options_.min_blob_texels, options_.dilate_texels, &out);
}

namespace {

// The warped samples under a tile's rows, asked for ahead of the tile (its 16 rows are 16
// streams of each array: more than the hardware prefetcher follows).
void PrefetchTileRows(const BaseBuffer& buffer, const WarpedBuffer& warped, const cv::Mat& raw,
                      const cv::Mat& warming, const BaseBuffer::Chunk& chunk) {
  for (int y = chunk.y0; y < chunk.y1; ++y) {
    const size_t row = static_cast<size_t>(y) * buffer.width + chunk.x0;
    __builtin_prefetch(warped.valid.data + row);
    __builtin_prefetch(warped.bgr.data + 3 * row);
    __builtin_prefetch(warped.bgr.data + 3 * row + 47);
    __builtin_prefetch(raw.data + row, 1);
    __builtin_prefetch(warming.data + row, 1);
  }
}

}  // namespace

namespace {

// The texels of `movers` (valid ones) connected to `foreground` join it; returns how many.
int JoinConnectedMovers(const cv::Mat& movers, const cv::Mat& valid, cv::Mat* foreground) {
  cv::Mat candidates = movers & valid;
  const cv::Rect box = cv::boundingRect(candidates);
  if (box.empty()) return 0;
  const cv::Rect roi = cv::Rect(box.x - 1, box.y - 1, box.width + 2, box.height + 2) &
                       cv::Rect(0, 0, movers.cols, movers.rows);
  cv::Mat seeds = (*foreground)(roi) != 0;
  if (cv::countNonZero(seeds) == 0) return 0;
  cv::Mat either = seeds | candidates(roi), labels;
  const int count = cv::connectedComponents(either, labels, 8, CV_32S);
  std::vector<uint8_t> touched(count, 0);
  for (int y = 0; y < roi.height; ++y) {
    const uint8_t* s = seeds.ptr<uint8_t>(y);
    const int* l = labels.ptr<int>(y);
    for (int x = 0; x < roi.width; ++x)
      if (s[x]) touched[l[x]] = 1;
  }
  int joined = 0;
  for (int y = 0; y < roi.height; ++y) {
    uint8_t* f = (*foreground)(roi).ptr<uint8_t>(y);
    const int* l = labels.ptr<int>(y);
    for (int x = 0; x < roi.width; ++x)
      if (l[x] > 0 && touched[l[x]] && !f[x]) f[x] = 255, ++joined;
  }
  return joined;
}

}  // namespace

void BufferBackground::Update(const BaseBuffer& buffer, const WarpedBuffer& warped, float gain,
                              bool debug, bool grow, BackgroundFrame* frame, const cv::Mat* movers,
                              const cv::Mat* agreed) {
  // The images are reused from frame to frame (no allocation, no page faults per frame),
  // except when debugging: then the stage's report holds them and each frame gets its own.
  const auto clear = [&](cv::Mat* image) {
    if (debug) {
      *image = cv::Mat::zeros(buffer.height, buffer.width, CV_8U);
    } else {
      image->create(buffer.height, buffer.width, CV_8U);
      image->setTo(0);
    }
  };
  cv::Mat foreground = std::move(frame->foreground), warming = std::move(frame->warming);
  *frame = BackgroundFrame{};
  frame->foreground = std::move(foreground);
  frame->warming = std::move(warming);
  clear(&frame->foreground);
  clear(&frame->warming);
  if (debug) clear(&frame->difference);
  if (options_.mode == BackgroundMode::kOff) return;
  // Only chunks that may hold valid texels; a skipped chunk's raw foreground from an earlier
  // frame is cleared (Clean reads raw_ around this frame's foreground).
  std::vector<ChunkStats> stats(buffer.chunks.size());
  cv::parallel_for_(
      cv::Range(0, static_cast<int>(buffer.chunks.size())), [&](const cv::Range& range) {
        for (int c = range.start; c < range.end; ++c) {
          const BaseBuffer::Chunk& chunk = buffer.chunks[c];
          if (warped.MayBeValid(chunk)) {
            if (c + 1 < range.end)
              PrefetchTileRows(buffer, warped, raw_, frame->warming, buffer.chunks[c + 1]);
            Classify(buffer, warped, gain, debug, chunk, &stats[c], frame);
          } else if (raw_set_[c]) {
            raw_(cv::Rect(chunk.x0, chunk.y0, chunk.x1 - chunk.x0, chunk.y1 - chunk.y0)).setTo(0);
          }
          raw_set_[c] = stats[c].foreground > 0;
        }
      });
  ChunkStats total;
  for (const ChunkStats& s : stats) {
    total.observed += s.observed, total.foreground += s.foreground, total.warming += s.warming;
    total.x_min = std::min(total.x_min, s.x_min), total.x_max = std::max(total.x_max, s.x_max);
    total.y_min = std::min(total.y_min, s.y_min), total.y_max = std::max(total.y_max, s.y_max);
  }
  frame->observed = total.observed;
  frame->foreground_raw = total.foreground;
  frame->warming_up = total.warming;
  if (total.foreground == 0) return;
  // Clean only around the foreground (the dilation's reach included).
  const int pad = options_.dilate_texels + 1;
  const cv::Rect roi = cv::Rect(cv::Point(total.x_min - pad, total.y_min - pad),
                                cv::Point(total.x_max + pad + 1, total.y_max + pad + 1)) &
                       cv::Rect(0, 0, buffer.width, buffer.height);
  Clean(roi, frame);
  frame->masked_ungrown = cv::countNonZero(frame->foreground(roi) & warped.valid(roi));
  const int reach = options_.grow_reach_texels;
  frame->masked = frame->masked_ungrown;
  if (grow && options_.grow_levels > 0 && reach > 0) {
    // From the flagged texels that survived the cleaning (not its dilation ring), by colour;
    // then cleaned again. raw_ stays this frame's classification. Not from the texels the
    // frames near this one agree with: where a mover the model learned as background has gone,
    // the model flags the background, and growth from there covered whole walls of its colour
    // (on a street capture 14 % of what was seen without a mover was never painted).
    const cv::Rect wide =
        cv::Rect(roi.x - reach, roi.y - reach, roi.width + 2 * reach, roi.height + 2 * reach) &
        cv::Rect(0, 0, buffer.width, buffer.height);
    cv::Mat grown = raw_(wide) & frame->foreground(wide);
    if (agreed && !agreed->empty()) grown.setTo(0, (*agreed)(wide));
    if (GrowForegroundByColour(warped.bgr(wide), warped.valid(wide),
                               static_cast<int>(options_.grow_levels), reach, &grown) > 0) {
      cv::Mat out = frame->foreground(wide);
      out.setTo(0);
      CleanForeground(grown, options_.min_blob_texels, options_.dilate_texels, &out);
      frame->masked = cv::countNonZero(out & warped.valid(wide));
    }
  }
  if (movers && !movers->empty() &&
      JoinConnectedMovers(*movers, warped.valid, &frame->foreground) > 0)
    frame->masked = cv::countNonZero(frame->foreground & warped.valid);
}

cv::Mat BufferBackground::Image(const BaseBuffer& buffer) const {
  cv::Mat image = cv::Mat::zeros(buffer.height, buffer.width, CV_8UC3);
  cv::Vec3b* out = image.ptr<cv::Vec3b>();
  for (int k = 0; k < buffer.NumTexels(); ++k) {
    cv::Vec3b& px = out[buffer.texel_index[k]];
    if (!robust_.empty() && robust_.samples[k] > 0) {
      for (int c = 0; c < 3; ++c) px[c] = cv::saturate_cast<uint8_t>(robust_.Mean(k, c));
    } else if (!average_.empty() && average_[k].count > 0) {
      for (int c = 0; c < 3; ++c)
        px[c] =
            cv::saturate_cast<uint8_t>(static_cast<float>(average_[k].sum[c]) / average_[k].count);
    }
  }
  return image;
}

}  // namespace fresco
