// Rasterizes a triangle mesh through any lens model, exactly: every output pixel's ray is
// precomputed once per camera (Camera::Unproject), bucketed in normalized (z=1) coordinates,
// and each triangle (clipped to the near plane, projected to the z=1 plane where its edges
// stay straight) is tested against the rays of the buckets it covers. Depth comes from the
// exact ray/plane intersection. This is the depth + triangle-id path the painting pipeline's
// occlusion stage uses every frame, so it has no colour work in it.
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
  double near_m = 1e-3;          // near clipping plane (camera z), metres
  bool cull_back_faces = false;  // glTF single-sided materials may set this per triangle
  int supersample = 1;           // N x N rays per pixel (N = 1..4)
};

struct RasterOutput {
  // One sample per ray: (height*N, width*N) when supersampling with N.
  cv::Mat depth;        // CV_32F camera z (metres), +inf where no surface
  cv::Mat triangle_id;  // CV_32S, -1 where no surface
  cv::Mat bary;         // CV_32FC2 barycentrics (b1, b2) of corners 1 and 2 (b0 = 1-b1-b2)
};

class Rasterizer {
 public:
  Rasterizer(const Camera& camera, const RasterOptions& options);
  ~Rasterizer();
  // `cam_from_local`: maps the mesh's local coordinates to the camera frame.
  void Rasterize(const TriangleMesh& mesh, const Rigid3d& cam_from_local,
                 RasterOutput* output) const;
  const Camera& camera() const { return camera_; }
  const RasterOptions& options() const { return options_; }
  // Normalized ray (x, y) of sample (col, row) in the supersampled grid; NaN if the lens
  // could not unproject it.
  Eigen::Vector2f Ray(int col, int row) const;

 private:
  struct RayTable;
  Camera camera_;
  RasterOptions options_;
  std::unique_ptr<RayTable> rays_;
};

}  // namespace fresco
