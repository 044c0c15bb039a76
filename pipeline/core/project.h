// The project file (docs/contract.md): which scene, camera, video and poses, plus every setting
// of the pipeline, with defaults that work. Parsing is strict: an unknown key, a wrong type
// or a bad value is an error naming the file and the JSON path of the field. Paths in the
// file are relative to the folder holding it; Project keeps them as written and resolves
// them on demand. Saving is atomic (temp file + rename) and load(save(p)) == p.
#pragma once

#include <string>
#include <vector>

#include "pipeline/core/status.h"

namespace fresco {

enum class SamplingMode { kNearest, kBilinear, kArea };
// kLatest: every visible sample overwrites (the paper). kQuality: a sample overwrites only
// when it is at least (1 - quality_slack) as sharp (pixels per texel) as the stored one.
enum class UpdatePolicy { kLatest, kQuality };

struct OcclusionOptions {
  bool enabled = true;
  // A texel is visible when its depth is within this fraction of the rendered depth
  // (relative tolerance, scales with depth) plus `tolerance_m`.
  double tolerance_rel = 0.01;
  double tolerance_m = 0.002;
  // Texels seen at more than this angle from the surface normal are not painted.
  double max_view_angle_deg = 80.0;

  bool operator==(const OcclusionOptions&) const = default;
};

// Texture alignment refinement (paper §3.5, refine_alignment.h). kAuto: measures the
// misalignment between the first frames and the buffers without correcting, then refines
// (`robust`) for the rest of the capture only when it exceeds what perfect poses give
// (auto_modes.h).
enum class RefineMode { kOff, kPaper, kRobust, kAuto };
// The most general 2D motion model refinement may choose (model selection picks simpler
// ones when the evidence does not need more).
enum class RefineModelLimit { kTranslation, kSimilarity, kAffine, kHomography };
struct RefineOptions {
  RefineMode mode = RefineMode::kAuto;
  RefineModelLimit max_model = RefineModelLimit::kHomography;
  int max_corners = 150;           // corners tracked per buffer and frame
  int search_px = 12;              // largest correction looked for, texels (else: no correction)
  int window_px = 7;               // matching window half-size, texels
  int pyramid_levels = 3;          // coarse-to-fine levels (robust mode)
  double ransac_px = 1.5;          // inlier threshold, texels
  double max_scale_change = 0.05;  // a fit that scales or shears more is refused
  // Corrections smaller than this (largest displacement over the region, texels) are
  // measured but not applied: registration noise applied frame after frame random-walks
  // the buffer away from the model.
  double min_correction_px = 0.25;
  int min_inliers = 10;
  // Register every Nth frame only (1 = every frame); the others only fill texels the
  // buffers lack (unregistered, they would overwrite registered texels with their error).
  int every_n_frames = 1;
  // Consensus anchoring (refine_anchor.h): move a buffer back by the mean of the corrections
  // it asked for, once anchor_min_frames agree on a move larger than anchor_step_px texels.
  bool anchor = true;
  // Correct the frame's pose from the matches of every buffer together, and derive each
  // buffer's correction from it (refine_pose.h), instead of one homography per buffer.
  bool pose = true;
  int anchor_min_frames = 3;
  int anchor_window_frames = 100;  // samples fade with this time constant (0: never)
  double anchor_step_px = 0.1;

  bool operator==(const RefineOptions&) const = default;
};

// Selective painting (paper §3.4): a per-texel background model in base-buffer space (so it
// works for moving cameras); texels whose sample differs from it are foreground and are not
// painted. kAverage: the paper's linear average of each texel's first `training_frames`
// samples, then image subtraction with a fixed `average_threshold`. kRobust: two colour
// modes per texel with weights over a sliding window (background = the heavier mode, so
// it converges to what the texel shows most of the time, whatever came first), an adaptive
// per-texel noise threshold and a per-frame global gain (exposure) estimate. kAuto: the
// robust model learns from the start, and what it finds over the first frames decides
// whether it keeps masking or is dropped (auto_modes.h).
enum class BackgroundMode { kOff, kAverage, kRobust, kAuto };

struct BackgroundOptions {
  BackgroundMode mode = BackgroundMode::kAuto;
  // kAverage: samples averaged per texel before it segments (at most 250), and the
  // foreground threshold on the largest channel difference, grey levels.
  int training_frames = 20;
  double average_threshold = 30.0;
  // kRobust: a texel's samples before its model is trusted. Until then what it paints is
  // provisional (any later background sample replaces it, whatever its quality).
  int warmup_frames = 8;
  // kRobust: the learning window in samples: weights follow the last ~N samples, so an
  // object that stops for ~N/2 of them becomes background, and the background it hid comes
  // back ~N/2 samples after it leaves; lighting drift is followed too. Measured (README):
  // 40 beats 100 and 300 on the static-camera clips, where people stand for a long time.
  int window_frames = 40;
  // kRobust: foreground beyond `sigma_threshold` standard deviations of the texel's noise
  // (RMS over channels), the noise never counted below `min_sigma` grey levels.
  double sigma_threshold = 3.0;
  double min_sigma = 6.0;
  // kRobust: divide each frame by its global gain (median sample/background ratio).
  bool normalize_gain = true;
  // Mask cleaning (both models): foreground blobs smaller than this are background
  // (noise), and the rest is dilated by this margin (blurred edges, shadows).
  int min_blob_texels = 12;
  int dilate_texels = 2;

  bool operator==(const BackgroundOptions&) const = default;
};

// The painted model's texture atlas (pipeline/paint/texture_atlas.h): base buffers packed
// into pages of at most page_size x page_size texels, each with padding_texels of its edge
// repeated around it.
struct AtlasOptions {
  int page_size = 4096;
  int padding_texels = 4;

  bool operator==(const AtlasOptions&) const = default;
};

// View selection and colour consistency for real photos (pipeline/paint/view_select.h), the
// `select` stage between background and paint: per frame a gain per colour channel,
// estimated against what the buffers already hold (median ratio over the texels both have)
// and divided out before painting; a score per texel (pixels per texel times the cosine of
// the view angle, uncapped, blended with the frame's median score over the buffer so that a
// region keeps one frame), much lower where the texel is seen near a depth discontinuity of
// the frame's depth map (silhouettes: where a mesh a few pixels off paints background); a
// painted texel takes a new frame's sample only when it scores clearly better.
struct SelectOptions {
  bool enabled = false;  // off: the quality policy alone (`update`, `quality_slack`); on costs
                         // 2-4 times the warp stage (real photos: docs/results.md)
  bool exposure = true;  // divide out each frame's gain against the buffers
  double switch_margin = 0.25;  // a painted texel switches frame when the score is this much better
  double region_weight = 0.5;   // 0: the texel's own score; 1: the frame's median over the buffer
  double edge_px = 6.0;         // texels seen within this many pixels of a depth discontinuity
  double edge_penalty = 0.1;    // ... have their score multiplied by this
  double edge_depth_rel = 0.05;  // neighbouring pixels whose depths differ by this fraction

  bool operator==(const SelectOptions&) const = default;
};

struct PipelineOptions {
  SamplingMode sampling = SamplingMode::kBilinear;
  double texel_size_m = 0.0;            // base-buffer texel edge in metres; 0 = automatic
  int max_buffer_texels = 1024 * 1024;  // per base buffer; bigger groups get coarser texels
  int update_every = 1;  // paint every N-th frame (the paper used 20 with refinement)
  UpdatePolicy update = UpdatePolicy::kQuality;
  double quality_slack = 0.2;  // kQuality: accept samples this much blurrier than stored
  // Weight of an accepted sample against what the texel holds (1 = replace, the paper's;
  // below 1 = running average, which averages out the frames' residual misalignment).
  double update_weight = 1.0;
  int max_frames = 0;         // 0 = all frames
  int threads = 0;            // 0 = all cores
  bool debug_images = false;  // write per-stage debug images (costs time)
  OcclusionOptions occlusion;
  RefineOptions refine;
  BackgroundOptions background;
  AtlasOptions atlas;
  SelectOptions select;

  bool operator==(const PipelineOptions&) const = default;
};

// Automatic base-buffer grouping (paper §3.6): neighbouring triangles whose normals are
// within `angle_deg` of the group's seed normal share a buffer.
struct GroupingEdit {
  std::string op;  // "merge" | "split" | "move" | "texel" (see grouping.h)
  std::vector<int> triangles;
  std::vector<int> groups;
  int target_group = -1;
  double texel_size_m = 0.0;  // per-group override when > 0

  bool operator==(const GroupingEdit&) const = default;
};
// One base-buffer group as stored in the project: its triangles (indices into the scene's
// triangle list, in glTF order) and an optional texel size of its own.
struct GroupSpec {
  std::vector<int> triangles;
  double texel_size_m = 0.0;  // > 0 overrides the session's texel size for this group

  bool operator==(const GroupSpec&) const = default;
};
// The grouping: automatic (region growing with `angle_deg`) unless `groups` is given, in
// which case exactly those groups are used (triangles in none are never painted); `edits`
// then apply in order. `fresco group PROJECT.json --save` stores the automatic result.
//
// Charts (charts.h): a triangle joins a chart when its normal, smoothed over its neighbours,
// is within `angle_deg` of the chart's mean (a cone, so normal noise does not stop the
// growth), the triangle faces the chart's plane and the chart stays under the largest
// buffer's texels; then charts smaller than `min_chart_texels` are merged into a neighbour
// whose plane all their triangles face, with a mean texel stretch (1 / cos of the angle to
// the plane) of at most `max_stretch`. min_chart_texels = 0: the paper's grouping.
struct GroupingOptions {
  double angle_deg = 20.0;
  int min_chart_texels = 256;
  double max_stretch = 2.0;
  std::vector<GroupSpec> groups;
  std::vector<GroupingEdit> edits;

  bool operator==(const GroupingOptions&) const = default;
};

// Ground truth a synthetic capture carries (fresco synth); empty when unknown.
struct TruthFiles {
  std::string poses;  // true poses (same format as `poses`)

  bool operator==(const TruthFiles&) const = default;
};

// Live sources (issue 12; pipeline/live/): a camera or stream as `video`, a pose feed
// (tcp://, udp://, fifo://) as `poses`, matched by time. Ignored for files.
struct LiveOptions {
  // Frames waiting between the source and the painter; when painting is slower the oldest
  // waiting frame is dropped (newest wins) and counted.
  int queue_frames = 4;
  double open_timeout_s = 10.0;  // the video stream must start within this
  // No frame for this long: the stream has ended (after `reconnects` reopen attempts).
  double read_timeout_s = 3.0;
  int reconnects = 0;
  bool stream_clock = true;        // frame times from the stream's timestamps (else arrival)
  double connect_timeout_s = 5.0;  // the pose feed must accept the connection within this
  // A pose feed that drops is reconnected with backoff; no connection for this long (wall
  // seconds) ends it with an error (0: keep trying).
  double pose_reconnect_give_up_s = 60.0;
  double pose_wait_s = 0.5;     // a frame waits this long for the tracker to reach its time
  double max_pose_gap_s = 0.5;  // no pose is interpolated between samples further apart
  // A frame this far before the first pose or after the last still gets one, extrapolated.
  double max_pose_extrapolate_s = 0.02;
  // Estimate time_offset_s from the first frames (time_offset_estimation.h): candidates
  // within +-offset_search_s of time_offset_s, scored by how well the frames warped with
  // them agree with the buffers they paint.
  bool estimate_offset = false;
  double offset_search_s = 0.5;
  int offset_window_frames = 30;
  // Track the offset during the session: every offset_track_every_frames frames, estimate it
  // again on the last offset_window_frames frames, candidates within +-offset_track_search_s
  // of the offset in use; the new estimate replaces it only when its score is at least
  // offset_track_min_gain (a fraction) lower than the score of the offset in use on the same
  // frames.
  bool track_offset = false;
  int offset_track_every_frames = 30;
  double offset_track_search_s = 0.15;
  double offset_track_min_gain = 0.1;

  bool operator==(const LiveOptions&) const = default;
};

// One video stream of a version-2 project (`streams`): its own camera, video and poses, and
// its own time offset (tracker clock minus video clock), paths as written in the file.
struct StreamSpec {
  std::string camera;
  std::string video;
  std::string poses;
  double time_offset_s = 0.0;
  // Frames per second of a file video, > 0 on every stream: frames are painted in time order
  // (frame i of a stream at i / fps). 0 on any stream: in turn by frame index.
  double fps = 0.0;

  bool operator==(const StreamSpec&) const = default;
};

// Version 1 (`"fresco": 1`): one stream, as top-level `camera`, `video`, `poses` and
// `time_offset_s`; `streams` is not allowed. Version 2: a non-empty `streams` list and none
// of those four top-level keys (they stay empty here).
struct Project {
  int fresco_version = 1;
  std::string scene;  // as written in the file
  std::string camera;
  std::string video;
  std::string poses;
  double time_offset_s = 0.0;       // tracker clock minus video clock (live/TUM matching)
  std::vector<StreamSpec> streams;  // version 2 only
  PipelineOptions pipeline;
  GroupingOptions grouping;
  TruthFiles truth;
  LiveOptions live;

  std::string file_path;  // where it was loaded from / saved to (absolute)
  // Resolves a path as written in the project against the project file's folder.
  // Empty stays empty; absolute paths, URLs and "device:N" are returned as written.
  std::string Resolve(const std::string& relative) const;

  // The video streams, whatever the version: a version-1 file's one stream, or `streams`.
  std::vector<StreamSpec> Streams() const;
  // JSON path naming stream `index`'s key in messages: "camera" (version 1) or
  // "streams[1].camera" (version 2).
  std::string StreamKey(int index, const std::string& key) const;
  // A version-1 view of stream `index` (every other setting as here), for code that reads
  // one stream (LoadCapture, live inputs). `index` must be < Streams().size().
  Project ForStream(int index) const;

  // Every field, file_path included.
  bool operator==(const Project&) const = default;
};

// Reads and validates the JSON (not the referenced files: see LoadCapture). `overrides` are
// "KEY=VALUE" strings applied by JSON path before validation (`pipeline.sampling=nearest`).
// VALUE is parsed as JSON when it parses, otherwise taken as a string.
Status LoadProject(const std::string& path, const std::vector<std::string>& overrides,
                   Project* project);
// Parses a project from text; `name` is used in messages and for resolving paths.
Status ParseProject(const std::string& text, const std::string& name,
                    const std::vector<std::string>& overrides, Project* project);
// Writes the project atomically. Paths stay relative to the new location.
Status SaveProject(const Project& project, const std::string& path);
std::string ProjectToJsonText(const Project& project);

std::string SamplingModeName(SamplingMode mode);
std::string BackgroundModeName(BackgroundMode mode);  // "off" | "average" | "robust"
// Parses "nearest" | "bilinear" | "area". Returns false for other names.
bool SamplingModeFromName(const std::string& name, SamplingMode* mode);

// Ok when the project has one video stream; else an error "FILE: streams: N video streams,
// but WHO reads one (fresco run paints several)" for code that reads a single stream.
Status CheckOneStream(const Project& project, const std::string& who);

// True for names that are not files: URLs ("udp://...", "tcp://...") and "device:N".
bool IsUrlOrDevice(const std::string& path);

}  // namespace fresco
