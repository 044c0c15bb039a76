// Exposure stage (pipeline.select.exposure; runs after refine, before background): a frame's
// colour transform against what the base buffers already hold, per channel sample = gain *
// stored + offset (a gain for exposure, an offset for haze and flare), undone on its warped
// samples before they are compared and painted. Photos of one scene taken with different
// exposures (or auto-exposure in a video) then paint one consistent texture at the buffers'
// exposure, which the first frames set; the painted scene is exported at the frames' mean
// transform (PaintSession::PaintedScene). The transform is fitted robustly (median ratio,
// then least squares weighted by Tukey's biweight) to the frame's and the buffers' values over
// the texels both have: movers and misregistered texels are a minority and weigh nothing. Estimated
// against the buffers every frame, it does not drift or flicker from frame to frame.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "pipeline/paint/base_buffer.h"
#include "pipeline/paint/frame_warp.h"
#include "pipeline/paint/paint_update.h"

namespace fresco {

struct ExposureGain {
  cv::Vec3d gain = cv::Vec3d(1, 1, 1);    // B, G, R: sample = gain * stored + offset
  cv::Vec3d offset = cv::Vec3d(0, 0, 0);  // levels (0..255)
  int samples = 0;                        // texels in common it was fitted to
  bool applied = false;                   // false: too few texels in common (identity)
};

struct ExposureOptions {
  int min_samples = 500;                   // fewer texels in common: no correction
  int max_samples = 40000;                 // texels sampled at most (evenly spread)
  double min_gain = 0.25, max_gain = 4.0;  // clamp
  double max_offset = 96;                  // levels, clamp
};

// The frame's transform against the buffers in `seen` (indices into the vectors).
ExposureGain EstimateExposureGain(const std::vector<BaseBuffer>& buffers,
                                  const std::vector<WarpedBuffer>& warped,
                                  const std::vector<PaintedBuffer>& painted,
                                  const std::vector<size_t>& seen,
                                  const ExposureOptions& options = ExposureOptions());

// Undoes the transform on the valid samples of the buffers in `seen` (rounded, saturated).
void ApplyExposureGain(const ExposureGain& gain, const std::vector<size_t>& seen,
                       std::vector<WarpedBuffer>* warped);

}  // namespace fresco
