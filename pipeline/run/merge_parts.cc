#include "pipeline/run/merge_parts.h"

#include <algorithm>
#include <filesystem>
#include <map>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "pipeline/core/atomic_file.h"
#include "pipeline/core/image_codecs.h"
#include "pipeline/core/image_io.h"
#include "pipeline/paint/texture_atlas.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

struct Part {
  std::string dir;
  Json metrics;
  int index = -1, count = 0;
  std::vector<std::string> files;  // every file of the part but metrics.json, sorted
};

// Member `key` of `j` (null when `j` is no object or has none).
const Json* Member(const Json& j, const std::string& key) {
  if (!j.is_object()) return nullptr;
  const auto it = j.find(key);
  return it == j.end() ? nullptr : &*it;
}

// The fields merging reads, each of the type it needs: the first that is not, named.
Status CheckFieldsMergeReads(const std::string& path, const Json& m) {
  const auto wrong = [&](const std::string& field, const char* want) {
    return Status::Error(path + ": " + field + ": missing or not " + want);
  };
  const auto is_count = [](const Json* v) { return v && v->is_number_integer() && *v >= 0; };
  const Json& shard = *Member(m, "shard");
  for (const char* key : {"index", "count"})
    if (!is_count(Member(shard, key))) return wrong(std::string("shard.") + key, "a count");
  const Json* layout = Member(shard, "layout");
  if (!layout || !layout->is_string()) return wrong("shard.layout", "a string");
  const Json* rects = Member(shard, "page_rects");
  if (!rects || !rects->is_array()) return wrong("shard.page_rects", "an array");
  for (size_t k = 0; k < rects->size(); ++k) {
    const Json& r = (*rects)[k];
    bool ok = r.is_array() && r.size() == 5;
    for (size_t i = 0; ok && i < 5; ++i) ok = is_count(&r[i]);
    if (!ok) return wrong("shard.page_rects[" + std::to_string(k) + "]", "5 counts");
  }
  const Json* buffers = Member(m, "buffers");
  if (!buffers || !buffers->is_array()) return wrong("buffers", "an array");
  const Json* own = Member(shard, "buffers");
  if (!own || !own->is_array()) return wrong("shard.buffers", "an array");
  for (size_t k = 0; k < own->size(); ++k) {
    const Json& id = (*own)[k];
    const std::string field = "shard.buffers[" + std::to_string(k) + "]";
    if (!is_count(&id) || id.get<size_t>() >= buffers->size())
      return wrong(field, "a buffer's index");
    if (!is_count(Member((*buffers)[id.get<size_t>()], "painted")))
      return wrong("buffers[" + id.dump() + "].painted", "a count");
  }
  for (const char* key : {"texels", "frames", "frames_painted"})
    if (!is_count(Member(m, key))) return wrong(key, "a count");
  const Json* atlas = Member(m, "atlas");
  if (!atlas || !is_count(Member(*atlas, "pages"))) return wrong("atlas.pages", "a count");
  const Json* sizes = Member(*atlas, "page_sizes");
  bool sizes_ok = sizes && sizes->is_array() && sizes->size() == (*atlas)["pages"].get<size_t>();
  for (size_t p = 0; sizes_ok && p < sizes->size(); ++p)
    sizes_ok = (*sizes)[p].is_array() && (*sizes)[p].size() == 2 && is_count(&(*sizes)[p][0]) &&
               is_count(&(*sizes)[p][1]);
  if (!sizes_ok) return wrong("atlas.page_sizes", "a width and height per page");
  const Json* streams = Member(m, "streams");
  if (!streams || !streams->is_array()) return wrong("streams", "an array");
  for (size_t s = 0; s < streams->size(); ++s)
    if (!is_count(Member((*streams)[s], "frames_painted")))
      return wrong("streams[" + std::to_string(s) + "].frames_painted", "a count");
  const Json* stage_ms = Member(m, "stage_ms");
  if (!stage_ms || !stage_ms->is_object()) return wrong("stage_ms", "an object");
  for (const auto& [stage, ms] : stage_ms->items())
    if (!ms.is_number()) return wrong("stage_ms." + stage, "a number");
  return Status::Ok();
}

Status ReadPart(const std::string& dir, Part* part) {
  part->dir = dir;
  const std::string path = dir + "/metrics.json";
  std::string text;
  if (!fs::is_directory(dir)) return Status::Error(dir + ": not a folder (a shard's part)");
  if (!fs::exists(path))
    return Status::Error(path + ": missing (not a finished part of `fresco run --shard`)");
  FRESCO_RETURN_IF_ERROR(ReadFileToString(path, &text));
  part->metrics = Json::parse(text, nullptr, false);
  if (part->metrics.is_discarded()) return Status::Error(path + ": not valid JSON");
  const Json& shard = part->metrics.contains("shard") ? part->metrics["shard"] : Json();
  if (!shard.is_object() || !shard.contains("index") || !shard.contains("count") ||
      !shard.contains("page_rects") || !shard.contains("buffers"))
    return Status::Error(path + ": shard: missing (not written by `fresco run --shard I/N`)");
  FRESCO_RETURN_IF_ERROR(CheckFieldsMergeReads(path, part->metrics));
  part->index = shard["index"].get<int>();
  part->count = shard["count"].get<int>();
  for (const fs::directory_entry& e : fs::directory_iterator(dir))
    if (e.is_regular_file() && e.path().filename() != "metrics.json")
      part->files.push_back(e.path().filename().string());
  std::sort(part->files.begin(), part->files.end());
  return Status::Ok();
}

// The parts in shard order, checked: one project and settings, every shard once.
Status CheckParts(std::vector<Part>* parts) {
  const Part& first = parts->front();
  const Json& a = first.metrics["shard"];
  std::map<int, std::string> seen;
  for (const Part& part : *parts) {
    const Json& b = part.metrics["shard"];
    const std::string where = part.dir + "/metrics.json: shard.";
    if (b["project"] != a["project"])
      return Status::Error(where + "project: " + b["project"].dump() + ", but " + first.dir +
                           " is a part of " + a["project"].dump());
    if (b["settings_hash"] != a["settings_hash"])
      return Status::Error(where + "settings_hash: painted with other settings than " +
                           first.dir + " (" + b["settings_hash"].dump() + " against " +
                           a["settings_hash"].dump() + ")");
    if (part.count != first.count)
      return Status::Error(where + "count: " + std::to_string(part.count) + " shards, but " +
                           first.dir + " is one of " + std::to_string(first.count));
    if (part.index < 0 || part.index >= part.count)
      return Status::Error(where + "index: " + std::to_string(part.index) + " out of 0.." +
                           std::to_string(part.count - 1));
    if (const auto it = seen.find(part.index); it != seen.end())
      return Status::Error(part.dir + ": shard " + std::to_string(part.index) + " of " +
                           std::to_string(part.count) + " repeated (also " + it->second + ")");
    seen[part.index] = part.dir;
  }
  for (int i = 0; i < first.count; ++i)
    if (!seen.count(i))
      return Status::Error("shard " + std::to_string(i) + " of " + std::to_string(first.count) +
                           " missing (parts given: " + std::to_string(parts->size()) + ")");
  std::sort(parts->begin(), parts->end(),
            [](const Part& x, const Part& y) { return x.index < y.index; });
  return Status::Ok();
}

bool IsTexture(const std::string& name) {
  return name.size() > 4 && name.compare(name.size() - 4, 4, ".png") == 0;
}

// Every part of one layout: the same fingerprint of it (shard.layout, LayoutDigest) and the
// same pages; shard 0's part holds the glTF and its .bin, which the others do not write.
Status CheckSameLayout(const std::vector<Part>& parts) {
  const Part& first = parts.front();
  const auto pages = [](const Part& part) {
    std::vector<std::string> names;
    for (const std::string& name : part.files)
      if (IsTexture(name)) names.push_back(name);
    return names;
  };
  const std::vector<std::string> first_pages = pages(first);
  if (std::find(first.files.begin(), first.files.end(), "painted.gltf") == first.files.end())
    return Status::Error(first.dir + ": no painted.gltf (shard 0's part holds it)");
  for (const Part& part : parts) {
    const Json& layout = part.metrics["shard"]["layout"];
    if (layout != first.metrics["shard"]["layout"])
      return Status::Error(part.dir + "/metrics.json: shard.layout: " + layout.dump() + ", but " +
                           first.dir + " has " + first.metrics["shard"]["layout"].dump() +
                           " (not parts of one layout)");
    if (pages(part) != first_pages)
      return Status::Error(part.dir + ": holds other pages than " + first.dir +
                           " (not parts of one run)");
  }
  return Status::Ok();
}

// Texture file `name` (painted_textureT.png): each part holds in it its rectangles on that
// page at StripPositions (ComposeAtlasStrip); they go back in place on a page of zeros (a
// texel of no buffer is zero).
Status JoinTexture(const std::vector<Part>& parts, const std::string& name, int num_pages,
                   const std::string& out_path) {
  const size_t end = name.size() - 4;  // before ".png"
  const size_t first = name.find_last_not_of("0123456789", end - 1) + 1;
  if (first >= end) return Status::Error(parts.front().dir + "/" + name + ": not a page's name");
  const int texture = std::stoi(name.substr(first, end - first));
  const int page = num_pages > 0 ? texture % num_pages : 0;
  const Json& size = parts.front().metrics["atlas"]["page_sizes"][page];
  cv::Mat joined = cv::Mat::zeros(size[1].get<int>(), size[0].get<int>(), CV_8UC4);
  for (const Part& part : parts) {
    const std::string path = part.dir + "/" + name;
    cv::Mat strip;
    if (!ReadImage(path, &strip, cv::IMREAD_UNCHANGED).ok())
      return Status::Error(path + ": cannot read the PNG");
    if (strip.type() != joined.type())
      return Status::Error(path + ": not 8-bit RGBA, as a part's page is");
    std::vector<cv::Rect> rects;
    std::vector<cv::Size> sizes;
    for (const Json& r : part.metrics["shard"]["page_rects"]) {
      if (r[0].get<int>() != page) continue;
      rects.emplace_back(r[1].get<int>(), r[2].get<int>(), r[3].get<int>(), r[4].get<int>());
      sizes.push_back(rects.back().size());
    }
    cv::Size strip_size;
    const std::vector<cv::Point> at = StripPositions(sizes, joined.cols, &strip_size);
    for (size_t k = 0; k < rects.size(); ++k) {
      const cv::Rect from(at[k], rects[k].size());
      if ((rects[k] & cv::Rect(cv::Point(), joined.size())) != rects[k] ||
          strip.size() != strip_size)
        return Status::Error(part.dir + "/metrics.json: shard.page_rects: not the rectangles " +
                             name + " holds");
      strip(from).copyTo(joined(rects[k]));
    }
  }
  std::vector<unsigned char> png;
  if (!EncodeImageBytes(".png", joined, &png))
    return Status::Internal(out_path + ": PNG encoding failed");
  return WriteFileAtomic(out_path, std::string(png.begin(), png.end()));
}

double Number(const Json& j, const char* key) {
  return j.contains(key) && j[key].is_number() ? j[key].get<double>() : 0.0;
}

// metrics.json of the joined run (see the header).
Json JoinMetrics(const std::vector<Part>& parts, MergeResult* result) {
  Json m = parts.front().metrics;
  m.erase("shard");
  m.erase("frames_skipped");
  // Each buffer's figures from the shard that painted it.
  long long painted = 0;
  for (const Part& part : parts)
    for (const Json& b : part.metrics["shard"]["buffers"]) {
      const size_t id = b.get<size_t>();
      m["buffers"][id] = part.metrics["buffers"][id];
      painted += part.metrics["buffers"][id]["painted"].get<long long>();
    }
  const long long texels = m["texels"].get<long long>();
  m["texels_painted"] = painted;
  m["coverage"] = texels > 0 ? static_cast<double>(painted) / texels : 0.0;
  // Frames: every shard read (or skipped) every frame; a frame is painted where some shard
  // painted it (the most any shard painted, with the frames it skipped, as one run paints).
  int frames_painted = 0;
  for (const Part& part : parts)
    frames_painted = std::max(
        frames_painted, part.metrics["frames_painted"].get<int>() +
                            static_cast<int>(Number(part.metrics["shard"], "frames_skipped")));
  m["frames_painted"] = frames_painted;
  for (size_t s = 0; s < m["streams"].size(); ++s) {
    int most = 0;
    for (const Part& part : parts) {
      const Json& stream = part.metrics["streams"][s];
      most = std::max(most, stream["frames_painted"].get<int>() +
                                static_cast<int>(Number(stream, "frames_skipped")));
    }
    m["streams"][s]["frames_painted"] = most;
    m["streams"][s].erase("frames_skipped");
  }
  // Time: the slowest shard's painting loop; stage times per frame summed over the shards.
  double seconds = 0, cpu = 0, rss = 0, wall = 0;
  std::map<std::string, double> stage_sum;
  Json shards = Json::array();
  for (const Part& part : parts) {
    const Json& pm = part.metrics;
    seconds = std::max(seconds, Number(pm, "seconds"));
    cpu += Number(pm["shard"], "cpu_seconds");
    if (pm.contains("peak_rss_mb")) rss = std::max(rss, Number(pm["peak_rss_mb"], "painting"));
    if (pm.contains("wall") && Number(pm["wall"], "seconds") >= wall) {
      wall = Number(pm["wall"], "seconds");
      m["wall"] = pm["wall"];
    }
    for (const auto& [stage, ms] : pm["stage_ms"].items())
      stage_sum[stage] += ms.get<double>() * pm["frames_painted"].get<int>();
    Json shard = pm["shard"];
    shard.erase("page_rects");
    shard["buffers"] = pm["shard"]["buffers"].size();
    shard["part"] = part.dir;
    shard["seconds"] = Number(pm, "seconds");
    shard["frames_painted"] = pm["frames_painted"];
    if (pm.contains("peak_rss_mb")) shard["peak_rss_mb"] = pm["peak_rss_mb"];
    if (pm.contains("wall")) shard["wall_seconds"] = pm["wall"]["seconds"];
    shards.push_back(shard);
    result->mean_shard_seconds += Number(pm, "seconds") / parts.size();
  }
  m["seconds"] = seconds;
  const int frames = m["frames"].get<int>();
  m["fps"] = seconds > 0 ? frames / seconds : 0.0;
  m["paint_fps"] = seconds > 0 ? frames_painted / seconds : 0.0;
  for (const auto& [stage, sum] : stage_sum)
    m["stage_ms"][stage] = frames_painted > 0 ? sum / frames_painted : 0.0;
  if (m.contains("peak_rss_mb")) m["peak_rss_mb"]["painting"] = rss;
  m["shards"] = shards;
  m["merge"] = {{"shards", parts.size()},
                {"cpu_seconds", cpu},
                {"largest_shard_seconds", seconds},
                {"mean_shard_seconds", result->mean_shard_seconds}};
  result->cpu_seconds = cpu;
  result->largest_shard_seconds = seconds;
  return m;
}

}  // namespace

Status MergeParts(const std::vector<std::string>& part_dirs, const std::string& out_dir,
                  MergeResult* result) {
  if (part_dirs.empty()) return Status::Error("fresco merge: no parts given");
  std::vector<Part> parts(part_dirs.size());
  for (size_t i = 0; i < part_dirs.size(); ++i)
    FRESCO_RETURN_IF_ERROR(ReadPart(part_dirs[i], &parts[i]));
  FRESCO_RETURN_IF_ERROR(CheckParts(&parts));
  FRESCO_RETURN_IF_ERROR(CheckSameLayout(parts));
  *result = MergeResult();
  result->shards = static_cast<int>(parts.size());
  const int num_pages = parts.front().metrics["atlas"]["pages"].get<int>();
  FRESCO_RETURN_IF_ERROR(MakeDirectories(out_dir));
  StagedFolder outputs;
  FRESCO_RETURN_IF_ERROR(outputs.Open(out_dir + "/.outputs"));
  for (const std::string& name : parts.front().files) {
    const std::string to = outputs.path() + "/" + name;
    if (IsTexture(name)) {
      FRESCO_RETURN_IF_ERROR(JoinTexture(parts, name, num_pages, to));
      ++result->textures;
      continue;
    }
    std::string contents;
    FRESCO_RETURN_IF_ERROR(ReadFileToString(parts.front().dir + "/" + name, &contents));
    FRESCO_RETURN_IF_ERROR(WriteFileAtomic(to, contents));
  }
  const Json metrics = JoinMetrics(parts, result);
  FRESCO_RETURN_IF_ERROR(WriteFileAtomic(outputs.path() + "/metrics.json", metrics.dump(2) + "\n"));
  return MoveFilesInto(outputs.path(), out_dir, {"metrics.json"});
}

}  // namespace fresco
