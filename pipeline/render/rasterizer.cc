// Ray-table rasterizer (see rasterizer.h for the design).
//
// Geometry of the inside test: in the camera frame, a ray through the origin with direction
// d = (x, y, 1) meets triangle (v0, v1, v2) at barycentrics b_i proportional to the signed
// volumes w_i = d . (v_{i+1} x v_{i+2}). With D = det(v0, v1, v2) = v0 . ((v1-v0) x (v2-v0)),
// w_i = b_i D / z, where z is the camera depth of the hit. So "all s*w_i >= 0" with
// s = sign(D) is exactly "the ray hits the triangle in front of the camera", and
// 1/z = (w0 + w1 + w2) / D = (N / D) . d with N the (unnormalised) triangle normal: inverse
// depth is linear in the normalized ray. These w_i are the straight edge functions of the
// triangle projected to the z=1 plane; the near-plane clip (z >= near_m) only bounds the
// buckets a triangle touches and is enforced exactly per ray by the depth test.
//
// Determinism: every ray belongs to exactly one bucket and buckets are processed one bucket
// row per task, so each ray is written by one thread only. Within a ray, the winner is the
// smallest depth, ties going to the smallest triangle id: a total order, so the result does
// not depend on the order in which triangles are visited or on the number of threads.
// Watertightness: two triangles sharing an edge compute the same edge function up to an exact
// sign flip (the cross product of the same two vertices), and the test is inclusive (>= 0),
// so no ray on a shared edge falls through a crack.
#include "pipeline/render/rasterizer.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <deque>
#include <limits>
#include <list>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>

#include <opencv2/core/utility.hpp>

namespace fresco {

namespace {

// Target bucket side in rays (a pinhole lens puts about 6x6 rays in a bucket); 4..8 measured
// within 10% of each other on the benchmark scenes, 16 is 1.5x slower.
constexpr int kBucketSideRays = 6;
// Grid traversal: sample rows per task, and boxes narrower than this many columns are
// scanned whole rather than per row between the edges.
constexpr int kBandRows = 8;
constexpr int kNarrowColumns = 12;
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr float kNaNf = std::numeric_limits<float>::quiet_NaN();

// Per-triangle set-up in the camera frame, in normalized (z=1) coordinates.
struct TriangleSetup {
  float edge[3][3];         // sign-normalised edge functions: w_i = e0 x + e1 y + e2 >= 0 inside
  double inv_depth[3];      // 1/z = a x + b y + c
  double bbox[4];           // xmin, ymin, xmax, ymax of the near-clipped projection (+ margin)
  int num_poly = 0;         // 0: triangle rejected (culled, behind the near plane, degenerate)
  int row0 = 0, row1 = -1;  // bucket rows covered
  int col0 = 0, col1 = -1;  // bucket columns covered
};

// The near-clipped triangle projected to z=1 (convex, TriangleSetup::num_poly = 3 or 4
// corners): kept only for the bucket traversal, which tightens each bucket row to it.
struct TrianglePolygon {
  double corner[4][2];
};

// The binned traversal's set-ups, per thread (the calling thread's: the workers write into
// them through pointers). They only grow, so a frame allocates nothing; ~110 bytes per
// triangle in view (Rasterizer::ReleaseThreadScratch frees them).
struct TraversalScratch {
  std::vector<TriangleSetup> setups;
  std::vector<int> triangles;
  std::vector<TrianglePolygon> polygons;
};
thread_local TraversalScratch traversal_scratch;
// RasterizeDepth's spare inverse-depth buffers on a grid (InverseDepthShards), per calling
// thread: ~4 bytes a sample for each thread beyond the first.
thread_local std::deque<std::vector<float>> depth_shard_spares;

// Triangles per cluster: 128 triangles consecutive in the order of their centroids along a
// Morton curve lie close together, so a cluster's box is small and culls well. (In a mesh's
// own order they need not: Sceaux's refined mesh's clusters of 128 consecutive triangles
// spanned 3 m of its 8 m, median, and a window of a quarter of the image culled none.)
constexpr int kClusterTriangles = 128;
// Depth only, on a grid: a triangle whose box covers more samples than this is scanned by
// bands of rows over all threads instead of whole by the thread that set it up.
constexpr long long kLargeTriangleSamples = 4096;

}  // namespace

struct Rasterizer::TriangleClusters {
  std::vector<Eigen::Vector3d> bounds_min, bounds_max;  // per cluster, local coordinates
  // The mesh's vertices in the order the triangles first use them, and the triangles
  // renumbered so (-1 for an index out of range): consecutive triangles read nearby vertices.
  // A photogrammetry mesh's triangles run across the surface while its vertex numbers jump
  // (Sceaux, refined: 13,600 apart from one triangle to the next, median), and the set-up's
  // vertex reads missed the cache.
  std::vector<Eigen::Vector3d> vertices;
  std::vector<Eigen::Vector3i> triangles;  // in the clusters' order
  std::vector<int> mesh_triangle;          // each one's triangle in the mesh
};

// The clusters of the last mesh seen, recognised by its arrays and a sample of its vertices
// (a mesh edited in place gets new clusters).
struct Rasterizer::ClusterCache {
  std::mutex mutex;
  const void* vertices = nullptr;
  const void* triangles = nullptr;
  size_t num_vertices = 0, num_triangles = 0;
  Eigen::Vector3d fingerprint = Eigen::Vector3d::Zero();
  std::shared_ptr<const TriangleClusters> clusters;
};

namespace {

Eigen::Vector3d VertexFingerprint(const TriangleMesh& mesh) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  const size_t n = mesh.vertices.size(), step = std::max<size_t>(1, n / 61);
  for (size_t i = 0; i < n; i += step) sum += mesh.vertices[i] * static_cast<double>(i + 1);
  return sum;
}

// Bits 0, 3, 6, ... of the result are v's bits 0, 1, 2, ... (v < 2^21).
uint64_t SpreadBits3(uint64_t v) {
  v &= 0x1fffff;
  v = (v | v << 32) & 0x1f00000000ffffull;
  v = (v | v << 16) & 0x1f0000ff0000ffull;
  v = (v | v << 8) & 0x100f00f00f00f00full;
  v = (v | v << 4) & 0x10c30c30c30c30c3ull;
  v = (v | v << 2) & 0x1249249249249249ull;
  return v;
}

// The mesh's triangles in the order of their centroids along a Morton curve over the mesh's
// bounds (ties by number); those with an index out of range or a corner not finite last.
std::vector<int> TrianglesInSpaceOrder(const TriangleMesh& mesh) {
  const int num_triangles = mesh.NumTriangles();
  const int num_vertices = static_cast<int>(mesh.vertices.size());
  auto usable = [&](int tri) {
    const Eigen::Vector3i& idx = mesh.triangles[tri];
    if ((idx.array() < 0).any() || (idx.array() >= num_vertices).any()) return false;
    for (int k = 0; k < 3; ++k)
      if (!mesh.vertices[idx[k]].allFinite()) return false;
    return true;
  };
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(kInf), hi = -lo;
  for (const Eigen::Vector3d& p : mesh.vertices)
    if (p.allFinite()) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  const Eigen::Vector3d extent = (hi - lo).cwiseMax(1e-12);
  std::vector<std::pair<uint64_t, int>> keyed(num_triangles);
  cv::parallel_for_(cv::Range(0, num_triangles), [&](const cv::Range& range) {
    for (int tri = range.start; tri < range.end; ++tri) {
      uint64_t key = ~uint64_t{0};
      if (usable(tri)) {
        const Eigen::Vector3i& idx = mesh.triangles[tri];
        const Eigen::Vector3d c =
            (mesh.vertices[idx[0]] + mesh.vertices[idx[1]] + mesh.vertices[idx[2]]) / 3.0;
        const Eigen::Vector3d u = ((c - lo).array() / extent.array()).cwiseMax(0.0).cwiseMin(1.0);
        key = 0;
        for (int a = 0; a < 3; ++a)
          key |= SpreadBits3(static_cast<uint64_t>(u[a] * 2097151.0)) << a;
      }
      keyed[tri] = {key, tri};
    }
  });
  std::sort(keyed.begin(), keyed.end());
  std::vector<int> order(num_triangles);
  for (int i = 0; i < num_triangles; ++i) order[i] = keyed[i].second;
  return order;
}

}  // namespace

std::shared_ptr<const Rasterizer::TriangleClusters> Rasterizer::ClustersFor(
    const TriangleMesh& mesh) const {
  ClusterCache& cache = *cluster_cache_;
  const Eigen::Vector3d fingerprint = VertexFingerprint(mesh);
  std::lock_guard<std::mutex> lock(cache.mutex);
  const auto same_mesh = [&](const ClusterCache& c) {
    return c.clusters && c.vertices == mesh.vertices.data() &&
           c.triangles == mesh.triangles.data() && c.num_vertices == mesh.vertices.size() &&
           c.num_triangles == mesh.triangles.size() &&
           (c.fingerprint.array() == fingerprint.array()).all();
  };
  if (same_mesh(cache)) return cache.clusters;
  // The clusters every rasterizer of the process built last (a few meshes'), shared: a run's
  // pre-pass, painting and held-out renderings each make rasterizers of the same mesh (ten
  // builds of 50 ms each on a 435k-triangle room otherwise).
  struct SharedClusters {
    size_t num_vertices = 0, num_triangles = 0, content = 0;
    std::shared_ptr<const TriangleClusters> clusters;
  };
  static std::mutex shared_clusters_mutex;
  static std::list<SharedClusters> shared_clusters;
  constexpr size_t kSharedClusterMeshes = 2;
  // Recognised by their whole content there (a copy of a mesh shares them too).
  const std::string_view vertex_bytes(reinterpret_cast<const char*>(mesh.vertices.data()),
                                      mesh.vertices.size() * sizeof(mesh.vertices[0]));
  const std::string_view triangle_bytes(reinterpret_cast<const char*>(mesh.triangles.data()),
                                        mesh.triangles.size() * sizeof(mesh.triangles[0]));
  const size_t content = std::hash<std::string_view>()(vertex_bytes) * 31 +
                         std::hash<std::string_view>()(triangle_bytes);
  const auto keep = [&](const std::shared_ptr<const TriangleClusters>& clusters) {
    cache.vertices = mesh.vertices.data();
    cache.triangles = mesh.triangles.data();
    cache.num_vertices = mesh.vertices.size();
    cache.num_triangles = mesh.triangles.size();
    cache.fingerprint = fingerprint;
    cache.clusters = clusters;
  };
  {
    std::lock_guard<std::mutex> shared_lock(shared_clusters_mutex);
    for (const SharedClusters& c : shared_clusters)
      if (c.num_vertices == mesh.vertices.size() && c.num_triangles == mesh.triangles.size() &&
          c.content == content) {
        keep(c.clusters);
        return c.clusters;
      }
  }
  auto clusters = std::make_shared<TriangleClusters>();
  const int num_triangles = mesh.NumTriangles();
  const int num_vertices = static_cast<int>(mesh.vertices.size());
  const int num_clusters = (num_triangles + kClusterTriangles - 1) / kClusterTriangles;
  clusters->bounds_min.assign(num_clusters, Eigen::Vector3d::Constant(kInf));
  clusters->bounds_max.assign(num_clusters, Eigen::Vector3d::Constant(-kInf));
  clusters->mesh_triangle = TrianglesInSpaceOrder(mesh);
  const std::vector<int>& order = clusters->mesh_triangle;
  cv::parallel_for_(cv::Range(0, num_clusters), [&](const cv::Range& range) {
    for (int c = range.start; c < range.end; ++c) {
      Eigen::Vector3d& lo = clusters->bounds_min[c];
      Eigen::Vector3d& hi = clusters->bounds_max[c];
      const int end = std::min(num_triangles, (c + 1) * kClusterTriangles);
      bool any = false;
      for (int pos = c * kClusterTriangles; pos < end; ++pos) {
        const Eigen::Vector3i& idx = mesh.triangles[order[pos]];
        if ((idx.array() < 0).any() || (idx.array() >= num_vertices).any()) continue;
        for (int k = 0; k < 3; ++k) {
          const Eigen::Vector3d& p = mesh.vertices[idx[k]];
          if (!p.allFinite()) continue;  // such triangles are skipped in set-up
          lo = lo.cwiseMin(p), hi = hi.cwiseMax(p), any = true;
        }
      }
      if (!any) lo = hi = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
    }
  });
  std::vector<int> renumbered(num_vertices, -1);
  clusters->triangles.resize(num_triangles);
  clusters->vertices.reserve(num_vertices);
  for (int pos = 0; pos < num_triangles; ++pos) {
    for (int k = 0; k < 3; ++k) {
      const int v = mesh.triangles[order[pos]][k];
      int& to = clusters->triangles[pos][k];
      if (v < 0 || v >= num_vertices) {
        to = -1;
        continue;
      }
      if (renumbered[v] < 0) {
        renumbered[v] = static_cast<int>(clusters->vertices.size());
        clusters->vertices.push_back(mesh.vertices[v]);
      }
      to = renumbered[v];
    }
  }
  keep(clusters);
  std::lock_guard<std::mutex> shared_lock(shared_clusters_mutex);
  shared_clusters.push_front({mesh.vertices.size(), mesh.triangles.size(), content, clusters});
  if (shared_clusters.size() > kSharedClusterMeshes) shared_clusters.pop_back();
  return clusters;
}

struct Rasterizer::RayTable {
  int width = 0;                           // sample grid width (camera width * N)
  int height = 0;                          // sample grid height
  std::vector<Eigen::Vector2f> by_sample;  // (height*width) normalized rays, NaN when invalid

  // Uniform bucket grid over the bounding box of the valid rays, normalized coordinates.
  int cols = 0, rows = 0;
  double x0 = 0, y0 = 0;                  // grid origin
  double cell_w = 1, cell_h = 1;          // bucket size
  double inv_cell_w = 1, inv_cell_h = 1;  // buckets per unit
  std::vector<int> bucket_start;          // (rows*cols + 1) offsets into the arrays below
  std::vector<float> xs, ys;              // rays in bucket order
  std::vector<int> sample;                // bucket order -> sample index (row*width + col)

  // A lens without distortion (pinhole) puts the rays on a grid: x depends on the column
  // only, y on the row only, both increasing. Then triangles are scanned row by row over
  // exactly the samples they can cover, instead of testing whole buckets of rays: a triangle
  // a few pixels across tests a few samples, not several buckets of 36.
  bool grid = false;
  std::vector<float> col_x;  // (width) x of every column's rays
  std::vector<float> row_y;  // (height) y of every row's rays

  // Linear fits of col_x and row_y (exact for a pinhole up to rounding): the searches below
  // start at the fitted index and walk to the exact one, so they are right for any
  // increasing table and take a step or two on a pinhole's.
  double col_origin = 0, col_inv_step = 0, row_origin = 0, row_inv_step = 0;

  // First index in [lo, hi] of an increasing table whose entry is >= value (strict: > value),
  // hi when none.
  template <bool kStrict>
  [[gnu::always_inline]] static int FirstFrom(const std::vector<float>& table, double origin,
                                              double inv_step, int lo, int hi, double value) {
    const auto beyond = [&](int i) { return kStrict ? table[i] > value : table[i] >= value; };
    const double guess = std::floor((value - origin) * inv_step);
    int i = static_cast<int>(std::clamp(guess, static_cast<double>(lo), static_cast<double>(hi)));
    while (i > lo && beyond(i - 1)) --i;
    while (i < hi && !beyond(i)) ++i;
    return i;
  }
  int FirstColAtLeast(int lo, int hi, double value) const {
    return FirstFrom<false>(col_x, col_origin, col_inv_step, lo, hi, value);
  }
  int FirstColAbove(int lo, int hi, double value) const {
    return FirstFrom<true>(col_x, col_origin, col_inv_step, lo, hi, value);
  }
  int FirstRowAtLeast(double value) const {
    return FirstFrom<false>(row_y, row_origin, row_inv_step, 0, height, value);
  }
  int FirstRowAbove(double value) const {
    return FirstFrom<true>(row_y, row_origin, row_inv_step, 0, height, value);
  }

  // Unprojects every sample of `camera` at n x n samples per pixel (by_sample).
  void Unproject(const Camera& camera, int n);
  // The bucket grid over the bounding box of the valid rays.
  void PlaceBuckets();
  // Counting sort of the valid rays into buckets (only for rays off a grid: a grid's are
  // scanned by its rows and columns).
  void SortIntoBuckets();
  // Whether the rays lie on a grid (grid, col_x, row_y and their fits).
  void FindGrid();

  int Col(double x) const {
    const double c = std::floor((x - x0) * inv_cell_w);
    return static_cast<int>(std::clamp(c, 0.0, static_cast<double>(cols - 1)));
  }
  int Row(double y) const {
    const double r = std::floor((y - y0) * inv_cell_h);
    return static_cast<int>(std::clamp(r, 0.0, static_cast<double>(rows - 1)));
  }
};

void Rasterizer::RayTable::Unproject(const Camera& camera, int n) {
  width = camera.width * n;
  height = camera.height * n;
  by_sample.assign(static_cast<size_t>(width) * height, Eigen::Vector2f(kNaNf, kNaNf));
  // Sample (c, r) of pixel (c/N, r/N) sits at subpixel offset ((c%N) + 0.5)/N - 0.5, with
  // pixel (0,0) centred on the top-left pixel.
  if (!camera.HasDistortion()) {
    // Camera::Unproject's arithmetic without distortion, each column's x and each row's y
    // worked out once: the same rays.
    std::vector<double> xs(width), ys(height);
    for (int c = 0; c < width; ++c)
      xs[c] = (c / n + ((c % n) + 0.5) / n - 0.5 - camera.cx) / camera.fx;
    for (int r = 0; r < height; ++r)
      ys[r] = (r / n + ((r % n) + 0.5) / n - 0.5 - camera.cy) / camera.fy;
    cv::parallel_for_(cv::Range(0, height), [&](const cv::Range& range) {
      for (int r = range.start; r < range.end; ++r) {
        for (int c = 0; c < width; ++c) {
          const Eigen::Vector2d target(xs[c], ys[r]);
          if (target.allFinite() && target.squaredNorm() <= camera.fold_r2)
            by_sample[static_cast<size_t>(r) * width + c] = target.cast<float>();
        }
      }
    });
    return;
  }
  cv::parallel_for_(cv::Range(0, height), [&](const cv::Range& range) {
    for (int r = range.start; r < range.end; ++r) {
      const double py = r / n + ((r % n) + 0.5) / n - 0.5;
      for (int c = 0; c < width; ++c) {
        const double px = c / n + ((c % n) + 0.5) / n - 0.5;
        Eigen::Vector2d normalized;
        if (camera.Unproject(Eigen::Vector2d(px, py), &normalized) && normalized.allFinite())
          by_sample[static_cast<size_t>(r) * width + c] = normalized.cast<float>();
      }
    }
  });
}

void Rasterizer::RayTable::PlaceBuckets() {
  double xmin = kInf, ymin = kInf, xmax = -kInf, ymax = -kInf;
  for (const Eigen::Vector2f& ray : by_sample) {
    if (!std::isfinite(ray.x())) continue;
    xmin = std::min(xmin, static_cast<double>(ray.x()));
    xmax = std::max(xmax, static_cast<double>(ray.x()));
    ymin = std::min(ymin, static_cast<double>(ray.y()));
    ymax = std::max(ymax, static_cast<double>(ray.y()));
  }
  if (!(xmin <= xmax)) {  // no valid ray at all
    xmin = ymin = 0;
    xmax = ymax = 1;
  }
  cols = std::max(1, (width + kBucketSideRays - 1) / kBucketSideRays);
  rows = std::max(1, (height + kBucketSideRays - 1) / kBucketSideRays);
  x0 = xmin;
  y0 = ymin;
  cell_w = std::max((xmax - xmin) / cols, 1e-12);
  cell_h = std::max((ymax - ymin) / rows, 1e-12);
  inv_cell_w = 1.0 / cell_w;
  inv_cell_h = 1.0 / cell_h;
}

// Stable: sample order within a bucket.
void Rasterizer::RayTable::SortIntoBuckets() {
  const int num_buckets = cols * rows;
  std::vector<int> bucket_of(by_sample.size(), -1);
  bucket_start.assign(num_buckets + 1, 0);
  for (size_t i = 0; i < by_sample.size(); ++i) {
    const Eigen::Vector2f& ray = by_sample[i];
    if (!std::isfinite(ray.x())) continue;
    bucket_of[i] = Row(ray.y()) * cols + Col(ray.x());
    ++bucket_start[bucket_of[i] + 1];
  }
  for (int b = 0; b < num_buckets; ++b) bucket_start[b + 1] += bucket_start[b];
  const int num_valid = bucket_start[num_buckets];
  xs.resize(num_valid);
  ys.resize(num_valid);
  sample.resize(num_valid);
  std::vector<int> fill(bucket_start.begin(), bucket_start.end() - 1);
  for (size_t i = 0; i < by_sample.size(); ++i) {
    if (bucket_of[i] < 0) continue;
    const int k = fill[bucket_of[i]]++;
    xs[k] = by_sample[i].x();
    ys[k] = by_sample[i].y();
    sample[k] = static_cast<int>(i);
  }
}

// Grid of rays? Every ray valid, x a function of the column alone and y of the row alone
// (bit for bit), both strictly increasing.
void Rasterizer::RayTable::FindGrid() {
  col_x.resize(width);
  row_y.resize(height);
  bool is_grid = std::all_of(by_sample.begin(), by_sample.end(),
                             [](const Eigen::Vector2f& ray) { return std::isfinite(ray.x()); });
  for (int c = 0; c < width && is_grid; ++c) col_x[c] = by_sample[c].x();
  for (int r = 0; r < height && is_grid; ++r)
    row_y[r] = by_sample[static_cast<size_t>(r) * width].y();
  for (int c = 1; c < width && is_grid; ++c) is_grid = col_x[c] > col_x[c - 1];
  for (int r = 1; r < height && is_grid; ++r) is_grid = row_y[r] > row_y[r - 1];
  for (int r = 0; r < height && is_grid; ++r) {
    const Eigen::Vector2f* row = &by_sample[static_cast<size_t>(r) * width];
    for (int c = 0; c < width && is_grid; ++c)
      is_grid = row[c].x() == col_x[c] && row[c].y() == row_y[r];
  }
  grid = is_grid;
  if (!grid) {
    col_x.clear(), row_y.clear();
  } else {
    col_origin = col_x.front(), row_origin = row_y.front();
    if (width > 1) col_inv_step = (width - 1) / (static_cast<double>(col_x.back()) - col_origin);
    if (height > 1) row_inv_step = (height - 1) / (static_cast<double>(row_y.back()) - row_origin);
  }
}

Rasterizer::Rasterizer(const Camera& camera, const RasterOptions& options)
    : camera_(camera), options_(options), cluster_cache_(std::make_unique<ClusterCache>()) {
  if (camera.width <= 0 || camera.height <= 0)
    throw std::invalid_argument("Rasterizer: camera size must be positive");
  if (options.supersample < 1 || options.supersample > 4)
    throw std::invalid_argument("Rasterizer: supersample must be 1..4, got " +
                                std::to_string(options.supersample));
  if (!(options.near_m > 0) || !std::isfinite(options.near_m))
    throw std::invalid_argument("Rasterizer: near_m must be positive and finite");
  rays_ = SharedRayTable(camera_, options.supersample);
}

namespace {

// Every field a ray table depends on, bit for bit.
bool SameRays(const Camera& a, int a_supersample, const Camera& b, int b_supersample) {
  return a_supersample == b_supersample && a.model == b.model && a.width == b.width &&
         a.height == b.height && a.fx == b.fx && a.fy == b.fy && a.cx == b.cx && a.cy == b.cy &&
         a.k1 == b.k1 && a.k2 == b.k2 && a.k3 == b.k3 && a.k4 == b.k4 && a.k5 == b.k5 &&
         a.k6 == b.k6 && a.p1 == b.p1 && a.p2 == b.p2 && a.fold_r2 == b.fold_r2;
}

}  // namespace

std::shared_ptr<const Rasterizer::RayTable> Rasterizer::SharedRayTable(const Camera& camera,
                                                                       int supersample) {
  // The tables the process built last, shared: a run's pre-pass, painting and held-out
  // renderings each make rasterizers of the same camera (the castle's 1416 x 1064 photos: four
  // tables a run, 90-170 ms each on a loaded machine, before).
  struct Shared {
    Camera camera;
    int supersample = 1;
    std::shared_ptr<const RayTable> rays;
  };
  static std::mutex mutex;
  static std::list<Shared> shared;
  constexpr size_t kSharedTables = 2;
  {
    std::lock_guard<std::mutex> lock(mutex);
    for (auto it = shared.begin(); it != shared.end(); ++it)
      if (SameRays(it->camera, it->supersample, camera, supersample)) {
        shared.splice(shared.begin(), shared, it);  // the most recent first
        return shared.front().rays;
      }
  }
  auto rays = std::make_shared<RayTable>();
  rays->Unproject(camera, supersample);
  rays->PlaceBuckets();
  rays->FindGrid();
  if (!rays->grid) rays->SortIntoBuckets();
  std::lock_guard<std::mutex> lock(mutex);
  shared.push_front({camera, supersample, rays});
  if (shared.size() > kSharedTables) shared.pop_back();
  return rays;
}

Rasterizer::~Rasterizer() = default;

Eigen::Vector2f Rasterizer::Ray(int col, int row) const {
  const RayTable& t = *rays_;
  if (col < 0 || row < 0 || col >= t.width || row >= t.height)
    throw std::out_of_range("Rasterizer::Ray: sample out of range");
  return t.by_sample[static_cast<size_t>(row) * t.width + col];
}

namespace {

// Clips triangle (camera frame) to z >= near and projects it to z=1. Returns corner count.
int ClipAndProject(const Eigen::Vector3d v[3], double near_m, double poly[4][2]) {
  int n = 0;
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d& a = v[i];
    const Eigen::Vector3d& b = v[(i + 1) % 3];
    const bool a_in = a.z() >= near_m, b_in = b.z() >= near_m;
    if (a_in) {
      poly[n][0] = a.x() / a.z();
      poly[n][1] = a.y() / a.z();
      ++n;
    }
    if (a_in != b_in) {
      const double s = (near_m - a.z()) / (b.z() - a.z());
      const Eigen::Vector3d p = a + s * (b - a);
      poly[n][0] = p.x() / near_m;
      poly[n][1] = p.y() / near_m;
      ++n;
    }
  }
  return n;
}

// x-range of the convex polygon within the slab y in [ylo, yhi]; false when they miss.
bool PolygonSlabRange(const TriangleSetup& s, const TrianglePolygon& poly, double ylo, double yhi,
                      double* xlo, double* xhi) {
  double lo = kInf, hi = -kInf;
  for (int i = 0; i < s.num_poly; ++i) {
    const double* a = poly.corner[i];
    const double* b = poly.corner[(i + 1) % s.num_poly];
    if (a[1] >= ylo && a[1] <= yhi) {
      lo = std::min(lo, a[0]);
      hi = std::max(hi, a[0]);
    }
    for (const double y : {ylo, yhi}) {
      if ((a[1] < y) != (b[1] < y)) {
        const double x = a[0] + (y - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
        lo = std::min(lo, x);
        hi = std::max(hi, x);
      }
    }
  }
  if (!(lo <= hi)) return false;
  *xlo = lo;
  *xhi = hi;
  return true;
}

// The nearest hit per sample as the largest inverse depth, for samples one thread owns:
// RasterizeDepth's record. Its rows are scanned by MaxInverseDepthRow (below), which does for a
// row of columns at once what the call operator does for one sample.
struct NearestInverseDepth {
  float* inv;       // the inverse depths so far (0: no hit)
  double inv_near;  // hits nearer than the near plane are dropped
  void operator()(int, int sample, float, float, double inv_z, const TriangleSetup&) const {
    const float inv_zf = static_cast<float>(inv_z);
    if (inv_zf > inv[sample] && inv_z > 0.0 && inv_z <= inv_near) inv[sample] = inv_zf;
  }
};

// RasterizeDepth's record on a grid of rays, where each triangle is scanned by the thread that
// set it up, so two threads may hit the same sample. Rather than an atomic maximum per hit,
// each task (a run of clusters) takes an inverse-depth buffer of its own while it runs (the
// output first, then zeroed spares kept by the calling thread, at most one per thread at a
// time) and RasterizeDepth takes the maximum over them at the end: the same depth map as one
// buffer, as a maximum does not depend on the order, and the rows scan vectorized.
class InverseDepthShards {
 public:
  // Only samples [first, end) are scanned (the rest of each spare is never read).
  InverseDepthShards(float* output, size_t samples, size_t first, size_t end, double inv_near,
                     std::deque<std::vector<float>>* spares)
      : output_(output),
        samples_(samples),
        first_(first),
        end_(end),
        inv_near_(inv_near),
        spares_(spares) {}
  // A buffer no other task writes until it is released.
  NearestInverseDepth Acquire() const {
    std::vector<float>* spare = nullptr;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!free_.empty()) {
        float* buffer = free_.back();
        free_.pop_back();
        return {buffer, inv_near_};
      }
      if (!output_taken_) {
        output_taken_ = true;
        return {output_, inv_near_};
      }
      if (used_spares_ == spares_->size()) spares_->emplace_back();
      spare = &(*spares_)[used_spares_++];  // a deque: stays put while others are added
    }
    // Outside the lock: the other tasks go on.
    if (spare->size() != samples_) spare->assign(samples_, 0.0f);
    std::fill(spare->begin() + first_, spare->begin() + end_, 0.0f);
    std::lock_guard<std::mutex> lock(mutex_);
    used_.push_back(spare->data());
    return {spare->data(), inv_near_};
  }
  void Release(float* buffer) const {
    std::lock_guard<std::mutex> lock(mutex_);
    free_.push_back(buffer);
  }
  // The spares written besides the output (call once the traversal is done).
  const std::vector<float*>& Spares() const { return used_; }

 private:
  float* output_;
  size_t samples_, first_, end_;
  double inv_near_;
  std::deque<std::vector<float>>* spares_;
  mutable std::mutex mutex_;
  mutable std::vector<float*> free_, used_;
  mutable bool output_taken_ = false;
  mutable size_t used_spares_ = 0;
};

// The record a task of the direct traversal uses: the traversal's record itself, or for
// InverseDepthShards a buffer taken when the task first scans a triangle (a task that scans
// none, as where every triangle is large, takes none) and held until the task ends.
template <class Record>
class TaskRecord {
 public:
  explicit TaskRecord(const Record& r) : record_(r) {}
  const Record& Get() { return record_; }

 private:
  const Record& record_;
};
template <>
class TaskRecord<InverseDepthShards> {
 public:
  explicit TaskRecord(const InverseDepthShards& s) : shards_(s) {}
  ~TaskRecord() {
    if (record_) shards_.Release(record_->inv);
  }
  TaskRecord(const TaskRecord&) = delete;
  TaskRecord& operator=(const TaskRecord&) = delete;
  const NearestInverseDepth& Get() {
    if (!record_) record_ = shards_.Acquire();
    return *record_;
  }

 private:
  const InverseDepthShards& shards_;
  std::optional<NearestInverseDepth> record_;
};

// The columns [c0, c1] of one sample row, `inv_row` its inverse depths: the inside test and the
// nearest-hit update of ScanGridTriangle with NearestInverseDepth, branch-free so that it
// vectorizes (the same float and double operations in the same order: the same result).
[[gnu::always_inline]] inline void MaxInverseDepthRowBody(const float* __restrict col_x, int c0,
                                                          int c1, float y, const TriangleSetup& s,
                                                          double inv_near,
                                                          float* __restrict inv_row) {
  const float e00 = s.edge[0][0], e01 = s.edge[0][1], e02 = s.edge[0][2];
  const float e10 = s.edge[1][0], e11 = s.edge[1][1], e12 = s.edge[1][2];
  const float e20 = s.edge[2][0], e21 = s.edge[2][1], e22 = s.edge[2][2];
  const double ia = s.inv_depth[0], ib = s.inv_depth[1], ic = s.inv_depth[2];
  const float w0y = e01 * y, w1y = e11 * y, w2y = e21 * y;
  const double iy = ib * static_cast<double>(y);
  for (int c = c0; c <= c1; ++c) {
    const float x = col_x[c];
    const float w0 = e00 * x + w0y + e02;
    const float w1 = e10 * x + w1y + e12;
    const float w2 = e20 * x + w2y + e22;
    const double inv_z = ia * static_cast<double>(x) + iy + ic;
    const float inv_zf = static_cast<float>(inv_z);
    const float current = inv_row[c];
    const bool hit = !(w0 < 0.f) & !(w1 < 0.f) & !(w2 < 0.f) & (inv_zf > current) & (inv_z > 0.0) &
                     (inv_z <= inv_near);
    inv_row[c] = hit ? inv_zf : current;
  }
}

__attribute__((target_clones("arch=x86-64-v4", "avx2", "default"))) void MaxInverseDepthRow(
    const float* __restrict col_x, int c0, int c1, float y, const TriangleSetup& s, double inv_near,
    float* __restrict inv_row) {
  MaxInverseDepthRowBody(col_x, c0, c1, y, s, inv_near, inv_row);
}

// Rows shorter than a vector (most rows of a photogrammetry mesh's small triangles) inline,
// without the call through the CPU dispatch: the same operations, the same result.
[[gnu::always_inline]] inline void MaxInverseDepthShortOrLongRow(const float* __restrict col_x,
                                                                 int c0, int c1, float y,
                                                                 const TriangleSetup& s,
                                                                 double inv_near,
                                                                 float* __restrict inv_row) {
  if (c1 - c0 < 8)
    MaxInverseDepthRowBody(col_x, c0, c1, y, s, inv_near, inv_row);
  else
    MaxInverseDepthRow(col_x, c0, c1, y, s, inv_near, inv_row);
}

// The same for a bucket's rays (a lens with distortion: rays off a grid), `best` their nearest
// inverse depths so far (kept per bucket row, written to the samples once the row is done, so
// that this loop has no scattered reads or writes); `inside` when the bucket lies wholly
// inside the triangle (no edge tests).
__attribute__((target_clones("arch=x86-64-v4", "avx2", "default"))) void MaxInverseDepthBucket(
    const float* __restrict xs, const float* __restrict ys, int n, bool inside,
    const TriangleSetup& s, double inv_near, float* __restrict best) {
  const float e00 = s.edge[0][0], e01 = s.edge[0][1], e02 = s.edge[0][2];
  const float e10 = s.edge[1][0], e11 = s.edge[1][1], e12 = s.edge[1][2];
  const float e20 = s.edge[2][0], e21 = s.edge[2][1], e22 = s.edge[2][2];
  const double ia = s.inv_depth[0], ib = s.inv_depth[1], ic = s.inv_depth[2];
  const int all_inside = inside;
  for (int k = 0; k < n; ++k) {
    const float x = xs[k], y = ys[k];
    const float w0 = e00 * x + e01 * y + e02;
    const float w1 = e10 * x + e11 * y + e12;
    const float w2 = e20 * x + e21 * y + e22;
    const double inv_z = ia * static_cast<double>(x) + ib * static_cast<double>(y) + ic;
    const float inv_zf = static_cast<float>(inv_z);
    const float current = best[k];
    const int hit = (all_inside | (!(w0 < 0.f) & !(w1 < 0.f) & !(w2 < 0.f))) & (inv_zf > current) &
                    (inv_z > 0.0) & (inv_z <= inv_near);
    best[k] = hit ? inv_zf : current;
  }
}

}  // namespace

// Scans one triangle over the grid's sample rows [row_lo, row_hi): per row, the columns
// between the triangle's edges (widened for rounding), each tested exactly as a bucket's rays
// are, so the two traversals accept the same samples.
template <class Table, class Record>
void ScanGridTriangle(const Table& t, const TriangleSetup& s, int tri, int row_lo, int row_hi,
                      const Record& record) {
  const float e00 = s.edge[0][0], e01 = s.edge[0][1], e02 = s.edge[0][2];
  const float e10 = s.edge[1][0], e11 = s.edge[1][1], e12 = s.edge[1][2];
  const float e20 = s.edge[2][0], e21 = s.edge[2][1], e22 = s.edge[2][2];
  const double ia = s.inv_depth[0], ib = s.inv_depth[1], ic = s.inv_depth[2];
  const int r0 = std::max(s.row0, row_lo), r1 = std::min(s.row1, row_hi - 1);
  // Narrow boxes are scanned whole; wider ones per row between the edges.
  const bool spans = s.col1 - s.col0 >= kNarrowColumns;
  const double x_abs = std::max({std::abs(s.bbox[0]), std::abs(s.bbox[2]), 1.0});
  for (int r = r0; r <= r1; ++r) {
    const float y = t.row_y[r];
    int c0 = s.col0, c1 = s.col1;
    if (spans) {
      double lo = s.bbox[0], hi = s.bbox[2];
      for (int i = 0; i < 3; ++i) {
        const double a = s.edge[i][0], b = s.edge[i][1] * static_cast<double>(y) + s.edge[i][2];
        if (a == 0.0) continue;  // an edge along the row: the exact tests below decide
        const double x = -b / a;
        const double slack =
            1e-6 *
            (std::abs(a) * x_abs + std::abs(s.edge[i][1] * static_cast<double>(y)) +
             std::abs(s.edge[i][2])) /
            std::abs(a);
        if (a > 0)
          lo = std::max(lo, x - slack);
        else
          hi = std::min(hi, x + slack);
      }
      if (!(lo <= hi)) continue;
      c0 = t.FirstColAtLeast(s.col0, s.col1 + 1, lo);
      c1 = t.FirstColAbove(c0, s.col1 + 1, hi) - 1;
    }
    const size_t row_sample = static_cast<size_t>(r) * t.width;
    if constexpr (std::is_same_v<Record, NearestInverseDepth>) {
      if (c0 <= c1)
        MaxInverseDepthShortOrLongRow(t.col_x.data(), c0, c1, y, s, record.inv_near,
                                      record.inv + row_sample);
      continue;
    }
    for (int c = c0; c <= c1; ++c) {
      const float x = t.col_x[c];
      const float w0 = e00 * x + e01 * y + e02;
      const float w1 = e10 * x + e11 * y + e12;
      const float w2 = e20 * x + e21 * y + e22;
      if (w0 < 0.f || w1 < 0.f || w2 < 0.f) continue;
      record(tri, static_cast<int>(row_sample + c), x, y, ia * x + ib * y + ic, s);
    }
  }
}

namespace {

// The set-up slots of the clusters in view: slot_start[c] .. slot_start[c + 1] are cluster c's
// triangles' (none for a cluster outside the rays' frustum). Clusters of consecutive triangles
// whose bounds lie outside it are skipped whole: the per-frame work follows the triangles in
// view, not the mesh's size.
template <class Table, class Clusters>
std::vector<int> SlotsInView(const Table& t, const Clusters& clusters, int num_triangles,
                             const Eigen::Matrix3d& rotation, const Eigen::Vector3d& translation,
                             double near_m, const double view[4]) {
  const double x0 = view[0], y0 = view[1], grid_x1 = view[2], grid_y1 = view[3];
  const int num_clusters = static_cast<int>(clusters.bounds_min.size());
  std::vector<int> slot_start(num_clusters + 1, 0);
  cv::parallel_for_(cv::Range(0, num_clusters), [&](const cv::Range& range) {
    for (int c = range.start; c < range.end; ++c) {
      const Eigen::Vector3d& lo = clusters.bounds_min[c];
      const Eigen::Vector3d& hi = clusters.bounds_max[c];
      // Outside when all 8 corners are beyond one of the frustum's planes (the near plane
      // and the four planes through the eye bounding the rays' normalized extent).
      int out[5] = {0, 0, 0, 0, 0};
      for (int k = 0; k < 8; ++k) {
        const Eigen::Vector3d p =
            rotation * Eigen::Vector3d((k & 1) ? hi.x() : lo.x(), (k & 2) ? hi.y() : lo.y(),
                                       (k & 4) ? hi.z() : lo.z()) +
            translation;
        out[0] += p.z() < near_m;
        out[1] += p.x() < x0 * p.z();
        out[2] += p.x() > grid_x1 * p.z();
        out[3] += p.y() < y0 * p.z();
        out[4] += p.y() > grid_y1 * p.z();
      }
      const bool culled = !lo.allFinite() || !hi.allFinite() ||
                          std::any_of(out, out + 5, [](int n) { return n == 8; });
      slot_start[c + 1] =
          culled ? 0 : std::min(num_triangles, (c + 1) * kClusterTriangles) - c * kClusterTriangles;
    }
  });
  for (int c = 0; c < num_clusters; ++c) slot_start[c + 1] += slot_start[c];
  return slot_start;
}

// Sets up the clusters' triangle at position `pos` in the camera frame (double): its edges, inverse
// depth, box and the samples (grid) or buckets it may cover, `poly` its clipped corners on z = 1.
// False (and s->num_poly 0) when it covers none: degenerate, behind the near plane, back-facing
// when culled, outside the rays' extent, or between samples.
template <class Table, class Clusters>
inline bool SetUpTriangle(const Table& t, const Clusters& clusters, int pos,
                          const Eigen::Matrix3d& rotation, const Eigen::Vector3d& translation,
                          double near_m, bool cull, const double view[4], TriangleSetup* setup,
                          double poly[4][2]) {
  TriangleSetup& s = *setup;
  const double view_x0 = view[0], view_y0 = view[1], grid_x1 = view[2], grid_y1 = view[3];
  s.num_poly = 0;
  const Eigen::Vector3i& idx = clusters.triangles[pos];
  if ((idx.array() < 0).any()) return false;
  const Eigen::Vector3d v[3] = {rotation * clusters.vertices[idx[0]] + translation,
                                rotation * clusters.vertices[idx[1]] + translation,
                                rotation * clusters.vertices[idx[2]] + translation};
  if (!v[0].allFinite() || !v[1].allFinite() || !v[2].allFinite()) return false;
  if (v[0].z() < near_m && v[1].z() < near_m && v[2].z() < near_m) return false;
  const Eigen::Vector3d normal = (v[1] - v[0]).cross(v[2] - v[0]);
  const double det = normal.dot(v[0]);  // det(v0, v1, v2): < 0 when front-facing
  if (!(det != 0.0) || !std::isfinite(det)) return false;  // plane through the eye
  if (cull && det > 0) return false;
  const int n = ClipAndProject(v, near_m, poly);
  if (n < 3) return false;
  double xmin = kInf, ymin = kInf, xmax = -kInf, ymax = -kInf;
  for (int i = 0; i < n; ++i) {
    xmin = std::min(xmin, poly[i][0]);
    xmax = std::max(xmax, poly[i][0]);
    ymin = std::min(ymin, poly[i][1]);
    ymax = std::max(ymax, poly[i][1]);
  }
  // Margin for rounding (the float inside test may accept rays a hair outside).
  const double margin = 1e-6 + 1e-7 * std::max({std::abs(xmin), std::abs(xmax),
                                                std::abs(ymin), std::abs(ymax)});
  xmin -= margin, ymin -= margin, xmax += margin, ymax += margin;
  if (!(xmax >= view_x0 && xmin <= grid_x1 && ymax >= view_y0 && ymin <= grid_y1)) return false;
  const double sign = det > 0 ? 1.0 : -1.0;
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d e = sign * v[(i + 1) % 3].cross(v[(i + 2) % 3]);
    for (int k = 0; k < 3; ++k) s.edge[i][k] = static_cast<float>(e[k]);
  }
  for (int k = 0; k < 3; ++k) s.inv_depth[k] = normal[k] / det;
  s.bbox[0] = xmin, s.bbox[1] = ymin, s.bbox[2] = xmax, s.bbox[3] = ymax;
  if (t.grid) {  // the columns and rows of samples inside the box
    s.col0 = t.FirstColAtLeast(0, t.width, xmin);
    s.col1 = t.FirstColAbove(s.col0, t.width, xmax) - 1;
    s.row0 = t.FirstRowAtLeast(ymin);
    s.row1 = t.FirstRowAbove(ymax) - 1;
    if (s.col0 > s.col1 || s.row0 > s.row1) return false;  // between samples: covers none
  } else {
    s.col0 = t.Col(xmin), s.col1 = t.Col(xmax);
    s.row0 = t.Row(ymin), s.row1 = t.Row(ymax);
  }
  s.num_poly = n;
  return true;
}

// Binned: the set-ups per bin of rows (grid: a band of kBandRows sample rows; else a bucket
// row), in ascending triangle order (counting sort): bin r's slots are
// row_triangles[row_start[r] .. row_start[r + 1]).
void BinByRows(const TriangleSetup* setups, int num_slots, int num_bins, int bin_div,
               std::vector<int>* row_start, std::vector<int>* row_triangles) {
  row_start->assign(num_bins + 1, 0);
  for (int slot = 0; slot < num_slots; ++slot) {
    const TriangleSetup& s = setups[slot];
    if (s.num_poly == 0) continue;
    for (int r = s.row0 / bin_div; r <= s.row1 / bin_div; ++r) ++(*row_start)[r + 1];
  }
  for (int r = 0; r < num_bins; ++r) (*row_start)[r + 1] += (*row_start)[r];
  row_triangles->resize((*row_start)[num_bins]);
  std::vector<int> fill(row_start->begin(), row_start->end() - 1);
  for (int slot = 0; slot < num_slots; ++slot) {
    const TriangleSetup& s = setups[slot];
    if (s.num_poly == 0) continue;
    for (int r = s.row0 / bin_div; r <= s.row1 / bin_div; ++r) (*row_triangles)[fill[r]++] = slot;
  }
}

// Binned, rays not on a grid: bucket rows [row_lo, row_hi), each with its triangles
// (BinByRows). RasterizeDepth (NearestInverseDepth): a bucket row's rays are consecutive; their
// nearest hits are kept in a local array while the row's triangles are scanned, then written to
// their samples.
template <class Table, class Polygon, class Record>
void ScanBucketRows(const Table& t, int row_lo, int row_hi, const TriangleSetup* setups,
                    const Polygon* polygons, const int* triangle_of_slot,
                    const std::vector<int>& row_start, const std::vector<int>& row_triangles,
                    const Record& record) {
  constexpr bool kDepthOnly = std::is_same_v<Record, NearestInverseDepth>;
  thread_local std::vector<float> row_best;
  for (int row = row_lo; row < row_hi; ++row) {
      const double slab_lo = t.y0 + row * t.cell_h, slab_hi = slab_lo + t.cell_h;
      const int row_begin = t.bucket_start[row * t.cols];
      const int row_end = t.bucket_start[(row + 1) * t.cols];
      if constexpr (kDepthOnly) row_best.assign(row_end - row_begin, 0.0f);
      for (int j = row_start[row]; j < row_start[row + 1]; ++j) {
        const int slot = row_triangles[j];
        const TriangleSetup& s = setups[slot];
        const int tri = triangle_of_slot[slot];
        int col0 = s.col0, col1 = s.col1;
        if (s.row0 != s.row1 && col0 != col1) {
          // Tighten to the polygon's extent within this bucket row.
          const double m = 1e-6 + 1e-7 * std::max(std::abs(slab_lo), std::abs(slab_hi));
          double xlo, xhi;
          if (!PolygonSlabRange(s, polygons[slot], slab_lo - m, slab_hi + m, &xlo, &xhi))
            continue;
          const double mx = 1e-6 + 1e-7 * std::max(std::abs(xlo), std::abs(xhi));
          col0 = std::max(col0, t.Col(xlo - mx));
          col1 = std::min(col1, t.Col(xhi + mx));
        }
        const float e00 = s.edge[0][0], e01 = s.edge[0][1], e02 = s.edge[0][2];
        const float e10 = s.edge[1][0], e11 = s.edge[1][1], e12 = s.edge[1][2];
        const float e20 = s.edge[2][0], e21 = s.edge[2][1], e22 = s.edge[2][2];
        const double ia = s.inv_depth[0], ib = s.inv_depth[1], ic = s.inv_depth[2];
        for (int col = col0; col <= col1; ++col) {
          const int bucket = row * t.cols + col;
          const int begin = t.bucket_start[bucket], end = t.bucket_start[bucket + 1];
          if (begin == end) continue;
          // The bucket's rectangle (every ray of the bucket is inside it, up to rounding)
          // against each edge: entirely outside one edge -> skip the bucket; well inside all
          // three -> every ray hits the plane inside the triangle, skip the edge tests.
          const double bx0 = t.x0 + col * t.cell_w, bx1 = bx0 + t.cell_w;
          bool outside = false, inside = true;
          for (int i = 0; i < 3 && !outside; ++i) {
            const double ex = s.edge[i][0], ey = s.edge[i][1], ez = s.edge[i][2];
            const double w_max =
                ex * (ex > 0 ? bx1 : bx0) + ey * (ey > 0 ? slab_hi : slab_lo) + ez;
            const double w_min =
                ex * (ex > 0 ? bx0 : bx1) + ey * (ey > 0 ? slab_lo : slab_hi) + ez;
            const double tolerance =
                1e-6 * (std::abs(ex) * std::max({std::abs(bx0), std::abs(bx1), 1.0}) +
                        std::abs(ey) * std::max({std::abs(slab_lo), std::abs(slab_hi), 1.0}) +
                        std::abs(ez));
            outside = w_max < -tolerance;
            inside = inside && w_min > tolerance;
          }
          if (outside) continue;
          if constexpr (kDepthOnly) {
            MaxInverseDepthBucket(t.xs.data() + begin, t.ys.data() + begin, end - begin, inside,
                                  s, record.inv_near, row_best.data() + (begin - row_begin));
            continue;
          }
          if (inside) {
            for (int k = begin; k < end; ++k) {
              const float x = t.xs[k], y = t.ys[k];
              record(tri, t.sample[k], x, y, ia * x + ib * y + ic, s);
            }
            continue;
          }
          for (int k = begin; k < end; ++k) {
            const float x = t.xs[k], y = t.ys[k];
            const float w0 = e00 * x + e01 * y + e02;
            const float w1 = e10 * x + e11 * y + e12;
            const float w2 = e20 * x + e21 * y + e22;
            if (w0 < 0.f || w1 < 0.f || w2 < 0.f) continue;
            record(tri, t.sample[k], x, y, ia * x + ib * y + ic, s);
          }
        }
      }
      if constexpr (kDepthOnly) {  // each sample's ray lies in one bucket: plain stores
        for (int k = row_begin; k < row_end; ++k)
          record.inv[t.sample[k]] = row_best[k - row_begin];
      }
    }
}

}  // namespace

template <bool kDirect, class Record, class BandRecord>
void Rasterizer::Traverse(const TriangleMesh& mesh, const Rigid3d& cam_from_local,
                          const Record& record, const BandRecord* band_record, const double* view,
                          const int* rows) const {
  const RayTable& t = *rays_;
  const int row_lo = rows ? rows[0] : 0, row_hi = rows ? rows[1] : t.height;
  const double whole[4] = {t.x0, t.y0, t.x0 + t.cell_w * t.cols, t.y0 + t.cell_h * t.rows};
  if (!view) view = whole;
  const double near_m = options_.near_m;
  const bool cull = options_.cull_back_faces;
  const std::shared_ptr<const TriangleClusters> clusters = ClustersFor(mesh);
  const int num_triangles = mesh.NumTriangles();
  const Eigen::Matrix3d rotation = cam_from_local.RotationMatrix();
  const Eigen::Vector3d translation = cam_from_local.translation;
  const int num_clusters = static_cast<int>(clusters->bounds_min.size());
  const std::vector<int> slot_start =
      SlotsInView(t, *clusters, num_triangles, rotation, translation, near_m, view);
  const int num_slots = slot_start[num_clusters];

  // Triangle set-up (independent per triangle, so parallel and deterministic), in the camera
  // frame (double).
  // In per-thread scratch buffers that only grow (every slot used is written below): no
  // allocation and no page faults per frame (a 175k-triangle mesh needs 30 MB of set-ups).
  // Direct (a grid of rays): each triangle is scanned as soon as it is set up, by the thread
  // that set it up; nothing is stored.
  if (kDirect && !t.grid) throw std::logic_error("Rasterizer: direct traversal needs a grid");
  std::vector<TriangleSetup>& setup_scratch = traversal_scratch.setups;
  std::vector<int>& triangle_scratch = traversal_scratch.triangles;
  std::vector<TrianglePolygon>& polygon_scratch = traversal_scratch.polygons;
  if (!kDirect && setup_scratch.size() < static_cast<size_t>(num_slots)) {
    setup_scratch.resize(num_slots);
    triangle_scratch.resize(num_slots);
  }
  if (!kDirect && !t.grid && polygon_scratch.size() < static_cast<size_t>(num_slots))
    polygon_scratch.resize(num_slots);
  TrianglePolygon* const polygons = polygon_scratch.data();
  TriangleSetup* const setups = setup_scratch.data();
  int* const triangle_of_slot = triangle_scratch.data();
  // Direct: triangles covering many samples are not scanned by the thread that set them up
  // but afterwards, by bands of rows over all threads (a few large triangles, as in a room,
  // would otherwise leave one thread scanning the whole image). Per cluster, in order.
  std::vector<std::vector<std::pair<int, TriangleSetup>>> large(kDirect ? num_clusters : 0);
  cv::parallel_for_(cv::Range(0, num_clusters), [&](const cv::Range& range) {
    std::optional<TaskRecord<Record>> task;  // direct: the record this task scans with
    if constexpr (kDirect) task.emplace(record);
    for (int c = range.start; c < range.end; ++c) {
      const int first = c * kClusterTriangles;
      for (int slot = slot_start[c]; slot < slot_start[c + 1]; ++slot) {
        const int pos = first + (slot - slot_start[c]);
        const int tri = clusters->mesh_triangle[pos];
        TriangleSetup direct_setup;
        TriangleSetup& s = kDirect ? direct_setup : setups[slot];
        if constexpr (!kDirect) triangle_of_slot[slot] = tri;
        double poly[4][2];
        if (!SetUpTriangle(t, *clusters, pos, rotation, translation, near_m, cull, view, &s, poly))
          continue;
        if constexpr (!kDirect)
          if (!t.grid) std::copy(&poly[0][0], &poly[0][0] + 8, &polygons[slot].corner[0][0]);
        if constexpr (kDirect) {
          const long long samples =
              static_cast<long long>(s.row1 - s.row0 + 1) * (s.col1 - s.col0 + 1);
          if (samples > kLargeTriangleSamples)
            large[c].emplace_back(tri, s);
          else
            ScanGridTriangle(t, s, tri, row_lo, row_hi, task->Get());
        }
      }
    }
  });
  if constexpr (kDirect) {
    std::vector<std::pair<int, TriangleSetup>> all;
    for (auto& list : large) all.insert(all.end(), list.begin(), list.end());
    if (all.empty()) return;
    const int num_bands = (t.height + kBandRows - 1) / kBandRows;
    cv::parallel_for_(cv::Range(0, num_bands), [&](const cv::Range& range) {
      for (int band = range.start; band < range.end; ++band) {
        const int band_lo = std::max(row_lo, band * kBandRows);
        const int band_hi = std::min({t.height, row_hi, band * kBandRows + kBandRows});
        if (band_lo >= band_hi) continue;
        for (const auto& [tri, setup] : all) {
          if (setup.row0 >= band_hi || setup.row1 < band_lo) continue;
          if (band_record)
            ScanGridTriangle(t, setup, tri, band_lo, band_hi, *band_record);
          else if constexpr (!std::is_same_v<Record, InverseDepthShards>)
            ScanGridTriangle(t, setup, tri, band_lo, band_hi, record);
        }
      }
    });
  } else {  // binned
    const int num_bins = t.grid ? (t.height + kBandRows - 1) / kBandRows : t.rows;
    std::vector<int> row_start, row_triangles;
    BinByRows(setups, num_slots, num_bins, t.grid ? kBandRows : 1, &row_start, &row_triangles);
    if (t.grid) {
      cv::parallel_for_(cv::Range(0, num_bins), [&](const cv::Range& range) {
        for (int band = range.start; band < range.end; ++band) {
          const int band_lo = band * kBandRows, band_hi = std::min(t.height, band_lo + kBandRows);
          for (int j = row_start[band]; j < row_start[band + 1]; ++j)
            ScanGridTriangle(t, setups[row_triangles[j]], triangle_of_slot[row_triangles[j]],
                             band_lo, band_hi, record);
        }
      });
      return;
    }
    cv::parallel_for_(cv::Range(0, t.rows), [&](const cv::Range& range) {
      ScanBucketRows(t, range.start, range.end, setups, polygons, triangle_of_slot, row_start,
                     row_triangles, record);
    });
  }
}

void Rasterizer::Rasterize(const TriangleMesh& mesh, const Rigid3d& cam_from_local,
                           RasterOutput* output) const {
  const RayTable& t = *rays_;
  // Per-sample results (sample order), in a per-thread scratch buffer reused across calls
  // (no page faults per frame). Each sample is written only by the task owning its bucket.
  struct RayHit {
    double inv_depth;  // 1/z of the nearest hit so far, 0 when none
    int id;            // its triangle, -1 when none
    float b1, b2;      // its barycentrics
  };
  // Large grids (> 64 MB of hits) use a buffer of their own, released after the call.
  thread_local std::vector<RayHit> scratch;
  std::vector<RayHit> large;
  std::vector<RayHit>& buffer = t.by_sample.size() * sizeof(RayHit) > (64u << 20) ? large : scratch;
  buffer.resize(t.by_sample.size());
  RayHit* hits = buffer.data();
  const double inv_near = 1.0 / options_.near_m;
  cv::parallel_for_(cv::Range(0, t.height), [&](const cv::Range& range) {
    std::fill(hits + static_cast<size_t>(range.start) * t.width,
              hits + static_cast<size_t>(range.end) * t.width, RayHit{0.0, -1, 0.f, 0.f});
  });

  // Records a hit of triangle `tri` on sample `sample` at inverse depth inv_z when it is the
  // nearest so far (ties: smallest id), with z >= near_m.
  Traverse<false>(mesh, cam_from_local,
                  [&](int tri, int sample, float x, float y, double inv_z, const TriangleSetup& s) {
                    RayHit& h = hits[sample];
                    if (!(inv_z > h.inv_depth || (inv_z == h.inv_depth && tri < h.id))) return;
                    if (!(inv_z > 0.0 && inv_z <= inv_near)) return;
                    const float w0 = s.edge[0][0] * x + s.edge[0][1] * y + s.edge[0][2];
                    const float w1 = s.edge[1][0] * x + s.edge[1][1] * y + s.edge[1][2];
                    const float w2 = s.edge[2][0] * x + s.edge[2][1] * y + s.edge[2][2];
                    const float sum = w0 + w1 + w2;
                    h.inv_depth = inv_z;
                    h.id = tri;
                    h.b1 = sum > 0.f ? std::max(w1, 0.f) / sum : 0.f;
                    h.b2 = sum > 0.f ? std::max(w2, 0.f) / sum : 0.f;
                  });

  // Outputs in sample order.
  output->depth.create(t.height, t.width, CV_32F);
  output->triangle_id.create(t.height, t.width, CV_32S);
  output->bary.create(t.height, t.width, CV_32FC2);
  cv::parallel_for_(cv::Range(0, t.height), [&](const cv::Range& range) {
    for (int r = range.start; r < range.end; ++r) {
      const RayHit* h = hits + static_cast<size_t>(r) * t.width;
      float* depth = output->depth.ptr<float>(r);
      int* ids = output->triangle_id.ptr<int>(r);
      cv::Vec2f* bary = output->bary.ptr<cv::Vec2f>(r);
      for (int c = 0; c < t.width; ++c) {
        const bool hit = h[c].id >= 0;
        depth[c] =
            hit ? static_cast<float>(1.0 / h[c].inv_depth) : std::numeric_limits<float>::infinity();
        ids[c] = h[c].id;
        bary[c] = cv::Vec2f(h[c].b1, h[c].b2);
      }
    }
  });
}

void Rasterizer::ReleaseThreadScratch() {
  traversal_scratch = TraversalScratch();
  depth_shard_spares.clear();
}

void Rasterizer::RasterizeDepth(const TriangleMesh& mesh, const Rigid3d& cam_from_local,
                                cv::Mat* depth) const {
  RasterizeDepth(mesh, cam_from_local, depth, cv::Rect());
}

void Rasterizer::RasterizeDepth(const TriangleMesh& mesh, const Rigid3d& cam_from_local,
                                cv::Mat* depth, const cv::Rect& window) const {
  const RayTable& t = *rays_;
  // The window's part of the view: its samples' rays (a grid: x by column, y by row) and one
  // more sample all round, so that rounding never leaves out a triangle that covers one.
  double window_view[4];
  const double* view = nullptr;
  int rows[2] = {0, t.height};  // the grid's rows scanned
  const int n = options_.supersample;
  const cv::Rect samples(window.x * n - 1, window.y * n - 1, window.width * n + 2,
                         window.height * n + 2);
  const cv::Rect in_grid = samples & cv::Rect(0, 0, t.width, t.height);
  if (t.grid && !window.empty() && in_grid != cv::Rect(0, 0, t.width, t.height)) {
    if (in_grid.empty()) {  // nothing of the window is in the image: no triangle needed
      depth->create(t.height, t.width, CV_32F);
      depth->setTo(std::numeric_limits<float>::infinity());
      return;
    }
    window_view[0] = t.col_x[in_grid.x];
    window_view[1] = t.row_y[in_grid.y];
    window_view[2] = t.col_x[in_grid.br().x - 1];
    window_view[3] = t.row_y[in_grid.br().y - 1];
    view = window_view;
    rows[0] = in_grid.y, rows[1] = in_grid.br().y;
  }
  if (!depth->isContinuous()) depth->release();  // rays index the samples as one array
  depth->create(t.height, t.width, CV_32F);
  // Inverse depth in place (0: no hit), then depth. The nearest hit is the largest float
  // inverse depth: a maximum, so the result does not depend on the visiting order.
  cv::parallel_for_(cv::Range(0, t.height), [&](const cv::Range& range) {
    for (int r = range.start; r < range.end; ++r)
      std::fill_n(depth->ptr<float>(r), t.width,
                  r >= rows[0] && r < rows[1] ? 0.0f : std::numeric_limits<float>::infinity());
  });
  float* inv = depth->ptr<float>();
  const double inv_near = 1.0 / options_.near_m;
  std::vector<float*> spares;  // grid: inverse depths written besides `inv`
  // The nearest hit so far, where one thread owns the sample.
  const NearestInverseDepth exclusive_record{inv, inv_near};
  if (!rays_->grid) {
    Traverse<false>(mesh, cam_from_local, exclusive_record, &exclusive_record, view);
  } else {
    // Triangles scanned by whichever thread set them up, each task into a buffer of its own;
    // the large triangles after, one thread per band of rows, into the output.
    const size_t width = static_cast<size_t>(t.width);
    const InverseDepthShards shards(inv, t.by_sample.size(), rows[0] * width, rows[1] * width,
                                    inv_near, &depth_shard_spares);
    Traverse<true>(mesh, cam_from_local, shards, &exclusive_record, view, rows);
    spares = shards.Spares();
  }
  cv::parallel_for_(cv::Range(rows[0], rows[1]), [&](const cv::Range& range) {
    for (int r = range.start; r < range.end; ++r) {
      float* d = depth->ptr<float>(r);
      const size_t row = static_cast<size_t>(r) * t.width;
      for (const float* spare : spares)
        for (int c = 0; c < t.width; ++c) d[c] = std::max(d[c], spare[row + c]);
      for (int c = 0; c < t.width; ++c)
        d[c] = d[c] > 0.0f ? 1.0f / d[c] : std::numeric_limits<float>::infinity();
    }
  });
}

}  // namespace fresco
