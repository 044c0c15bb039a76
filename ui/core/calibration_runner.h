// The app's calibration worker: on its own thread, lists the images of a folder and detects
// the board image by image (a snapshot after each, so the panel's "enough data yet?" light
// follows the detections), solves on request (calib::SolveViews) and saves the .cameramodel,
// report and pictures with the CLI's code (calib::WriteCalibrationOutputs). Headless.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <opencv2/core.hpp>

#include "calib/calibrate.h"
#include "ui/core/camera_attach.h"  // AttachCameraToProject

namespace fresco {

struct CalibrationImage {
  std::string path, name;
  bool done = false;  // detection ran
  bool used = false;  // the board was found and the image is not excluded: run.views[view]
  int view = -1;
  std::string reason;     // why rejected
  bool excluded = false;  // the operator's checkbox (or the request's exclude patterns)
  std::vector<calib::CornerObservation> corners;  // the detection, kept while excluded
};

struct CalibrationSnapshot {
  uint64_t version = 0;  // increases with every publish
  std::string status;    // "", "detecting 3/13", "detected", "solving", "solved", "error: ..."
  bool busy = false;
  bool has_request = false;
  calib::CalibrateRequest request;
  std::vector<CalibrationImage> images;  // by name, as listed
  int images_done = 0;
  calib::CalibrationRun run;  // views and rejected; after a solve, everything
  bool solved = false;
  calib::DataReadiness readiness;
  cv::Mat coverage_picture;     // every detection so far
  cv::Mat residuals_picture;    // after a solve
  cv::Mat uncertainty_picture;  // after a solve: projection uncertainty map
  std::string saved_path;       // the last .cameramodel written
  // A solve under way: its fits finished of all it will make, and when it started (the panel
  // shows elapsed and remaining time from these).
  bool solving = false;
  int solves_done = 0, solves_total = 0;
  std::chrono::steady_clock::time_point solve_started;
};

class CalibrationRunner {
 public:
  CalibrationRunner();
  ~CalibrationRunner();

  // Starts over on this folder and board (a detection under way stops after its image).
  void Detect(const calib::CalibrateRequest& request);
  void Solve();  // on the views detected so far, with the request's model
  // Stops a detection or solve under way: a detection after its image, a solve within about
  // 0.1 s, mid-fit too (each fit runs in a child process, killed). The detections are kept,
  // an earlier solve's results too; nothing is written. Status "cancelled: ...".
  void Cancel();
  // Leaves image `name` out of (or puts it back into) the views; an earlier solve is stale.
  void Exclude(const std::string& name, bool excluded);
  void Save(const std::string& cameramodel_path);
  void WaitIdle();  // tests, --screenshot
  std::shared_ptr<const CalibrationSnapshot> Snapshot() const;

 private:
  struct Command {
    enum Kind { kDetect, kSolve, kSave, kExclude, kInclude, kQuit } kind = kQuit;
    calib::CalibrateRequest request;
    std::string path;  // kSave: the file; kExclude / kInclude: the image name
  };
  void Post(Command::Kind kind, const calib::CalibrateRequest& request = {},
            const std::string& path = "");
  void Loop();
  void RunDetect(const calib::CalibrateRequest& request);
  void RunSolve();
  void RunSave(const std::string& path);
  void RunExclude(const std::string& name, bool excluded);
  void RebuildViews();  // run.views from the images used and not excluded
  void UpdateReadiness();
  // The split test before any solve (calib::CheckOneCameraBeforeSolving): a folder mixing two
  // cameras keeps the light off green from detection on (the caller updates the readiness).
  void CheckOneCamera();
  void Publish();

  mutable std::mutex mutex_;
  std::condition_variable wake_, idle_;
  std::deque<Command> queue_;
  bool busy_ = false;
  std::atomic<bool> cancel_{false};
  std::shared_ptr<const CalibrationSnapshot> snapshot_;
  CalibrationSnapshot working_;  // worker only
  // The split test has run on the views as they are (worker only): until then the light is
  // never green, whatever the views' count and coverage.
  bool cameras_checked_ = false;
  std::thread thread_;
};

// Where Save proposes to write: beside the project (its folder, named after the image
// folder: PROJECT_DIR/cam0.cameramodel), or with no project beside the image folder
// (PARENT/cam0.cameramodel); never inside the image folder.
std::string DefaultCameraModelPath(const std::string& images_dir, const std::string& project_file);

}  // namespace fresco
