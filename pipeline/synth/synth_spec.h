// What to synthesize, from a JSON spec file and/or the command line: the scene (a built-in
// procedural scene or a glTF, PLY or OBJ file) and every SynthOptions setting, with defaults that
// fit the scene (a hand-held walk inside the room, a walk down the street, an orbit around an
// object). Parsing is strict: an unknown key, a wrong type or a bad value is an error that
// names the spec file and the field.
//
// Spec file (every key optional except "scene"; relative paths resolve against the spec
// file's folder):
//   {
//     "fresco_synth": 1,                      // format version (optional)
//     "scene": "builtin:cube-room" | "builtin:street" | "builtin:plane" | "builtin:cube"
//              | "builtin:blocks"
//              | "PATH.gltf"
//              | {"builtin": "cube-room", "size_m": [4, 3, 4], "seed": 1,
//                 "textures": {"floor": "a.jpg", ...}, "repeat": {"floor": [2, 2], ...}}
//              | {"builtin": "street", "length_m": 40, "street_width_m": 10,
//                 "buildings_per_side": 5, "min_height_m": 6, "max_height_m": 14, "seed": 1}
//              | {"builtin": "plane", "width_m": 2, "height_m": 2, "texture": "img.png"}
//              | {"builtin": "cube", "edge_m": 1, "texture": "img.png"}
//              | {"builtin": "blocks", "ground_m": 6, "blocks": 7, "area_m": 3,
//                 "min_size_m": 0.4, "max_size_m": 1.1, "max_height_m": 1.6,
//                 "texels_per_m": 160, "seed": 1},
//     "mesh": {"subdivide": 1, "noise_m": 0, "seed": 1},  // large noisy meshes (mesh_refine.h)
//     "out": "capture",                       // output folder
//     "frames": 120, "size": [640, 480] (or "640x480"), "lens": "pinhole" | "opencv4" |
//     "opencv5" | "opencv8", "hfov_deg": 70,
//     "path": {"kind": "orbit" | "walk" | "handheld", "target": [x, y, z], "radius_m",
//              "height_m", "turns", "start_deg", "wander_m", "wobble_deg", "look_at_target",
//              "pitch_deg", "tilt_deg", "walk_from": [..], "walk_to": [..], "look_around_deg",
//              "bob_m"},
//     "movers": [{"shape": "sphere" | "box", "radius_m", "rgb": [r, g, b], "start": [..],
//                 "end": [..], "period_frames", "phase", "spin_deg_per_frame"}],
//     "random_movers": 2, "mover_region": {"min": [..], "max": [..]},
//     "pose_noise_deg": 0, "pose_noise_m": 0, "exposure": 0,
//     "supersample": 2, "background_rgb": [128, 128, 128], "seed": 1, "threads": 0,
//     "streams": [{"name": "fixed", "path": {"kind": "fixed", "eye": [..], "target": [..]},
//                  "frames", "size", "lens", "hfov_deg", "pose_noise_deg", "pose_noise_m",
//                  "exposure", "supersample", "seed", "time_offset_s", "fps"}, ...]
//   }
// "streams" makes a multi-camera capture: each entry starts from the settings above and
// overrides them (a path with a "kind" starts from the scene's defaults for that kind);
// scene, movers and background are shared. Path kind "fixed": a still camera at "eye"
// (default: where the path's circle starts) looking at "target".
#pragma once

#include <string>
#include <vector>

#include "pipeline/core/scene.h"
#include "pipeline/core/status.h"
#include "pipeline/synth/synthesize.h"

namespace fresco {

// One setting given on top of the spec (command line): a dotted JSON path ("frames",
// "path.kind") and its value, parsed as JSON when it parses (and `as_string` is false),
// otherwise taken as a string.
struct SynthSpecOverride {
  std::string key;
  std::string value;
  bool as_string = false;
};

struct SynthSpecInput {
  std::string text = "{}";                   // the spec's JSON text
  std::string name = "command line";         // the spec file, for messages
  std::string base_dir = ".";                // relative paths in the spec resolve against it
  std::vector<SynthSpecOverride> overrides;  // paths in overrides should be absolute
};

struct SynthJob {
  Scene scene;
  std::string scene_source;  // "builtin:cube-room", ... or the scene file
  // Per scene texture: the image file it was made from (absolute), "" when procedural or
  // loaded from glTF. ExportSynthScene points the written glTF at these files.
  std::vector<std::string> texture_files;
  SynthOptions options;  // the spec's settings (one stream), the streams' defaults
  // "streams": one entry per camera (synth_writer.h: WriteSynthStreams); empty for a spec
  // without them (one camera, `options`).
  std::vector<SynthStream> streams;
  std::string out_dir;  // resolved; "" when neither the spec nor an override gives one
  std::string name;     // the spec's name, for messages
};

// Builds the scene and options. Errors: "NAME: FIELD: what is wrong".
Status BuildSynthJob(const SynthSpecInput& input, SynthJob* job);
// Reads SPEC.json and builds the job (base_dir = the spec's folder).
Status LoadSynthJob(const std::string& spec_path, const std::vector<SynthSpecOverride>& overrides,
                    SynthJob* job);

// Every setting of `options` as canonical JSON text (sorted keys, the spec's field names).
std::string SynthOptionsToJson(const SynthOptions& options);

}  // namespace fresco
