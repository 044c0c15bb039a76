// The whole-capture pre-pass's outcome in a file (`fresco run --prepass FILE`): what the joint
// pose check and the movers found across views decided (the poses every frame paints at, each
// frame's movers, the decisions handed to the `auto` modes), written once and read by every
// shard of the project instead of running the pre-pass again. Exact: the poses' doubles and the
// masks' bytes come back as they were written, so a shard that reads the file paints what one
// that ran the pre-pass paints.
#pragma once

#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "pipeline/core/project.h"
#include "pipeline/core/status.h"
#include "pipeline/paint/base_buffer.h"
#include "pipeline/paint/joint_pose_adjustment.h"
#include "pipeline/run/paint_job.h"

namespace fresco {

// Whether opening `project` for painting runs the whole-capture pre-pass (refine.joint, or
// movers across views; captures from files).
bool NeedsWholeCapturePrepass(const Project& project);

// Writes the pre-pass outcome that `job` holds (after the pre-pass ran, if the project needs
// one) to `path`, atomically, with the layout of the job's charts (PaintSession::Layout): the
// shards that read it build only their own charts' texels.
Status WritePrepassFile(const std::string& path, const Project& project, const PaintJob& job);

// Reads `path` (written for the same project and settings, else bad input naming the file and
// the field) and applies it to `job`, as the pre-pass would have: the captures' poses and
// movers, the session's decisions, job->joint_poses and job->mover_masks.
Status ReadPrepassFile(const std::string& path, const Project& project, PaintJob* job);

// The layout of the charts in `path` (checked as ReadPrepassFile checks it; every triangle a
// triangle of the mesh's `num_triangles`), or none when the file holds none.
Status ReadPrepassLayout(const std::string& path, const Project& project, int num_triangles,
                         std::optional<BufferLayout>* layout);

// metrics.json's "joint_poses" (and the file's): the adjustment's figures, without the poses.
nlohmann::json PoseAdjustSummaryJson(const PoseAdjustResult& a);

}  // namespace fresco
