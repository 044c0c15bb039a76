#include "pipeline/paint/mover_masks.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>

#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "pipeline/core/scaled_camera.h"
#include "pipeline/paint/auto_modes.h"
#include "pipeline/paint/mover_follow.h"
#include "pipeline/render/rasterizer.h"

namespace fresco {
namespace {

// One frame at the reduced size: its colours, their 3 x 3 range, its depth and its surface
// points (local coordinates, NaN off the surface).
struct SmallFrame {
  cv::Mat bgr, low, high;  // CV_8UC3
  cv::Mat depth;           // CV_32F camera z, +inf off the surface
  cv::Mat points;          // CV_32FC3 local
  cv::Mat surface;         // CV_8U, 255 where `points` has one (the pixel shows the mesh)
  std::vector<int> surface_pixels;  // their indices (y * cols + x), in order
  const Camera* camera = nullptr;
  Rigid3d cam_from_local;
};

// Where frame `self`'s surface points land in frame `other` (pixel index, -1 where `other`
// does not see them), and the gain per channel from `other`'s colours to `self`'s over them.
void Correspond(const SmallFrame& self, const SmallFrame& other, double depth_tolerance,
                std::vector<int>* where, std::array<float, 3>* gain) {
  where->assign(self.points.total(), -1);
  std::array<double, 3> sum_self{}, sum_other{};
  const Eigen::Matrix3d rotation = other.cam_from_local.rotation.toRotationMatrix();
  const Eigen::Vector3d& translation = other.cam_from_local.translation;
  const cv::Vec3f* points = self.points.ptr<cv::Vec3f>();
  const cv::Vec3b* self_bgr = self.bgr.ptr<cv::Vec3b>();
  const cv::Vec3b* other_bgr = other.bgr.ptr<cv::Vec3b>();
  const float* other_depth = other.depth.ptr<float>();
  const int cols = other.depth.cols, rows = other.depth.rows;
  for (const int i : self.surface_pixels) {
    const cv::Vec3f& p = points[i];
    const Eigen::Vector3d in_other = rotation * Eigen::Vector3d(p[0], p[1], p[2]) + translation;
    Eigen::Vector2d pixel;
    if (!other.camera->Project(in_other, &pixel)) continue;
    // The nearest pixel (rounded half up), inside the image.
    if (!(pixel.x() >= -0.5 && pixel.y() >= -0.5 && pixel.x() < cols - 0.5 &&
          pixel.y() < rows - 0.5))
      continue;
    const int u = static_cast<int>(pixel.x() + 0.5), v = static_cast<int>(pixel.y() + 0.5);
    const int k = v * cols + u;
    const float seen = other_depth[k];
    if (!(std::abs(seen - in_other.z()) <= depth_tolerance * in_other.z())) continue;
    (*where)[i] = k;
    const cv::Vec3b a = self_bgr[i], b = other_bgr[k];
    for (int c = 0; c < 3; ++c) sum_self[c] += a[c], sum_other[c] += b[c];
  }
  for (int c = 0; c < 3; ++c)
    (*gain)[c] = sum_other[c] > 0 ? static_cast<float>(sum_self[c] / sum_other[c]) : 1.0f;
}

// What frame `self`'s comparison with one frame near it found, per pixel of its surface
// (SmallFrame::surface_pixels): the other frame's pixel index times 2, plus 1 where the colours
// differ; -1 where the other frame does not see the point. The passes all judge from the same
// comparisons (only the other frames' masks change): the first pass makes them, the later
// ones read them (4 bytes a surface pixel and comparison: 3 MB a frame at most at 320 x 240).
struct Comparison {
  int other = 0;
  std::vector<int> seen;
};

Comparison Compare(const SmallFrame& self, int other_index, const SmallFrame& other,
                   const MoverMaskOptions& options) {
  std::vector<int> where;
  std::array<float, 3> gain;
  Correspond(self, other, options.depth_tolerance, &where, &gain);
  Comparison comparison;
  comparison.other = other_index;
  comparison.seen.resize(self.surface_pixels.size());
  const float limit = static_cast<float>(options.difference);
  const cv::Vec3b* self_bgr = self.bgr.ptr<cv::Vec3b>();
  const cv::Vec3b* low = other.low.ptr<cv::Vec3b>();
  const cv::Vec3b* high = other.high.ptr<cv::Vec3b>();
  for (size_t s = 0; s < self.surface_pixels.size(); ++s) {
    const int p = self.surface_pixels[s], k = where[p];
    if (k < 0) {
      comparison.seen[s] = -1;
      continue;
    }
    const cv::Vec3b a = self_bgr[p], lo = low[k], hi = high[k];
    float worst = 0;
    for (int c = 0; c < 3; ++c) {
      const float value = a[c], below = gain[c] * lo[c] - value, above = value - gain[c] * hi[c];
      worst = std::max(worst, std::max(below, above));
    }
    comparison.seen[s] = 2 * k + (worst > limit ? 1 : 0);
  }
  return comparison;
}

// What frame `self`'s comparisons with its neighbours found, before cleaning: per pixel, the
// frames that see its surface point and those that differ from it; the pixels that differ
// from most of them (`mask`), how many were judged, how many of those differ in regions.
struct FirstLook {
  cv::Mat seeing, differing, mask;  // CV_8U
  long long judged = 0, compact = 0;
};

// Frame `self`'s first look from its neighbours; `previous` (optional): the masks of the pass
// before, whose masked pixels do not judge. `comparisons`: its comparisons with the frames
// near it (made here when empty).
FirstLook LookAtFrame(const std::vector<SmallFrame>& frames, int self_index,
                      const MoverMaskOptions& options, const std::vector<cv::Mat>* previous,
                      std::vector<Comparison>* comparisons) {
  const SmallFrame& self = frames[self_index];
  const int n = static_cast<int>(frames.size());
  if (comparisons->empty())
    for (int offset : options.offsets)
      for (int sign : {-1, 1}) {
        const int o = self_index + sign * offset;
        if (o < 0 || o >= n || frames[o].points.empty()) continue;
        comparisons->push_back(Compare(self, o, frames[o], options));
      }
  FirstLook look;
  look.seeing = cv::Mat(self.bgr.size(), CV_8U, cv::Scalar(0));
  look.differing = cv::Mat(self.bgr.size(), CV_8U, cv::Scalar(0));
  uchar* seeing_data = look.seeing.data;
  uchar* differing_data = look.differing.data;
  for (const Comparison& comparison : *comparisons) {
    const int o = comparison.other;
    const uchar* other_masked = previous && !(*previous)[o].empty() ? (*previous)[o].data : nullptr;
    for (size_t s = 0; s < self.surface_pixels.size(); ++s) {
      const int seen = comparison.seen[s];
      if (seen < 0 || (other_masked && other_masked[seen >> 1])) continue;
      const int p = self.surface_pixels[s];
      ++seeing_data[p];
      if (seen & 1) ++differing_data[p];
    }
  }
  look.mask = cv::Mat(self.bgr.size(), CV_8U, cv::Scalar(0));
  for (const int p : self.surface_pixels) {
    const int seen = seeing_data[p], differ = differing_data[p];
    if (seen < options.min_differing) continue;
    ++look.judged;
    if (differ >= options.min_differing && differ >= options.share * seen) look.mask.data[p] = 255;
  }
  // What differs in regions, not along lines (MoverMaskResult::compact; the first pass's).
  cv::Mat regions_only;
  cv::morphologyEx(look.mask, regions_only, cv::MORPH_OPEN,
                   cv::getStructuringElement(cv::MORPH_RECT, cv::Size(3, 3)));
  look.compact = cv::countNonZero(regions_only);
  return look;
}

// Frame `self`'s mask from its first look, cleaned. `joinable`: the surface pixels that may
// join a mover by their colour (those that differ from a frame that sees them, or are seen by
// too few); `agreed`: the surface pixels the frames that see them agree with
// (MoverMaskResult::agreed); `ringed_regions`: the regions of one colour the mask rings (joined
// to it; ringed_regions.h); `regions`: the frame's colour regions, kept for the later passes;
// `flagged`: its masked pixels among those judged.
cv::Mat CleanMask(const SmallFrame& self, const FirstLook& look, const MoverMaskOptions& options,
                  long long* flagged, cv::Mat* joinable, cv::Mat* agreed, cv::Mat* ringed_regions,
                  ColourRegionLabels* regions) {
  const cv::Mat& seeing = look.seeing;
  const cv::Mat& differing = look.differing;
  cv::Mat mask = look.mask.clone();
  // Cleaning: small blobs are noise. A mover's pixels that match the frames near it (its
  // inside, where they show it too: it is large or slow) join it: within each blob's box,
  // the pixels of its colours. Not pixels that agree with every frame that sees them: the
  // background beside a blob of its own colour (a façade beside a misjudged patch of it).
  *joinable = (differing >= 1) | (seeing < options.min_differing);
  // Agreed: no frame differs, or one of at least four (the rest of a mover a frame's mask
  // missed): on the three sets of captures with movers a little more painted of what was seen
  // without a mover and a little less of the movers than with none differing alone.
  *agreed = ((differing == 0) & (seeing >= 1)) | ((differing <= 1) & (seeing >= 4));
  joinable->setTo(0, ~self.surface);
  agreed->setTo(0, ~self.surface);
  cv::Mat labels, stats, centroids;
  const int count = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8, CV_32S);
  cv::Mat grown = mask.clone();
  for (int label = 1; label < count; ++label) {
    const int area = stats.at<int>(label, cv::CC_STAT_AREA);
    const cv::Rect box(
        stats.at<int>(label, cv::CC_STAT_LEFT), stats.at<int>(label, cv::CC_STAT_TOP),
        stats.at<int>(label, cv::CC_STAT_WIDTH), stats.at<int>(label, cv::CC_STAT_HEIGHT));
    if (area < options.min_blob_px) {
      grown(box).setTo(0, labels(box) == label);
      continue;
    }
    if (!options.grow) continue;
    const ColourSet colours =
        ColourSet::Of(self.bgr(box), labels(box) == label, std::max(2, area / 100));
    for (int y = box.y; y < box.br().y; ++y)
      for (int x = box.x; x < box.br().x; ++x)
        if (joinable->at<uchar>(y, x) && colours.Contains(self.bgr.at<cv::Vec3b>(y, x)))
          grown.at<uchar>(y, x) = 255;
  }
  mask = grown;
  cv::Mat ringed;
  if (options.ringed.share > 0)
    ringed = RingedRegions(self.bgr, mask, self.surface, options.ringed, regions);
  if (options.dilate_px > 0)
    cv::dilate(mask, mask,
               cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * options.dilate_px + 1,
                                                                     2 * options.dilate_px + 1)));
  *flagged = cv::countNonZero(mask & (seeing >= options.min_differing));
  if (!ringed.empty()) mask |= ringed;
  *ringed_regions = ringed;
  return mask;
}

// Per camera: the camera at the reduced size and its rasterizer (which holds each pixel's
// ray); with MoverMaskOptions::full_size_depth, the rasterizer of the camera itself.
struct SmallCamera {
  std::unique_ptr<Camera> camera;
  std::unique_ptr<Rasterizer> rasterizer;
  std::unique_ptr<Rasterizer> full;
};

// The frame's surface points (local) and which pixels show the surface, from its depth and
// the ray of each pixel: `ray_of(x, y)`.
template <class RayOf>
void SurfacePoints(const Rigid3d& cam_from_local, const RayOf& ray_of, SmallFrame* d) {
  d->points.create(d->depth.size(), CV_32FC3);
  d->surface = cv::Mat::zeros(d->depth.size(), CV_8U);
  const Rigid3d local_from_cam = cam_from_local.Inverse();
  for (int y = 0; y < d->depth.rows; ++y)
    for (int x = 0; x < d->depth.cols; ++x) {
      const float z = d->depth.at<float>(y, x);
      const Eigen::Vector2f ray = ray_of(x, y);
      if (!std::isfinite(z) || !ray.allFinite()) {
        d->points.at<cv::Vec3f>(y, x) = cv::Vec3f(NAN, NAN, NAN);
        continue;
      }
      const Eigen::Vector3d p = local_from_cam * Eigen::Vector3d(ray.x() * z, ray.y() * z, z);
      d->points.at<cv::Vec3f>(y, x) = cv::Vec3f(p.x(), p.y(), p.z());
      d->surface.at<uchar>(y, x) = 255;
      d->surface_pixels.push_back(y * d->depth.cols + x);
    }
}

// One frame at the reduced size (SmallFrame) through its small camera; `full_depth` (with
// MoverMaskOptions::full_size_depth): the depth at the camera's full size, rasterized here.
void MakeSmallFrame(const TriangleMesh& mesh, const MoverMaskFrame& in, const SmallCamera& s,
                    SmallFrame* d, cv::Mat* full_depth) {
  d->camera = s.camera.get();
  d->cam_from_local = in.cam_from_local;
  const cv::Size size(s.camera->width, s.camera->height);
  if (in.bgr.size() == size)
    d->bgr = in.bgr.isContinuous() ? in.bgr : in.bgr.clone();
  else
    cv::resize(in.bgr, d->bgr, size, 0, 0, cv::INTER_AREA);
  const cv::Mat box = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(3, 3));
  cv::erode(d->bgr, d->low, box);
  cv::dilate(d->bgr, d->high, box);
  if (!s.full) {
    s.rasterizer->RasterizeDepth(mesh, in.cam_from_local, &d->depth);
    SurfacePoints(
        in.cam_from_local, [&](int x, int y) { return s.rasterizer->Ray(x, y); }, d);
    return;
  }
  // Each small pixel: the full-size sample nearest its centre, its depth and its ray.
  s.full->RasterizeDepth(mesh, in.cam_from_local, full_depth);
  const double sx = static_cast<double>(full_depth->cols) / size.width;
  const double sy = static_cast<double>(full_depth->rows) / size.height;
  std::vector<int> col(size.width), row(size.height);
  for (int x = 0; x < size.width; ++x)
    col[x] = std::clamp(static_cast<int>(std::floor((x + 0.5) * sx)), 0, full_depth->cols - 1);
  for (int y = 0; y < size.height; ++y)
    row[y] = std::clamp(static_cast<int>(std::floor((y + 0.5) * sy)), 0, full_depth->rows - 1);
  d->depth.create(size, CV_32F);
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x)
      d->depth.at<float>(y, x) = full_depth->at<float>(row[y], col[x]);
  SurfacePoints(
      in.cam_from_local, [&](int x, int y) { return s.full->Ray(col[x], row[y]); }, d);
}

// The frames at the reduced size (empty where a frame has no camera or colour image); the
// small cameras they point to are kept in `small`; `full_depths` (with
// MoverMaskOptions::full_size_depth): each frame's depth at its camera's full size.
std::vector<SmallFrame> SmallFrames(const TriangleMesh& mesh,
                                    const std::vector<MoverMaskFrame>& given,
                                    const MoverMaskOptions& options,
                                    std::map<const Camera*, SmallCamera>* small,
                                    std::vector<cv::Mat>* full_depths) {
  const auto usable = [](const MoverMaskFrame& in) {
    return in.camera && !in.bgr.empty() && in.bgr.type() == CV_8UC3;
  };
  for (const MoverMaskFrame& in : given) {
    if (!usable(in)) continue;
    SmallCamera& s = (*small)[in.camera];
    if (s.camera) continue;
    const cv::Size size = MoverMaskSize(*in.camera, options);
    s.camera = std::make_unique<Camera>(ScaledCamera(*in.camera, size.width, size.height));
    if (options.full_size_depth)
      s.full = std::make_unique<Rasterizer>(*in.camera, RasterOptions());
    else
      s.rasterizer = std::make_unique<Rasterizer>(*s.camera, RasterOptions());
  }
  // Frames at once (a frame's rasterizing is mostly on one core).
  std::vector<SmallFrame> frames(given.size());
  full_depths->assign(options.full_size_depth ? given.size() : 0, cv::Mat());
  cv::parallel_for_(cv::Range(0, static_cast<int>(given.size())), [&](const cv::Range& range) {
    for (int f = range.start; f < range.end; ++f)
      if (usable(given[f]))
        MakeSmallFrame(mesh, given[f], small->at(given[f].camera), &frames[f],
                       options.full_size_depth ? &(*full_depths)[f] : nullptr);
  });
  return frames;
}

// Progress after pass `done` of `passes`: the pixels masked and the frames whose masks changed.
void ReportPass(const MoverMaskOptions& options, const MoverMaskResult& result, int done,
                int passes, const std::vector<uint8_t>& changed) {
  if (!options.progress) return;
  long long masked = 0;
  for (const cv::Mat& m : result.masks)
    if (!m.empty()) masked += cv::countNonZero(m);
  const long long frames_changed = std::count(changed.begin(), changed.end(), 1);
  char line[160];
  std::snprintf(line, sizeof line, "%d frames, %lld pixels masked, %lld frames changed",
                static_cast<int>(result.masks.size()), masked, frames_changed);
  options.progress(done, passes, line);
}

// The joinable pixels and ringed regions the frames' judging gives, and each frame's
// comparisons with the frames near it (kept for the later passes).
struct Judged {
  std::vector<cv::Mat> joinable, ringed;
  std::vector<ColourRegionLabels> regions;
  std::vector<std::vector<Comparison>> comparisons;
};

// A later pass judges a frame again only where a frame it is compared with had its mask
// changed by the pass before (`changed`); returns the frames whose masks this pass changed.
std::vector<uint8_t> JudgeAgain(const std::vector<SmallFrame>& frames,
                                const MoverMaskOptions& options,
                                const std::vector<uint8_t>& changed, Judged* judged,
                                MoverMaskResult* result) {
  const int n = static_cast<int>(frames.size());
  const std::vector<cv::Mat> previous = result->masks;
  std::vector<uint8_t> now_changed(n, 0);
  cv::parallel_for_(cv::Range(0, n), [&](const cv::Range& range) {
    for (int f = range.start; f < range.end; ++f) {
      if (frames[f].points.empty()) continue;
      bool any = false;
      for (int offset : options.offsets)
        for (int o : {f - offset, f + offset}) any = any || (o >= 0 && o < n && changed[o]);
      if (!any) continue;
      long long unused = 0;
      const FirstLook look = LookAtFrame(frames, f, options, &previous, &judged->comparisons[f]);
      result->masks[f] = CleanMask(frames[f], look, options, &unused, &judged->joinable[f],
                                   &result->agreed[f], &judged->ringed[f], &judged->regions[f]);
      now_changed[f] = cv::norm(result->masks[f], previous[f], cv::NORM_INF) > 0;
    }
  });
  return now_changed;
}

// The movers followed across frames over the pixels that may join them.
void FollowAcrossFrames(const std::vector<SmallFrame>& frames, const Judged& judged,
                        const MoverMaskOptions& options, MoverMaskResult* result) {
  const int n = static_cast<int>(frames.size());
  const std::vector<cv::Mat>& joinable = judged.joinable;
  const std::vector<cv::Mat>& ringed = judged.ringed;
  std::vector<FollowFrame> follow(n);
  for (int f = 0; f < n; ++f)
    if (!joinable[f].empty()) follow[f] = FollowFrame{frames[f].bgr, joinable[f]};
  if (options.ringed_follow_frames > 0) {
    // The regions the masks ring, followed over any pixel of the surface (their inside
    // agrees with the frames near it), then what that found followed as the rest is.
    std::vector<FollowFrame> any_surface(n);
    std::vector<cv::Mat> found(n);
    for (int f = 0; f < n; ++f) {
      if (joinable[f].empty() || ringed[f].empty()) continue;
      any_surface[f] = FollowFrame{frames[f].bgr, frames[f].surface};
      found[f] = ringed[f].clone();
    }
    FollowMovers(any_surface, options.ringed_follow_frames, &found);
    for (int f = 0; f < n; ++f)
      if (!found[f].empty()) result->masks[f] |= found[f];
  }
  FollowMovers(follow, options.follow_frames, &result->masks);
}

// Whether the frames judged so far (every `stride`-th from the first) are enough: the caller
// drops the masks below a share (later_passes_min_fraction) and they show in regions under
// `below` times it.
bool JudgedAreEnough(const MoverMaskOptions& options, const std::vector<long long>& judged,
                     const std::vector<long long>& compact, int stride, double below) {
  const int n = static_cast<int>(judged.size());
  if (options.later_passes_min_fraction <= 0 || below <= 0 || n < stride * options.half_min_frames)
    return false;
  long long judged_so_far = 0, compact_so_far = 0;
  for (int f = 0; f < n; f += stride) judged_so_far += judged[f], compact_so_far += compact[f];
  return judged_so_far > 0 &&
         compact_so_far < below * options.later_passes_min_fraction * judged_so_far;
}

}  // namespace

cv::Mat MoverMaskResult::Packed(size_t k) const {
  if (k >= masks.size() || masks[k].empty()) return cv::Mat();
  cv::Mat packed = cv::Mat::zeros(masks[k].size(), CV_8U);
  if (k < agreed.size() && !agreed[k].empty()) packed.setTo(kAgreedPixel, agreed[k]);
  packed.setTo(kMoverPixel, masks[k]);
  return packed;
}

MoverMaskOptions MoverMaskOptionsFor(const BackgroundOptions& background) {
  MoverMaskOptions options;
  if (!background.across_views || background.mode == BackgroundMode::kOff) options.passes = 1;
  if (background.mode == BackgroundMode::kAuto)
    options.later_passes_min_fraction = kBackgroundAcrossViewsThreshold;
  return options;
}

cv::Size MoverMaskSize(const Camera& camera, const MoverMaskOptions& options) {
  const int side = std::max(camera.width, camera.height);
  if (options.max_side_px <= 0 || side <= options.max_side_px)
    return cv::Size(camera.width, camera.height);
  const double scale = static_cast<double>(options.max_side_px) / side;
  return cv::Size(std::max(1, static_cast<int>(std::lround(camera.width * scale))),
                  std::max(1, static_cast<int>(std::lround(camera.height * scale))));
}

Status FindMoverMasks(const TriangleMesh& mesh, const std::vector<MoverMaskFrame>& given,
                      const MoverMaskOptions& options, MoverMaskResult* result) {
  const auto start = std::chrono::steady_clock::now();
  *result = MoverMaskResult();
  const int n = static_cast<int>(given.size());
  result->masks.resize(n);
  std::map<const Camera*, SmallCamera> small;
  const std::vector<SmallFrame> frames = SmallFrames(mesh, given, options, &small, &result->depths);
  std::vector<long long> judged(n, 0), flagged(n, 0), compact(n, 0);
  Judged judging;
  judging.joinable.resize(n);
  judging.ringed.resize(n);
  judging.comparisons.resize(n);
  judging.regions.resize(n);
  result->agreed.resize(n);
  const bool keep_comparisons = options.passes > 1;
  // The first pass judges every fourth frame, then every second, then the rest (f % stride ==
  // first): a frame's judging reads only the frames, so in turn they judge as all at once.
  std::vector<FirstLook> looks(n);
  const auto judge = [&](int first, int stride) {
    const int count = (n - first + stride - 1) / stride;
    cv::parallel_for_(cv::Range(0, std::max(0, count)), [&](const cv::Range& range) {
      for (int k = range.start; k < range.end; ++k) {
        const int f = stride * k + first;
        if (frames[f].points.empty()) continue;
        looks[f] = LookAtFrame(frames, f, options, nullptr, &judging.comparisons[f]);
        judged[f] = looks[f].judged, compact[f] = looks[f].compact;
        if (!keep_comparisons) std::vector<Comparison>().swap(judging.comparisons[f]);
      }
    });
  };
  const bool quarter_first = options.half_enough_below > 0 && options.quarter_enough_below > 0 &&
                             n >= 4 * options.half_min_frames;
  judge(0, quarter_first ? 4 : 2);
  const bool enough =
      quarter_first && JudgedAreEnough(options, judged, compact, 4, options.quarter_enough_below);
  if (quarter_first && !enough) judge(2, 4);
  if (enough || JudgedAreEnough(options, judged, compact, 2, options.half_enough_below)) {
    // The caller drops the masks: they are left as the comparisons found them, not cleaned.
    for (int f = 0; f < n; ++f)
      if (!looks[f].mask.empty())
        result->masks[f] = looks[f].mask, flagged[f] = cv::countNonZero(looks[f].mask);
  } else {
    judge(1, 2);
    cv::parallel_for_(cv::Range(0, n), [&](const cv::Range& range) {
      for (int f = range.start; f < range.end; ++f)
        if (!looks[f].mask.empty())
          result->masks[f] = CleanMask(frames[f], looks[f], options, &flagged[f],
                                       &judging.joinable[f], &result->agreed[f], &judging.ringed[f],
                                       keep_comparisons ? &judging.regions[f] : nullptr);
    });
  }
  looks.clear();
  for (int f = 0; f < n; ++f) {
    result->judged += judged[f], result->flagged += flagged[f], result->compact += compact[f];
    result->frames_judged += judged[f] > 0 ? 1 : 0;
  }
  // A later pass judges a frame again only where a frame it is compared with had its mask
  // changed by the pass before (the first pass: any masked pixel); none once nothing changes.
  const bool later_passes = result->compact_fraction() > options.later_passes_min_fraction;
  const int passes = later_passes ? std::max(1, options.passes) : 1;
  std::vector<uint8_t> changed(n, 0);
  for (int f = 0; f < n; ++f)
    changed[f] = !result->masks[f].empty() && cv::countNonZero(result->masks[f]) > 0;
  ReportPass(options, *result, 1, passes, changed);
  for (int pass = 1; pass < passes; ++pass) {
    changed = JudgeAgain(frames, options, changed, &judging, result);
    ReportPass(options, *result, pass + 1, passes, changed);
    if (std::find(changed.begin(), changed.end(), 1) == changed.end()) break;
  }
  if (passes > 1 && options.follow_frames > 0) FollowAcrossFrames(frames, judging, options, result);
  for (int f = 0; f < n; ++f)
    if (!result->agreed[f].empty()) result->agreed[f].setTo(0, result->masks[f]);
  result->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return Status::Ok();
}

}  // namespace fresco
