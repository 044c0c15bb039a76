// The project file (docs/contract.md): which scene, camera, video and poses, plus every setting
// of the pipeline, with defaults that work. Parsing is strict: an unknown key, a wrong type
// or a bad value is an error naming the file and the JSON path of the field. Paths in the
// file are relative to the folder holding it; Project keeps them as written and resolves
// them on demand. Saving is atomic (temp file + rename) and load(save(p)) == p.
#pragma once

#include <string>
#include <vector>

#include "pipeline/core/status.h"
#include "pipeline/settings/pipeline_options.h"

namespace fresco {

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

// Live sources (pipeline/live/): a camera or stream as `video`, a pose feed
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

// The bytes of `options` that its listed fields hold (offset, size): what the project file
// reads and writes of it. A test checks that every other byte is padding, so that a member
// left out of its struct's Fields() list cannot go unnoticed.
std::vector<std::pair<size_t, size_t>> ListedFieldBytes(PipelineOptions* options);

// Ok when the project has one video stream; else an error "FILE: streams: N video streams,
// but WHO reads one (fresco run paints several)" for code that reads a single stream.
Status CheckOneStream(const Project& project, const std::string& who);

// True for names that are not files: URLs ("udp://...", "tcp://...") and "device:N".
bool IsUrlOrDevice(const std::string& path);

}  // namespace fresco
