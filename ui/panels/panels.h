// The panels, one factory per file in ui/panels/ (registered in panel_registry.cc), and the
// app-level actions they share.
#pragma once

#include <memory>
#include <string>

#include "ui/core/new_project_bootstrap.h"
#include "ui/core/panel.h"
#include "ui/core/project_paths.h"

namespace fresco {

std::unique_ptr<Panel> MakeProjectPanel();
inline constexpr const char* kProjectPanelTitle = "Project";
std::unique_ptr<Panel> MakePipelinePanel();
std::unique_ptr<Panel> MakeViewportPanel();
std::unique_ptr<Panel> MakeGroupingPanel();
// A stage panel shows one pipeline stage's metrics and debug images for the current frame.
std::unique_ptr<Panel> MakeStagePanel(const std::string& stage, const std::string& title);
// What a stage panel with no debug image says instead, true to the worker's state: they come
// when paused (while playing or seeking), this frame was painted without them (paused after
// playing: Step or F5 paints one with them), or the stage drew none for this frame.
std::string NoDebugImagesNote(const RunnerSnapshot& snap);
std::unique_ptr<Panel> MakeInputFramePanel();
std::unique_ptr<Panel> MakePaintedBuffersPanel();
std::unique_ptr<Panel> MakeTimingPanel();
std::unique_ptr<Panel> MakeMisalignmentPanel();
// Calibration: a window over columns 2-5, closed until opened from the View menu
// or by `fresco gui --calib-images`.
std::unique_ptr<Panel> MakeCalibrationPanel();
inline constexpr const char* kCalibrationPanelTitle = "Calibration";
// Poses with COLMAP: a window over columns 2-5, closed until opened from the View
// menu or by `fresco gui --poses`.
std::unique_ptr<Panel> MakePosesPanel();
inline constexpr const char* kPosesPanelTitle = "Poses";
// New project (File > New project..., the Project panel's New): a form, closed until asked
// for (UiContext::new_project_requested).
std::unique_ptr<Panel> MakeNewProjectDialog();
inline constexpr const char* kNewProjectTitle = "New project";

// What the New project form asks for: paths as typed (absolute, or relative to the working
// folder), URLs for live sources.
struct NewProjectForm : ProjectPaths {
  std::string project_file;  // where to save it (must not exist yet)
  // Poses bootstrapped with COLMAP (new_project_bootstrap.h) instead of read from `poses`,
  // which then holds optional rough poses that place them.
  bool bootstrap = false;
  NewProjectBootstrapOptions colmap;
};
// Builds the project (paths relative to the project file), checks it as `fresco run` does
// when it loads one (the errors are its one-line "FILE: field: ..." messages) and saves it
// atomically; on an error nothing is written.
Status BuildNewProject(const NewProjectForm& form, Project* project);

// Opens `path` (after the unsaved-changes prompt when the project has edits; the app frame
// shows it) and restarts the pipeline on it.
void RequestOpen(UiContext& ui, const std::string& path);
// Restarts the pipeline on the open project as it is now (its files just changed): the
// worker's first snapshot says whether they could be read, as after Open.
void ReopenProject(UiContext& ui);
// Restarts the pipeline with the project as edited (settings and grouping).
void ApplyProject(UiContext& ui);
// Undo (or redo) one edit; restarts the pipeline when the grouping or the poses changed.
void UndoRedo(UiContext& ui, bool undo);

}  // namespace fresco
