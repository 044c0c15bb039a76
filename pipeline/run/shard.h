// Painting one project in shards (`fresco run --shard I/N`, `fresco merge`, `fresco slurm`):
// the atlas is laid out once from the whole mesh, identically in every shard; each shard
// paints the buffers (charts) assigned to it, near each other and balanced by their texels
// and the frames that see them, and skips the frames
// whose view meets none of them before reading them. Whole-capture decisions (the joint pose
// adjustment, the movers found across views, the `auto` modes) are taken by every shard over
// the whole capture, the same way, and while a frame's outcome in one buffer depends on the
// others a shard paints every buffer (PaintSession::CouplesBuffers): so the shards' buffers,
// joined, are exactly those of one run.
#pragma once

#include <array>
#include <string>
#include <utility>
#include <vector>

#include "pipeline/core/project.h"
#include "pipeline/core/scene.h"
#include "pipeline/core/status.h"
#include "pipeline/paint/base_buffer.h"
#include "pipeline/paint/texture_atlas.h"

namespace fresco {

struct ShardSpec {
  int index = 0;  // 0 <= index < count
  int count = 0;  // 0: not sharded
  bool sharded() const { return count > 0; }
};

// Reads "I/N" (0 <= I < N, N >= 1): an error naming `what` (e.g. "--shard") and the value.
Status ParseShardSpec(const std::string& text, const std::string& what, ShardSpec* spec);

// A fingerprint of the project and its settings (16 hex digits, FNV-1a of its JSON text): parts
// and pre-pass files made for one project and settings carry the same.
std::string SettingsHash(const Project& project);

// A fingerprint of what a painted glTF's geometry is made of (16 hex digits): the scene's mesh
// and origin, and each buffer's triangles, texel frame and place in the atlas (so its UVs).
// Parts that hold the same write the same painted.gltf and .bin: only shard 0's part holds
// them, and `fresco merge` checks the others' fingerprint against it.
std::string LayoutDigest(const Scene& scene, const std::vector<BaseBuffer>& buffers,
                         const TextureAtlas& atlas);

// Which views (poses of the capture, a sample of them) see each buffer (its bounds in their
// view): seen[b] holds one bit per view, (num_views + 63) / 64 words; each view stands for
// frames_per_view frames of the capture. Optionally boxes[b]: for each view that sees buffer b,
// the box its bounds project into, as a share of the image ({x0, y0, x1, y1} in 0..1).
struct BufferViews {
  int num_views = 0;
  double frames_per_view = 1;
  std::vector<std::vector<unsigned long long>> seen;
  std::vector<std::vector<std::pair<int, std::array<float, 4>>>> boxes;
  // Sets that view `v` sees buffer `b` (sizes `seen` for `buffers` buffers on first use).
  void Mark(size_t buffers, size_t b, int v);
  int Count(size_t b) const;  // how many views see buffer b
};

// What a shard's work is made of (in any one unit, e.g. nanoseconds of a core): each texel it
// holds (built, written), each texel of a buffer for each frame that sees the buffer (the warp
// tests the part of it in view), each frame that sees any of its buffers (the frame read, the
// whole mesh's depth rendered at it: paid once per frame however many of its buffers it sees),
// and per_frame_window more times the share of the image the box of its buffers' boxes in the
// frame covers (the depth rendered there; the whole image without BufferViews::boxes).
struct ShardCosts {
  double per_texel = 0;
  double per_texel_frame = 1;
  double per_frame = 0;
  double per_frame_window = 0;
};

// What one shard's buffers amount to, in the terms of ShardCosts.
struct ShardWork {
  double texels = 0;         // surface texels held
  double texel_frames = 0;   // each buffer's texels times the frames that see it
  double frames = 0;         // the frames that see any of its buffers
  double window_frames = 0;  // those frames times the share of the image their boxes' box takes
  double Cost(const ShardCosts& costs) const {
    return costs.per_texel * texels + costs.per_texel_frame * texel_frames +
           costs.per_frame * frames + costs.per_frame_window * window_frames;
  }
};

// The work of each of `count` shards given the shard of each buffer (AssignBuffersToShards).
std::vector<ShardWork> ShardWorks(const std::vector<BaseBuffer>& buffers, const BufferViews& views,
                                  const std::vector<int>& shard, int count);

// The shard each buffer goes to (size: buffers), by space: the buffers are cut in two across
// the longest side of the box of their centres (the centres of their bounds), recursively, each
// cut giving either side count / 2 and the rest of the count's shards. A set of buffers' work
// is that of `costs` (ShardWork). A cut is the one whose larger side's work per shard is least.
// Then, while it lowers the most work of any shard, a buffer moves from that shard to the one
// where the larger of the two shards' work is least: halving evenly leaves a shard whose
// charts many frames see (a long road) with more than its share. So a shard's charts lie
// together (mostly), a frame that looks elsewhere is skipped, and a shard of few texels seen
// by most frames holds fewer frames' worth of other charts. Without views (num_views 0) a
// buffer's work is its texels. Deterministic: every shard computes the same.
std::vector<int> AssignBuffersToShards(const std::vector<BaseBuffer>& buffers,
                                       const BufferViews& views, const ShardCosts& costs,
                                       int count);

}  // namespace fresco
