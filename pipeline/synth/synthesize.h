// Synthetic captures: the paper's simulation experiment (§4, fig. 8), and the one test
// fixture every test builds on (like COLMAP's SynthesizeDataset). A scene (built in memory,
// see procedural_scenes.h, or loaded from glTF) is rendered along a camera path
// (camera_path.h) through a known lens; the true poses are kept while the given poses get
// optional noise; moving objects (movers.h) and exposure changes can be added. Everything
// can stay in memory (tests: SynthesizeCapture) or be streamed to a project folder that
// `fresco run` accepts as is (synth_writer.h: WriteSynthCapture).
//
// The steps, in order: PlanSynthCapture (camera, poses, noise, gains, movers: cheap, no
// pixels), then RenderSynthFrames (renders frame after frame, in order, into a sink).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "pipeline/core/camera.h"
#include "pipeline/core/poses.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/core/scene.h"
#include "pipeline/core/status.h"
#include "pipeline/synth/camera_path.h"
#include "pipeline/synth/movers.h"

namespace fresco {

struct SynthOptions {
  int frames = 60;
  int width = 640, height = 480;  // pixels
  // kPinhole, kOpenCV4, kOpenCV5 or kOpenCV8 (mild distortion, see MakeSynthCamera).
  LensModel lens = LensModel::kPinhole;
  double hfov_deg = 70.0;  // horizontal field of view of the pinhole part: gives fx

  // The camera path (camera_path.h, CameraPathOptions has the details of each field).
  CameraPathKind path = CameraPathKind::kHandheld;
  // orbit: the point looked at; handheld: the centre wandered around. World, metres.
  Eigen::Vector3d target = Eigen::Vector3d::Zero();
  double radius_m = 1.0;       // orbit radius; handheld: radius of the base circle
  double height_m = 0.0;       // orbit/handheld: world height (y) of the camera's circle
  double turns = 1.0;          // orbit: revolutions; handheld: turns of the circle and heading
  double start_deg = 0.0;      // angle of the first position on the circle (0 = +X, 90 = +Z)
  double wander_m = 0.2;       // handheld: RMS of the smooth random position wander
  double wobble_deg = 4.0;     // handheld/walk: RMS of the smooth look-direction shake
  bool look_at_target = true;  // handheld: look at `target`, or freely outwards
  double pitch_deg = 0.0;      // handheld (free look) and walk: mean pitch, + = up
  double tilt_deg = 0.0;       // handheld (free look): slow up/down sweep amplitude
  Eigen::Vector3d walk_from = Eigen::Vector3d(-1, 0, 0);  // walk: eye positions, world
  Eigen::Vector3d walk_to = Eigen::Vector3d(1, 0, 0);
  double look_around_deg = 20.0;                   // walk: amplitude of the glances left/right
  double bob_m = 0.02;                             // walk: vertical step bob
  Eigen::Vector3d eye = Eigen::Vector3d(0, 0, 1);  // fixed: the camera's position, world

  std::vector<MoverOptions> movers;  // explicit movers
  // Plus this many movers placed automatically (MakeRandomMovers) inside
  // [mover_region_min, mover_region_max] (world; both zero = the scene's bounds).
  int random_movers = 0;
  Eigen::Vector3d mover_region_min = Eigen::Vector3d::Zero();
  Eigen::Vector3d mover_region_max = Eigen::Vector3d::Zero();
  // Noise on the given poses (the true ones are kept): RMS rotation error in degrees
  // (random axis), and RMS camera-centre error in metres (random direction), independent
  // per frame.
  double pose_noise_deg = 0.0;
  double pose_noise_m = 0.0;
  // Exposure changes: per-frame gain on the rendered colours, gain = exp(g) where g has RMS
  // `exposure_jitter` (70 % of its variance a smooth drift, 30 % frame-to-frame flicker).
  // 0.1 gives gains of roughly ±10 %. Gains are clamped to [0.25, 4].
  double exposure_jitter = 0.0;
  int supersample = 2;  // N x N samples per pixel (1..4): anti-aliased frames
  cv::Vec3b background_rgb = cv::Vec3b(128, 128, 128);  // where no surface is seen
  unsigned seed = 1;
  int threads = 0;  // frames rendered in parallel; 0 = all cores

  Status Check() const;  // message names the field ("frames: must be >= 1")
  // The path fields above as CameraPathOptions, and back.
  CameraPathOptions PathOptions() const;
  void SetPathOptions(const CameraPathOptions& path_options);
};

// One camera of a multi-camera capture: its folder name, its settings (its own camera,
// path, frames, noise; the scene and the movers are shared) and its time offset as written
// in the project (tracker clock minus video clock).
struct SynthStream {
  std::string name;
  SynthOptions options;
  double time_offset_s = 0.0;
  // Frames per second, written into the project (frames are painted in time order); 0: not
  // given (every stream gives it or none does). The movers keep to one clock: a stream at
  // twice the first stream's rate sees them move half as far per frame.
  double fps = 0.0;
};

struct SynthCapture {
  Camera camera;
  std::vector<PosedImage> true_poses;   // cam_from_world, names "%06d.png", ids from 1
  std::vector<PosedImage> given_poses;  // the same with the pose noise
  std::vector<double> exposure_gains;   // per frame (1 without exposure changes)
  std::vector<MoverOptions> movers;     // explicit + automatically placed
  std::vector<cv::Mat> frames_bgr;      // CV_8UC3 (empty when streamed to disk)
};

// Frame file name for frame `index`: "000012.png".
std::string SynthFrameName(int index);

// Camera, true and given poses, exposure gains and movers; no rendering. Deterministic.
Status PlanSynthCapture(const Scene& scene, const SynthOptions& options, SynthCapture* plan);

// Renders the planned frames in order (frames in parallel on `options.threads` threads)
// and hands each to `sink(index, bgr)` in order; a failed Status from the sink stops it.
using SynthFrameSink = std::function<Status(int index, const cv::Mat& bgr)>;
Status RenderSynthFrames(const Scene& scene, const SynthOptions& options, const SynthCapture& plan,
                         const SynthFrameSink& sink);

// Plans and renders the whole capture in memory (frames_bgr filled).
Status SynthesizeCapture(const Scene& scene, const SynthOptions& options, SynthCapture* capture);

}  // namespace fresco
