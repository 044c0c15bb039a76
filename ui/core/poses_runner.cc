#include "ui/core/poses_runner.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>

#include "pipeline/core/atomic_file.h"
#include "pipeline/poses/colmap_log_progress.h"
#include "pipeline/poses/verify_report.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;

}  // namespace

PosesRunner::PosesRunner()
    : snapshot_(std::make_shared<PosesSnapshot>()), thread_([this] { Loop(); }) {}

PosesRunner::~PosesRunner() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    quit_ = true;
    queue_.clear();
    cancel_ = true;
    wake_.notify_one();
  }
  thread_.join();
}

void PosesRunner::Run(const PosesRequest& request) {
  std::lock_guard<std::mutex> lock(mutex_);
  cancel_ = true;  // the worker drops a run under way
  queue_.clear();  // only the newest request matters
  queue_.push_back(request);
  wake_.notify_one();
}

void PosesRunner::Cancel() {
  std::lock_guard<std::mutex> lock(mutex_);
  cancel_ = true;
  if (queue_.empty()) return;
  // A request the worker has not started yet ends here: its snapshot says it was cancelled
  // (a caller waiting for the request to finish must see it finish).
  auto cancelled = std::make_shared<PosesSnapshot>(*snapshot_);
  cancelled->version = snapshot_->version + 1;
  cancelled->has_request = true;
  cancelled->request = queue_.back();
  cancelled->busy = false;
  cancelled->status = "cancelled";
  snapshot_ = std::move(cancelled);
  queue_.clear();
}

void PosesRunner::WaitIdle() {
  std::unique_lock<std::mutex> lock(mutex_);
  idle_.wait(lock, [this] { return queue_.empty() && !busy_; });
}

std::shared_ptr<const PosesSnapshot> PosesRunner::Snapshot() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return snapshot_;
}

void PosesRunner::Publish() {
  ++working_.version;
  auto copy = std::make_shared<const PosesSnapshot>(working_);
  std::lock_guard<std::mutex> lock(mutex_);
  snapshot_ = std::move(copy);
}

void PosesRunner::Loop() {
  while (true) {
    PosesRequest request;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      busy_ = false;
      if (queue_.empty()) idle_.notify_all();
      wake_.wait(lock, [this] { return quit_ || !queue_.empty(); });
      if (quit_) return;
      request = std::move(queue_.front());
      queue_.pop_front();
      busy_ = true;
      cancel_ = false;
    }
    RunOnce(request);
    working_.busy = false;
    Publish();
  }
}

void PosesRunner::RunOnce(const PosesRequest& request) {
  // Versions only grow (a cancel of a queued request publishes one from another thread).
  const uint64_t version = std::max(working_.version, Snapshot()->version);
  working_ = PosesSnapshot();
  working_.version = version;
  working_.has_request = true;
  working_.request = request;
  working_.busy = true;
  working_.started = working_.step_started = std::chrono::steady_clock::now();
  working_.status = request.colmap.existing_model.empty()
                        ? std::string("preparing the frames")
                        : std::string("reading ") + request.colmap.existing_model;
  Publish();

  BootstrapOptions bootstrap = request.bootstrap;
  if (!request.control_points_file.empty()) {
    if (Status s = ReadControlPoints(request.control_points_file, &bootstrap.control_points);
        !s.ok()) {
      working_.status = std::string("error: ") + s.message();
      return;
    }
    bootstrap.control_file = request.control_points_file;
  }
  if (Status s = MakeDirectories(request.out_dir); !s.ok()) {
    working_.status = std::string("error: ") + s.message();
    return;
  }
  ProjectColmapOptions options = request.colmap;
  options.out_dir = (fs::path(request.out_dir) / "colmap").string();
  options.colmap.cancel = &cancel_;
  const std::string options_out_dir = options.out_dir;
  options.colmap.progress = [this, options_out_dir](const std::string& step, int index, int total) {
    working_.step = index + 1;
    working_.steps = total;
    working_.step_name = step;
    working_.step_started = std::chrono::steady_clock::now();
    const fs::path logs = fs::path(options_out_dir) / "logs";
    char prefix[16];
    std::snprintf(prefix, sizeof(prefix), "%02d_", index + 1);
    working_.step_log = (logs / (prefix + step + ".log")).string();
    if (index > 0 && working_.step_images == 0) {  // the feature extractor's count
      std::error_code ec;
      for (const auto& entry : fs::directory_iterator(logs, ec))
        if (entry.path().filename().string().rfind("01_", 0) == 0)
          working_.step_images =
              ReadColmapStepProgress(ReadFileTail(entry.path().string(), 4096), 0).total;
    }
    working_.status = std::string("colmap ") + std::to_string(index + 1) + "/" +
                      std::to_string(total) + ": " + step;
    Publish();
  };
  // Held by pointer: its frames point into its own capture and model.
  auto colmap = std::make_unique<ProjectColmap>();
  if (Status s = RunColmapOnProject(request.project, options, colmap.get()); !s.ok()) {
    working_.status = cancel_ ? "cancelled" : std::string("error: ") + s.message();
    return;
  }
  working_.reconstructed = true;
  working_.frames = static_cast<int>(colmap->frames.size());
  working_.registered = colmap->run.registered;
  working_.colmap_seconds = colmap->run.seconds;
  working_.step_seconds = colmap->run.step_seconds;
  working_.matcher = colmap->run.matcher;
  working_.frames_offered = colmap->run.frames_offered;
  working_.keyframes = colmap->run.keyframes;
  for (const ProjectColmapFrame& f : colmap->frames) working_.frame_index.push_back(f.index);

  // `fresco poses verify`: the table, verify.json and verify.png.
  Status s =
      VerifyPoses(VerifyInputs(*colmap), colmap->scene_size_m, request.verify, &working_.verify);
  if (s.ok()) {
    s = WriteVerifyReport(working_.verify, colmap->run,
                          (fs::path(request.out_dir) / "verify.json").string(),
                          (fs::path(request.out_dir) / "verify.png").string());
  }
  working_.verified = s.ok();
  if (!s.ok()) working_.verify_error = s.message();

  // `fresco poses bootstrap` from the same reconstruction.
  BootstrapResult result;
  s = BootstrapFromColmap(request.project, *colmap, bootstrap, &result);
  if (s.ok()) s = WriteBootstrap(request.project, *colmap, result, request.out_dir);
  working_.bootstrapped = s.ok();
  if (s.ok()) {
    working_.bootstrap_poses = BootstrapPosesPath(request.out_dir);
    working_.aligned_with = result.aligned_with;
    working_.bootstrap_inliers = result.inliers;
    working_.bootstrap_compared = result.compared;
    working_.bootstrap_comparison = result.comparison;
  } else {
    working_.bootstrap_error = s.message();
  }

  char line[200];
  std::snprintf(line, sizeof(line), "done: %d of %d frames registered", working_.registered,
                working_.frames);
  working_.status = line;
  std::snprintf(line, sizeof(line), " in %.1f s", working_.colmap_seconds);
  working_.status += request.colmap.existing_model.empty() ? line : " (earlier model)";
  if (working_.verified) {
    working_.status += ", " + std::to_string(working_.verify.flagged) + " flagged, " +
                       std::to_string(working_.verify.borderline) + " borderline";
  }
}

Status ApplyBootstrappedPoses(const PosesSnapshot& snap, AppState* state) {
  if (!snap.bootstrapped) return Status::Error("no bootstrapped poses to apply");
  if (!state->has_project) return Status::Error("no project open");
  if (fs::path(snap.request.project.file_path).lexically_normal() !=
      fs::path(state->project.file_path).lexically_normal()) {
    return Status::Error(std::string("the poses were bootstrapped for ") +
                         snap.request.project.file_path + ", not the open project " +
                         state->project.file_path);
  }
  state->BeginEdit();
  state->project.poses = snap.bootstrap_poses;
  state->message = std::string("poses: ") + snap.bootstrap_poses +
                   " (bootstrapped with COLMAP; undo restores the previous poses)";
  return Status::Ok();
}

}  // namespace fresco
