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

#include <string>
#include <vector>

#include "pipeline/core/project.h"
#include "pipeline/core/status.h"
#include "pipeline/paint/base_buffer.h"

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

// The shard each buffer goes to (size: buffers), by space: the buffers are cut in two across
// the longest side of the box of their centres (the centres of their bounds), recursively, each
// cut giving either side the share of the work its shards are (count / 2 of count to the
// first); a buffer's work is its surface texels times the frames that see it
// (`frames_seeing[b]`, at least 1; empty: 1 each). So a shard's charts lie together, and a
// frame that looks elsewhere is skipped. Deterministic: every shard computes the same.
std::vector<int> AssignBuffersToShards(const std::vector<BaseBuffer>& buffers,
                                       const std::vector<int>& frames_seeing, int count);

}  // namespace fresco
