// Which painted texels took their colour from a moving object, followed frame by frame (a
// synthetic capture knows where its movers were). Per painted frame: the pixels that show a
// mover (the movers rasterized at the frame's TRUE pose, one pixel of margin for the
// anti-aliased edges) are warped into every buffer the way the painter maps that frame (its
// GIVEN pose, the same depth test), and every texel the frame wrote takes the frame's flag.
// At the end each painted texel says whether its colour came from a mover: the exact
// "painted-mover fraction", in texel space (Figures) and, rendered as a texture
// (MaskImages), in any view.
//
// `update: mean` rewrites a texel with every sample, so which sample came last says nothing
// there: each sample's weight in the texel's sums (PaintedBuffer::mean_sum, and
// unmasked_sum while `update: auto` decides) is followed instead, and a texel shows a mover
// where movers are kMoverShare or more of the weight its mean holds.
//
// A texel the refinement's anchoring moved counts as written by that frame (its flag is the
// frame's, not carried along): only captures with refinement on are affected.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "pipeline/core/camera.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/core/scene.h"
#include "pipeline/paint/paint_session.h"
#include "pipeline/render/rasterizer.h"
#include "pipeline/synth/movers.h"

namespace fresco {

class MoverProvenance {
 public:
  // `world_scene`: the static scene the frames were rendered from (world coordinates);
  // `painted_scene`: the scene the session paints (its local origin); `camera`: the frames'.
  MoverProvenance(const Scene& world_scene, const std::vector<MoverOptions>& movers,
                  const Scene& painted_scene, const Camera& camera, const PaintSession& session);

  // Around PaintSession::PaintFrame of frame `frame` (the synth plan's index).
  void BeforeFrame(const PaintSession& session);
  void AfterFrame(const PaintSession& session, int frame, const Rigid3d& true_cam_from_world,
                  const Rigid3d& given_cam_from_world);

  struct Figures {
    long long painted = 0;        // on-surface texels painted
    long long painted_mover = 0;  // ... whose colour came from a mover
    // ... of which seen with a mover on them at least as often as without: no per-texel
    // model can tell those.
    long long mover_dominated = 0;
    long long open = 0;          // on-surface texels seen at least once with no mover on them
    long long open_painted = 0;  // ... that are painted
    // Why the texels painted from a mover were (painted_mover, split four ways):
    long long mover_never_open = 0;     // never seen without a mover: nothing else to paint
    long long mover_open_masked = 0;    // each sample without a mover was kept out of painting
    long long mover_open_passed = 0;    // ... not kept out, not taken (the texel kept a sample
                                        // it preferred, a mover's or one later replaced by it)
    long long mover_open_replaced = 0;  // one was painted, then a mover's replaced it
    double mover_fraction() const { return painted > 0 ? double(painted_mover) / painted : 0.0; }
    double open_coverage() const { return open > 0 ? double(open_painted) / open : 0.0; }
  };
  Figures Count(const PaintSession& session) const;

  // Per buffer, CV_8UC4 of the buffer's size: white where the stored sample came from a
  // mover, black elsewhere, alpha as painted (for PaintSession::PaintedScene(images)).
  std::vector<cv::Mat> MaskImages(const PaintSession& session) const;

 private:
  const Scene& painted_scene_;
  const Camera& camera_;
  MoverScene movers_;
  Rasterizer raster_;
  NormalizedBounds bounds_;
  std::vector<cv::Mat> before_;  // painted BGRA before the frame
  // Per buffer: does the stored sample show a mover; how often the texel was seen with and
  // without a mover on it; whether a sample without a mover was painted, and whether one was
  // neither painted nor kept out of painting.
  std::vector<cv::Mat> shows_mover_, n_mover_, n_open_, open_written_, open_passed_;
  // `update: mean`: per buffer, the weight of a sums' samples that showed a mover and of all
  // (CV_32FC2), for mean_sum and unmasked_sum; their weights before the frame (CV_32F).
  struct MeanShares {
    std::vector<cv::Mat> shares, before;
  };
  MeanShares mean_, unmasked_, sharp_;  // sharp_: PaintedBuffer::sharp_sum
  bool deciding_before_ = false, model_before_ = false;
  bool ShowsMover(const PaintSession& session, size_t b, int idx) const;
};

}  // namespace fresco
