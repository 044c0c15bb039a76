#include "pipeline/eval/mover_provenance.h"

#include <opencv2/imgproc.hpp>

#include "pipeline/paint/frame_warp.h"
#include "pipeline/render/renderer.h"

namespace fresco {

namespace {

// A texel averaged from every view shows a mover where movers are at least this share of
// the weight it holds: a quarter of a mover's contrast to the background, or more.
constexpr double kMoverShare = 0.25;

// The weight channel of `sums` (CV_32FC4: negative while provisional samples only), or
// empty.
cv::Mat Weights(const cv::Mat& sums) {
  cv::Mat w;
  if (!sums.empty()) cv::extractChannel(sums, w, 3);
  return w;
}

// What each texel's sums took this frame (weights `before` -> `after`) into `shares`
// (mover weight, total weight), the flag `mover` (CV_8U) telling whether it showed a mover.
// The first trusted sample replaces provisional ones (texel_update.h, AddToMean): so do the
// shares.
void TakeShares(const cv::Mat& before, const cv::Mat& after, const cv::Mat& mover,
                cv::Mat* shares) {
  if (after.empty()) return;
  for (int y = 0; y < after.rows; ++y) {
    const float* a = after.ptr<float>(y);
    const float* b = before.empty() ? nullptr : before.ptr<float>(y);
    const uchar* m = mover.ptr<uchar>(y);
    cv::Vec2f* s = shares->ptr<cv::Vec2f>(y);
    for (int x = 0; x < after.cols; ++x) {
      float was = b ? b[x] : 0.0f;
      if (was < 0 && a[x] > 0) s[x] = cv::Vec2f(0, 0), was = 0;
      const float taken = std::abs(a[x]) - std::abs(was);
      if (taken <= 1e-6f) continue;
      s[x][1] += taken;
      if (m[x]) s[x][0] += taken;
    }
  }
}

}  // namespace

MoverProvenance::MoverProvenance(const Scene& world_scene, const std::vector<MoverOptions>& movers,
                                 const Scene& painted_scene, const Camera& camera,
                                 const PaintSession& session)
    : painted_scene_(painted_scene),
      camera_(camera),
      movers_(world_scene, movers),
      raster_(camera, RasterOptions()),
      bounds_(ComputeNormalizedBounds(camera)) {
  const std::vector<BaseBuffer>& buffers = session.buffers();
  for (const BaseBuffer& buffer : buffers) {
    shows_mover_.push_back(cv::Mat::zeros(buffer.height, buffer.width, CV_8U));
    n_mover_.push_back(cv::Mat::zeros(buffer.height, buffer.width, CV_16U));
    n_open_.push_back(cv::Mat::zeros(buffer.height, buffer.width, CV_16U));
    open_written_.push_back(cv::Mat::zeros(buffer.height, buffer.width, CV_8U));
    open_passed_.push_back(cv::Mat::zeros(buffer.height, buffer.width, CV_8U));
    for (MeanShares* m : {&mean_, &unmasked_, &sharp_})
      m->shares.push_back(cv::Mat::zeros(buffer.height, buffer.width, CV_32FC2));
  }
  before_.resize(buffers.size());
  mean_.before.resize(buffers.size());
  unmasked_.before.resize(buffers.size());
  sharp_.before.resize(buffers.size());
}

void MoverProvenance::BeforeFrame(const PaintSession& session) {
  for (size_t b = 0; b < before_.size(); ++b) {
    const PaintedBuffer& painted = session.painted()[b];
    painted.bgra.copyTo(before_[b]);
    mean_.before[b] = Weights(painted.mean_sum);
    unmasked_.before[b] = Weights(painted.unmasked_sum);
    sharp_.before[b] = Weights(painted.sharp_sum);
  }
  deciding_before_ = session.DecidingUpdate();
  model_before_ = session.options().background.mode != BackgroundMode::kOff;
}

void MoverProvenance::AfterFrame(const PaintSession& session, int frame,
                                 const Rigid3d& true_cam_from_world,
                                 const Rigid3d& given_cam_from_world) {
  // The pixels showing a mover, with a pixel of margin (the frames are anti-aliased).
  movers_.SetFrame(frame);
  RasterOutput with_movers;
  raster_.Rasterize(movers_.scene().mesh, CamFromLocal(movers_.scene(), true_cam_from_world),
                    &with_movers);
  cv::Mat mover_px = with_movers.triangle_id >= movers_.FirstMoverTriangle();
  cv::dilate(mover_px, mover_px, cv::Mat::ones(3, 3, CV_8U));
  cv::Mat mover_bgr;
  cv::cvtColor(mover_px, mover_bgr, cv::COLOR_GRAY2BGR);
  // Warped as the painter warped the frame: its given pose, its depth test.
  FrameView view;
  view.camera = &camera_;
  view.cam_from_local = CamFromLocal(painted_scene_, given_cam_from_world);
  view.centre_local = view.cam_from_local.Centre();
  view.frame_bgr = &mover_bgr;
  cv::Mat depth;
  raster_.RasterizeDepth(painted_scene_.mesh, view.cam_from_local, &depth);
  view.depth = &depth;
  view.bounds = bounds_;
  WarpOptions warp_options;
  warp_options.sampling = session.options().sampling;
  warp_options.occlusion = session.options().occlusion;
  // `update: auto` decided this frame for the mean without the model: the sums the texels
  // hold from now on are the unmasked ones (with this frame's sample).
  const bool took_unmasked = deciding_before_ && model_before_ && !session.DecidingUpdate() &&
                             session.options().background.mode == BackgroundMode::kOff &&
                             session.options().update == UpdatePolicy::kMean;
  // ... or for `sharp_mean`: the texels hold its sums from now on.
  const bool took_sharp = deciding_before_ && !session.DecidingUpdate() &&
                          session.options().update == UpdatePolicy::kSharpMean;
  const std::vector<BaseBuffer>& buffers = session.buffers();
  for (size_t b = 0; b < buffers.size(); ++b) {
    WarpedBuffer warped;
    WarpFrameToBuffer(buffers[b], view, warp_options, &warped);
    if (warped.visible == 0) continue;
    cv::Mat mover_texel;
    cv::extractChannel(warped.bgr, mover_texel, 0);
    mover_texel = mover_texel > 0;
    cv::Mat diff, written;
    cv::absdiff(before_[b], session.painted()[b].bgra, diff);
    cv::transform(diff, written, cv::Matx14f(1, 1, 1, 1));
    written = written > 0;
    mover_texel.copyTo(shows_mover_[b], written);
    const cv::Mat open = warped.valid & ~mover_texel;
    cv::add(n_mover_[b], 1, n_mover_[b], warped.valid & mover_texel);
    cv::add(n_open_[b], 1, n_open_[b], open);
    open_written_[b].setTo(255, open & written);
    const cv::Mat kept_out = session.KeptOutOfPainting(b);
    open_passed_[b].setTo(255, kept_out.empty() ? open & ~written : open & ~written & ~kept_out);
    const PaintedBuffer& painted = session.painted()[b];
    if (took_unmasked) {  // mean_sum holds the unmasked sums now
      TakeShares(unmasked_.before[b], Weights(painted.mean_sum), mover_texel, &unmasked_.shares[b]);
    } else if (took_sharp) {  // ... or the sharp ones
      TakeShares(sharp_.before[b], Weights(painted.mean_sum), mover_texel, &sharp_.shares[b]);
    } else {
      TakeShares(sharp_.before[b], Weights(painted.sharp_sum), mover_texel, &sharp_.shares[b]);
      TakeShares(mean_.before[b], Weights(painted.mean_sum), mover_texel, &mean_.shares[b]);
      TakeShares(unmasked_.before[b], Weights(painted.unmasked_sum), mover_texel,
                 &unmasked_.shares[b]);
    }
  }
  if (took_unmasked) mean_.shares = unmasked_.shares;
  if (took_sharp) mean_.shares = sharp_.shares;
}

bool MoverProvenance::ShowsMover(const PaintSession& session, size_t b, int idx) const {
  if (session.options().update != UpdatePolicy::kMean &&
      session.options().update != UpdatePolicy::kSharpMean)
    return shows_mover_[b].data[idx] != 0;
  const cv::Vec2f share = mean_.shares[b].ptr<cv::Vec2f>()[idx];
  return share[0] > 0 && share[0] >= kMoverShare * share[1];
}

MoverProvenance::Figures MoverProvenance::Count(const PaintSession& session) const {
  Figures f;
  const std::vector<BaseBuffer>& buffers = session.buffers();
  for (size_t b = 0; b < buffers.size(); ++b) {
    const BaseBuffer& buffer = buffers[b];
    const cv::Vec4b* bgra = session.painted()[b].bgra.ptr<cv::Vec4b>();
    const uint16_t* n_mover = n_mover_[b].ptr<uint16_t>();
    const uint16_t* n_open = n_open_[b].ptr<uint16_t>();
    for (int k = 0; k < buffer.NumTexels(); ++k) {
      if (!buffer.on_surface[k]) continue;
      const int idx = buffer.texel_index[k];
      const bool painted = bgra[idx][3] == 255;
      const bool mover = painted && ShowsMover(session, b, idx);
      f.painted += painted;
      f.painted_mover += mover;
      f.mover_dominated += mover && n_mover[idx] >= n_open[idx];
      if (mover) {
        if (n_open[idx] == 0)
          ++f.mover_never_open;
        else if (open_written_[b].data[idx])
          ++f.mover_open_replaced;
        else if (open_passed_[b].data[idx])
          ++f.mover_open_passed;
        else
          ++f.mover_open_masked;
      }
      f.open += n_open[idx] > 0;
      f.open_painted += painted && n_open[idx] > 0;
    }
  }
  return f;
}

std::vector<cv::Mat> MoverProvenance::MaskImages(const PaintSession& session) const {
  std::vector<cv::Mat> images(shows_mover_.size());
  for (size_t b = 0; b < images.size(); ++b) {
    cv::Mat alpha;
    cv::extractChannel(session.painted()[b].bgra, alpha, 3);
    cv::Mat m = cv::Mat::zeros(shows_mover_[b].size(), CV_8U);
    for (int idx = 0; idx < static_cast<int>(m.total()); ++idx)
      m.data[idx] = ShowsMover(session, b, idx) ? 255 : 0;
    cv::merge(std::vector<cv::Mat>{m, m, m, alpha}, images[b]);
  }
  return images;
}

}  // namespace fresco
