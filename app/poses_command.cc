// `fresco poses verify|bootstrap`: runs COLMAP on a project's frames (its intrinsics held
// fixed) and either judges the project's poses against it (verify.json, verify.png) or
// writes poses from it, aligned to the scene, with a new project pointing at them.
#include <filesystem>
#include <iostream>

#include "app/commands.h"
#include "app/progress.h"
#include "pipeline/core/atomic_file.h"
#include "pipeline/core/poses.h"
#include "pipeline/core/project.h"
#include "pipeline/poses/bootstrap.h"
#include "pipeline/poses/bootstrap_run.h"
#include "pipeline/poses/project_colmap.h"
#include "pipeline/poses/verify.h"
#include "pipeline/poses/verify_report.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;

const char* kVerb = "poses";

const char* kColmapOptionsHelp =
    "COLMAP options (both subcommands):\n"
    "  --every N            use every Nth frame (default 1)\n"
    "  --max-frames N       at most N frames (default: all)\n"
    "  --max-image-size PX  downscale images to this longest side for SIFT (default: COLMAP's\n"
    "                       3200); keypoints are scaled back, intrinsics stay the project's\n"
    "  --matcher M          auto (default: sequential for a video or a frame folder whose\n"
    "                       poses are in sequence, else exhaustive up to 60 images),\n"
    "                       exhaustive or sequential (loop detection off: no vocab tree)\n"
    "  --keyframe-step F    in a sequence, send a frame to COLMAP when its given pose moved\n"
    "                       F x scene size since the last one sent (default 0.005)...\n"
    "  --keyframe-rotation-deg X  ...or turned X degrees (default 2); 0 and 0: every frame\n"
    "                       (the other frames are registered to the keyframes afterwards)\n"
    "  --scene-size-m M     scene size for the position threshold (default: the diagonal of\n"
    "                       the scene's bounding box)\n"
    "  --colmap PROGRAM     the colmap program (default: `colmap` on PATH)\n"
    "  --colmap-model DIR   do not run COLMAP: use the text model of an earlier run (e.g.\n"
    "                       OUT/colmap/sparse_txt/0 of `fresco poses verify`, or\n"
    "                       .../sparse_txt/registered with the frames between keyframes;\n"
    "                       the keyframes are chosen as that run chose them)\n"
    "  --max-features N     at most N SIFT features per image (default: COLMAP's 8192);\n"
    "                       fewer is faster (matching time grows with N squared)\n"
    "  --threads N          threads for COLMAP (default: all cores)\n"
    "  --quiet              no progress on stderr\n"
    "The COLMAP workspace is DIR/colmap/: its exact commands in commands.txt, each step's\n"
    "log in logs/, the reconstruction in sparse/ and sparse_txt/.";

ArgSpec PosesArgSpec(const std::string& sub) {
  ArgSpec spec;
  spec.min_positional = 2;
  spec.max_positional = 2;
  spec.options = {"--out",          "--every",        "--max-frames",    "--max-image-size",
                  "--matcher",      "--scene-size-m", "--colmap",        "--threads",
                  "--colmap-model", "--max-features", "--keyframe-step", "--keyframe-rotation-deg"};
  spec.switches = {"--quiet"};
  spec.required = {"--out"};
  if (sub == "verify") {
    spec.usage = "fresco poses verify PROJECT.json --out DIR [OPTIONS...]";
    spec.options.insert(
        {"--rotation-threshold-deg", "--position-threshold", "--window", "--drift-neighbours"});
    spec.help = std::string(
                    "Runs COLMAP on the project's frames, aligns its reconstruction to the\n"
                    "project's poses (robust similarity; locally over windows of neighbouring\n"
                    "frames on long sequences) and writes DIR/verify.json (per frame:\n"
                    "rotation_error_deg, position_error_m, flagged; registered; thresholds;\n"
                    "alignment) and DIR/verify.png (both errors along the sequence).\n"
                    "  --rotation-threshold-deg X  flag above X degrees (default 0.5)\n"
                    "  --position-threshold F      flag above F x scene size (default 0.01)\n"
                    "  --window N                  local alignment over N frames (default 40;\n"
                    "                              0 = one global alignment)\n"
                    "  --drift-neighbours N        where the disagreement drifts along the\n"
                    "                              sequence, judge each frame against N frames\n"
                    "                              on each side (default 5; 0 = never)\n") +
                kColmapOptionsHelp;
  } else {
    spec.usage =
        "fresco poses bootstrap PROJECT.json --out DIR [--control-points FILE] [OPTIONS...]";
    spec.options.insert({"--control-points", "--inlier-position", "--inlier-rotation-deg",
                         "--refine-max-distance"});
    spec.switches.insert("--refine-mesh");
    spec.help =
        std::string(
            "Runs COLMAP on the project's frames and writes poses for every registered\n"
            "frame, aligned to the scene: DIR/sparse/{cameras,images,points3D}.txt and\n"
            "DIR/project.json (the input project pointing at them; the input is never\n"
            "overwritten), DIR/bootstrap.json (alignment, registered frames).\n"
            "  --control-points FILE     align with >= 3 known world points instead of\n"
            "                            the project's poses. One per line:\n"
            "                            NAME X Y Z IMAGE U V [IMAGE U V ...]\n"
            "                            (metres; pixels, (0,0) = centre of top-left)\n"
            "  --inlier-position F       given poses within F x scene size support the\n"
            "                            alignment (default 0.02)\n"
            "  --inlier-rotation-deg X   ...and within X degrees (default 2)\n"
            "  --refine-mesh             then refine the alignment by ICP of COLMAP's\n"
            "                            sparse points to the scene's mesh\n"
            "                            (point-to-plane, similarity)\n"
            "  --refine-max-distance F   ICP pairs within F x scene size (default 0.02)\n") +
        kColmapOptionsHelp;
  }
  return spec;
}

int PositiveDoubleOption(const Args& args, const ArgSpec& spec, const std::string& option,
                         double* value) {
  if (!args.Has(option)) return -1;
  std::string error;
  if (!ParseDouble(args.Get(option), option, value, &error)) {
    return UsageError(kVerb, spec, error);
  }
  if (!(*value >= 0)) return UsageError(kVerb, spec, option + ": must be >= 0");
  return -1;
}

int IntOption(const Args& args, const ArgSpec& spec, const std::string& option, int min,
              int* value) {
  if (!args.Has(option)) return -1;
  std::string error;
  if (!ParseInt(args.Get(option), option, value, &error)) return UsageError(kVerb, spec, error);
  if (*value < min) {
    return UsageError(kVerb, spec, option + ": must be >= " + std::to_string(min));
  }
  return -1;
}

// Parses the COLMAP options and runs COLMAP on the project. Returns -1 on success, else the
// exit code (after printing the error).
int RunColmapStage(const Args& args, const ArgSpec& spec, const Project& project,
                   const std::string& out_dir, ProjectColmap* result) {
  ProjectColmapOptions options;
  options.out_dir = (fs::path(out_dir) / "colmap").string();
  int code = -1;
  if ((code = IntOption(args, spec, "--every", 1, &options.every_n_frames)) >= 0) return code;
  if ((code = IntOption(args, spec, "--max-frames", 0, &options.max_frames)) >= 0) return code;
  if ((code = IntOption(args, spec, "--max-image-size", 0, &options.colmap.max_image_size)) >= 0)
    return code;
  if ((code = IntOption(args, spec, "--threads", 0, &options.colmap.threads)) >= 0) return code;
  if ((code = IntOption(args, spec, "--max-features", 0, &options.colmap.max_num_features)) >= 0)
    return code;
  if ((code = PositiveDoubleOption(args, spec, "--scene-size-m", &options.scene_size_m)) >= 0)
    return code;
  if ((code = PositiveDoubleOption(args, spec, "--keyframe-step", &options.keyframe_step_rel)) >= 0)
    return code;
  if ((code = PositiveDoubleOption(args, spec, "--keyframe-rotation-deg",
                                   &options.keyframe_rotation_deg)) >= 0)
    return code;
  options.load_scene = args.Switch("--refine-mesh");
  const std::string matcher = args.Get("--matcher", "auto");
  if (matcher == "auto") {
    options.colmap.matcher = ColmapMatcher::kAuto;
  } else if (matcher == "exhaustive") {
    options.colmap.matcher = ColmapMatcher::kExhaustive;
  } else if (matcher == "sequential") {
    options.colmap.matcher = ColmapMatcher::kSequential;
  } else {
    return UsageError(kVerb, spec,
                      "--matcher: expected auto, exhaustive or sequential, got '" + matcher + "'");
  }
  options.colmap.program = args.Get("--colmap");
  options.existing_model = args.Get("--colmap-model");
  if (!options.existing_model.empty() && !fs::is_directory(options.existing_model))
    return Fail(Status::Error(options.existing_model + ": --colmap-model: no such folder"));
  if (options.existing_model.empty() && FindColmap(options.colmap.program).empty()) {
    return Fail(Status::Failed(
        (options.colmap.program.empty() ? "colmap" : options.colmap.program) +
        ": program not found on PATH (install Debian's `colmap` package, or pass --colmap PATH)"));
  }
  const bool quiet = args.Switch("--quiet");
  Progress progress("colmap", 5, quiet);  // the runner gives the steps' count as it starts
  options.colmap.progress = [&](const std::string& step, int index, int total) {
    progress.SetTotal(total);
    if (!quiet && index < total) progress.Update(index, step);
  };
  if (Status s = RunColmapOnProject(project, options, result); !s.ok()) return Fail(s);
  char detail[200];
  std::snprintf(detail, sizeof(detail), "%d of %d frames registered, %.1f s",
                result->run.registered, static_cast<int>(result->frames.size()),
                result->run.seconds);
  progress.Finish(detail);
  if (!result->run.matcher.empty()) {
    std::string steps;
    for (const auto& [step, seconds] : result->run.step_seconds) {
      std::snprintf(detail, sizeof(detail), "%s%s %.1f s", steps.empty() ? "" : ", ", step.c_str(),
                    seconds);
      steps += detail;
    }
    std::cout << "colmap: " << result->run.keyframes << " of " << result->run.frames_offered
              << " frames reconstructed as keyframes";
    const int others = static_cast<int>(result->frames.size()) - result->run.keyframes;
    if (others > 0) {
      std::cout << ", " << result->run.registered_later << " of the other " << others
                << " registered to them";
      if (!result->run.register_error.empty())
        std::cout << " (" << result->run.register_error << ")";
    }
    std::cout << "; " << result->run.matcher << " matching; " << steps << "\n";
  }
  return -1;
}

int RunVerify(const Args& args, const ArgSpec& spec, const Project& project,
              const std::string& out_dir) {
  VerifyOptions options;
  int code = -1;
  if ((code = PositiveDoubleOption(args, spec, "--rotation-threshold-deg",
                                   &options.rotation_threshold_deg)) >= 0)
    return code;
  if ((code = PositiveDoubleOption(args, spec, "--position-threshold",
                                   &options.position_threshold_rel)) >= 0)
    return code;
  if ((code = IntOption(args, spec, "--window", 0, &options.window_frames)) >= 0) return code;
  if ((code = IntOption(args, spec, "--drift-neighbours", 0, &options.drift_neighbours)) >= 0)
    return code;
  if (Status s = options.Check(); !s.ok()) return UsageError(kVerb, spec, s.message());

  ProjectColmap colmap;
  if ((code = RunColmapStage(args, spec, project, out_dir, &colmap)) >= 0) return code;
  VerifyResult result;
  if (Status s = VerifyPoses(VerifyInputs(colmap), colmap.scene_size_m, options, &result);
      !s.ok()) {
    return Fail(s.WithMessage(project.poses + ": " + s.message()));
  }
  const Status written =
      WriteVerifyReport(result, colmap.run, (fs::path(out_dir) / "verify.json").string(),
                        (fs::path(out_dir) / "verify.png").string());
  if (!written.ok()) return Fail(written);
  std::cout << "verify: " << result.compared << " frames compared (" << result.registered
            << " registered by COLMAP), " << result.flagged << " flagged, " << result.borderline
            << " borderline\n"
            << VerifyAgreementText(result) << "\n";
  for (const std::string& note : VerifyNotes(result)) std::cout << "note: " << note << "\n";
  std::cout << "wrote " << (fs::path(out_dir) / "verify.json").string() << "\n";
  return kExitOk;
}

int RunBootstrap(const Args& args, const ArgSpec& spec, const Project& project,
                 const std::string& out_dir) {
  double inlier_position_rel = 0.02, inlier_rotation_deg = 2.0;
  int code = -1;
  if ((code = PositiveDoubleOption(args, spec, "--inlier-position", &inlier_position_rel)) >= 0)
    return code;
  if ((code = PositiveDoubleOption(args, spec, "--inlier-rotation-deg", &inlier_rotation_deg)) >= 0)
    return code;
  double refine_max_distance_rel = 0.02;
  if ((code = PositiveDoubleOption(args, spec, "--refine-max-distance",
                                   &refine_max_distance_rel)) >= 0)
    return code;
  const fs::path new_project_path = fs::absolute(fs::path(out_dir) / "project.json");
  if (fs::absolute(project.file_path).lexically_normal() == new_project_path.lexically_normal()) {
    return UsageError(kVerb, spec, "--out: would overwrite the input project " + project.file_path);
  }
  std::vector<ControlPoint> control_points;
  const std::string control_file = args.Get("--control-points");
  if (!control_file.empty()) {
    if (Status s = ReadControlPoints(control_file, &control_points); !s.ok()) {
      return Fail(s);
    }
  }

  ProjectColmap colmap;
  if ((code = RunColmapStage(args, spec, project, out_dir, &colmap)) >= 0) return code;
  BootstrapOptions options;
  options.control_points = std::move(control_points);
  options.control_file = control_file;
  options.inlier_position_rel = inlier_position_rel;
  options.inlier_rotation_deg = inlier_rotation_deg;
  options.refine_mesh = args.Switch("--refine-mesh");
  options.refine_max_distance_rel = refine_max_distance_rel;
  BootstrapResult result;
  Status s = BootstrapFromColmap(project, colmap, options, &result);
  if (s.ok()) s = WriteBootstrap(project, colmap, result, out_dir);
  if (!s.ok()) return Fail(s);
  std::cout << "bootstrap: " << colmap.run.registered << " of " << colmap.frames.size()
            << " frames posed (" << result.aligned_with << ")\n"
            << result.comparison.summary << "\n"
            << "wrote " << new_project_path.string() << "\n";
  return kExitOk;
}

}  // namespace

int RunVerbPoses(const CommandArgs& argv) {
  const std::string sub = argv.empty() ? "" : argv[0];
  if (sub != "verify" && sub != "bootstrap") {
    const bool help = sub == "--help" || sub == "-h";
    (help ? std::cout : std::cerr)
        << (help ? "" : "fresco poses: expected 'verify' or 'bootstrap'\n")
        << "usage: fresco poses verify PROJECT.json --out DIR [OPTIONS...]\n"
        << "       fresco poses bootstrap PROJECT.json --out DIR [--control-points FILE] "
           "[OPTIONS...]\n"
        << "(fresco poses verify --help, fresco poses bootstrap --help for the options)\n";
    return help ? kExitOk : kExitBadInput;
  }
  const ArgSpec spec = PosesArgSpec(sub);
  Args args;
  if (int code = ParseVerbArgs(kVerb, argv, spec, &args); code >= 0) return code;
  Project project;
  if (Status s = LoadProject(args.positional[1], {}, &project); !s.ok()) return Fail(s);
  // One stream, seen as a version-1 project (a bootstrapped project is written as one).
  if (Status s = CheckOneStream(project, "fresco poses"); !s.ok()) return Fail(s);
  project = project.ForStream(0);
  const std::string out_dir = args.Get("--out");
  if (Status s = MakeDirectories(out_dir); !s.ok()) return Fail(s);
  return sub == "verify" ? RunVerify(args, spec, project, out_dir)
                         : RunBootstrap(args, spec, project, out_dir);
}

}  // namespace fresco
