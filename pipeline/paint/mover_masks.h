// Movers found across views: each frame of a capture compared, pixel by pixel, with the other
// frames near it in the capture (1, 2, 4, ... frames before and after), each warped onto it
// through the mesh (the surface point a pixel shows, projected into the other frame, where
// that frame's depth map says it sees it too). A pixel that differs from most of the frames
// that see its surface point shows something that is not the mesh: a mover, wherever it goes
// and however few times each texel is seen (the background model learns per texel, over many
// samples). The masks mark those pixels; the share of the pixels masked over a capture is the
// evidence background.mode `auto` decides on before painting a capture from files
// (auto_modes.h).
//
// Differences are judged against the other frame's 3 x 3 range around the point (a pixel's
// misalignment costs nothing), after a gain per colour channel between the two frames (over
// the pixels both see: exposure), on the largest channel. A large or slow mover matches the
// frames near it where they show it too: its blob grows over the pixels of its colours within
// its box, the regions of one colour the mask rings join it (ringed_regions.h), later passes
// judge again without the pixels the pass before masked in the other frames, and what they
// found is followed by its colours into the frames next to it (mover_follow.h). Frames are
// compared at a reduced size (max_side_px); masks have that size.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "pipeline/core/camera.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/core/scene.h"
#include "pipeline/core/status.h"
#include "pipeline/settings/background_options.h"
#include "pipeline/paint/ringed_regions.h"

namespace fresco {

struct MoverMaskOptions {
  std::vector<int> offsets = {1, 2, 4, 8, 16};  // frame i is compared with i -/+ each
  int max_side_px = 320;                        // frames are compared resized to this
  double difference = 30;  // grey levels beyond the other frame's 3 x 3 range (largest channel)
  double share = 0.5;      // a pixel differing from this share of the frames that see it ...
  int min_differing = 2;   // ... and from at least this many is a mover's
  double depth_tolerance = 0.03;  // relative: the other frame sees the point when its depth agrees
  int min_blob_px = 4;            // smaller flagged blobs are noise (at the reduced size)
  // Within each flagged blob's box, pixels of its colours join it (ColourSet, mover_follow.h),
  // except those that agree with every frame that sees them.
  bool grow = true;
  int dilate_px = 1;  // the rest grows by this margin (blurred edges)
  // Then the regions of one colour the mask rings join it (ringed_regions.h): a plain mover the
  // frames near it show over the same surface (large, slow, moving with the camera) differs from
  // them only at its edges. Not counted in the share masked (the evidence `auto` decides on: it
  // stays what the comparison found). `share` 0: none.
  RingedRegionOptions ringed;
  // Passes after the first judge each pixel again without the other frames' pixels the pass
  // before masked (they show a mover, not the background): a large or slow mover's inside, which
  // the frames near it show too, is found from its edges inwards, and the background beside a
  // mover is no longer masked for what a neighbour showed. The share masked (the evidence
  // background `auto` decides on) is the first pass's.
  int passes = 5;
  // ... only when the first pass found more than this share of the pixels judged in compact
  // regions (MoverMaskResult::compact; a caller that drops the masks below a threshold:
  // background `auto`).
  double later_passes_min_fraction = 0;
  // After the passes (where they run), the movers found are followed by their colours into the
  // frames up to this many frames away (FollowMovers, mover_follow.h; 0: not followed) ...
  int follow_frames = 6;
  // ... the regions the masks ring (`ringed`) first, into the frames up to this many away, over
  // any pixel of the surface, not only those a frame near differs from: a plain mover's inside
  // agrees with the frames near it, and where its ring is missed in a frame, so is its inside.
  // 0: not followed that way.
  int ringed_follow_frames = 2;
  // The first pass judges every second frame first; with later_passes_min_fraction set, where
  // those show in regions less than this share of it (and the capture has at least twice
  // half_min_frames frames), the others are not judged (their masks stay empty) and the masks
  // are not cleaned (left as the comparisons found them): the caller drops the masks anyway.
  // 0: every frame judged.
  double half_enough_below = 0.75;
  int half_min_frames = 12;
  // ... and before that, on a capture of at least four times half_min_frames frames, every
  // fourth frame: where those show in regions less than this share of it, the others are not
  // judged either (frames taken at even steps through the capture: a mover in a stretch of it
  // shows in them as in every second frame). 0: the half first.
  double quarter_enough_below = 0.5;
  // Each frame's depth rasterized at the camera's full size (sampled down to the reduced size:
  // each pixel takes the full-size sample nearest its centre, unprojected by that sample's
  // ray) and kept (MoverMaskResult::depths) for painting, whose depth stage takes it instead
  // of rasterizing the frame again: the mesh is rasterized once a frame, not twice (the cost
  // is mostly the triangles', whatever the size). Else rasterized at the reduced size.
  bool full_size_depth = false;
  // Called after each pass (optional): passes done, passes at most, a line for people.
  std::function<void(int done, int total, const std::string& line)> progress;
};

struct MoverMaskFrame {
  cv::Mat bgr;  // CV_8UC3, any size (resized to the camera's aspect at max_side_px)
  const Camera* camera = nullptr;
  Rigid3d cam_from_local;
};

// The values of a frame's mask as painting takes it (MoverMaskResult::Packed, Frame::movers):
// a mover's pixel, or a surface pixel that the frames near it that see its surface point agree
// with (at least one sees it and none differs, or at most one of four or more: it shows what
// the mesh there looks like).
inline constexpr uint8_t kMoverPixel = 255;
inline constexpr uint8_t kAgreedPixel = 128;

struct MoverMaskResult {
  std::vector<cv::Mat> masks;  // CV_8U, 255 = a mover's pixel; one per frame (empty: not judged)
  // CV_8U, 255 = a surface pixel not masked that the frames compared with it agree with (seen
  // by at least one of them and differing from none, or from at most one of four or more); one
  // per frame, as `masks`.
  std::vector<cv::Mat> agreed;
  std::string not_run;    // why nothing was looked for ("" when it ran)
  long long judged = 0;   // surface pixels seen by enough other frames to be judged
  long long flagged = 0;  // ... of which masked (after cleaning; see half_enough_below)
  // ... of which the comparison found in compact regions (first pass): what differs from most
  // of the frames near it, less every line narrower than 3 pixels (an opening by 3 x 3). A
  // mover is a region; a blurred frame, a slightly misaligned one, or the mesh's error at its
  // edges differs along the image's edges only (a real hand-held capture of a static scene,
  // TUM's teddy: 1.6 % of the pixels differ, 0.2 % in regions; the suites' captures without
  // movers 0.2 % and 0.00 %). The evidence background `auto` decides on.
  long long compact = 0;
  int frames_judged = 0;  // frames with a pixel judged (MoverMaskOptions::half_enough_below)
  // With MoverMaskOptions::full_size_depth: each frame's depth at its camera's full size
  // (CV_32F camera z, +inf off the surface, as Rasterizer::RasterizeDepth; empty where the
  // frame was not usable).
  std::vector<cv::Mat> depths;
  double seconds = 0;

  double fraction() const { return judged > 0 ? static_cast<double>(flagged) / judged : 0.0; }
  double compact_fraction() const {
    return judged > 0 ? static_cast<double>(compact) / judged : 0.0;
  }
  // Frame k's mask and agreed pixels in one image: kMoverPixel, kAgreedPixel, 0 elsewhere.
  cv::Mat Packed(size_t k) const;
};

Status FindMoverMasks(const TriangleMesh& mesh, const std::vector<MoverMaskFrame>& frames,
                      const MoverMaskOptions& options, MoverMaskResult* result);

// The options a capture painted with `background` looks for its movers with: the later passes
// only where the masks are kept (across_views) and, with `auto`, only when the first pass
// decides the model on (auto_modes.h).
MoverMaskOptions MoverMaskOptionsFor(const BackgroundOptions& background);

// The size frames of `camera` are compared at (its aspect, the longer side at most max_side_px).
cv::Size MoverMaskSize(const Camera& camera, const MoverMaskOptions& options);

}  // namespace fresco
