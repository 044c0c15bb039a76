// `fresco synth`: makes a synthetic capture (frames, poses, camera, truth) from a built-in or
// glTF scene, the paper's simulation experiment. Settings come from a spec file, the
// command line, or both (the command line wins).
#include <cstdio>
#include <filesystem>
#include <iostream>

#include "app/commands.h"
#include "app/interrupt.h"
#include "app/progress.h"
#include "pipeline/synth/synth_spec.h"
#include "pipeline/synth/synth_writer.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;

const char* kVerb = "synth";

ArgSpec SynthArgSpec() {
  ArgSpec spec;
  spec.usage = "fresco synth [SPEC.json] [--scene SCENE] [--out DIR] [OPTIONS...]";
  spec.help =
      "Options: [--frames N] [--size WxH] [--lens pinhole|opencv4|opencv5|opencv8] [--hfov DEG]\n"
      "  [--path orbit|walk|handheld] [--movers N] [--pose-noise-deg X] [--pose-noise-m Y]\n"
      "  [--exposure J] [--supersample N] [--seed S] [--threads N] [--set KEY=VALUE ...]\n"
      "  [--if-changed] [--scene-only]\n"
      "\n"
      "Renders a synthetic capture of a scene along a camera path (the paper's simulation\n"
      "experiment) and writes it as a project folder that `fresco run DIR/project.json`\n"
      "accepts as is:\n"
      "  DIR/frames/000000.png ...  DIR/camera.cameramodel  DIR/sparse/{cameras,images}.txt\n"
      "  (given poses)  DIR/truth/images.txt (true poses)  DIR/truth/exposure.txt\n"
      "  DIR/truth/movers.json  DIR/scene.gltf (without movers)  DIR/synth.json\n"
      "  DIR/project.json\n"
      "A spec with \"streams\" (several cameras, e.g. a fixed one and a hand-held one) writes\n"
      "  each stream's files in DIR/NAME/ and a project listing the streams; options below\n"
      "  set every stream's defaults.\n"
      "The same scene and settings (and seed) give the same files. Ctrl-C (or SIGTERM) while\n"
      "rendering stops, keeps DIR's earlier capture (or none) and exits 130 (143).\n"
      "\n"
      "  SPEC.json           settings file (see pipeline/synth/synth_spec.h); relative paths\n"
      "                      in it resolve against its folder; options below override it\n"
      "  --scene SCENE       builtin:cube-room (4x3x4 m room, the paper's fig. 8),\n"
      "                      builtin:street (facades and a street), builtin:plane,\n"
      "                      builtin:cube, builtin:blocks (boxes on a ground, for\n"
      "                      COLMAP), or a scene file (.gltf/.glb, .ply, .obj)\n"
      "  --out DIR           output folder (default: the spec's \"out\")\n"
      "  --frames N          number of frames (default 60)\n"
      "  --size WxH          image size in pixels (default 640x480)\n"
      "  --lens L            pinhole (default), or opencv4/opencv5/opencv8 with mild\n"
      "                      barrel distortion\n"
      "  --hfov DEG          horizontal field of view (default 70): fx = W/2 / tan(hfov/2)\n"
      "  --path P            orbit, walk, handheld or fixed (default: handheld in the\n"
      "                      room, walk down the street, orbit around other scenes); its\n"
      "                      geometry fits the scene, tune it with --set path.radius_m=...\n"
      "                      (fixed: a still camera at path.eye looking at path.target)\n"
      "  --movers N          add N moving coloured spheres/boxes (in frames only, never in\n"
      "                      the written scene)\n"
      "  --pose-noise-deg X  RMS rotation error of the given poses, degrees (default 0)\n"
      "  --pose-noise-m Y    RMS camera-position error of the given poses, metres (default 0)\n"
      "  --exposure J        RMS of the log exposure gain per frame (0.1 = about +-10 %)\n"
      "  --supersample N     N x N samples per pixel, 1..4 (default 2)\n"
      "  --seed S            random seed for the path, noise, movers (default 1)\n"
      "  --threads N         frames rendered in parallel (default 0 = all cores)\n"
      "  --set KEY=VALUE     any spec setting by its JSON path, e.g. --set path.turns=2,\n"
      "                      --set background_rgb=[0,0,0]\n"
      "  --if-changed        do nothing when DIR already holds a complete capture of the\n"
      "                      same scene and settings\n"
      "  --scene-only        write only DIR/scene.gltf (textures made from image files keep\n"
      "                      pointing at those files)\n"
      "\n"
      "Examples:\n"
      "  fresco synth projects/cube-room/synth.json --if-changed\n"
      "  fresco synth --scene builtin:street --out /tmp/street --frames 90 --movers 2 \\\n"
      "      --pose-noise-deg 0.3 --pose-noise-m 0.03";
  spec.min_positional = 0;
  spec.max_positional = 1;
  spec.options = {"--scene",        "--out",         "--frames", "--size",
                  "--lens",         "--hfov",        "--path",   "--movers",
                  "--exposure",     "--supersample", "--seed",   "--pose-noise-deg",
                  "--pose-noise-m", "--threads"};
  spec.repeatable = {"--set"};
  spec.switches = {"--if-changed", "--scene-only"};
  return spec;
}

std::string Absolute(const std::string& path) {
  return fs::absolute(fs::path(path)).lexically_normal().string();
}

// Command-line settings become overrides of the spec, checked here first so that errors
// name the option. Returns "" or what is wrong.
std::string ParseOverrides(const Args& args, std::vector<SynthSpecOverride>* overrides) {
  std::string error;
  struct NumberOption {
    const char* option;
    const char* key;
    bool integer;
  };
  static const NumberOption kNumbers[] = {{"--frames", "frames", true},
                                          {"--hfov", "hfov_deg", false},
                                          {"--movers", "random_movers", true},
                                          {"--pose-noise-deg", "pose_noise_deg", false},
                                          {"--pose-noise-m", "pose_noise_m", false},
                                          {"--exposure", "exposure", false},
                                          {"--supersample", "supersample", true},
                                          {"--seed", "seed", true},
                                          {"--threads", "threads", true}};
  for (const NumberOption& n : kNumbers) {
    if (!args.Has(n.option)) continue;
    const std::string text = args.Get(n.option);
    if (n.integer) {
      int value = 0;
      if (!ParseInt(text, n.option, &value, &error)) return error;
    } else {
      double value = 0;
      if (!ParseDouble(text, n.option, &value, &error)) return error;
    }
    overrides->push_back({n.key, text, false});
  }
  if (args.Has("--size")) overrides->push_back({"size", args.Get("--size"), true});
  if (args.Has("--lens")) overrides->push_back({"lens", args.Get("--lens"), true});
  if (args.Has("--path")) overrides->push_back({"path.kind", args.Get("--path"), true});
  if (args.Has("--scene")) {
    std::string scene = args.Get("--scene");
    if (scene.rfind("builtin:", 0) != 0) scene = Absolute(scene);
    overrides->push_back({"scene", scene, true});
  }
  for (const std::string& set : args.All("--set")) {
    const size_t eq = set.find('=');
    if (eq == std::string::npos || eq == 0) return "--set: '" + set + "' is not KEY=VALUE";
    overrides->push_back({set.substr(0, eq), set.substr(eq + 1), false});
  }
  return "";
}

// --scene-only: the scene alone, as DIR/scene.gltf.
int ExportSceneOnly(const SynthJob& job, const std::string& out) {
  const std::string gltf = (fs::path(out) / "scene.gltf").string();
  const Status status = ExportSynthScene(job.scene, job.texture_files, gltf);
  if (!status.ok()) return Fail(status);
  std::cout << "wrote " << gltf << " (" << job.scene.mesh.NumTriangles() << " triangles, "
            << job.scene.textures.size() << " textures) from " << job.scene_source << "\n";
  return kExitOk;
}

// What was written, stream by stream, and how to run it.
void PrintWritten(const SynthJob& job, const std::string& out, const SynthWriteResult& result) {
  if (job.streams.empty()) {
    std::cout << "wrote " << out << ": " << result.frames << " frames " << job.options.width << "x"
              << job.options.height << " of " << job.scene_source << "\n";
  } else {
    std::cout << "wrote " << out << ": " << job.streams.size() << " streams of " << job.scene_source
              << "\n";
    for (const SynthStream& stream : job.streams) {
      const SynthOptions& o = stream.options;
      std::cout << "  " << stream.name << "/: " << o.frames << " frames " << o.width << "x"
                << o.height << ", " << CameraPathKindName(o.path) << " path\n";
    }
  }
  std::cout << "run it: fresco run " << (fs::path(out) / "project.json").string() << " --out OUT\n";
}

// Renders and writes the capture (every stream) to `out`; returns the exit code.
int WriteCapture(const SynthJob& job, const std::string& out, bool if_changed) {
  SynthWriteOptions write_options;
  write_options.skip_if_current = if_changed;
  write_options.scene_source = job.scene_source;
  int total_frames = job.streams.empty() ? job.options.frames : 0;
  for (const SynthStream& stream : job.streams) total_frames += stream.options.frames;
  Progress progress("synth", total_frames);
  int frames_written = 0;
  write_options.progress = [&](int done, int total) {
    frames_written = done;
    progress.Update(done);
  };
  write_options.stop = [] { return Interrupted(); };
  SynthWriteResult result;
  InterruptCatcher interrupt;
  const Status status =
      job.streams.empty() ? WriteSynthCapture(job.scene, job.options, out, write_options, &result)
                          : WriteSynthStreams(job.scene, job.streams, out, write_options, &result);
  if (Interrupted() && !status.ok()) {
    progress.Clear();
    std::fprintf(stderr,
                 "fresco synth: interrupted by %s after %d of %d frames; %s keeps its earlier "
                 "capture, if any (nothing of this one was kept)\n",
                 InterruptSignalName().c_str(), frames_written, total_frames, out.c_str());
    return InterruptExitCode();
  }
  if (!status.ok()) return Fail(status);
  if (result.skipped) {
    std::cout << "synth: " << out << " is current (" << result.frames << " frames, fingerprint "
              << result.fingerprint << "): nothing to do\n";
    return kExitOk;
  }
  progress.Finish();
  PrintWritten(job, out, result);
  if (Interrupted()) {  // after the frames: the capture was finished first
    std::fprintf(stderr, "fresco synth: interrupted by %s while writing; finished %s first\n",
                 InterruptSignalName().c_str(), out.c_str());
    return InterruptExitCode();
  }
  return kExitOk;
}

}  // namespace

int RunVerbSynth(const CommandArgs& argv) {
  const ArgSpec spec = SynthArgSpec();
  Args args;
  if (int code = ParseVerbArgs(kVerb, argv, spec, &args); code >= 0) return code;
  std::vector<SynthSpecOverride> overrides;
  if (const std::string error = ParseOverrides(args, &overrides); !error.empty())
    return UsageError(kVerb, spec, error);

  SynthJob job;
  Status status;
  if (!args.positional.empty()) {
    status = LoadSynthJob(args.positional[0], overrides, &job);
  } else {
    if (!args.Has("--scene")) {
      return UsageError(kVerb, spec, "missing --scene (or a SPEC.json)");
    }
    SynthSpecInput input;
    input.overrides = overrides;
    status = BuildSynthJob(input, &job);
  }
  if (!status.ok()) return Fail(status);
  const std::string out = args.Has("--out") ? Absolute(args.Get("--out")) : job.out_dir;
  if (out.empty()) return UsageError(kVerb, spec, "missing --out (or \"out\" in the spec)");
  if (args.Switch("--scene-only")) return ExportSceneOnly(job, out);
  return WriteCapture(job, out, args.Switch("--if-changed"));
}

}  // namespace fresco
