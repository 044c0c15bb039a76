#include "pipeline/paint/frame_warp.h"

#include <algorithm>
#include <atomic>
#include <cmath>

#include <opencv2/core/utility.hpp>

namespace fresco {
namespace {

inline void SampleBilinear(const cv::Mat& img, double u, double v, float out[3]) {
  const int x0 = std::min(std::max(static_cast<int>(std::floor(u)), 0), img.cols - 1);
  const int y0 = std::min(std::max(static_cast<int>(std::floor(v)), 0), img.rows - 1);
  const int x1 = std::min(x0 + 1, img.cols - 1), y1 = std::min(y0 + 1, img.rows - 1);
  const float fx = static_cast<float>(std::clamp(u - x0, 0.0, 1.0));
  const float fy = static_cast<float>(std::clamp(v - y0, 0.0, 1.0));
  const uint8_t* r0 = img.ptr<uint8_t>(y0);
  const uint8_t* r1 = img.ptr<uint8_t>(y1);
  const float w00 = (1 - fx) * (1 - fy), w10 = fx * (1 - fy), w01 = (1 - fx) * fy, w11 = fx * fy;
  for (int c = 0; c < 3; ++c)
    out[c] = w00 * r0[3 * x0 + c] + w10 * r0[3 * x1 + c] + w01 * r1[3 * x0 + c] +
             w11 * r1[3 * x1 + c];
}

}  // namespace

void WarpFrameToBuffer(const BaseBuffer& buffer, const std::vector<Eigen::Vector3f>& triangle_normals,
                       const FrameView& view, const WarpOptions& options, WarpedBuffer* warped) {
  const int w = buffer.width, h = buffer.height;
  if (warped->bgr.rows != h || warped->bgr.cols != w) {
    warped->bgr.create(h, w, CV_8UC3);
    warped->valid.create(h, w, CV_8U);
    warped->quality.create(h, w, CV_32F);
  }
  warped->valid.setTo(0);
  const Camera& camera = *view.camera;
  const cv::Mat& frame = *view.frame_bgr;
  const Eigen::Matrix3f R = view.cam_from_local.RotationMatrix().cast<float>();
  const Eigen::Vector3f t = view.cam_from_local.translation.cast<float>();
  const Eigen::Vector3f centre = view.centre_local.cast<float>();
  const float cos_max = static_cast<float>(std::cos(options.occlusion.max_view_angle_deg * M_PI / 180.0));
  const double focal = 0.5 * (camera.fx + camera.fy);
  const bool use_depth = options.occlusion.enabled && view.depth && !view.depth->empty();
  const double max_u = camera.width - 1, max_v = camera.height - 1;
  const int levels = static_cast<int>(view.pyramid.size());
  std::atomic<int> in_view{0}, visible{0}, occluded{0}, grazing{0};

  cv::parallel_for_(cv::Range(0, buffer.NumTexels()), [&](const cv::Range& range) {
    int n_in = 0, n_vis = 0, n_occ = 0, n_graze = 0;
    for (int k = range.start; k < range.end; ++k) {
      const Eigen::Vector3f& X = buffer.point[k];
      const Eigen::Vector3f p = R * X + t;
      if (!(p.z() > options.near_m)) continue;
      const Eigen::Vector3f to_cam = centre - X;
      const float dist = to_cam.norm();
      const float cos_view = triangle_normals[buffer.triangle[k]].dot(to_cam) / dist;
      if (cos_view < cos_max) {
        ++n_graze;
        continue;
      }
      Eigen::Vector2d uv;
      if (!camera.Project(p.cast<double>(), &uv)) continue;
      if (!(uv.x() >= 0 && uv.y() >= 0 && uv.x() <= max_u && uv.y() <= max_v)) continue;
      ++n_in;
      const double z = p.z();
      if (use_depth) {
        const double tan_view = std::sqrt(std::max(0.0, 1.0 - double(cos_view) * cos_view)) /
                                std::max(double(cos_view), 1e-3);
        const double tol = options.occlusion.tolerance_rel * z + options.occlusion.tolerance_m +
                           1.5 * z * tan_view / focal;
        const cv::Mat& depth = *view.depth;
        bool ok = true;
        if (options.sampling == SamplingMode::kNearest) {
          const float d = depth.at<float>(static_cast<int>(std::lround(uv.y())),
                                          static_cast<int>(std::lround(uv.x())));
          ok = std::abs(d - z) <= tol;
        } else {
          const int x0 = static_cast<int>(uv.x()), y0 = static_cast<int>(uv.y());
          const int x1 = std::min(x0 + 1, depth.cols - 1), y1 = std::min(y0 + 1, depth.rows - 1);
          const float* r0 = depth.ptr<float>(y0);
          const float* r1 = depth.ptr<float>(y1);
          ok = std::abs(r0[x0] - z) <= tol && std::abs(r0[x1] - z) <= tol &&
               std::abs(r1[x0] - z) <= tol && std::abs(r1[x1] - z) <= tol;
        }
        if (!ok) {
          ++n_occ;
          continue;
        }
      }
      ++n_vis;
      const int idx = buffer.texel_index[k];
      const int ti = idx % w, tj = idx / w;
      uint8_t* out = warped->bgr.ptr<uint8_t>(tj) + 3 * ti;
      float rgb[3];
      if (options.sampling == SamplingMode::kNearest) {
        const uint8_t* src = frame.ptr<uint8_t>(static_cast<int>(std::lround(uv.y()))) +
                             3 * static_cast<int>(std::lround(uv.x()));
        out[0] = src[0], out[1] = src[1], out[2] = src[2];
      } else {
        int level = 0;
        if (options.sampling == SamplingMode::kArea && levels > 1) {
          // Pixels one texel covers (its longer side): average them on a coarser level.
          const double footprint = focal * buffer.texel_size_m / z;
          level = std::clamp(static_cast<int>(std::floor(std::log2(std::max(footprint, 1.0)))), 0,
                             levels - 1);
        }
        const double scale = 1.0 / (1 << level);
        SampleBilinear(view.pyramid.empty() ? frame : view.pyramid[level],
                       (uv.x() + 0.5) * scale - 0.5, (uv.y() + 0.5) * scale - 0.5, rgb);
        for (int c = 0; c < 3; ++c) out[c] = static_cast<uint8_t>(std::lround(rgb[c]));
      }
      warped->valid.at<uint8_t>(tj, ti) = 255;
      warped->quality.at<float>(tj, ti) =
          static_cast<float>(std::min(1.0, focal * buffer.texel_size_m * cos_view / z));
    }
    in_view += n_in, visible += n_vis, occluded += n_occ, grazing += n_graze;
  });
  warped->in_view = in_view;
  warped->visible = visible;
  warped->occluded = occluded;
  warped->grazing = grazing;
}

}  // namespace fresco
