// Writes a synthetic capture as a project folder that `fresco run DIR/project.json` accepts
// as is. Frames are rendered and written one at a time (memory does not grow with the
// capture's length) into a staging folder that replaces DIR/frames/ only once every frame
// is written (StagedFolder); every file is written atomically, and project.json last, so a
// folder with a project.json is complete, and a write that fails or is stopped while
// rendering leaves the earlier capture as it was.
//
//   DIR/frames/000000.png ...        the video (8-bit sRGB)
//   DIR/camera.cameramodel           the lens (mrcal)
//   DIR/sparse/cameras.txt           the lens again (COLMAP: PINHOLE, OPENCV or FULL_OPENCV)
//   DIR/sparse/images.txt            the given poses (with the requested noise), names =
//                                    frame files; sparse/points3D.txt is empty
//   DIR/truth/images.txt             the true poses (+ truth/cameras.txt, points3D.txt)
//   DIR/truth/exposure.txt           per frame: NAME GAIN
//   DIR/truth/movers.json            the moving objects and their centre at every frame
//   DIR/scene.gltf (+ .bin, PNGs)    the static scene, without the movers
//   DIR/synth.json                   every setting used
//   DIR/synth_stamp.txt              fingerprint of scene + settings (see skip_if_current)
//   DIR/project.json                 fresco 1, scene, camera, video, poses, truth.poses
//
// DIR/frames/ belongs to the capture: it is replaced whole (the frames of an earlier, longer
// capture would be read as video, and any other file in it goes too).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "pipeline/core/scene.h"
#include "pipeline/core/status.h"
#include "pipeline/synth/synthesize.h"

namespace fresco {

struct SynthWriteOptions {
  // Called after each frame is written: (frames written, total frames).
  std::function<void(int done, int total)> progress;
  // Checked before each frame is written; when it returns true the write stops with an
  // error, the earlier capture in DIR (if any) untouched (e.g. Ctrl-C).
  std::function<bool()> stop;
  // When DIR already holds a complete capture of the same scene and settings (same
  // fingerprint in synth_stamp.txt, and project.json present), write nothing.
  bool skip_if_current = false;
  // Where the written scene came from, recorded in synth.json ("builtin:cube-room", a path).
  std::string scene_source;
};

struct SynthWriteResult {
  bool skipped = false;     // skip_if_current found the capture current
  std::string fingerprint;  // hex
  int frames = 0;
};

Status WriteSynthCapture(const Scene& scene, const SynthOptions& options, const std::string& dir,
                         const SynthWriteOptions& write_options,
                         SynthWriteResult* result = nullptr);

// A multi-camera capture: each stream in DIR/NAME/ (frames/, camera.cameramodel, sparse/,
// truth/ as above), the scene, synth.json (each stream's settings) and a version-2
// DIR/project.json listing the streams (NAME/camera.cameramodel, NAME/frames/,
// NAME/sparse/images.txt, the stream's time offset and fps); true poses are in
// NAME/truth/images.txt.
// The first stream's movers (explicit and placed) are every stream's movers: frame i of
// every stream shows them where they are at frame i. All frames are rendered before anything
// of an earlier capture in DIR is replaced. result->frames counts every stream's frames.
Status WriteSynthStreams(const Scene& scene, const std::vector<SynthStream>& streams,
                         const std::string& dir, const SynthWriteOptions& write_options,
                         SynthWriteResult* result = nullptr);

// The streams as written: `resolved` are the streams with the first stream's movers given to
// every other one, `plans` their planned captures (PlanSynthCapture). Errors name the stream
// ("streams[1].frames: ...").
Status PlanSynthStreams(const Scene& scene, const std::vector<SynthStream>& streams,
                        std::vector<SynthStream>* resolved, std::vector<SynthCapture>* plans);

// A 64-bit fingerprint (16 hex digits) of the scene's content (geometry, UVs, materials,
// texture pixels), every setting that changes the output (not `threads`), the planned
// camera, poses, gains and movers, and the rendered pixels of frame 0: a change to the code
// that makes any of them changes it too. "" for invalid options.
std::string SynthFingerprint(const Scene& scene, const SynthOptions& options);

// Writes just the scene as glTF (SaveGltfScene). Where `texture_files[i]` names the image file
// scene texture i was made from, the glTF points at that file (relative to the glTF's
// folder) instead of a re-encoded PNG copy: bundled scenes keep their small JPEGs.
Status ExportSynthScene(const Scene& scene, const std::vector<std::string>& texture_files,
                        const std::string& gltf_path);

}  // namespace fresco
