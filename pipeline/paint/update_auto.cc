// `update: auto`: the sharpest view or the mean of every view (with or without the background
// model), decided on frames held out of the decision (PaintSession::DecideUpdate,
// paint_session.h).
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>

#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "pipeline/paint/mover_masks.h"
#include "pipeline/paint/paint_session.h"
#include "pipeline/paint/texture_atlas.h"
#include "pipeline/render/renderer.h"

namespace fresco {

namespace {

// `base` where `sums` (less `held`, when given) have no weight, their mean elsewhere.
cv::Mat MeanTexels(const cv::Mat& base, const cv::Mat& sums, const cv::Mat& held = cv::Mat()) {
  cv::Mat bgra = base.clone();
  if (sums.empty()) return bgra;
  for (int y = 0; y < bgra.rows; ++y) {
    const cv::Vec4f* sum = sums.ptr<cv::Vec4f>(y);
    const cv::Vec4f* less = held.empty() ? nullptr : held.ptr<cv::Vec4f>(y);
    cv::Vec4b* texel = bgra.ptr<cv::Vec4b>(y);
    for (int x = 0; x < bgra.cols; ++x) {
      const cv::Vec4f s = less ? sum[x] - less[x] : sum[x];
      if (std::abs(s[3]) <= 1e-6f) continue;  // negative: provisional samples only
      MeanOfSums(&s[0], &texel[x][0]);
      texel[x][3] = 255;
    }
  }
  return bgra;
}

// PSNR of each rendering (RGBA) against `frame` over the pixels all of them paint, less
// `movers` (kMoverPixel, any size); false when there is none.
bool ComparedPsnr(const std::vector<cv::Mat>& rendered, const cv::Mat& frame, const cv::Mat& movers,
                  std::vector<double>* psnr) {
  cv::Mat compared(frame.size(), CV_8U, cv::Scalar(255));
  for (const cv::Mat& rgba : rendered) {
    cv::Mat alpha;
    cv::extractChannel(rgba, alpha, 3);
    compared &= alpha == 255;
  }
  if (!movers.empty()) {
    cv::Mat at_size;
    cv::resize(movers, at_size, frame.size(), 0, 0, cv::INTER_NEAREST);
    compared &= at_size != kMoverPixel;
  }
  const int pixels = cv::countNonZero(compared);
  if (pixels == 0) return false;
  psnr->clear();
  for (const cv::Mat& rgba : rendered) {
    cv::Mat bgr;
    cv::cvtColor(rgba, bgr, cv::COLOR_RGBA2BGR);
    const double mse = cv::norm(bgr, frame, cv::NORM_L2SQR, compared) / (3.0 * pixels);
    psnr->push_back(10 * std::log10(255.0 * 255.0 / std::max(mse, 1e-10)));
  }
  return true;
}

// The texture of each of `scene`'s atlas pages (PaintSession::PaintedScene: textures 0..pages-1)
// composed again from `buffer_bgra`, in the memory it has.
void ComposePagesInto(const TextureAtlas& atlas, const std::vector<cv::Mat>& buffer_bgra,
                      Scene* scene) {
  for (size_t page = 0; page < atlas.pages.size(); ++page) {
    cv::Mat& rgba = scene->textures[page].rgba;
    ComposeAtlasPageInto(atlas, static_cast<int>(page), buffer_bgra, &rgba);
    cv::cvtColor(rgba, rgba, cv::COLOR_BGRA2RGBA);
  }
}

// fn(b) for buffers b = 0 .. count-1, several at once (each reads and writes its own).
void ForEachBufferOf(size_t count, const std::function<void(size_t)>& fn) {
  cv::parallel_for_(cv::Range(0, static_cast<int>(count)), [&](const cv::Range& range) {
    for (int b = range.start; b < range.end; ++b) fn(static_cast<size_t>(b));
  });
}

}  // namespace

// Decided `quality` (basis `why`) without a comparison: the sums go.
void PaintSession::KeepSharpestViews(const char* why) {
  update_held_out_.clear();
  update_auto_.basis = why;
  update_auto_.decided_at_frame = frames_seen_;
  update_auto_.state = AutoDecision::State::kOff;
  options_.update = UpdatePolicy::kQuality;
  for (PaintedBuffer& p : painted_)
    for (cv::Mat* m : {&p.mean_sum, &p.unmasked_sum, &p.shadow_bgra, &p.shadow_quality, &p.held_sum,
                       &p.held_unmasked_sum, &p.sharp_sum, &p.held_sharp_sum})
      m->release();
}

// The candidates painted without the frames held out, rendered at those frames' poses:
// `psnr_sum[c]` over the frames measured (the return value). Candidate 0 the sharpest view,
// 1 the mean, 2 the mean without the model, 3 the sharp mean (`candidates`: the first n, or
// those listed).
int PaintSession::ScoreHeldOut(size_t n, std::vector<double>* psnr_sum,
                               const std::vector<int>& candidates) const {
  std::vector<int> kinds = candidates;
  if (kinds.empty())
    for (size_t c = 0; c < n; ++c) kinds.push_back(static_cast<int>(c));
  n = kinds.size();
  // One scene (the mesh with its atlas UVs), its pages composed again for each candidate; each
  // frame rasterized once and shaded with each.
  const auto candidate = [&](size_t c) {
    std::vector<cv::Mat> texels(painted_.size());
    ForEachBufferOf(painted_.size(), [&](size_t b) {
      const PaintedBuffer& p = painted_[b];
      const cv::Mat& base = p.shadow_bgra.empty() ? p.bgra : p.shadow_bgra;
      const int kind = kinds[c];
      texels[b] = AtMeanExposure(kind == 0   ? base
                                 : kind == 1 ? MeanTexels(base, p.mean_sum, p.held_sum)
                                 : kind == 2 ? MeanTexels(base, p.unmasked_sum, p.held_unmasked_sum)
                                             : MeanTexels(base, p.sharp_sum, p.held_sharp_sum));
    });
    return texels;
  };
  Scene scene = PaintedScene(candidate(0));
  std::vector<std::unique_ptr<Renderer>> renderers;
  std::vector<RasterOutput> rasters(update_held_out_.size());
  std::vector<std::vector<cv::Mat>> rendered(update_held_out_.size(), std::vector<cv::Mat>(n));
  for (size_t f = 0; f < update_held_out_.size(); ++f) {
    renderers.push_back(std::make_unique<Renderer>(update_held_out_[f].camera, RenderOptions()));
    renderers[f]->RasterizeScene(scene, update_held_out_[f].cam_from_world, &rasters[f]);
  }
  for (size_t c = 0; c < n; ++c) {
    if (c > 0) ComposePagesInto(atlas_, candidate(c), &scene);
    for (size_t f = 0; f < update_held_out_.size(); ++f)
      renderers[f]->ShadeScene(scene, rasters[f], &rendered[f][c]);
  }
  psnr_sum->assign(n, 0.0);
  std::vector<double> psnr;
  int measured = 0;
  for (size_t f = 0; f < update_held_out_.size(); ++f) {
    const HeldOutFrame& frame = update_held_out_[f];
    if (!ComparedPsnr(rendered[f], frame.bgr, frame.movers, &psnr)) continue;
    for (size_t c = 0; c < n; ++c) (*psnr_sum)[c] += psnr[c];
    ++measured;
  }
  return measured;
}

// The model off from now on (its sums the mean's), on `gain_db` over `measured` frames.
void PaintSession::TurnModelOffByFramesHeldOut(double gain_db, int measured) {
  background_auto_.OffByFramesHeldOut(frames_seen_, gain_db, measured);
  options_.background.mode = BackgroundMode::kOff;
  background_.clear();
  background_frame_.clear();
  for (PaintedBuffer& p : painted_) {
    // No sample is provisional without the model: every view counts.
    cv::absdiff(p.quality, 0, p.quality);
    if (!p.shadow_quality.empty()) cv::absdiff(p.shadow_quality, 0, p.shadow_quality);
    p.mean_sum = p.unmasked_sum;
    p.held_sum = p.held_unmasked_sum;
    p.unmasked_sum.release();
    p.held_unmasked_sum.release();
  }
}

bool PaintSession::DecidingModelOnHeldOut() const {
  return DecidingUpdate() && options_.refine.mode == RefineMode::kOff &&
         options_.background.mode != BackgroundMode::kOff &&
         requested_background_ == BackgroundMode::kAuto;
}

void PaintSession::DecideModelEarly() {
  if (!DecidingModelOnHeldOut() || model_decided_early_) return;
  model_decided_early_ = true;
  std::vector<double> psnr_sum;
  const int measured = ScoreHeldOut(/*candidates=*/3, &psnr_sum);
  if (measured > 0 && psnr_sum[2] > std::max(psnr_sum[0], psnr_sum[1]))
    TurnModelOffByFramesHeldOut((psnr_sum[2] - psnr_sum[1]) / measured, measured);
}

void PaintSession::DecideUpdate() {
  if (!DecidingUpdate()) return;
  // Refinement `auto` came on (as StartAutoModes with refinement on).
  if (options_.refine.mode != RefineMode::kOff) return KeepSharpestViews("refinement_on");
  // The candidates, without the frames held out: the sharpest view, the mean of every view
  // and, where background `auto` turned the model on, that mean without the model (winning
  // turns it off). A model on by hand stays as the paper paints with it: the sharpest view.
  const bool model_on = options_.background.mode != BackgroundMode::kOff;
  const bool without_model = model_on && requested_background_ == BackgroundMode::kAuto;
  if (model_on && !without_model) return KeepSharpestViews("background_model_on");
  // The sharp mean where its sums were kept (TexelUpdateRule::sharp_too: not with layers).
  bool sharp = false;
  for (const PaintedBuffer& p : painted_) sharp |= !p.sharp_sum.empty();
  std::vector<int> kinds = {0, 1};
  if (without_model) kinds.push_back(2);
  if (sharp) kinds.push_back(3);
  const size_t n = kinds.size();
  std::vector<double> psnr_sum;
  const int measured = ScoreHeldOut(n, &psnr_sum, kinds);
  update_held_out_.clear();
  // The best of the sharpest view and the means that weigh every view alike; the sharp mean
  // where it beats them and the mean by kSharpMeanMarginDb a frame (where it hardly differs
  // from the mean, every view alike is the safer choice: on real photos the frames held out
  // tell the two apart by less than that, and the sharp one scored lower at views left out).
  size_t best = 0;
  for (size_t c = 1; c < n && measured > 0; ++c)
    if (kinds[c] != 3 && psnr_sum[c] > psnr_sum[best]) best = c;
  if (sharp && measured > 0 && psnr_sum[n - 1] > psnr_sum[best] &&
      psnr_sum[n - 1] > psnr_sum[1] + kSharpMeanMarginDb * measured)
    best = n - 1;
  const int chosen = kinds[best];
  update_auto_.frames_measured = measured;
  update_auto_.decided_at_frame = frames_seen_;
  // The chosen mean's gain, or where none won, the best one's shortfall.
  const double top =
      best > 0 ? psnr_sum[best] : *std::max_element(psnr_sum.begin() + 1, psnr_sum.end());
  update_auto_.evidence =
      measured > 0 ? (top - psnr_sum[0]) / measured : std::numeric_limits<double>::quiet_NaN();
  const bool mean = chosen > 0;
  update_auto_.state = mean ? AutoDecision::State::kOn : AutoDecision::State::kOff;
  if (chosen == 3) update_auto_.basis = "held_out_sharp";
  options_.update = chosen == 3 ? UpdatePolicy::kSharpMean
                    : mean      ? UpdatePolicy::kMean
                                : UpdatePolicy::kQuality;
  if (chosen == 2) TurnModelOffByFramesHeldOut((psnr_sum[best] - psnr_sum[1]) / measured, measured);
  // What every frame painted, the chosen way.
  ForEachBufferOf(painted_.size(), [&](size_t b) {
    PaintedBuffer& p = painted_[b];
    if (chosen == 3) p.mean_sum = p.sharp_sum;
    if (mean) {
      p.bgra = MeanTexels(p.bgra, p.mean_sum);
      cv::absdiff(p.quality, 0, p.quality);  // none provisional: every view counts
      // The mean paints texels the sharpest view had not (samples the model kept out): counted.
      const BaseBuffer& buffer = set_.buffers[b];
      int painted = 0;
      for (size_t k = 0; k < buffer.texel_index.size(); ++k)
        painted += buffer.on_surface[k] && p.bgra.ptr<cv::Vec4b>()[buffer.texel_index[k]][3] > 0;
      p.painted_surface_texels = painted;
    } else {
      p.mean_sum.release();
    }
    for (cv::Mat* m : {&p.unmasked_sum, &p.shadow_bgra, &p.shadow_quality, &p.held_sum,
                       &p.held_unmasked_sum, &p.sharp_sum, &p.held_sharp_sum})
      m->release();
  });
}

}  // namespace fresco
