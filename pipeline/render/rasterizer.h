// Rasterizes a triangle mesh through any lens model, exactly: every output pixel's ray is
// precomputed once per camera (Camera::Unproject), bucketed in normalized (z=1) coordinates,
// and each triangle (clipped to the near plane, projected to the z=1 plane where its edges
// stay straight) is tested against the rays of the buckets it covers. Depth comes from the
// exact ray/plane intersection. No colour work: the renderer shades from the triangle ids and
// barycentrics, and the painting pipeline's occlusion stage takes the depth alone
// (RasterizeDepth) every frame.
//
// Exactness: a sample shows the nearest triangle its ray meets at camera z >= near_m (ties in
// depth go to the smallest triangle id), the same answer as a brute-force ray cast of the same
// rays; triangles partly behind the camera draw only their part in front of the near plane.
// Edge tests are inclusive and watertight (no cracks between triangles sharing an edge).
// Determinism: parallel over rows of buckets (cv::parallel_for_), each ray owned by one
// task, so the output is bit-identical whatever the number of threads. Rasterize() is const
// and may be called from several threads at once.
#pragma once

#include <memory>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "pipeline/core/camera.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/core/scene.h"

namespace fresco {

struct RasterOptions {
  double near_m = 1e-3;  // near clipping plane (camera z), metres
  // Skip triangles seen from behind (counter-clockwise = front, as in glTF). Applies to every
  // triangle (per-material single-sidedness is not looked at).
  bool cull_back_faces = false;
  // N x N rays per pixel (N = 1..4): sample i of pixel c sits at c + (i + 0.5)/N - 0.5.
  int supersample = 1;
};

struct RasterOutput {
  // One sample per ray: (height*N, width*N) when supersampling with N.
  cv::Mat depth;        // CV_32F camera z (metres; exact ray/plane hit), +inf where no surface
  cv::Mat triangle_id;  // CV_32S, -1 where no surface
  cv::Mat bary;         // CV_32FC2 barycentrics (b1, b2) of corners 1 and 2 (b0 = 1-b1-b2)
};

class Rasterizer {
 public:
  // Unprojects every sample once per camera (the ray table, shared by the rasterizers of
  // the same camera and supersampling: ~4 ms for 640x480 pinhole, ~25 ms with
  // distortion). Throws std::invalid_argument for a camera without size or bad options.
  Rasterizer(const Camera& camera, const RasterOptions& options);
  ~Rasterizer();
  // `cam_from_local`: maps the mesh's local coordinates to the camera frame. Triangles with
  // bad indices or non-finite corners are skipped.
  void Rasterize(const TriangleMesh& mesh, const Rigid3d& cam_from_local,
                 RasterOutput* output) const;
  // Depth only (CV_32F, as RasterOutput::depth): what the occlusion test needs, without the
  // triangle ids and barycentrics (4 bytes per ray instead of a 24-byte hit record and three
  // output images: 1.25 against 3.00 ms at 1280x720, paint_bench BM_DepthRaster).
  void RasterizeDepth(const TriangleMesh& mesh, const Rigid3d& cam_from_local,
                      cv::Mat* depth) const;
  // ... exact within `window` (the camera's pixels; empty: the whole image) and one sample
  // about it, anything elsewhere: only the triangles whose bounds meet the window's part of
  // the view are set up, and only its rows are scanned (the rows above and below it infinite)
  // (a lens with distortion: the whole image).
  void RasterizeDepth(const TriangleMesh& mesh, const Rigid3d& cam_from_local, cv::Mat* depth,
                      const cv::Rect& window) const;
  // Builds what rasterizing `mesh` needs once (the culling clusters of its triangles), which
  // the first Rasterize or RasterizeDepth would otherwise build.
  void Prepare(const TriangleMesh& mesh) const { ClustersFor(mesh); }
  // Rasterize keeps set-up buffers per thread that only grow (no allocation per frame): ~110
  // bytes per triangle in view, for the rest of the thread's life. This frees the calling
  // thread's, after a one-off rasterization of a large mesh.
  static void ReleaseThreadScratch();
  const Camera& camera() const { return camera_; }
  const RasterOptions& options() const { return options_; }
  // Normalized ray (x, y) of sample (col, row) in the supersampled grid; NaN if the lens
  // could not unproject it.
  Eigen::Vector2f Ray(int col, int row) const;

 private:
  struct RayTable;
  // The ray table of `camera` at `supersample`, built or shared with the rasterizers made
  // before of the same camera.
  static std::shared_ptr<const RayTable> SharedRayTable(const Camera& camera, int supersample);
  // Bounds of runs of triangles near in space, for culling whole runs per frame (computed once
  // per mesh and cached; see ClustersFor).
  struct TriangleClusters;
  struct ClusterCache;
  std::shared_ptr<const TriangleClusters> ClustersFor(const TriangleMesh& mesh) const;
  // Sets up the triangles and calls record(tri, sample, x, y, inv_z, setup) for every ray
  // inside a triangle at inverse depth inv_z (near plane not yet checked). Binned (kDirect
  // false): each sample is recorded by one thread only. Direct (rays on a grid only): each
  // triangle is scanned by the thread that set it up, so record must be thread-safe; the
  // large triangles are scanned afterwards by bands of rows, one thread a band, through
  // band_record (which need not be: no other thread writes the band's samples then).
  // `view` (x0, y0, x1, y1 of the normalized rays; null: the ray table's bounds): triangles
  // wholly outside it are not set up. `rows` (direct only; null: all): only the grid's rows
  // rows[0] <= row < rows[1] are scanned.
  template <bool kDirect, class Record, class BandRecord = Record>
  void Traverse(const TriangleMesh& mesh, const Rigid3d& cam_from_local, const Record& record,
                const BandRecord* band_record = nullptr, const double* view = nullptr,
                const int* rows = nullptr) const;
  Camera camera_;
  RasterOptions options_;
  std::shared_ptr<const RayTable> rays_;  // shared by the rasterizers of one camera
  std::unique_ptr<ClusterCache> cluster_cache_;
};

}  // namespace fresco
