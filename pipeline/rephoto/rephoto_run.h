// Virtual rephotography of a project's own frames (Waechter et al. 2017): each frame with a
// pose (or every N-th) is left out in turn, the model is painted from the others with the
// project's settings (the painting job, pipeline/run/), the painted model is rendered at the
// left-out frame's pose and compared with the frame: PSNR over the pixels where the painted
// surface is seen, local 1 - NCC (9 x 9 boxes, eroded mask), completeness. Behind
// `fresco rephoto`; needs no ground truth, so it scores real photos and videos.
//
//   RephotoOptions options;  options.every = 1;
//   RephotoResult result;
//   Status s = RunRephoto("project.json", options, &result);   // bad input: names file, field
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "pipeline/core/status.h"
#include "pipeline/paint/stage_report.h"

namespace fresco {

struct RephotoOptions {
  std::vector<std::string> overrides;  // project settings "KEY=VALUE" (as `fresco run --set`)
  // Leave out every `every`-th frame with a pose (the first, then every N-th after it), one
  // paint run each; 1: each frame.
  int every = 1;
  // Progress: (cases done, total, a line about the case just finished or started).
  std::function<void(int done, int total, const std::string& line)> progress;
  // Checked between frames; true stops the run with an error ("interrupted").
  std::function<bool()> stop;
  Status Check() const;
};

// One left-out frame.
struct RephotoFrame {
  std::string name;           // the frame's name (its pose's name)
  int counter = 0;            // position among the frames read (all streams), 0-based
  int stream = 0;             // index into Project::Streams()
  int frames_painted = 0;     // frames painted from (the others)
  int view_layers = 0;        // view-dependent layers the render blended (pipeline.layers)
  double paint_seconds = 0;   // wall time of that paint run (reading and painting)
  AutoDecisions decisions;    // what that run's `auto` modes decided
  double psnr_db = 0;         // over the compared pixels (NaN: none)
  double one_minus_ncc = 1;   // local 9 x 9, eroded mask (1 when nothing compared)
  double completeness = 0;    // surface pixels of the view that are painted
  double image_coverage = 0;  // compared pixels / image pixels
  long long pixels = 0;       // compared pixels
};

struct RephotoResult {
  std::string project;               // the project file as given
  int frames_read = 0;               // frames of the project read (all streams)
  int frames_posed = 0;              // ... with a pose
  std::vector<RephotoFrame> frames;  // the left-out frames, in order
};

// Called once per left-out frame with its figures, the render (black where not painted)
// and the frame itself (both CV_8UC3, the camera's size); an error stops the run.
using RephotoViewSink = std::function<Status(const RephotoFrame& frame, const cv::Mat& rendered_bgr,
                                             const cv::Mat& photo_bgr)>;

// Loads the project (with the overrides), finds its frames with poses and scores each
// left-out frame. Errors: bad input naming the file and field (a live project, fewer than 2
// frames with poses, what the painting job refuses), or "interrupted".
Status RunRephoto(const std::string& project_path, const RephotoOptions& options,
                  const RephotoViewSink& sink, RephotoResult* result);

}  // namespace fresco
