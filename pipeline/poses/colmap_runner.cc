#include "pipeline/poses/colmap_runner.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <sstream>

#include "pipeline/core/atomic_file.h"
#include "pipeline/core/run_process.h"

#ifndef FRESCO_COLMAP_EXECUTABLE
#define FRESCO_COLMAP_EXECUTABLE ""
#endif

namespace fresco {
namespace {

namespace fs = std::filesystem;

std::string JoinParams(const std::vector<double>& params) {
  std::ostringstream out;
  out.precision(17);
  for (size_t i = 0; i < params.size(); ++i) out << (i ? "," : "") << params[i];
  return out.str();
}

struct Step {
  std::string name;
  std::vector<std::string> args;  // after the program
};

// The feature extraction's limits the options set (image size, features per image).
void AddSiftLimits(const ColmapRunOptions& options, std::vector<std::string>* args) {
  if (options.max_image_size > 0)
    args->insert(args->end(),
                 {"--SiftExtraction.max_image_size", std::to_string(options.max_image_size)});
  if (options.max_num_features > 0)
    args->insert(args->end(),
                 {"--SiftExtraction.max_num_features", std::to_string(options.max_num_features)});
}

// The workspace's folders and files.
struct Workspace {
  explicit Workspace(const std::string& folder) : root(fs::absolute(folder)) {}
  fs::path root;
  fs::path logs = root / "logs";
  fs::path database = root / "database.db";
  fs::path sparse = root / "sparse";
  fs::path sparse_txt = root / "sparse_txt";
};

// A fresh run: COLMAP appends to an existing database and model folders.
Status PrepareWorkspace(const Workspace& ws) {
  FRESCO_RETURN_IF_ERROR(MakeDirectories(ws.logs.string()));
  std::error_code ec;
  for (const fs::path& p : {ws.database, ws.sparse, ws.sparse_txt}) fs::remove_all(p, ec);
  fs::remove(ws.root / "commands.txt", ec);
  for (const auto& entry : fs::directory_iterator(ws.logs, ec)) fs::remove(entry.path(), ec);
  FRESCO_RETURN_IF_ERROR(MakeDirectories(ws.sparse.string()));
  return MakeDirectories(ws.sparse_txt.string());
}

// Runs COLMAP's steps, each with its command line appended to commands.txt, its output in
// logs/NN_name.log and its time in the result.
struct StepRunner {
  std::string program;
  const Workspace* ws = nullptr;
  const ColmapRunOptions* options = nullptr;
  int total_steps = 0;
  ColmapRunResult* result = nullptr;

  Status Run(const Step& step, int index) const {
    if (options->progress) options->progress(step.name, index, total_steps);
    std::vector<std::string> argv = {program};
    argv.insert(argv.end(), step.args.begin(), step.args.end());
    // COLMAP's own log (glog) into the step's log with its output, not into files of its
    // own in /tmp (a dozen per run, never removed).
    argv.insert(argv.begin() + 2, {"--log_to_stderr", "1"});
    std::string line;
    for (const std::string& a : argv) {
      if (!line.empty()) line += ' ';
      line += ShellQuote(a);
    }
    const std::string commands_path = (ws->root / "commands.txt").string();
    std::string commands;
    ReadFileToString(commands_path, &commands);  // absent the first time
    FRESCO_RETURN_IF_ERROR(WriteFileAtomic(commands_path, commands + line + "\n"));
    char prefix[16];
    std::snprintf(prefix, sizeof(prefix), "%02d_", index + 1);
    const fs::path log = ws->logs / (prefix + step.name + ".log");
    const auto step_start = std::chrono::steady_clock::now();
    int exit_code = 0;
    if (Cancelled()) return Status::Error("colmap: cancelled");
    FRESCO_RETURN_IF_ERROR(RunProcess(argv, log.string(), &exit_code, options->cancel));
    if (Cancelled()) return Status::Error("colmap: cancelled");
    result->step_seconds.push_back(
        {step.name,
         std::chrono::duration<double>(std::chrono::steady_clock::now() - step_start).count()});
    if (exit_code != 0) {
      return Status::Error("colmap " + step.name + " failed (exit code " +
                           std::to_string(exit_code) + "); see its log " + log.string());
    }
    return Status::Ok();
  }

  bool Cancelled() const { return options->cancel && *options->cancel; }
};

// The feature extraction over all images (or the listed ones, whose list it writes), with
// the camera's model and parameters.
Status ExtractionStep(const ColmapRunOptions& options, const Workspace& ws,
                      const std::string& threads, Step* step) {
  std::string model_name;
  std::vector<double> params;
  FRESCO_RETURN_IF_ERROR(ColmapCameraParams(options.camera, "camera", &model_name, &params));
  *step = {"feature_extractor",
           {"feature_extractor", "--database_path", ws.database.string(), "--image_path",
            options.image_path, "--ImageReader.single_camera", "1", "--ImageReader.camera_model",
            model_name, "--ImageReader.camera_params", JoinParams(params),
            "--SiftExtraction.use_gpu", "0", "--SiftExtraction.num_threads", threads}};
  if (!options.image_names.empty()) {
    std::string list;
    for (const std::string& name : options.image_names) list += name + "\n";
    const fs::path list_path = ws.root / "image_list.txt";
    FRESCO_RETURN_IF_ERROR(WriteFileAtomic(list_path.string(), list));
    step->args.insert(step->args.end(), {"--image_list_path", list_path.string()});
  }
  AddSiftLimits(options, &step->args);
  return Status::Ok();
}

// The images the run covers: those listed, else the files in the image folder.
int CountImages(const ColmapRunOptions& options) {
  int image_count = static_cast<int>(options.image_names.size());
  if (image_count == 0) {
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(options.image_path, ec)) {
      if (entry.is_regular_file()) ++image_count;
    }
  }
  return image_count;
}

// Exhaustive matching (by choice, or for few unordered images) or sequential.
Step MatchingStep(const ColmapRunOptions& options, const Workspace& ws, const std::string& threads,
                  bool exhaustive) {
  if (exhaustive) {
    return {"exhaustive_matcher",
            {"exhaustive_matcher", "--database_path", ws.database.string(),
             "--SiftMatching.use_gpu", "0", "--SiftMatching.num_threads", threads}};
  }
  return {"sequential_matcher",
          {"sequential_matcher", "--database_path", ws.database.string(), "--SiftMatching.use_gpu",
           "0", "--SiftMatching.num_threads", threads, "--SequentialMatching.overlap",
           std::to_string(options.sequential_overlap), "--SequentialMatching.loop_detection", "0"}};
}

// Every model the mapper made, converted to TXT; keeps the largest in the result and its
// folder in `best_folder`. `step_index`: the conversions' step number.
Status ConvertModels(const StepRunner& runner, int image_count, int step_index,
                     std::string* best_folder) {
  const Workspace& ws = *runner.ws;
  ColmapRunResult* result = runner.result;
  std::vector<std::string> model_folders;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(ws.sparse, ec)) {
    if (entry.is_directory()) model_folders.push_back(entry.path().filename().string());
  }
  std::sort(model_folders.begin(), model_folders.end());
  result->models = static_cast<int>(model_folders.size());
  if (model_folders.empty()) {
    return Status::Error("colmap mapper made no reconstruction from " +
                         std::to_string(image_count) + " images (too few matches?); see its log " +
                         (ws.logs / "03_mapper.log").string());
  }
  int best = -1;
  for (size_t i = 0; i < model_folders.size(); ++i) {
    const fs::path txt = ws.sparse_txt / model_folders[i];
    FRESCO_RETURN_IF_ERROR(MakeDirectories(txt.string()));
    FRESCO_RETURN_IF_ERROR(
        runner.Run({"model_converter",
                    {"model_converter", "--input_path", (ws.sparse / model_folders[i]).string(),
                     "--output_path", txt.string(), "--output_type", "TXT"}},
                   step_index));
    ColmapModel model;
    FRESCO_RETURN_IF_ERROR(ReadColmapModel(txt.string(), &model));
    if (best < 0 || model.images.size() > result->model.images.size()) {
      best = static_cast<int>(i);
      result->model = std::move(model);
    }
  }
  *best_folder = model_folders[best];
  return Status::Ok();
}

// The frames between keyframes, registered to the keyframes' reconstruction (in
// `model_folder`); their steps are numbered from `first`. A failure here keeps the
// keyframes' reconstruction (said in register_error); a cancel ends the run.
Status RegisterOthers(const StepRunner& runner, const std::string& threads,
                      const std::string& model_folder, int first) {
  const Workspace& ws = *runner.ws;
  const ColmapRunOptions& options = *runner.options;
  ColmapRunResult* result = runner.result;
  const fs::path registered = ws.root / "sparse_registered";
  const fs::path registered_txt = ws.sparse_txt / "registered";
  std::error_code ec;
  fs::remove_all(registered, ec);
  FRESCO_RETURN_IF_ERROR(MakeDirectories(registered.string()));
  FRESCO_RETURN_IF_ERROR(MakeDirectories(registered_txt.string()));
  std::string list, pairs;
  for (const std::string& name : options.register_names) list += name + "\n";
  for (const auto& [a, b] : options.register_pairs) pairs += a + " " + b + "\n";
  const fs::path list_path = ws.root / "register_list.txt",
                 pairs_path = ws.root / "register_pairs.txt";
  FRESCO_RETURN_IF_ERROR(WriteFileAtomic(list_path.string(), list));
  FRESCO_RETURN_IF_ERROR(WriteFileAtomic(pairs_path.string(), pairs));
  const std::string database = ws.database.string();
  Step extract{
      "feature_extractor_others",
      {"feature_extractor", "--database_path", database, "--image_path", options.image_path,
       "--image_list_path", list_path.string(), "--ImageReader.existing_camera_id", "1",
       "--SiftExtraction.use_gpu", "0", "--SiftExtraction.num_threads", threads}};
  AddSiftLimits(options, &extract.args);
  const std::vector<Step> later = {
      extract,
      {"matches_importer",
       {"matches_importer", "--database_path", database, "--match_list_path", pairs_path.string(),
        "--match_type", "pairs", "--SiftMatching.use_gpu", "0", "--SiftMatching.num_threads",
        threads}},
      {"image_registrator",
       {"image_registrator", "--database_path", database, "--input_path",
        (ws.sparse / model_folder).string(), "--output_path", registered.string(),
        "--Mapper.ba_refine_focal_length", "0", "--Mapper.ba_refine_principal_point", "0",
        "--Mapper.ba_refine_extra_params", "0", "--Mapper.num_threads", threads}},
      {"model_converter",
       {"model_converter", "--input_path", registered.string(), "--output_path",
        registered_txt.string(), "--output_type", "TXT"}}};
  Status status = Status::Ok();
  for (size_t i = 0; i < later.size() && status.ok(); ++i)
    status = runner.Run(later[i], first + static_cast<int>(i));
  ColmapModel model;
  if (status.ok()) status = ReadColmapModel(registered_txt.string(), &model);
  if (runner.Cancelled()) return Status::Error("colmap: cancelled");
  if (!status.ok()) {
    result->register_error = status.message();
  } else if (model.images.size() >= result->model.images.size()) {
    result->registered_later =
        static_cast<int>(model.images.size()) - static_cast<int>(result->model.images.size());
    result->model = std::move(model);
  }
  return Status::Ok();
}

}  // namespace

std::string FindColmap(const std::string& program) {
  if (!program.empty()) return FindProgram(program);
  std::string found = FindProgram("colmap");
  if (found.empty()) found = FindProgram(FRESCO_COLMAP_EXECUTABLE);
  return found;
}

Status RunColmap(const ColmapRunOptions& options, ColmapRunResult* result) {
  const auto start = std::chrono::steady_clock::now();
  const std::string program = FindColmap(options.program);
  if (program.empty()) {
    return Status::Error(
        (options.program.empty() ? std::string("colmap") : options.program) +
        ": program not found on PATH (install Debian's `colmap` package, or pass its path)");
  }
  result->program = program;
  const Workspace ws(options.workspace);
  FRESCO_RETURN_IF_ERROR(PrepareWorkspace(ws));
  const std::string threads = std::to_string(options.threads > 0 ? options.threads : -1);

  std::vector<Step> steps(1);
  FRESCO_RETURN_IF_ERROR(ExtractionStep(options, ws, threads, &steps[0]));
  const int image_count = CountImages(options);
  const bool exhaustive = options.matcher == ColmapMatcher::kExhaustive ||
                          (options.matcher == ColmapMatcher::kAuto && !options.ordered &&
                           image_count <= options.exhaustive_max_images);
  result->matcher = exhaustive ? "exhaustive" : "sequential";
  steps.push_back(MatchingStep(options, ws, threads, exhaustive));
  steps.push_back({"mapper",
                   {"mapper", "--database_path", ws.database.string(), "--image_path",
                    options.image_path, "--output_path", ws.sparse.string(),
                    "--Mapper.ba_refine_focal_length", "0", "--Mapper.ba_refine_principal_point",
                    "0", "--Mapper.ba_refine_extra_params", "0", "--Mapper.num_threads", threads}});

  const int total_steps =
      static_cast<int>(steps.size()) + 1 + (options.register_names.empty() ? 0 : 4);
  const StepRunner runner{program, &ws, &options, total_steps, result};
  for (size_t i = 0; i < steps.size(); ++i) {
    FRESCO_RETURN_IF_ERROR(runner.Run(steps[i], static_cast<int>(i)));
  }
  std::string best_folder;
  FRESCO_RETURN_IF_ERROR(
      ConvertModels(runner, image_count, static_cast<int>(steps.size()), &best_folder));
  if (!options.register_names.empty()) {
    FRESCO_RETURN_IF_ERROR(
        RegisterOthers(runner, threads, best_folder, static_cast<int>(steps.size()) + 1));
  }
  result->registered = static_cast<int>(result->model.images.size());
  result->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (result->registered < options.min_registered) {
    return Status::Error("colmap registered only " + std::to_string(result->registered) + " of " +
                         std::to_string(image_count) + " images (at least " +
                         std::to_string(options.min_registered) + " needed); see " +
                         (ws.logs / "03_mapper.log").string());
  }
  return Status::Ok();
}

}  // namespace fresco
