#include "pipeline/run/shard.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <numeric>

namespace fresco {
namespace {

// A whole non-negative decimal number, digits only.
bool ParseCount(const std::string& text, long* value) {
  if (text.empty() || text.size() > 9 ||
      !std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; }))
    return false;
  *value = std::strtol(text.c_str(), nullptr, 10);
  return true;
}

}  // namespace

Status ParseShardSpec(const std::string& text, const std::string& what, ShardSpec* spec) {
  const size_t slash = text.find('/');
  long index = -1, count = -1;
  if (slash == std::string::npos || !ParseCount(text.substr(0, slash), &index) ||
      !ParseCount(text.substr(slash + 1), &count))
    return Status::Error(what + ": '" + text + "' is not I/N (shard I of N, e.g. 0/4)");
  if (count < 1) return Status::Error(what + ": '" + text + "': N must be at least 1");
  if (index >= count)
    return Status::Error(what + ": '" + text + "': I must be in 0.." + std::to_string(count - 1));
  spec->index = static_cast<int>(index);
  spec->count = static_cast<int>(count);
  return Status::Ok();
}

namespace {

// FNV-1a, fed bytes or 64-bit words; its value as 16 hex digits.
struct Fnv1a {
  unsigned long long hash = 1469598103934665603ULL;
  void Add(unsigned long long value) { hash = (hash ^ value) * 1099511628211ULL; }
  std::string Hex() const {
    char hex[17];
    std::snprintf(hex, sizeof hex, "%016llx", hash);
    return hex;
  }
};

}  // namespace

std::string SettingsHash(const Project& project) {
  Fnv1a fnv;
  for (unsigned char c : ProjectToJsonText(project)) fnv.Add(c);
  return fnv.Hex();
}

std::string LayoutDigest(const Scene& scene, const std::vector<BaseBuffer>& buffers,
                         const TextureAtlas& atlas) {
  Fnv1a fnv;  // over 64-bit words
  const auto add = [&fnv](auto value) {
    unsigned long long word = 0;
    static_assert(sizeof(value) <= sizeof(word));
    std::memcpy(&word, &value, sizeof(value));
    fnv.Add(word);
  };
  const auto add_vector = [&add](const Eigen::Vector3d& v) { add(v.x()), add(v.y()), add(v.z()); };
  const TriangleMesh& mesh = scene.mesh;
  add(mesh.vertices.size()), add(mesh.triangles.size());
  add_vector(scene.origin_in_world);
  for (const Eigen::Vector3d& v : mesh.vertices) add_vector(v);
  for (const Eigen::Vector3i& t : mesh.triangles) add(t.x()), add(t.y()), add(t.z());
  add(atlas.pages.size());
  for (const cv::Size& page : atlas.pages) add(page.width), add(page.height);
  add(buffers.size());
  for (size_t b = 0; b < buffers.size(); ++b) {
    const BaseBuffer& buffer = buffers[b];
    const AtlasPlacement place =
        b < atlas.placements.size() ? atlas.placements[b] : AtlasPlacement();
    add(place.page), add(place.x), add(place.y);
    add_vector(buffer.origin), add_vector(buffer.axis_u), add_vector(buffer.axis_v);
    add(buffer.texel_size_m), add(buffer.triangles.size());
    for (int t : buffer.triangles) add(t);
  }
  return fnv.Hex();
}

void BufferViews::Mark(size_t buffers, size_t b, int v) {
  const size_t words = (static_cast<size_t>(num_views) + 63) / 64;
  if (seen.size() != buffers) seen.assign(buffers, std::vector<unsigned long long>(words, 0));
  seen[b][v / 64] |= 1ULL << (v % 64);
}

int BufferViews::Count(size_t b) const {
  int n = 0;
  if (b < seen.size())
    for (unsigned long long w : seen[b]) n += __builtin_popcountll(w);
  return n;
}

namespace {

using Box = std::array<float, 4>;  // {x0, y0, x1, y1}, empty when x0 > x1

double BoxArea(const Box& w) {
  return w[0] < w[2] && w[1] < w[3] ? static_cast<double>(w[2] - w[0]) * (w[3] - w[1]) : 0.0;
}

Box JoinBoxes(const Box& a, const Box& b) {
  return {std::min(a[0], b[0]), std::min(a[1], b[1]), std::max(a[2], b[2]), std::max(a[3], b[3])};
}

// The work of every shard (ShardWork), kept as buffers move between shards: per shard and view,
// how many of its buffers the view sees, which, and the box of their boxes.
class ShardLoads {
 public:
  ShardLoads(const std::vector<BaseBuffer>& buffers, const BufferViews& views,
             const std::vector<int>& shard, int count)
      : views_(views),
        with_views_(views.num_views > 0 && views.seen.size() == buffers.size()),
        with_boxes_(with_views_ && views.boxes.size() == buffers.size()),
        shard_(shard),
        texels_(buffers.size()),
        views_of_(buffers.size()),
        shards_(count) {
    for (Shard& one : shards_) {
      one.seen_by.assign(with_views_ ? views.num_views : 0, 0);
      one.members.assign(with_boxes_ ? views.num_views : 0, {});
      one.window.assign(with_boxes_ ? views.num_views : 0, Box{1, 1, 0, 0});
    }
    for (size_t b = 0; b < buffers.size(); ++b) {
      texels_[b] = static_cast<double>(std::max<long long>(buffers[b].num_surface_texels, 1));
      if (with_views_)
        for (int v = 0; v < views.num_views; ++v)
          if (views.seen[b][v / 64] >> (v % 64) & 1) views_of_[b].push_back(v);
      Add(b, shard[b]);
    }
  }

  ShardWork Work(int s) const {
    const Shard& one = shards_[s];
    ShardWork work;
    work.texels = one.texels;
    work.texel_frames = one.texel_views * views_.frames_per_view;
    work.frames = one.views * views_.frames_per_view;
    work.window_frames = (with_boxes_ ? one.window_area : one.views) * views_.frames_per_view;
    return work;
  }

  // Shard s's work without buffer b (one of its own).
  ShardWork WorkWithout(int s, size_t b) const {
    const Shard& one = shards_[s];
    ShardWork work = Work(s);
    const double per_view = views_.frames_per_view;
    work.texels -= texels_[b];
    work.texel_frames -= texels_[b] * views_of_[b].size() * per_view;
    for (int v : views_of_[b])
      if (one.seen_by[v] == 1) work.frames -= per_view;
    if (!with_boxes_) {
      work.window_frames = work.frames;
      return work;
    }
    for (const auto& [v, box] : views_.boxes[b]) {
      const Box& w = one.window[v];
      if (box[0] > w[0] && box[1] > w[1] && box[2] < w[2] && box[3] < w[3]) continue;  // inside
      Box rest{1, 1, 0, 0};
      for (size_t other : one.members[v])
        if (other != b) rest = JoinBoxes(rest, BoxOf(other, v));
      work.window_frames += (BoxArea(rest) - BoxArea(w)) * per_view;
    }
    return work;
  }

  // Shard s's work with buffer b (another shard's) added.
  ShardWork WorkWith(int s, size_t b) const {
    const Shard& one = shards_[s];
    ShardWork work = Work(s);
    const double per_view = views_.frames_per_view;
    work.texels += texels_[b];
    work.texel_frames += texels_[b] * views_of_[b].size() * per_view;
    for (int v : views_of_[b])
      if (one.seen_by[v] == 0) work.frames += per_view;
    if (!with_boxes_) {
      work.window_frames = work.frames;
      return work;
    }
    for (const auto& [v, box] : views_.boxes[b])
      work.window_frames +=
          (BoxArea(JoinBoxes(one.window[v], box)) - BoxArea(one.window[v])) * per_view;
    return work;
  }

  void Move(size_t b, int to) {
    Remove(b, shard_[b]);
    Add(b, to);
    shard_[b] = to;
  }

  const std::vector<int>& shard() const { return shard_; }

 private:
  struct Shard {
    double texels = 0;
    double texel_views = 0;    // texels times the views that see them
    int views = 0;             // views that see any of its buffers
    double window_area = 0;    // the sum over views of its window's share of the image
    std::vector<int> seen_by;  // per view: how many of its buffers it sees
    std::vector<std::vector<size_t>> members;  // per view: which (with boxes)
    std::vector<Box> window;                   // per view: the box of their boxes
  };

  const Box& BoxOf(size_t b, int v) const {
    const auto& boxes = views_.boxes[b];
    const auto it =
        std::lower_bound(boxes.begin(), boxes.end(), v,
                         [](const auto& entry, int view) { return entry.first < view; });
    return it->second;
  }

  void Add(size_t b, int s) {
    Shard& one = shards_[s];
    one.texels += texels_[b];
    one.texel_views += texels_[b] * views_of_[b].size();
    for (int v : views_of_[b]) one.views += one.seen_by[v]++ == 0;
    if (!with_boxes_) return;
    for (const auto& [v, box] : views_.boxes[b]) {
      one.members[v].push_back(b);
      one.window_area -= BoxArea(one.window[v]);
      one.window[v] = JoinBoxes(one.window[v], box);
      one.window_area += BoxArea(one.window[v]);
    }
  }

  void Remove(size_t b, int s) {
    Shard& one = shards_[s];
    one.texels -= texels_[b];
    one.texel_views -= texels_[b] * views_of_[b].size();
    for (int v : views_of_[b]) one.views -= --one.seen_by[v] == 0;
    if (!with_boxes_) return;
    for (const auto& [v, box] : views_.boxes[b]) {
      auto& members = one.members[v];
      members.erase(std::find(members.begin(), members.end(), b));
      Box rest{1, 1, 0, 0};
      for (size_t other : members) rest = JoinBoxes(rest, BoxOf(other, v));
      one.window_area += BoxArea(rest) - BoxArea(one.window[v]);
      one.window[v] = rest;
    }
  }

  const BufferViews& views_;
  const bool with_views_, with_boxes_;
  std::vector<int> shard_;
  std::vector<double> texels_;
  std::vector<std::vector<int>> views_of_;  // per buffer: the views that see it, in order
  std::vector<Shard> shards_;
};

// AssignBuffersToShards' last step: buffers move off the shard of most work while that lowers
// it (up to kMaxMoves moves).
std::vector<int> BalanceMoves(const std::vector<BaseBuffer>& buffers, const BufferViews& views,
                              const ShardCosts& costs, const std::vector<int>& shard, int count) {
  constexpr int kMaxMoves = 256;
  const bool with_views = views.num_views > 0 && views.seen.size() == buffers.size();
  const auto cost = [&](const ShardWork& w) { return with_views ? w.Cost(costs) : w.texels; };
  ShardLoads loads(buffers, views, shard, count);
  std::vector<double> now(count);
  std::vector<std::vector<size_t>> members(count);
  for (int s = 0; s < count; ++s) now[s] = cost(loads.Work(s));
  for (size_t b = 0; b < shard.size(); ++b) members[shard[b]].push_back(b);
  for (int move = 0; move < kMaxMoves; ++move) {
    const int from = static_cast<int>(std::max_element(now.begin(), now.end()) - now.begin());
    if (members[from].size() <= 1) break;
    double best = now[from] * (1 - 1e-9), best_from = 0, best_to = 0;
    size_t moved = buffers.size();
    int to = -1;
    for (size_t b : members[from]) {
      const double without = cost(loads.WorkWithout(from, b));
      if (without >= best) continue;
      for (int d = 0; d < count; ++d) {
        if (d == from) continue;
        const double with = cost(loads.WorkWith(d, b));
        if (std::max(without, with) < best)
          best = std::max(without, with), best_from = without, best_to = with, moved = b, to = d;
      }
    }
    if (to < 0) break;
    loads.Move(moved, to);
    now[from] = best_from, now[to] = best_to;
    members[from].erase(std::find(members[from].begin(), members[from].end(), moved));
    members[to].insert(std::upper_bound(members[to].begin(), members[to].end(), moved), moved);
  }
  return loads.shard();
}

}  // namespace

std::vector<ShardWork> ShardWorks(const std::vector<BaseBuffer>& buffers, const BufferViews& views,
                                  const std::vector<int>& shard, int count) {
  const ShardLoads loads(buffers, views, shard, count);
  std::vector<ShardWork> works;
  for (int s = 0; s < count; ++s) works.push_back(loads.Work(s));
  return works;
}

std::vector<int> AssignBuffersToShards(const std::vector<BaseBuffer>& buffers,
                                       const BufferViews& views, const ShardCosts& costs,
                                       int count) {
  std::vector<int> shard(buffers.size(), 0);
  if (count <= 1) return shard;
  const bool with_views = views.num_views > 0 && views.seen.size() == buffers.size();
  const size_t words = with_views ? views.seen[0].size() : 0;
  const double frame_work = costs.per_frame * views.frames_per_view;
  std::vector<double> work(buffers.size());
  std::vector<Eigen::Vector3d> centre(buffers.size());
  for (size_t b = 0; b < buffers.size(); ++b) {
    const double texels =
        static_cast<double>(std::max<long long>(buffers[b].num_surface_texels, 1));
    work[b] = with_views ? texels * (costs.per_texel +
                                     costs.per_texel_frame * views.Count(b) * views.frames_per_view)
                         : texels;
    centre[b] = 0.5 * (buffers[b].bounds_min + buffers[b].bounds_max);
  }
  std::vector<size_t> ids(buffers.size());
  std::iota(ids.begin(), ids.end(), 0);
  const bool with_boxes = with_views && views.boxes.size() == buffers.size();
  const double window_work = costs.per_frame_window * views.frames_per_view;
  // The work of ids [begin, k) for every k in (begin, end] (from_end: of ids [k, end) for k in
  // [begin, end)), at index k - begin - 1 (from_end: k - begin).
  const auto side_work = [&](size_t begin, size_t end, bool from_end) {
    std::vector<double> out(end - begin);
    std::vector<unsigned long long> seen(words, 0);
    // Per view, the box of the buffers' boxes so far (empty: x0 > x1), and the sum of their areas.
    std::vector<std::array<float, 4>> window(with_boxes ? views.num_views : 0,
                                             std::array<float, 4>{1, 1, 0, 0});
    double sum = 0, windows = 0;
    for (size_t step = 0; step < end - begin; ++step) {
      const size_t id = ids[from_end ? end - 1 - step : begin + step];
      sum += work[id];
      int frames = 0;
      for (size_t w = 0; w < words; ++w)
        frames += __builtin_popcountll(seen[w] |= views.seen[id][w]);
      if (with_boxes)
        for (const auto& [v, box] : views.boxes[id]) {
          std::array<float, 4>& w = window[v];
          windows -= BoxArea(w);
          w = JoinBoxes(w, box);
          windows += BoxArea(w);
        }
      out[from_end ? end - begin - 1 - step : step] =
          sum + frame_work * frames + window_work * (with_boxes ? windows : frames);
    }
    return out;
  };
  // Shards [first, first + n) take ids [begin, end).
  const std::function<void(size_t, size_t, int, int)> split = [&](size_t begin, size_t end,
                                                                  int first, int n) {
    if (n == 1 || end - begin <= 1) {
      for (size_t k = begin; k < end; ++k) shard[ids[k]] = first;
      return;
    }
    Eigen::Vector3d low = centre[ids[begin]], high = low;
    for (size_t k = begin; k < end; ++k)
      low = low.cwiseMin(centre[ids[k]]), high = high.cwiseMax(centre[ids[k]]);
    int axis = 0;
    (high - low).maxCoeff(&axis);
    std::sort(ids.begin() + begin, ids.begin() + end, [&](size_t a, size_t b) {
      return centre[a][axis] != centre[b][axis] ? centre[a][axis] < centre[b][axis] : a < b;
    });
    // The cut (each side keeps a buffer) whose larger side's work per shard is least.
    const int left = n / 2;
    const std::vector<double> first_side = side_work(begin, end, false);
    const std::vector<double> second_side = side_work(begin, end, true);
    size_t cut = begin + 1;
    double best = -1;
    for (size_t k = begin + 1; k < end; ++k) {
      const double larger =
          std::max(first_side[k - begin - 1] / left, second_side[k - begin] / (n - left));
      if (best < 0 || larger < best) best = larger, cut = k;
    }
    split(begin, cut, first, left);
    split(cut, end, first + left, n - left);
  };
  split(0, ids.size(), 0, count);
  return BalanceMoves(buffers, views, costs, shard, count);
}

}  // namespace fresco
