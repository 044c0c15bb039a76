// Which shard paints each chart (AssignBuffersToShards): a shard pays every frame that sees any
// of its charts once (the frame read, the whole mesh's depth rendered), so charts seen by the
// same frames go to the same shard where texels alone would split them; and every texel it
// holds, however few frames see it.
#include <array>
#include <vector>

#include <gtest/gtest.h>

#include "pipeline/run/shard.h"

namespace fresco {
namespace {

// Buffer b of `texels` surface texels centred at x = b along a street.
std::vector<BaseBuffer> BuffersAlongX(const std::vector<int>& texels) {
  std::vector<BaseBuffer> buffers(texels.size());
  for (size_t b = 0; b < texels.size(); ++b) {
    buffers[b].num_surface_texels = texels[b];
    buffers[b].bounds_min = Eigen::Vector3d(b - 0.4, 0, 0);
    buffers[b].bounds_max = Eigen::Vector3d(b + 0.4, 1, 0);
  }
  return buffers;
}

// Buffers 0 and 1 seen by views 0-9, buffers 2 and 3 by views 10-19.
BufferViews TwoGroupsOfViews() {
  BufferViews views;
  views.num_views = 20;
  for (int v = 0; v < 20; ++v)
    for (size_t b = v < 10 ? 0 : 2; b < (v < 10 ? 2u : 4u); ++b) views.Mark(4, b, v);
  return views;
}

// Only `per_texel`, `per_texel_frame` or `per_frame` costs.
ShardCosts Costs(double per_texel, double per_texel_frame, double per_frame) {
  ShardCosts costs;
  costs.per_texel = per_texel;
  costs.per_texel_frame = per_texel_frame;
  costs.per_frame = per_frame;
  return costs;
}

TEST(ShardAssign, TexelsAloneBalanceTexelsTimesViews) {
  // Work 1000, 1000, 3000, 3000: the cut nearest half of 8000 is after the third (5000 |
  // 3000); then buffer 0 moves to the other shard (4000 | 4000).
  const std::vector<int> shard = AssignBuffersToShards(BuffersAlongX({100, 100, 300, 300}),
                                                       TwoGroupsOfViews(), Costs(0, 1, 0), 2);
  EXPECT_EQ(shard, (std::vector<int>{1, 0, 0, 1}));
}

TEST(ShardAssign, AFrameCostsOnceAShardSoChartsSeenTogetherStayTogether) {
  // Each view costs 1000 texels' work in every shard it meets: {0, 1, 2} | {3} reads 20 + 10
  // views (25000 and 13000), {0, 1} | {2, 3} reads 10 + 10 (12000 and 16000).
  const BufferViews views = TwoGroupsOfViews();
  const std::vector<int> shard =
      AssignBuffersToShards(BuffersAlongX({100, 100, 300, 300}), views, Costs(0, 1, 1000), 2);
  EXPECT_EQ(shard, (std::vector<int>{0, 0, 1, 1}));
  EXPECT_EQ(views.Count(0), 10);
  EXPECT_EQ(views.Count(3), 10);
}

TEST(ShardAssign, ATexelHeldCostsHoweverFewFramesSeeIt) {
  // Buffer 0 (400 texels) seen by one view, buffers 1-3 (100 each) by the same ten.
  BufferViews views;
  views.num_views = 10;
  views.Mark(4, 0, 0);
  for (int v = 0; v < 10; ++v)
    for (size_t b = 1; b < 4; ++b) views.Mark(4, b, v);
  const std::vector<BaseBuffer> buffers = BuffersAlongX({400, 100, 100, 100});
  // Texels times frames: 400, 1000, 1000, 1000; {0, 1} | {2, 3} (1400 and 2000).
  EXPECT_EQ(AssignBuffersToShards(buffers, views, Costs(0, 1, 0), 2),
            (std::vector<int>{0, 0, 1, 1}));
  // Texels held: 400 | 300.
  EXPECT_EQ(AssignBuffersToShards(buffers, views, Costs(1, 0, 0), 2),
            (std::vector<int>{0, 1, 1, 1}));
  // 10 a texel held, 1 a texel a frame: 4400, 2000, 2000, 2000 -> 4400 | 6000; with each view
  // standing for 10 frames 8000, 11000, 11000, 11000 -> 19000 | 22000.
  EXPECT_EQ(AssignBuffersToShards(buffers, views, Costs(10, 1, 0), 2),
            (std::vector<int>{0, 1, 1, 1}));
  views.frames_per_view = 10;
  EXPECT_EQ(AssignBuffersToShards(buffers, views, Costs(10, 1, 0), 2),
            (std::vector<int>{0, 0, 1, 1}));
}

TEST(ShardAssign, AFramesDepthCostsTheShareOfTheImageItsChartsTakeIn) {
  // Buffers of 100, 100, 300 texels, all seen by 10 views: buffer 0 in the left half of the
  // image, 1 in the right half, 2 in a speck of it.
  BufferViews views;
  views.num_views = 10;
  const std::array<float, 4> box[3] = {{0, 0, 0.5, 1}, {0.5, 0, 1, 1}, {0.5, 0.5, 0.51, 0.51}};
  for (int v = 0; v < 10; ++v)
    for (size_t b = 0; b < 3; ++b) views.Mark(3, b, v);
  const std::vector<BaseBuffer> buffers = BuffersAlongX({100, 100, 300});
  ShardCosts costs = Costs(0, 1, 0);
  costs.per_frame_window = 3000;
  // Without boxes each frame's depth is the whole image's: {0} 31000 | {1, 2} 34000, or
  // {0, 1} 32000 | {2} 33000.
  EXPECT_EQ(AssignBuffersToShards(buffers, views, costs, 2), (std::vector<int>{0, 0, 1}));
  // With them: {0} 16000 | {1, 2} 19000, or {0, 1} 32000 | {2} 3003.
  views.boxes.resize(3);
  for (int v = 0; v < 10; ++v)
    for (size_t b = 0; b < 3; ++b) views.boxes[b].push_back({v, box[b]});
  EXPECT_EQ(AssignBuffersToShards(buffers, views, costs, 2), (std::vector<int>{0, 1, 1}));
}

TEST(ShardAssign, WithoutViewsTexelsAreTheWork) {
  const std::vector<int> shard = AssignBuffersToShards(
      BuffersAlongX({100, 100, 100, 100, 100, 300}), BufferViews(), Costs(0, 1, 0), 2);
  EXPECT_EQ(shard, (std::vector<int>{0, 0, 0, 0, 1, 1}));
  // One shard: every buffer in it.
  EXPECT_EQ(AssignBuffersToShards(BuffersAlongX({5, 6}), BufferViews(), Costs(0, 1, 0), 1),
            (std::vector<int>{0, 0}));
}

}  // namespace
}  // namespace fresco
