#include "pipeline/paint/painting_state.h"

namespace fresco {
namespace {

// Every image of each kind of per-buffer state, one list per kind: the state packs them. An
// image mostly equal to one before it (a shadow of the texels, the sums without the model)
// comes with that one, to be packed against (packed_image.h).
template <typename F>
void ForEachImage(PaintedBuffer& p, F f) {
  for (cv::Mat* m : {&p.bgra, &p.quality, &p.texel_kind, &p.mean_sum, &p.held_sum}) f(*m);
  f(p.unmasked_sum, &p.mean_sum), f(p.shadow_bgra, &p.bgra), f(p.shadow_quality, &p.quality);
  f(p.held_unmasked_sum, &p.held_sum), f(p.sharp_sum, &p.mean_sum),
      f(p.held_sharp_sum, &p.held_sum);
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
template <typename F>
void ForEachImage(std::vector<BufferBackground>& models, F f) {
  for (BufferBackground& model : models) model.ForEachArray(f);
}

// The arrays of a model as bytes to pack (a view, no copy), released once packed and filled
// back from their packing; images as they are.
cv::Mat BytesOf(const cv::Mat& image) { return image; }
template <typename T>
cv::Mat BytesOf(std::vector<T>& array) {
  if (array.empty()) return cv::Mat();
  return cv::Mat(1, static_cast<int>(array.size() * sizeof(T)), CV_8U, array.data());
}
void Release(cv::Mat& image) { image.release(); }
template <typename T>
void Release(std::vector<T>& array) {
  std::vector<T>().swap(array);
}
void Fill(const PackedImage& packed, cv::Mat& image, const cv::Mat* reference) {
  image = packed.Unpacked(reference);
}
template <typename T>
void Fill(const PackedImage& packed, std::vector<T>& array, const cv::Mat*) {
  array.resize(packed.raw_bytes() / sizeof(T));
  packed.CopyTo(array.data());
}

// Packs the images (and the models' arrays) of a state's lists (SaveState), each against the
// same image of the state saved before (`earlier`, null: none) to share its blocks, releasing
// them in the lists; Unpack (RestoreState) fills them back in the same order.
class ImagePacker {
 public:
  ImagePacker(PaintSession::State* state, const PaintSession::State* earlier)
      : state_(state), earlier_(earlier) {}

  // `to` = `from` with its images packed into the state, as the part `what`.
  template <typename T>
  void Pack(const char* what, const std::vector<T>& from, std::vector<T>* to) {
    *to = from;  // the images still shared
    PaintSession::State::Part part{what};
    for (T& item : *to) {
      ForEachImage(item, [&](auto& array, const cv::Mat* reference = nullptr) {
        const size_t i = state_->images.size();
        const bool has_earlier = earlier_ && i < earlier_->images.size();
        state_->images.emplace_back(BytesOf(array), has_earlier ? &earlier_->images[i] : nullptr,
                                    reference);
        part.raw += state_->images.back().raw_bytes();
        state_->images.back().ForEachBlock([&](const void*, size_t n) { part.held += n; });
      });
      ForEachImage(item, [](auto& array, const cv::Mat* = nullptr) { Release(array); });
    }
    state_->block_bytes += part.held;
    state_->bytes += part.held;
    state_->parts.push_back(part);
  }

 private:
  PaintSession::State* state_;
  const PaintSession::State* earlier_;
};

// `to` = `from` with its images unpacked from `state`, from its image `*next` on.
template <typename T>
void Unpack(const PaintSession::State& state, const std::vector<T>& from, std::vector<T>* to,
            size_t* next) {
  *to = from;
  for (T& item : *to)
    ForEachImage(item, [&](auto& array, const cv::Mat* reference = nullptr) {
      Fill(state.images[(*next)++], array, reference);
    });
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
  const std::shared_ptr<const State> earlier = last_saved_.lock();
  ImagePacker packer(&s, earlier.get());
  packer.Pack("painted buffers", painted_, &s.painted);
  packer.Pack("warped images", warped_, &s.warped);
  packer.Pack("movers warped", movers_warped_, &s.movers_warped);
  packer.Pack("mover texels", mover_texels_, &s.mover_texels);
  packer.Pack("agreed texels", agreed_texels_, &s.agreed_texels);
  packer.Pack("near-mover texels", near_mover_texels_, &s.near_mover_texels);
  packer.Pack("refine anchors", anchors_, &s.anchors);
  packer.Pack("view layers", layers_, &s.layers);
  packer.Pack("background frames", background_frame_, &s.background_frame);
  packer.Pack("background models", background_, &s.background);
  s.parts.push_back({"frames held out", bytes, bytes});
  s.frames_seen = frames_seen_;
  s.exposure_gain_sum = exposure_gain_sum_;
  s.exposure_offset_sum = exposure_offset_sum_;
  s.exposure_frames = exposure_frames_;
  s.frame_misalignment_px = frame_misalignment_px_;
  s.frame_explained_px = frame_explained_px_;
  s.bytes += bytes;
  last_saved_ = state;
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
  size_t next = 0;  // the state is restored from again: painting must not write into it
  Unpack(s, s.painted, &painted_, &next);
  Unpack(s, s.warped, &warped_, &next);
  Unpack(s, s.movers_warped, &movers_warped_, &next);
  Unpack(s, s.mover_texels, &mover_texels_, &next);
  Unpack(s, s.agreed_texels, &agreed_texels_, &next);
  Unpack(s, s.near_mover_texels, &near_mover_texels_, &next);
  Unpack(s, s.anchors, &anchors_, &next);
  Unpack(s, s.layers, &layers_, &next);
  Unpack(s, s.background_frame, &background_frame_, &next);
  Unpack(s, s.background, &background_, &next);
  frames_seen_ = s.frames_seen;
  exposure_gain_sum_ = s.exposure_gain_sum;
  exposure_offset_sum_ = s.exposure_offset_sum;
  exposure_frames_ = s.exposure_frames;
  frame_misalignment_px_ = s.frame_misalignment_px;
  frame_explained_px_ = s.frame_explained_px;
}

}  // namespace fresco
