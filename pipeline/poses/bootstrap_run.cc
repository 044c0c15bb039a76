#include "pipeline/poses/bootstrap_run.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "pipeline/core/atomic_file.h"
#include "pipeline/poses/pose_alignment.h"
#include "pipeline/poses/verify.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;

nlohmann::json ReportJson(const ProjectColmap& colmap, const BootstrapResult& result,
                          const std::string& project_path) {
  nlohmann::json report;
  report["aligned_with"] = result.aligned_with;
  if (result.aligned_with == "control_points") {
    report["control_point_residual_m"] = result.control_point_residual_m;
  } else {
    report["inliers"] = result.inliers;
    report["compared"] = result.compared;
  }
  if (result.refined) {
    const MeshIcpResult& icp = result.icp;
    report["mesh_icp"] = {{"pairs", icp.pairs},
                          {"iterations", icp.iterations},
                          {"max_distance_m", result.icp_max_distance_m},
                          {"median_distance_before_m", icp.median_distance_before_m},
                          {"median_distance_after_m", icp.median_distance_after_m}};
  }
  const Sim3d& w = result.world_from_colmap;
  report["scale"] = w.scale;
  report["world_from_colmap"] = {
      {"scale", w.scale},
      {"rotation_wxyz", {w.rotation.w(), w.rotation.x(), w.rotation.y(), w.rotation.z()}},
      {"translation_m", {w.translation.x(), w.translation.y(), w.translation.z()}}};
  report["frames"] = colmap.frames.size();
  report["registered"] = colmap.run.registered;
  report["not_registered"] = result.not_registered;
  report["colmap_seconds"] = colmap.run.seconds;
  const PosesComparison& c = result.comparison;
  report["compared_with_given"] = {{"frames", c.compared},
                                   {"agreeing", c.agreeing},
                                   {"median_rotation_deg", c.median_rotation_deg},
                                   {"max_rotation_deg", c.max_rotation_deg},
                                   {"median_position_m", c.median_position_m},
                                   {"max_position_m", c.max_position_m},
                                   {"collinear_centres", c.collinear},
                                   {"drifts", c.drifts},
                                   {"drift_first", c.drift_first},
                                   {"drift_last", c.drift_last},
                                   {"better", c.better},
                                   {"summary", c.summary}};
  report["project"] = project_path;
  return report;
}

// Where the drift itself carries frames beyond the agreement thresholds, named as `fresco poses
// verify` names it (VerifyResult::drift_first, drift_last): not every frame that differs
// smoothly (a reconstruction that bends at its end, aligned by one fit, differs smoothly along
// the whole walk). Counts those frames in `frames`; false when the verification finds none.
bool DriftStretch(const ProjectColmap& colmap, const BootstrapOptions& options, std::string* first,
                  std::string* last, int* frames) {
  VerifyOptions verify;
  verify.rotation_threshold_deg = options.agree_rotation_deg;
  verify.position_threshold_rel = options.agree_position_rel;
  VerifyResult r;
  if (!VerifyPoses(VerifyInputs(colmap), colmap.scene_size_m, verify, &r).ok() ||
      !r.drift_followed || r.drift_first.empty()) {
    return false;
  }
  *first = r.drift_first;
  *last = r.drift_last;
  *frames = static_cast<int>(std::count_if(r.frames.begin(), r.frames.end(),
                                           [](const FrameVerdict& v) { return v.in_drift; }));
  return true;
}

PosesComparison Compare(const std::vector<PosePair>& pairs, const ProjectColmap& colmap,
                        const Sim3d& world_from_colmap, const PoseAlignmentOptions& thresholds,
                        const BootstrapOptions& options, bool aligned_with_poses) {
  PosesComparison c;
  c.compared = static_cast<int>(pairs.size());
  std::vector<double> rotation, position;
  std::vector<Eigen::Vector3d> centres;
  for (const PosePair& p : pairs) {
    const PoseError e = ComparePose(p, world_from_colmap);
    rotation.push_back(e.rotation_deg);
    position.push_back(e.position_m);
    c.max_rotation_deg = std::max(c.max_rotation_deg, e.rotation_deg);
    c.max_position_m = std::max(c.max_position_m, e.position_m);
    if (e.rotation_deg < thresholds.inlier_rotation_deg &&
        e.position_m < thresholds.inlier_position_m) {
      ++c.agreeing;
    }
    centres.push_back(p.given_cam_from_world.Centre());
  }
  c.median_rotation_deg = Median(rotation);
  c.median_position_m = Median(position);
  c.collinear = MeasureCentreSpread(centres, thresholds).collinear;
  if (c.compared == 0) {
    c.better = "none";
    c.summary =
        "No registered frame has a given pose: nothing to compare the bootstrapped poses with.";
    return c;
  }
  char figures[160];
  std::snprintf(figures, sizeof(figures),
                "median difference %.3g deg, %.3g m; up to %.3g deg, %.3g m", c.median_rotation_deg,
                c.median_position_m, c.max_rotation_deg, c.max_position_m);
  const std::string agree =
      std::to_string(c.agreeing) + " of the " + std::to_string(c.compared) + " given poses";
  const Disagreement d = MeasureDisagreement(
      pairs, world_from_colmap, thresholds.inlier_rotation_deg, thresholds.inlier_position_m);
  c.drifts = d.Drifts();
  if (c.drifts) {
    c.better = "unknown";
    c.drift_first = pairs[d.first].name;
    c.drift_last = pairs[d.last].name;
    int in_drift = d.smooth;
    const bool named = DriftStretch(colmap, options, &c.drift_first, &c.drift_last, &in_drift);
    c.summary = "The bootstrapped poses agree with " + agree +
                (named ? "; a drift carries the " + std::to_string(in_drift) + " frames from " +
                             c.drift_first + " to " + c.drift_last + " beyond the thresholds"
                       : ", and differ from " + std::to_string(in_drift) +
                             " smoothly along the sequence (" + c.drift_first + " to " +
                             c.drift_last + ")") +
                ": COLMAP's reconstruction or the given poses drift there, and nothing here "
                "says which (" +
                figures + "). Check those frames before applying.";
  } else if (2 * c.agreeing >= c.compared && c.agreeing >= 3) {
    c.better = "bootstrapped";
    c.summary = "The bootstrapped poses agree with " + agree + " and replace the " +
                std::to_string(c.compared - c.agreeing) + " that disagree (" + figures + ").";
  } else if (aligned_with_poses) {
    c.better = "given";
    c.summary = "Only " + agree +
                " agree with COLMAP's reconstruction: the bootstrapped poses "
                "are likely WORSE than the given ones (" +
                figures + "). Keep the given poses.";
  } else {
    c.better = "unknown";
    c.summary = "Placed by the control points, the bootstrapped poses agree with only " + agree +
                " (" + figures + "): one of the two is wrong; check the control points.";
  }
  return c;
}

}  // namespace

Status BootstrapFromColmap(const Project& project, const ProjectColmap& colmap,
                           const BootstrapOptions& options, BootstrapResult* result) {
  *result = BootstrapResult();
  std::vector<PosePair> pairs;
  for (const ProjectColmapFrame& f : colmap.frames) {
    if (f.given && f.colmap) {
      pairs.push_back({f.name, f.given->cam_from_world, f.colmap->cam_from_world});
    }
  }
  PoseAlignmentOptions align;
  align.inlier_position_m = options.inlier_position_rel * colmap.scene_size_m;
  align.inlier_rotation_deg = options.inlier_rotation_deg;
  if (!options.control_points.empty()) {
    ControlPointFit fit;
    FRESCO_RETURN_IF_ERROR(AlignWithControlPoints(options.control_points, options.control_file,
                                                  colmap.run.model, colmap.camera, &fit)
                               .Reclassified(StatusKind::kFailed));
    result->world_from_colmap = fit.world_from_colmap;
    result->aligned_with = "control_points";
    result->control_point_residual_m = fit.residual_m;
  } else {
    if (pairs.size() < 3) {
      return Status::Failed(project.poses + ": only " + std::to_string(pairs.size()) +
                            " registered frames have a given pose: give --control-points to "
                            "place COLMAP's reconstruction in the scene");
    }
    PoseAlignment alignment;
    if (Status s = AlignColmapToPoses(pairs, align, &alignment); !s.ok()) {
      return Status::Failed(project.poses + ": " + s.message());
    }
    result->world_from_colmap = alignment.world_from_colmap;
    result->aligned_with = "given_poses";
    result->inliers = alignment.num_inliers;
    result->compared = static_cast<int>(pairs.size());
  }
  if (options.refine_mesh) {
    MeshIcpOptions icp;
    icp.max_distance_m = options.refine_max_distance_rel * colmap.scene_size_m;
    std::vector<Eigen::Vector3d> points;
    for (const Point3D& p : colmap.run.model.points) points.push_back(p.xyz);
    if (Status s = AlignPointsToMesh(points, colmap.capture.scene, result->world_from_colmap, icp,
                                     &result->icp);
        !s.ok()) {
      return Status::Failed(project.scene + ": " + s.message());
    }
    result->world_from_colmap = result->icp.world_from_colmap;
    result->refined = true;
    result->icp_max_distance_m = icp.max_distance_m;
  }
  PoseAlignmentOptions agree = align;
  agree.inlier_rotation_deg = options.agree_rotation_deg;
  agree.inlier_position_m = options.agree_position_rel * colmap.scene_size_m;
  result->comparison = Compare(pairs, colmap, result->world_from_colmap, agree, options,
                               result->aligned_with == "given_poses");
  result->model = TransformModel(colmap.run.model, result->world_from_colmap);
  result->model.cameras = {{1, colmap.camera}};
  for (PosedImage& image : result->model.images) image.camera_id = 1;
  for (const ProjectColmapFrame& f : colmap.frames) {
    if (!f.colmap) result->not_registered.push_back(f.name);
  }
  return Status::Ok();
}

std::string BootstrapPosesPath(const std::string& out_dir) {
  return fs::absolute(fs::path(out_dir) / "sparse" / "images.txt").string();
}

Status WriteBootstrap(const Project& project, const ProjectColmap& colmap,
                      const BootstrapResult& result, const std::string& out_dir) {
  const fs::path new_project_path = fs::absolute(fs::path(out_dir) / "project.json");
  if (fs::absolute(project.file_path).lexically_normal() == new_project_path.lexically_normal()) {
    return Status::OutputError(out_dir + ": would overwrite the input project " +
                               project.file_path);
  }
  const fs::path sparse = fs::path(out_dir) / "sparse";
  Project out = project;
  out.poses = BootstrapPosesPath(out_dir);
  FRESCO_RETURN_IF_ERROR(MakeDirectories(sparse.string()));
  FRESCO_RETURN_IF_ERROR(WriteColmapModel(sparse.string(), result.model));
  FRESCO_RETURN_IF_ERROR(SaveProject(out, new_project_path.string()));
  FRESCO_RETURN_IF_ERROR(
      WriteFileAtomic((fs::path(out_dir) / "bootstrap.json").string(),
                      ReportJson(colmap, result, new_project_path.string()).dump(2)));
  return Status::Ok();
}

}  // namespace fresco
