// `fresco calib`: camera intrinsics from images of a board (docs/contract.md "Calibration").
//   fresco calib solve IMAGES_DIR --board BOARD --out CAMERA.cameramodel [--model MODEL]
//   fresco calib board BOARD --out BOARD.png [--dpi N]
// Bad input (a bad board spec, a folder without usable images) is one line on stderr and
// exit 2; every output is written atomically.
#include <algorithm>
#include <cstdio>
#include <iostream>
#include <memory>

#include "app/commands.h"
#include "app/progress.h"
#include "calib/board_image.h"
#include "calib/calibrate.h"
#include "calib/report.h"
#include "calib/sample_views.h"
#include "pipeline/core/atomic_file.h"
#include "pipeline/core/cameramodel_io.h"
#include "pipeline/core/image_io.h"

namespace fresco {
namespace {

using calib::BoardSpec;

const char kUsage[] =
    "fresco calib solve IMAGES_DIR --board BOARD --out CAMERA.cameramodel [--model MODEL]\n"
    "       fresco calib board BOARD --out BOARD.png [--dpi N]\n"
    "       fresco calib sample BOARD --out DIR [--views N] [--seed N] [--blur PX] [--noise GREY]";

const char kSolveHelp[] =
    R"(Detects the board in every image of IMAGES_DIR (*.png *.jpg *.jpeg *.bmp *.tif), solves
the intrinsics with mrcal and writes CAMERA.cameramodel (mrcal's format) and, beside it,
CAMERA.report.json, CAMERA.residuals.png, CAMERA.coverage.png and CAMERA.uncertainty.png
(projection uncertainty over the imager at the boards' median range; figures in the report).

  --board BOARD        chessboard:COLSxROWS:SQUARE_M (inner corners, e.g. chessboard:9x6:0.025)
                       or aprilgrid:COLSxROWS:TAG_M:SPACING (Kalibr AprilGrid of tag36h11,
                       e.g. aprilgrid:6x6:0.088:0.3)
  --model MODEL        auto (default: the simplest model the data supports, every model
                       tried in the report), pinhole, opencv4, opencv5, opencv8, splined
  --exclude NAMES      images not to use: file names or shell globs, comma-separated
                       (e.g. 'right*.jpg,left07.jpg'); may repeat. The report lists them
                       under images_excluded
  --corners-vnl FILE   also write the detected corners as mrcal's corners.vnl (for
                       mrcal-calibrate-cameras)
  --no-pictures        do not write the PNG pictures
  --no-cross-validation  skip the half-data solves (faster; auto then compares fits only)
  --all-halves         solve every model's halves, even where the choice does not depend
                       on them (same choice, slower; the report then compares all)
  --no-refine          AprilGrid: keep the detectors' corners (no cornerSubPix)
  --no-second-look     AprilGrid: the apriltag library alone (no second look for the tags
                       it misses: thinned black, then OpenCV's aruco)
  --quiet              no summary on stdout)";

const char kBoardHelp[] =
    R"(Renders a printable board from the apriltag library's own tag36h11 family (AprilGrid)
or a chessboard, at --dpi (default 300), and writes BOARD.png and BOARD.json (the physical
size of what is drawn). Print at 100 % scale and check the size with a ruler.)";

// The names --exclude lists (comma-separated, each option may repeat).
std::vector<std::string> ExcludedNames(const Args& args) {
  std::vector<std::string> names;
  for (const std::string& list : args.All("--exclude"))
    for (size_t start = 0; start <= list.size();) {
      const size_t comma = std::min(list.find(',', start), list.size());
      if (comma > start) names.push_back(list.substr(start, comma - start));
      start = comma + 1;
    }
  return names;
}

// The summary on stdout: what was left out, every model tried, the one chosen and its
// projection uncertainty.
void PrintSolveSummary(const calib::CalibrationRun& run, const std::string& out) {
  for (const std::string& name : run.excluded) std::cout << "excluded " << name << "\n";
  for (const calib::RejectedImage& r : run.rejected)
    std::cout << "rejected " << r.name << ": " << r.reason << "\n";
  for (const calib::ModelTrial& t : run.choice.trials) {
    char line[256];
    if (!t.status.ok()) {
      std::cout << "model " << t.short_name << ": failed: " << t.status.message() << "\n";
      continue;
    }
    std::snprintf(line, sizeof(line), "model %-8s rms %.4f px  sigma %.4f px  ",
                  t.short_name.c_str(), t.fit.rms_px, t.fit.noise_sigma_px);
    std::cout << line << calib::CrossValidationText(t) << "  " << calib::VerdictText(t) << "\n";
  }
  const calib::SolveResult& fit = run.Chosen().fit;
  std::cout << "chosen " << run.Chosen().short_name << " (" << run.Chosen().lensmodel << "): fx "
            << fit.intrinsics[0] << " fy " << fit.intrinsics[1] << " cx " << fit.intrinsics[2]
            << " cy " << fit.intrinsics[3] << ", rms " << fit.rms_px << " px, " << run.views.size()
            << " images used, " << run.rejected.size() << " rejected, " << run.excluded.size()
            << " excluded\n";
  for (const std::string& doubt : run.camera_doubts)
    std::cout << "NOT ONE CAMERA: " << doubt << "\n";
  const calib::UncertaintyMap& u = run.uncertainty;
  char line[256];
  std::snprintf(line, sizeof(line),
                "projection uncertainty at %.2f m: centre %.3f px, median where observed "
                "%.3f px, max %.3f px\n",
                u.range_m, u.centre_px, u.median_observed_px, u.max_px);
  std::cout << line;
  std::cout << "wrote " << out << " and " << calib::SiblingPath(out, ".report.json") << "\n";
}

int RunSolve(const CommandArgs& argv) {
  ArgSpec spec;
  spec.usage =
      "fresco calib solve IMAGES_DIR --board BOARD --out CAMERA.cameramodel [--model MODEL]";
  spec.help = kSolveHelp;
  spec.min_positional = 1;
  spec.max_positional = 1;
  spec.options = {"--board", "--out", "--model", "--corners-vnl"};
  spec.repeatable = {"--exclude"};
  spec.switches = {"--no-pictures", "--no-cross-validation", "--all-halves",
                   "--no-refine",   "--no-second-look",      "--quiet"};
  spec.required = {"--board", "--out"};
  Args args;
  if (int code = ParseVerbArgs("calib solve", argv, spec, &args); code >= 0) return code;
  calib::CalibrateRequest request;
  request.images_dir = args.positional[0];
  request.exclude = ExcludedNames(args);
  if (Status s = calib::ParseBoardSpec(args.Get("--board"), "--board", &request.board); !s.ok())
    return Fail(s);
  request.model = args.Get("--model", "auto");
  bool known = request.model == "auto";
  for (const std::string& name : calib::LensModelShortNames()) known |= name == request.model;
  if (!known)
    return UsageError("calib solve", spec,
                      "--model: '" + request.model +
                          "' is not auto, pinhole, opencv4, opencv5, opencv8 or splined");
  request.cross_validate = !args.Switch("--no-cross-validation");
  request.all_halves = args.Switch("--all-halves");
  request.detect.refine_tag_corners = !args.Switch("--no-refine");
  request.detect.second_look = !args.Switch("--no-second-look");
  const std::string out = args.Get("--out");
  const bool quiet = args.Switch("--quiet");

  // Progress on stderr: detection image by image, then each solve (auto on 30 AprilGrid
  // images runs 15 solves over minutes).
  std::unique_ptr<Progress> detect_progress, solve_progress;
  request.progress = [&](const std::string& stage, int done, int total, const std::string& what) {
    std::unique_ptr<Progress>& bar = stage == "detect" ? detect_progress : solve_progress;
    if (!bar) {
      if (stage == "solve" && detect_progress) detect_progress->Finish();
      bar = std::make_unique<Progress>("calib " + stage, total, quiet);
    }
    bar->Update(done, what);
  };
  calib::CalibrationRun run;
  if (Status s = calib::DetectViews(request, &run); !s.ok()) {
    for (const calib::RejectedImage& r : run.rejected)
      std::cerr << "  rejected " << r.name << ": " << r.reason << "\n";
    return Fail(s);
  }
  if (Status s = calib::SolveViews(request, &run); !s.ok()) {
    return Fail(s);
  }
  if (solve_progress) solve_progress->Finish();
  calib::CalibrationOutputs outputs;
  outputs.pictures = !args.Switch("--no-pictures");
  outputs.corners_vnl = args.Get("--corners-vnl");
  std::string optimization_inputs_missing;
  if (Status s =
          calib::WriteCalibrationOutputs(out, request, run, outputs, &optimization_inputs_missing);
      !s.ok())
    return Fail(s);
  if (!optimization_inputs_missing.empty())
    std::cerr << "warning: " << out << " has no optimization_inputs (mrcal's uncertainty and "
              << "residual tools need them): " << optimization_inputs_missing << "\n";

  for (const std::string& w : run.warnings) std::cerr << "warning: " << w << "\n";
  if (!quiet) PrintSolveSummary(run, out);
  return kExitOk;
}

int RunBoard(const CommandArgs& argv) {
  ArgSpec spec;
  spec.usage = "fresco calib board BOARD --out BOARD.png [--dpi N]";
  spec.help = kBoardHelp;
  spec.min_positional = 1;
  spec.max_positional = 1;
  spec.options = {"--out", "--dpi"};
  spec.required = {"--out"};
  Args args;
  if (int code = ParseVerbArgs("calib board", argv, spec, &args); code >= 0) return code;
  BoardSpec board;
  if (Status s = calib::ParseBoardSpec(args.positional[0], "BOARD", &board); !s.ok())
    return Fail(s);
  double dpi = 300;
  std::string error;
  if (args.Has("--dpi") && !ParseDouble(args.Get("--dpi"), "--dpi", &dpi, &error))
    return UsageError("calib board", spec, error);
  calib::BoardImage image;
  if (Status s = calib::RenderBoardImage(board, dpi, &image); !s.ok()) return Fail(s);
  const std::string out = args.Get("--out");
  if (Status s = WriteImageAtomic(out, image.gray); !s.ok()) return Fail(s);
  char json[1024];
  std::snprintf(json, sizeof(json),
                "{\n  \"board\": \"%s\",\n  \"dpi\": %g,\n  \"image_px\": [%d, %d],\n"
                "  \"image_size_m\": [%.6f, %.6f],\n  \"pattern_size_m\": [%.6f, %.6f],\n"
                "  \"drawn_square_m\": %.6f,\n  \"drawn_spacing\": %.6f,\n"
                "  \"family\": \"%s\"\n}\n",
                board.text.c_str(), dpi, image.gray.cols, image.gray.rows, image.image_width_m,
                image.image_height_m, image.pattern_width_m, image.pattern_height_m,
                image.drawn_square_m, image.drawn_spacing,
                board.kind == calib::BoardKind::kAprilGrid ? "tag36h11" : "chessboard");
  const std::string sidecar = calib::SiblingPath(out, ".json");
  if (Status s = WriteFileAtomic(sidecar, json); !s.ok()) return Fail(s);
  std::cout << image.label << "\nwrote " << out << " (" << image.gray.cols << "x" << image.gray.rows
            << " px) and " << sidecar << "\n";
  return kExitOk;
}

int RunSample(const CommandArgs& argv) {
  ArgSpec spec;
  spec.usage =
      "fresco calib sample BOARD --out DIR [--views N] [--seed N] [--blur PX] [--noise GREY]";
  spec.help =
      "Makes sample calibration images to try calibration with: the AprilGrid BOARD (as\n"
      "fresco calib board prints it) seen through a known lens with strong barrel distortion\n"
      "(mrcal LENSMODEL_OPENCV4, 1024x768) from views that sweep the imager, borders and\n"
      "corners included. Writes DIR/view_000.png ... and DIR/truth.cameramodel (the lens the\n"
      "views were made with: compare what fresco calib solve finds against it).\n\n"
      "  --views N      number of views (default 20)\n"
      "  --seed N       the views' poses and noise (default 1)\n"
      "  --blur PX      Gaussian blur sigma in pixels (default 0)\n"
      "  --noise GREY   Gaussian noise sigma in grey levels (default 1)";
  spec.min_positional = spec.max_positional = 1;
  spec.options = {"--out", "--views", "--seed", "--blur", "--noise"};
  spec.required = {"--out"};
  Args args;
  if (int code = ParseVerbArgs("calib sample", argv, spec, &args); code >= 0) return code;
  BoardSpec board;
  if (Status s = calib::ParseBoardSpec(args.positional[0], "BOARD", &board); !s.ok())
    return Fail(s);
  if (board.kind != calib::BoardKind::kAprilGrid)
    return UsageError("calib sample", spec, "BOARD: sample views are made of AprilGrid boards");
  int views = 20, seed = 1;
  calib::SyntheticImageOptions options;
  options.noise_px = 1;
  std::string error;
  if ((args.Has("--views") && !ParseInt(args.Get("--views"), "--views", &views, &error)) ||
      (args.Has("--seed") && !ParseInt(args.Get("--seed"), "--seed", &seed, &error)) ||
      (args.Has("--blur") &&
       !ParseDouble(args.Get("--blur"), "--blur", &options.blur_sigma_px, &error)) ||
      (args.Has("--noise") &&
       !ParseDouble(args.Get("--noise"), "--noise", &options.noise_px, &error)))
    return UsageError("calib sample", spec, error);
  if (views < 1 || views > 1000 || options.blur_sigma_px < 0 || options.blur_sigma_px > 20 ||
      options.noise_px < 0 || options.noise_px > 100)
    return UsageError("calib sample", spec, "--views 1 to 1000, --blur 0 to 20, --noise 0 to 100");
  const std::string out = args.Get("--out");
  if (Status s = MakeDirectories(out); !s.ok()) return Fail(s);
  const calib::SyntheticLens lens;
  const calib::SyntheticImageRenderer renderer(board, lens, /*kalibr_squares=*/false);
  const auto poses = calib::WholeBoardPoses(board, lens, views, static_cast<unsigned>(seed));
  for (size_t v = 0; v < poses.size(); ++v) {
    options.seed = static_cast<unsigned>(seed) * 1000 + static_cast<unsigned>(v);
    const calib::SyntheticImage image = renderer.Render(poses[v], options);
    char name[32];
    std::snprintf(name, sizeof(name), "/view_%03zu.png", v);
    if (Status s = WriteImageAtomic(out + name, image.gray); !s.ok()) return Fail(s);
  }
  LensModel model = LensModel::kPinhole;
  LensModelFromName(lens.lensmodel, &model);
  CameraModelFile truth;
  truth.camera = Camera::FromParams(model, lens.width, lens.height, lens.intrinsics);
  const std::string truth_path = out + "/truth.cameramodel";
  if (Status s = WriteCameraModel(truth_path, truth); !s.ok()) return Fail(s);
  std::cout << "wrote " << poses.size() << " views (" << lens.width << "x" << lens.height << ") to "
            << out << " and the lens they were made with to " << truth_path << "\n";
  return kExitOk;
}

}  // namespace

int RunVerbCalib(const CommandArgs& argv) {
  if (argv.empty() || argv[0] == "--help" || argv[0] == "-h") {
    (argv.empty() ? std::cerr : std::cout) << "usage: " << kUsage << "\n";
    return argv.empty() ? kExitBadInput : kExitOk;
  }
  const CommandArgs rest(argv.begin() + 1, argv.end());
  if (argv[0] == "solve") return RunSolve(rest);
  if (argv[0] == "board") return RunBoard(rest);
  if (argv[0] == "sample") return RunSample(rest);
  std::cerr << "fresco calib: unknown sub-command '" << argv[0] << "'\nusage: " << kUsage << "\n";
  return kExitBadInput;
}

}  // namespace fresco
