// The app's painting worker (PipelineRunner, headless) on a project, played to the end: what
// the job layer's tests compare with `fresco run`.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "pipeline/core/project.h"
#include "ui/core/pipeline_runner.h"

namespace fresco::testing {

// The worker's last snapshot after playing `project_json` (loaded with its own settings and
// `overrides`, "KEY=VALUE" as --set) to its end or its error; no review renders, no debug
// images.
inline std::shared_ptr<const RunnerSnapshot> PlayInApp(
    const std::string& project_json, const std::vector<std::string>& overrides = {}) {
  Project project;
  const Status loaded = LoadProject(project_json, overrides, &project);
  EXPECT_TRUE(loaded.ok()) << loaded.message();
  RunnerOptions options;
  options.misalignment = false;
  options.debug_images = false;
  PipelineRunner runner(options);
  runner.Restart(project);
  runner.Play();
  runner.WaitIdle();
  return runner.Snapshot();
}

}  // namespace fresco::testing
