#include "pipeline/synth/synthesize.h"

#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <exception>
#include <map>
#include <memory>
#include <mutex>
#include <thread>

#include <opencv2/imgproc.hpp>

#include "pipeline/render/renderer.h"
#include "pipeline/synth/random.h"

namespace fresco {
namespace {

constexpr double kRadiansPerDegree = M_PI / 180.0;

RenderOptions MakeRenderOptions(const SynthOptions& options) {
  RenderOptions r;
  r.raster.supersample = options.supersample;
  r.filter = TextureFilter::kBilinear;
  r.background = cv::Vec4b(options.background_rgb[0], options.background_rgb[1],
                           options.background_rgb[2], 255);
  return r;
}

// Renders frames of one plan: owns a scene copy with the movers (moved per frame); the
// renderer (thread-safe) is shared.
class FrameRenderer {
 public:
  FrameRenderer(const Scene& scene, const Renderer& renderer, const SynthCapture& plan)
      : scene_(scene, plan.movers), renderer_(renderer), plan_(plan) {}

  void Render(int index, cv::Mat* bgr) {
    scene_.SetFrame(index);
    RenderOutput output;
    renderer_.Render(scene_.scene(), plan_.true_poses[index].cam_from_world, &output);
    cv::cvtColor(output.rgba, *bgr, cv::COLOR_RGBA2BGR);
    const double gain = plan_.exposure_gains[index];
    if (gain != 1.0) bgr->convertTo(*bgr, CV_8U, gain);
  }

 private:
  MoverScene scene_;
  const Renderer& renderer_;
  const SynthCapture& plan_;
};

}  // namespace

Status SynthOptions::Check() const {
  if (frames < 1 || frames > 1000000) return Status::Error("frames: must be in [1, 1000000]");
  Camera camera;
  FRESCO_RETURN_IF_ERROR(MakeSynthCamera(lens, width, height, hfov_deg, &camera));
  FRESCO_RETURN_IF_ERROR(PathOptions().Check());
  for (size_t m = 0; m < movers.size(); ++m) {
    FRESCO_RETURN_IF_ERROR(movers[m].Check("movers[" + std::to_string(m) + "]"));
  }
  if (random_movers < 0 || random_movers > 100) {
    return Status::Error("random_movers: must be in [0, 100]");
  }
  if (!mover_region_min.allFinite() || !mover_region_max.allFinite()) {
    return Status::Error("mover_region: not finite");
  }
  if (!std::isfinite(pose_noise_deg) || pose_noise_deg < 0 || pose_noise_deg > 90) {
    return Status::Error("pose_noise_deg: must be in [0, 90]");
  }
  if (!std::isfinite(pose_noise_m) || pose_noise_m < 0) {
    return Status::Error("pose_noise_m: must be >= 0");
  }
  if (!std::isfinite(exposure_jitter) || exposure_jitter < 0 || exposure_jitter > 1) {
    return Status::Error("exposure: must be in [0, 1]");
  }
  if (supersample < 1 || supersample > 4) return Status::Error("supersample: must be in [1, 4]");
  if (threads < 0 || threads > 256) return Status::Error("threads: must be in [0, 256]");
  return Status::Ok();
}

CameraPathOptions SynthOptions::PathOptions() const {
  CameraPathOptions p;
  p.kind = path;
  p.target = target;
  p.radius_m = radius_m;
  p.height_m = height_m;
  p.turns = turns;
  p.start_deg = start_deg;
  p.wander_m = wander_m;
  p.wobble_deg = wobble_deg;
  p.look_at_target = look_at_target;
  p.pitch_deg = pitch_deg;
  p.tilt_deg = tilt_deg;
  p.walk_from = walk_from;
  p.walk_to = walk_to;
  p.look_around_deg = look_around_deg;
  p.bob_m = bob_m;
  p.eye = eye;
  return p;
}

void SynthOptions::SetPathOptions(const CameraPathOptions& p) {
  path = p.kind;
  target = p.target;
  radius_m = p.radius_m;
  height_m = p.height_m;
  turns = p.turns;
  start_deg = p.start_deg;
  wander_m = p.wander_m;
  wobble_deg = p.wobble_deg;
  look_at_target = p.look_at_target;
  pitch_deg = p.pitch_deg;
  tilt_deg = p.tilt_deg;
  walk_from = p.walk_from;
  walk_to = p.walk_to;
  look_around_deg = p.look_around_deg;
  bob_m = p.bob_m;
  eye = p.eye;
}

std::string SynthFrameName(int index) {
  char name[32];
  std::snprintf(name, sizeof(name), "%06d.png", index);
  return name;
}

Status PlanSynthCapture(const Scene& scene, const SynthOptions& options, SynthCapture* plan) {
  FRESCO_RETURN_IF_ERROR(options.Check());
  *plan = SynthCapture();
  FRESCO_RETURN_IF_ERROR(MakeSynthCamera(options.lens, options.width, options.height,
                                         options.hfov_deg, &plan->camera));

  // True poses along the path.
  const std::vector<Rigid3d> path =
      MakeCameraPath(options.PathOptions(), options.frames, options.seed);
  for (int i = 0; i < options.frames; ++i) {
    PosedImage image;
    image.image_id = i + 1;
    image.camera_id = 1;
    image.name = SynthFrameName(i);
    image.cam_from_world = path[i];
    plan->true_poses.push_back(image);
  }

  // Given poses: rotation noise about a random axis (per-axis sigma so that the RMS angle is
  // pose_noise_deg), camera-centre noise in a random direction (RMS pose_noise_m).
  SynthRandom pose_random(options.seed, 21);
  const double sigma_r = options.pose_noise_deg * kRadiansPerDegree / std::sqrt(3.0);
  const double sigma_t = options.pose_noise_m / std::sqrt(3.0);
  for (const PosedImage& truth : plan->true_poses) {
    PosedImage given = truth;
    const Eigen::Vector3d r(pose_random.Normal(), pose_random.Normal(), pose_random.Normal());
    const Eigen::Vector3d dc(pose_random.Normal(), pose_random.Normal(), pose_random.Normal());
    if (options.pose_noise_deg > 0 || options.pose_noise_m > 0) {
      const Eigen::Quaterniond q =
          (Rigid3d::QuaternionFromAxisAngle(sigma_r * r) * truth.cam_from_world.rotation)
              .normalized();
      const Eigen::Vector3d centre = truth.cam_from_world.Centre() + sigma_t * dc;
      given.cam_from_world = Rigid3d(q, -(q * centre));
    }
    plan->given_poses.push_back(given);
  }

  // Exposure gains.
  SynthRandom gain_random(options.seed, 31);
  const SmoothNoise drift(&gain_random, 0.2, 1.0);
  for (int i = 0; i < options.frames; ++i) {
    const double flicker = gain_random.Normal();
    double g =
        options.exposure_jitter * (std::sqrt(0.7) * drift(i / 60.0) + std::sqrt(0.3) * flicker);
    plan->exposure_gains.push_back(options.exposure_jitter > 0 ? std::clamp(std::exp(g), 0.25, 4.0)
                                                               : 1.0);
  }

  // Movers: explicit, then placed automatically in the region (default: the scene bounds).
  plan->movers = options.movers;
  if (options.random_movers > 0) {
    RandomMoverOptions random;
    random.count = options.random_movers;
    random.seed = options.seed;
    random.region_min = options.mover_region_min;
    random.region_max = options.mover_region_max;
    if (random.region_min.isZero() && random.region_max.isZero()) {
      scene.Bounds(&random.region_min, &random.region_max);
      random.region_min = scene.WorldFromLocal(random.region_min);
      random.region_max = scene.WorldFromLocal(random.region_max);
    }
    const std::vector<MoverOptions> placed = MakeRandomMovers(random, plan->camera, path);
    plan->movers.insert(plan->movers.end(), placed.begin(), placed.end());
  }
  return Status::Ok();
}

Status RenderSynthFrames(const Scene& scene, const SynthOptions& options, const SynthCapture& plan,
                         const SynthFrameSink& sink) {
  const int frames = static_cast<int>(plan.true_poses.size());
  if (frames == 0) return Status::Ok();
  if (static_cast<int>(plan.exposure_gains.size()) != frames) {
    return Status::Internal("synth: plan has " + std::to_string(plan.exposure_gains.size()) +
                            " gains for " + std::to_string(frames) + " frames");
  }
  int threads =
      options.threads > 0 ? options.threads : static_cast<int>(std::thread::hardware_concurrency());
  threads = std::clamp(threads, 1, frames);
  const Renderer renderer(plan.camera, MakeRenderOptions(options));

  if (threads == 1) {
    FrameRenderer frame_renderer(scene, renderer, plan);
    for (int i = 0; i < frames; ++i) {
      cv::Mat bgr;
      frame_renderer.Render(i, &bgr);
      FRESCO_RETURN_IF_ERROR(sink(i, bgr));
    }
    return Status::Ok();
  }

  // Workers render frames in any order; this thread hands them to the sink in order. At most
  // `window` frames wait in memory.
  const int window = 2 * threads;
  std::mutex mutex;
  std::condition_variable changed;
  std::map<int, cv::Mat> ready;
  int next_to_render = 0, next_to_emit = 0;
  bool stop = false;
  // The first exception of any thread (out of memory): it stops every thread and is
  // rethrown here once they are joined, never ending the process from a worker.
  std::exception_ptr failure;
  const auto fail = [&](std::exception_ptr e) {
    {
      std::lock_guard<std::mutex> lock(mutex);
      if (!failure) failure = e;
      stop = true;
    }
    changed.notify_all();
  };
  std::vector<std::thread> workers;
  for (int t = 0; t < threads; ++t) {
    workers.emplace_back([&] {
      try {
        FrameRenderer frame_renderer(scene, renderer, plan);
        while (true) {
          int index;
          {
            std::unique_lock<std::mutex> lock(mutex);
            changed.wait(lock, [&] { return stop || next_to_render < next_to_emit + window; });
            if (stop || next_to_render >= frames) return;
            index = next_to_render++;
          }
          cv::Mat bgr;
          frame_renderer.Render(index, &bgr);
          {
            std::lock_guard<std::mutex> lock(mutex);
            ready[index] = std::move(bgr);
          }
          changed.notify_all();
        }
      } catch (...) {
        fail(std::current_exception());
      }
    });
  }
  Status status;
  try {
    while (next_to_emit < frames) {
      cv::Mat bgr;
      {
        std::unique_lock<std::mutex> lock(mutex);
        changed.wait(lock, [&] { return failure || ready.count(next_to_emit) > 0; });
        if (failure) break;
        bgr = std::move(ready[next_to_emit]);
        ready.erase(next_to_emit);
      }
      status = sink(next_to_emit, bgr);
      {
        std::lock_guard<std::mutex> lock(mutex);
        ++next_to_emit;
        if (!status.ok()) stop = true;
      }
      changed.notify_all();
      if (!status.ok()) break;
    }
  } catch (...) {
    fail(std::current_exception());
  }
  {
    std::lock_guard<std::mutex> lock(mutex);
    stop = true;
  }
  changed.notify_all();
  for (std::thread& w : workers) w.join();
  if (failure) std::rethrow_exception(failure);
  return status;
}

Status SynthesizeCapture(const Scene& scene, const SynthOptions& options, SynthCapture* capture) {
  FRESCO_RETURN_IF_ERROR(PlanSynthCapture(scene, options, capture));
  capture->frames_bgr.assign(capture->true_poses.size(), cv::Mat());
  return RenderSynthFrames(scene, options, *capture, [&](int index, const cv::Mat& bgr) {
    capture->frames_bgr[index] = bgr;
    return Status::Ok();
  });
}

}  // namespace fresco
