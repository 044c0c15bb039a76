#include "pipeline/paint/painting_state.h"

namespace fresco {
namespace {

// Every image of each kind of per-buffer state, one list per kind: the copy clones them and
// counts their bytes.
template <typename F>
void ForEachImage(PaintedBuffer& p, F f) {
  for (cv::Mat* m : {&p.bgra, &p.quality, &p.texel_kind, &p.mean_sum, &p.unmasked_sum,
                     &p.shadow_bgra, &p.shadow_quality, &p.held_sum, &p.held_unmasked_sum})
    f(*m);
}
template <typename F>
void ForEachImage(WarpedBuffer& w, F f) {
  for (cv::Mat* m : {&w.bgr, &w.valid, &w.quality}) f(*m);
}
template <typename F>
void ForEachImage(RefineAnchor& a, F f) {
  for (cv::Mat* m : {&a.sum, &a.count, &a.background_pending, &a.surface}) f(*m);
}
template <typename F>
void ForEachImage(BackgroundFrame& b, F f) {
  for (cv::Mat* m : {&b.foreground, &b.warming, &b.kept_out, &b.difference}) f(*m);
}
template <typename F>
void ForEachImage(cv::Mat& m, F f) {
  f(m);
}
template <typename F>
void ForEachImage(ViewLayer& layer, F f) {
  for (PaintedBuffer& p : layer.painted) ForEachImage(p, f);
}

// Copies `from` into `to` with every image cloned; adds the images' bytes to `bytes`.
template <typename T>
void DeepCopy(const std::vector<T>& from, std::vector<T>* to, size_t* bytes) {
  *to = from;  // the images still shared
  for (T& item : *to)
    ForEachImage(item, [bytes](cv::Mat& m) {
      m = m.clone();
      *bytes += m.total() * m.elemSize();
    });
}

void DeepCopy(const std::vector<std::vector<BufferBackground>>& from,
              std::vector<std::vector<BufferBackground>>* to, size_t* bytes) {
  to->assign(from.size(), {});
  for (size_t s = 0; s < from.size(); ++s)
    for (const BufferBackground& model : from[s]) {
      (*to)[s].push_back(model.Clone());
      *bytes += model.Bytes();
    }
}

}  // namespace

std::shared_ptr<const PaintSession::State> PaintSession::SaveState() const {
  auto state = std::make_shared<State>();
  State& s = *state;
  size_t bytes = 0;
  s.options = options_;
  s.update_auto = update_auto_;
  s.update_held_out = update_held_out_;
  for (HeldOutFrame& frame : s.update_held_out) {
    frame.bgr = frame.bgr.clone(), frame.movers = frame.movers.clone();
    bytes +=
        frame.bgr.total() * frame.bgr.elemSize() + frame.movers.total() * frame.movers.elemSize();
  }
  s.model_decided_early = model_decided_early_;
  s.refine_auto = refine_auto_;
  s.background_auto = background_auto_;
  s.background_across_views = background_across_views_;
  s.own_only = own_only_.load();
  s.frames_painted_whole = frames_painted_whole_;
  DeepCopy(painted_, &s.painted, &bytes);
  DeepCopy(warped_, &s.warped, &bytes);
  DeepCopy(movers_warped_, &s.movers_warped, &bytes);
  DeepCopy(mover_texels_, &s.mover_texels, &bytes);
  DeepCopy(agreed_texels_, &s.agreed_texels, &bytes);
  DeepCopy(near_mover_texels_, &s.near_mover_texels, &bytes);
  DeepCopy(anchors_, &s.anchors, &bytes);
  DeepCopy(layers_, &s.layers, &bytes);
  DeepCopy(background_, &s.background, &bytes);
  DeepCopy(background_frame_, &s.background_frame, &bytes);
  s.frames_seen = frames_seen_;
  s.exposure_gain_sum = exposure_gain_sum_;
  s.exposure_offset_sum = exposure_offset_sum_;
  s.exposure_frames = exposure_frames_;
  s.frame_misalignment_px = frame_misalignment_px_;
  s.frame_explained_px = frame_explained_px_;
  s.bytes = bytes;
  return state;
}

void PaintSession::RestoreState(const State& s) {
  const bool debug_images = options_.debug_images;  // the client's, not the state's
  options_ = s.options;
  options_.debug_images = debug_images;
  update_auto_ = s.update_auto;
  update_held_out_ = s.update_held_out;
  for (HeldOutFrame& frame : update_held_out_)
    frame.bgr = frame.bgr.clone(), frame.movers = frame.movers.clone();
  model_decided_early_ = s.model_decided_early;
  refine_auto_ = s.refine_auto;
  background_auto_ = s.background_auto;
  background_across_views_ = s.background_across_views;
  own_only_.store(s.own_only);
  frames_painted_whole_ = s.frames_painted_whole;
  size_t bytes = 0;  // the state is restored from again: painting must not write into it
  DeepCopy(s.painted, &painted_, &bytes);
  DeepCopy(s.warped, &warped_, &bytes);
  DeepCopy(s.movers_warped, &movers_warped_, &bytes);
  DeepCopy(s.mover_texels, &mover_texels_, &bytes);
  DeepCopy(s.agreed_texels, &agreed_texels_, &bytes);
  DeepCopy(s.near_mover_texels, &near_mover_texels_, &bytes);
  DeepCopy(s.anchors, &anchors_, &bytes);
  DeepCopy(s.layers, &layers_, &bytes);
  DeepCopy(s.background, &background_, &bytes);
  DeepCopy(s.background_frame, &background_frame_, &bytes);
  frames_seen_ = s.frames_seen;
  exposure_gain_sum_ = s.exposure_gain_sum;
  exposure_offset_sum_ = s.exposure_offset_sum;
  exposure_frames_ = s.exposure_frames;
  frame_misalignment_px_ = s.frame_misalignment_px;
  frame_explained_px_ = s.frame_explained_px;
}

}  // namespace fresco
