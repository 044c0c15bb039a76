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

std::string Quote(const std::string& arg) {
  if (!arg.empty() && arg.find_first_of(" \t\"'\\$`;&|<>()*?") == std::string::npos) return arg;
  std::string out = "'";
  for (char c : arg) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

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
  const fs::path ws = fs::absolute(options.workspace);
  const fs::path logs = ws / "logs";
  const fs::path database = ws / "database.db";
  const fs::path sparse = ws / "sparse";
  const fs::path sparse_txt = ws / "sparse_txt";
  FRESCO_RETURN_IF_ERROR(MakeDirectories(logs.string()));
  // A fresh run: COLMAP appends to an existing database and model folders.
  std::error_code ec;
  for (const fs::path& p : {database, sparse, sparse_txt}) fs::remove_all(p, ec);
  fs::remove(ws / "commands.txt", ec);
  for (const auto& entry : fs::directory_iterator(logs, ec)) fs::remove(entry.path(), ec);
  FRESCO_RETURN_IF_ERROR(MakeDirectories(sparse.string()));
  FRESCO_RETURN_IF_ERROR(MakeDirectories(sparse_txt.string()));

  std::string model_name;
  std::vector<double> params;
  FRESCO_RETURN_IF_ERROR(ColmapCameraParams(options.camera, "camera", &model_name, &params));
  const std::string threads = std::to_string(options.threads > 0 ? options.threads : -1);

  std::vector<Step> steps;
  {
    Step s{"feature_extractor",
           {"feature_extractor", "--database_path", database.string(), "--image_path",
            options.image_path, "--ImageReader.single_camera", "1", "--ImageReader.camera_model",
            model_name, "--ImageReader.camera_params", JoinParams(params),
            "--SiftExtraction.use_gpu", "0", "--SiftExtraction.num_threads", threads}};
    if (!options.image_names.empty()) {
      std::string list;
      for (const std::string& name : options.image_names) list += name + "\n";
      const fs::path list_path = ws / "image_list.txt";
      FRESCO_RETURN_IF_ERROR(WriteFileAtomic(list_path.string(), list));
      s.args.insert(s.args.end(), {"--image_list_path", list_path.string()});
    }
    AddSiftLimits(options, &s.args);
    steps.push_back(s);
  }
  int image_count = static_cast<int>(options.image_names.size());
  if (image_count == 0) {
    for (const auto& entry : fs::directory_iterator(options.image_path, ec)) {
      if (entry.is_regular_file()) ++image_count;
    }
  }
  const bool exhaustive = options.matcher == ColmapMatcher::kExhaustive ||
                          (options.matcher == ColmapMatcher::kAuto && !options.ordered &&
                           image_count <= options.exhaustive_max_images);
  result->matcher = exhaustive ? "exhaustive" : "sequential";
  if (exhaustive) {
    steps.push_back({"exhaustive_matcher",
                     {"exhaustive_matcher", "--database_path", database.string(),
                      "--SiftMatching.use_gpu", "0", "--SiftMatching.num_threads", threads}});
  } else {
    steps.push_back(
        {"sequential_matcher",
         {"sequential_matcher", "--database_path", database.string(), "--SiftMatching.use_gpu", "0",
          "--SiftMatching.num_threads", threads, "--SequentialMatching.overlap",
          std::to_string(options.sequential_overlap), "--SequentialMatching.loop_detection", "0"}});
  }
  steps.push_back({"mapper",
                   {"mapper", "--database_path", database.string(), "--image_path",
                    options.image_path, "--output_path", sparse.string(),
                    "--Mapper.ba_refine_focal_length", "0", "--Mapper.ba_refine_principal_point",
                    "0", "--Mapper.ba_refine_extra_params", "0", "--Mapper.num_threads", threads}});

  const int total_steps =
      static_cast<int>(steps.size()) + 1 + (options.register_names.empty() ? 0 : 4);
  auto run_step = [&](const Step& step, int index) -> Status {
    if (options.progress) options.progress(step.name, index, total_steps);
    std::vector<std::string> argv = {program};
    argv.insert(argv.end(), step.args.begin(), step.args.end());
    // COLMAP's own log (glog) into the step's log with its output, not into files of its
    // own in /tmp (a dozen per run, never removed).
    argv.insert(argv.begin() + 2, {"--log_to_stderr", "1"});
    std::string line;
    for (const std::string& a : argv) {
      if (!line.empty()) line += ' ';
      line += Quote(a);
    }
    std::string commands;
    ReadFileToString((ws / "commands.txt").string(), &commands);  // absent the first time
    FRESCO_RETURN_IF_ERROR(WriteFileAtomic((ws / "commands.txt").string(), commands + line + "\n"));
    char prefix[16];
    std::snprintf(prefix, sizeof(prefix), "%02d_", index + 1);
    const fs::path log = logs / (prefix + step.name + ".log");
    const auto step_start = std::chrono::steady_clock::now();
    int exit_code = 0;
    if (options.cancel && *options.cancel) return Status::Error("colmap: cancelled");
    FRESCO_RETURN_IF_ERROR(RunProcess(argv, log.string(), &exit_code, options.cancel));
    if (options.cancel && *options.cancel) return Status::Error("colmap: cancelled");
    result->step_seconds.push_back(
        {step.name,
         std::chrono::duration<double>(std::chrono::steady_clock::now() - step_start).count()});
    if (exit_code != 0) {
      return Status::Error("colmap " + step.name + " failed (exit code " +
                           std::to_string(exit_code) + "); see its log " + log.string());
    }
    return Status::Ok();
  };
  for (size_t i = 0; i < steps.size(); ++i) {
    FRESCO_RETURN_IF_ERROR(run_step(steps[i], static_cast<int>(i)));
  }

  // Every model the mapper made, converted to TXT; keep the largest.
  std::vector<std::string> model_folders;
  for (const auto& entry : fs::directory_iterator(sparse, ec)) {
    if (entry.is_directory()) model_folders.push_back(entry.path().filename().string());
  }
  std::sort(model_folders.begin(), model_folders.end());
  result->models = static_cast<int>(model_folders.size());
  if (model_folders.empty()) {
    return Status::Error("colmap mapper made no reconstruction from " +
                         std::to_string(image_count) + " images (too few matches?); see its log " +
                         (logs / "03_mapper.log").string());
  }
  int best = -1;
  for (size_t i = 0; i < model_folders.size(); ++i) {
    const fs::path txt = sparse_txt / model_folders[i];
    FRESCO_RETURN_IF_ERROR(MakeDirectories(txt.string()));
    FRESCO_RETURN_IF_ERROR(
        run_step({"model_converter",
                  {"model_converter", "--input_path", (sparse / model_folders[i]).string(),
                   "--output_path", txt.string(), "--output_type", "TXT"}},
                 static_cast<int>(steps.size())));
    ColmapModel model;
    FRESCO_RETURN_IF_ERROR(ReadColmapModel(txt.string(), &model));
    if (best < 0 || model.images.size() > result->model.images.size()) {
      best = static_cast<int>(i);
      result->model = std::move(model);
    }
  }
  if (!options.register_names.empty()) {
    // The frames between keyframes, registered to the keyframes' reconstruction.
    const fs::path registered = ws / "sparse_registered";
    const fs::path registered_txt = sparse_txt / "registered";
    fs::remove_all(registered, ec);
    FRESCO_RETURN_IF_ERROR(MakeDirectories(registered.string()));
    FRESCO_RETURN_IF_ERROR(MakeDirectories(registered_txt.string()));
    std::string list, pairs;
    for (const std::string& name : options.register_names) list += name + "\n";
    for (const auto& [a, b] : options.register_pairs) pairs += a + " " + b + "\n";
    const fs::path list_path = ws / "register_list.txt", pairs_path = ws / "register_pairs.txt";
    FRESCO_RETURN_IF_ERROR(WriteFileAtomic(list_path.string(), list));
    FRESCO_RETURN_IF_ERROR(WriteFileAtomic(pairs_path.string(), pairs));
    Step extract{"feature_extractor_others",
                 {"feature_extractor", "--database_path", database.string(), "--image_path",
                  options.image_path, "--image_list_path", list_path.string(),
                  "--ImageReader.existing_camera_id", "1", "--SiftExtraction.use_gpu", "0",
                  "--SiftExtraction.num_threads", threads}};
    AddSiftLimits(options, &extract.args);
    const std::vector<Step> later = {
        extract,
        {"matches_importer",
         {"matches_importer", "--database_path", database.string(), "--match_list_path",
          pairs_path.string(), "--match_type", "pairs", "--SiftMatching.use_gpu", "0",
          "--SiftMatching.num_threads", threads}},
        {"image_registrator",
         {"image_registrator", "--database_path", database.string(), "--input_path",
          (sparse / model_folders[best]).string(), "--output_path", registered.string(),
          "--Mapper.ba_refine_focal_length", "0", "--Mapper.ba_refine_principal_point", "0",
          "--Mapper.ba_refine_extra_params", "0", "--Mapper.num_threads", threads}},
        {"model_converter",
         {"model_converter", "--input_path", registered.string(), "--output_path",
          registered_txt.string(), "--output_type", "TXT"}}};
    // A failure here keeps the keyframes' reconstruction (said in register_error); a cancel
    // ends the run.
    const int first = static_cast<int>(steps.size()) + 1;
    Status status = Status::Ok();
    for (size_t i = 0; i < later.size() && status.ok(); ++i)
      status = run_step(later[i], first + static_cast<int>(i));
    ColmapModel model;
    if (status.ok()) status = ReadColmapModel(registered_txt.string(), &model);
    if (options.cancel && *options.cancel) return Status::Error("colmap: cancelled");
    if (!status.ok()) {
      result->register_error = status.message();
    } else if (model.images.size() >= result->model.images.size()) {
      result->registered_later =
          static_cast<int>(model.images.size()) - static_cast<int>(result->model.images.size());
      result->model = std::move(model);
    }
  }
  result->registered = static_cast<int>(result->model.images.size());
  result->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (result->registered < options.min_registered) {
    return Status::Error("colmap registered only " + std::to_string(result->registered) + " of " +
                         std::to_string(image_count) + " images (at least " +
                         std::to_string(options.min_registered) + " needed); see " +
                         (logs / "03_mapper.log").string());
  }
  return Status::Ok();
}

}  // namespace fresco
