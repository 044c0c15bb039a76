#include "ui/core/calibration_runner.h"

#include <cstdio>
#include <filesystem>

#include "calib/camera_consistency.h"
#include "calib/pictures.h"
#include "calib/report.h"

namespace fresco {

CalibrationRunner::CalibrationRunner()
    : snapshot_(std::make_shared<CalibrationSnapshot>()), thread_([this] { Loop(); }) {}

CalibrationRunner::~CalibrationRunner() {
  cancel_ = true;
  Post(Command::kQuit);
  thread_.join();
}

void CalibrationRunner::Detect(const calib::CalibrateRequest& request) {
  cancel_ = true;  // the worker drops a detection under way
  Post(Command::kDetect, request);
}
void CalibrationRunner::Solve() {
  cancel_ = false;
  Post(Command::kSolve);
}
void CalibrationRunner::Cancel() { cancel_ = true; }
void CalibrationRunner::Save(const std::string& path) { Post(Command::kSave, {}, path); }
void CalibrationRunner::Exclude(const std::string& name, bool excluded) {
  Post(excluded ? Command::kExclude : Command::kInclude, {}, name);
}

void CalibrationRunner::Post(Command::Kind kind, const calib::CalibrateRequest& request,
                             const std::string& path) {
  Command command;
  command.kind = kind;
  command.request = request;
  command.path = path;
  std::lock_guard<std::mutex> lock(mutex_);
  queue_.push_back(std::move(command));
  wake_.notify_one();
}

void CalibrationRunner::WaitIdle() {
  std::unique_lock<std::mutex> lock(mutex_);
  idle_.wait(lock, [this] { return queue_.empty() && !busy_; });
}

std::shared_ptr<const CalibrationSnapshot> CalibrationRunner::Snapshot() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return snapshot_;
}

void CalibrationRunner::Publish() {
  ++working_.version;
  auto copy = std::make_shared<const CalibrationSnapshot>(working_);
  std::lock_guard<std::mutex> lock(mutex_);
  snapshot_ = std::move(copy);
}

void CalibrationRunner::Loop() {
  while (true) {
    Command command;
    bool superseded = false;  // only the newest detection matters
    {
      std::unique_lock<std::mutex> lock(mutex_);
      busy_ = false;
      if (queue_.empty()) idle_.notify_all();
      wake_.wait(lock, [this] { return !queue_.empty(); });
      command = std::move(queue_.front());
      queue_.pop_front();
      busy_ = true;
      for (const Command& later : queue_) superseded |= later.kind == Command::kDetect;
      if (command.kind == Command::kDetect && !superseded) cancel_ = false;
    }
    if (command.kind == Command::kQuit) return;
    if (command.kind == Command::kDetect && superseded) continue;
    working_.busy = true;
    if (command.kind == Command::kDetect) RunDetect(command.request);
    if (command.kind == Command::kSolve) RunSolve();
    if (command.kind == Command::kSave) RunSave(command.path);
    if (command.kind == Command::kExclude || command.kind == Command::kInclude)
      RunExclude(command.path, command.kind == Command::kExclude);
    working_.busy = false;
    Publish();
  }
}

void CalibrationRunner::UpdateReadiness() {
  const calib::CalibrationRun& run = working_.run;
  calib::CalibrationSeed seed;
  const bool seeded = working_.solved || (static_cast<int>(run.views.size()) >= calib::kMinViews &&
                                          calib::SeedCalibration(run.views, working_.request.board,
                                                                 run.width, run.height, &seed)
                                              .ok());
  // Until the split test has seen these views the light is not green: one doubt more.
  std::vector<std::string> doubts = run.camera_doubts;
  if (!cameras_checked_ && static_cast<int>(run.views.size()) >= calib::kMinViews)
    doubts.push_back(working_.images_done < static_cast<int>(working_.images.size())
                         ? "one camera? checked after the last image is detected"
                         : "one camera? being checked now");
  working_.readiness = calib::AssessReadiness(run.views, run.width, run.height,
                                              working_.solved ? &run.seed
                                              : seeded        ? &seed
                                                              : nullptr,
                                              doubts);
  if (!run.views.empty()) working_.coverage_picture = calib::DrawCoverage(run);
}

void CalibrationRunner::RunDetect(const calib::CalibrateRequest& request) {
  const uint64_t version = working_.version;
  working_ = CalibrationSnapshot();
  working_.version = version;
  working_.has_request = true;
  working_.request = request;
  working_.busy = true;
  cameras_checked_ = false;
  std::vector<std::string> paths;
  if (Status s = calib::ListImages(request.images_dir, &paths); !s.ok()) {
    working_.status = "error: " + s.message();
    return;
  }
  for (const std::string& path : paths) {
    CalibrationImage image;
    image.path = path;
    image.name = std::filesystem::path(path).filename().string();
    working_.images.push_back(image);
  }
  UpdateReadiness();
  for (CalibrationImage& image : working_.images) {
    working_.status = "detecting " + std::to_string(working_.images_done + 1) + "/" +
                      std::to_string(working_.images.size());
    Publish();
    if (cancel_) {  // a newer detection replaces this status, a Cancel keeps it
      working_.status = "cancelled: detection stopped after " +
                        std::to_string(working_.images_done) + " of " +
                        std::to_string(working_.images.size()) + " images";
      return;
    }
    image.excluded = calib::IsExcluded(image.name, request.exclude);
    const size_t views_before = working_.run.views.size();
    const bool found = calib::DetectImage(image.path, request, &working_.run);
    image.done = true;
    if (found) {
      image.corners = working_.run.views.back().corners;
      working_.run.views.resize(views_before);  // RebuildViews adds it back unless excluded
    } else {
      image.reason = working_.run.rejected.back().reason;
    }
    ++working_.images_done;
    RebuildViews();
    UpdateReadiness();
  }
  CheckOneCamera();
  UpdateReadiness();
  working_.status = "detected: board in " + std::to_string(working_.run.views.size()) + " of " +
                    std::to_string(working_.images.size()) + " images";
  if (!working_.run.excluded.empty())
    working_.status += " (" + std::to_string(working_.run.excluded.size()) + " excluded)";
}

void CalibrationRunner::CheckOneCamera() {
  working_.status =
      "checking that the " + std::to_string(working_.run.views.size()) + " images are one camera's";
  cameras_checked_ = false;
  UpdateReadiness();
  Publish();
  calib::CheckOneCameraBeforeSolving(working_.request, &working_.run);
  cameras_checked_ = true;
}

void CalibrationRunner::RebuildViews() {
  calib::CalibrationRun& run = working_.run;
  run.views.clear();
  run.excluded.clear();
  for (CalibrationImage& image : working_.images) {
    image.used = false;
    image.view = -1;
    if (image.excluded) {
      run.excluded.push_back(image.name);
      continue;
    }
    if (!image.done || !image.reason.empty()) continue;
    image.used = true;
    image.view = static_cast<int>(run.views.size());
    run.views.push_back({image.name, image.corners});
  }
}

void CalibrationRunner::RunExclude(const std::string& name, bool excluded) {
  for (CalibrationImage& image : working_.images)
    if (image.name == name) image.excluded = excluded;
  RebuildViews();
  if (working_.solved) {  // the solve was on other views: start its results over
    working_.solved = false;
    working_.run.choice = {};
    working_.run.warnings.clear();
    working_.residuals_picture = cv::Mat();
    working_.uncertainty_picture = cv::Mat();
  }
  bool more_queued = false;  // several images ticked in a row: check once, after the last
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const Command& later : queue_)
      more_queued |= later.kind == Command::kExclude || later.kind == Command::kInclude;
  }
  if (more_queued)
    cameras_checked_ = false;  // checked after the last one
  else
    CheckOneCamera();
  UpdateReadiness();
  working_.status = (excluded ? "excluded " : "included ") + name + ": " +
                    std::to_string(working_.run.views.size()) + " images used; solve again";
}

void CalibrationRunner::RunSolve() {
  if (!working_.has_request) return;
  working_.status = "solving (" + working_.request.model + ")";
  Publish();
  calib::CalibrationRun run = working_.run;  // detections kept if the solve fails
  run.choice = {};
  run.warnings.clear();
  calib::CalibrateRequest request = working_.request;
  struct Cancelled {};  // thrown from the progress call between two fits
  request.progress = [this](const std::string&, int done, int total, const std::string& what) {
    working_.solves_done = done;
    working_.solves_total = total;
    if (cancel_) throw Cancelled{};
    working_.status =
        "solving " + std::to_string(done + 1) + "/" + std::to_string(total) + ": " + what;
    Publish();
  };
  // A fit under way is abandoned too (it runs in a child process that Cancel kills).
  request.cancelled = [this] { return cancel_.load(); };
  working_.solving = true;
  working_.solves_done = working_.solves_total = 0;
  working_.solve_started = std::chrono::steady_clock::now();
  Status solved;
  try {
    solved = calib::SolveViews(request, &run);
    if (cancel_) throw Cancelled{};  // the last fit abandoned: its model failed, not chosen
  } catch (const Cancelled&) {
    working_.solving = false;
    working_.status = "cancelled: the solve stopped after " + std::to_string(working_.solves_done) +
                      " of " + std::to_string(working_.solves_total) +
                      " fits; the detections are kept";
    return;
  }
  working_.solving = false;
  if (!solved.ok()) {
    working_.status = "error: " + solved.message();
    return;
  }
  working_.run = std::move(run);
  working_.solved = true;
  cameras_checked_ = true;  // the solve ran the split test with the chosen model
  working_.residuals_picture = calib::DrawResiduals(working_.run);
  working_.uncertainty_picture = calib::DrawUncertainty(working_.run);
  UpdateReadiness();
  const calib::ModelTrial& chosen = working_.run.Chosen();
  char line[160];
  std::snprintf(line, sizeof(line), "solved: %s, rms %.3f px", chosen.short_name.c_str(),
                chosen.fit.rms_px);
  working_.status = line;
}

void CalibrationRunner::RunSave(const std::string& path) {
  if (!working_.solved) {
    working_.status = "error: solve before saving";
    return;
  }
  if (Status s = calib::WriteCalibrationOutputs(path, working_.request, working_.run, {});
      !s.ok()) {
    working_.status = "error: " + s.message();
    return;
  }
  working_.saved_path = path;
  working_.status = "saved " + path + " and " + calib::SiblingPath(path, ".report.json");
}

std::string DefaultCameraModelPath(const std::string& images_dir, const std::string& project_file) {
  namespace fs = std::filesystem;
  fs::path folder = fs::path(images_dir).lexically_normal();
  if (folder.filename().empty()) folder = folder.parent_path();  // "dir/" -> "dir"
  std::string name = folder.filename().string();
  if (name.empty() || name == "." || name == "..") name = "camera";
  const fs::path beside = project_file.empty() ? fs::absolute(folder).parent_path()
                                               : fs::path(project_file).parent_path();
  return (beside / (name + ".cameramodel")).string();
}

}  // namespace fresco
