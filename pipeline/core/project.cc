// The project file: strict JSON in, pretty JSON out. Each struct's fields are listed once,
// in a `Fields(struct, visitor)` template that both the reader and the writer walk, so the
// two cannot drift apart. The reader rejects unknown keys, wrong types and out-of-range
// values with "FILE: json.path: what is wrong".
#include "pipeline/core/project.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "pipeline/core/atomic_file.h"
#include "pipeline/settings/setting_rule.h"
#include "pipeline/core/settings.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr int kOldestVersion = 1;
constexpr int kProjectVersion = 2;  // the newest this Fresco reads
// Version-1 keys that version 2 replaces by `streams`.
constexpr const char* kStreamKeys[] = {"camera", "video", "poses", "time_offset_s"};

// ---- The fields, each listed once. ----------------------------------------------------------


template <class V>
void Fields(GroupingEdit& e, V& v) {
  v.Field("op", e.op, {.required = true, .choices = {"merge", "split", "move", "texel"}});
  v.Field("triangles", e.triangles, {.min = 0});
  v.Field("groups", e.groups, {.min = 0});
  v.Field("target_group", e.target_group, {.min = -1});
  v.Field("texel_size_m", e.texel_size_m, {.min = 0});
}

template <class V>
void Fields(GroupSpec& g, V& v) {
  v.Field("triangles", g.triangles, {.min = 0});
  v.Field("texel_size_m", g.texel_size_m, {.min = 0});
}

template <class V>
void Fields(GroupingOptions& o, V& v) {
  v.Field("angle_deg", o.angle_deg,
          {.min = 0,
           .max = 180,
           .help = "a neighbouring triangle joins a chart when its normal, smoothed over its "
                   "neighbours (noise averages out, sharp edges stay), is within this of the "
                   "chart's mean; the triangle itself must face the chart's plane (no fold)"});
  v.Field("min_chart_texels", o.min_chart_texels,
          {.min = 0,
           .help = "smaller charts are merged into the neighbour they share most edges with, when "
                   "its plane sees them with a mean stretch of at most `max_stretch` and every "
                   "triangle faces it; what still remains smaller (triangles the noise folded "
                   "over) goes to shared charts, one per axis direction and region; 0 = the "
                   "paper's grouping (§3.6)"});
  v.Field("max_stretch", o.max_stretch,
          {.min = 1,
           .max = 100,
           .help = "texel stretch (1 / cos of the angle to the chart's plane, of the smoothed "
                   "normals) allowed while a chart grows away from its seed and, on average, when "
                   "merging small charts"});
  v.List("groups", o.groups);
  v.List("edits", o.edits);
}

template <class V>
void Fields(TruthFiles& t, V& v) {
  v.Field("poses", t.poses);
}

template <class V>
void Fields(LiveOptions& o, V& v) {
  v.Field("queue_frames", o.queue_frames,
          {.min = 1,
           .max = 1000,
           .help = "frames waiting between the video and the painter; when full the oldest is "
                   "dropped (newest wins) and counted"});
  v.Field("open_timeout_s", o.open_timeout_s,
          {.min = 0, .min_exclusive = true, .help = "the video stream must start within this"});
  v.Field("read_timeout_s", o.read_timeout_s,
          {.min = 0,
           .min_exclusive = true,
           .help = "no frame for this long ends the stream (after `reconnects` attempts)"});
  v.Field("reconnects", o.reconnects, {.min = 0, .help = "times a stalled stream is reopened"});
  v.Field("stream_clock", o.stream_clock,
          {.help = "frame times from the stream's timestamps (else arrival times)"});
  v.Field("connect_timeout_s", o.connect_timeout_s,
          {.min = 0, .help = "the tracker (`tcp://`) must accept the connection within this"});
  v.Field("pose_reconnect_give_up_s", o.pose_reconnect_give_up_s,
          {.min = 0,
           .help = "a tracker that drops is reconnected with backoff (0.1 s doubling to 2 s); no "
                   "connection for this long ends the feed with an error (0 = keep trying)"});
  v.Field("pose_wait_s", o.pose_wait_s,
          {.min = 0, .help = "a frame waits up to this for the tracker to reach its time"});
  v.Field("max_pose_gap_s", o.max_pose_gap_s,
          {.min = 0,
           .min_exclusive = true,
           .help = "no pose is interpolated between samples further apart"});
  v.Field("max_pose_extrapolate_s", o.max_pose_extrapolate_s,
          {.min = 0,
           .help = "a frame this far before the first pose or after the last still gets one, "
                   "extrapolated"});
  v.Field("estimate_offset", o.estimate_offset,
          {.help = "estimate `time_offset_s` from the first frames"});
  v.Field("offset_search_s", o.offset_search_s,
          {.min = 0,
           .min_exclusive = true,
           .max = 60,
           .help = "candidates within ± this of the set `time_offset_s`"});
  v.Field("offset_window_frames", o.offset_window_frames,
          {.min = 4, .max = 1000, .help = "frames used for each estimate"});
  v.Field("track_offset", o.track_offset, {.help = "estimate the offset again during the session"});
  v.Field("offset_track_every_frames", o.offset_track_every_frames,
          {.min = 1,
           .max = 100000,
           .help = "re-estimate every N frames, on the last `offset_window_frames` frames"});
  v.Field("offset_track_search_s", o.offset_track_search_s,
          {.min = 0,
           .min_exclusive = true,
           .max = 60,
           .help = "re-estimation candidates within ± this of the offset in use"});
  v.Field("offset_track_min_gain", o.offset_track_min_gain,
          {.min = 0,
           .max = 1,
           .help = "a new estimate replaces the offset in use only when its score is at least this "
                   "fraction lower"});
}

template <class V>
void Fields(StreamSpec& s, V& v) {
  v.Field("camera", s.camera, {.required = true, .non_empty = true});
  v.Field("video", s.video, {.required = true, .non_empty = true});
  v.Field("poses", s.poses, {.required = true, .non_empty = true});
  v.Field("time_offset_s", s.time_offset_s);
  v.Field("fps", s.fps, {.min = 0, .max = 10000});
}

// camera, video, poses and time_offset_s (version 1) and streams (version 2) are each
// allowed in one version only: ParseProject checks which, ProjectToJsonText writes its own.
template <class V>
void Fields(Project& p, V& v) {
  v.Field("fresco", p.fresco_version, {.required = true});
  v.Field("scene", p.scene, {.required = true, .non_empty = true});
  v.Field("camera", p.camera, {.non_empty = true});
  v.Field("video", p.video, {.non_empty = true});
  v.Field("poses", p.poses, {.non_empty = true});
  v.Field("time_offset_s", p.time_offset_s);
  v.List("streams", p.streams);
  v.Object("pipeline", p.pipeline);
  v.Object("grouping", p.grouping);
  v.Object("truth", p.truth);
  v.Object("live", p.live);
}

// A new member must be added to its Fields() above (read and written) and to the test's
// NonDefaultProject(); then update the size here. (x86-64 Linux sizes.) The stages' settings
// (PipelineOptions and the option structs in their stage headers) need neither: settings_test
// checks that every byte of them is a listed field or padding, and sets every listed setting
// away from its default for the round trip.
static_assert(sizeof(void*) != 8 || sizeof(Project) - sizeof(PipelineOptions) == 424,
              "see Fields(Project)");
static_assert(sizeof(void*) != 8 || sizeof(GroupingEdit) == 96, "see Fields(GroupingEdit)");
static_assert(sizeof(void*) != 8 || sizeof(GroupSpec) == 32, "see Fields(GroupSpec)");
static_assert(sizeof(void*) != 8 || sizeof(GroupingOptions) == 72, "see Fields(GroupingOptions)");
static_assert(sizeof(void*) != 8 || sizeof(TruthFiles) == 32, "see Fields(TruthFiles)");
static_assert(sizeof(void*) != 8 || sizeof(LiveOptions) == 120, "see Fields(LiveOptions)");
static_assert(sizeof(void*) != 8 || sizeof(StreamSpec) == 112, "see Fields(StreamSpec)");

// ---- Writing. -------------------------------------------------------------------------------

class JsonWriter {
 public:
  explicit JsonWriter(Json* object) : object_(object) { *object_ = Json::object(); }

  template <class T>
  void Field(const char* key, const T& value, const Rule& = {}) {
    (*object_)[key] = value;
  }
  template <class E>
  void Enum(const char* key, const E& value, const EnumNames<E>& names, const char* /*help*/ = "") {
    for (const auto& [e, name] : names) {
      if (e == value) (*object_)[key] = name;
    }
  }
  template <class T>
  void Object(const char* key, T& value) {
    JsonWriter sub(&(*object_)[key]);
    Fields(value, sub);
  }
  template <class T>
  void List(const char* key, std::vector<T>& values) {
    Json array = Json::array();
    for (T& value : values) {
      Json item;
      JsonWriter sub(&item);
      Fields(value, sub);
      array.push_back(std::move(item));
    }
    (*object_)[key] = std::move(array);
  }

 private:
  Json* object_;
};

// ---- Reading. -------------------------------------------------------------------------------

std::string Describe(const Json& j) {
  std::string kind;
  switch (j.type()) {
    case Json::value_t::null:
      return "null";
    case Json::value_t::boolean:
      kind = "boolean";
      break;
    case Json::value_t::number_integer:
    case Json::value_t::number_unsigned:
    case Json::value_t::number_float:
      kind = "number";
      break;
    case Json::value_t::string:
      kind = "string";
      break;
    case Json::value_t::array:
      return "array";
    case Json::value_t::object:
      return "object";
    default:
      return "invalid value";
  }
  std::string text = j.dump();
  if (text.size() > 40) text = text.substr(0, 37) + "...";
  return kind + " " + text;
}

std::string FormatNumber(double value) {
  Json j = value;
  if (value == std::floor(value) && std::abs(value) < 1e15) j = static_cast<long long>(value);
  return j.dump();
}

int EditDistance(const std::string& a, const std::string& b) {
  std::vector<int> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = static_cast<int>(j);
  for (size_t i = 1; i <= a.size(); ++i) {
    int diagonal = row[0];
    row[0] = static_cast<int>(i);
    for (size_t j = 1; j <= b.size(); ++j) {
      const int up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] != b[j - 1])});
      diagonal = up;
    }
  }
  return row[b.size()];
}

// True when JSON path `inner` is `outer` or inside it ("a.b[2].c" is within "a.b").
bool Within(const std::string& inner, const std::string& outer) {
  if (inner.rfind(outer, 0) != 0) return false;
  return inner.size() == outer.size() || inner[outer.size()] == '.' || inner[outer.size()] == '[';
}

// Shared by every object level of one parse: the file name, which JSON paths came from
// --set, and the first error.
struct ReadContext {
  std::string file;
  std::map<std::string, std::string> overridden;  // JSON path -> "KEY=VALUE" as given
  Status status;

  void Fail(const std::string& path, const std::string& what) {
    if (!status.ok()) return;
    std::string message = file + ": " + path + ": " + what;
    for (const auto& [set_path, arg] : overridden) {
      if (Within(path, set_path) || Within(set_path, path)) {
        message += " (from --set " + arg + ")";
        break;
      }
    }
    status = Status::Error(message);
  }
};

std::string ChildPath(const std::string& parent, const std::string& key) {
  return parent.empty() ? key : parent + "." + key;
}

class JsonReader {
 public:
  JsonReader(const Json& object, std::string path, ReadContext* context)
      : object_(object), path_(std::move(path)), context_(context) {}

  void Field(const char* key, bool& value, const Rule& rule = {}) {
    const Json* j = Find(key, rule);
    if (!j) return;
    if (!j->is_boolean()) return Fail(key, "expected true or false, got " + Describe(*j));
    value = j->get<bool>();
  }

  void Field(const char* key, int& value, const Rule& rule = {}) {
    const Json* j = Find(key, rule);
    if (j) ReadInt(*j, ChildPath(path_, key), rule, &value);
  }

  void Field(const char* key, double& value, const Rule& rule = {}) {
    const Json* j = Find(key, rule);
    if (!j) return;
    if (!j->is_number()) return Fail(key, "expected a number, got " + Describe(*j));
    const double v = j->get<double>();
    if (!std::isfinite(v)) return Fail(key, "not a finite number");
    if (CheckRange(ChildPath(path_, key), v, rule)) value = v;
  }

  void Field(const char* key, std::string& value, const Rule& rule = {}) {
    const Json* j = Find(key, rule);
    if (!j) return;
    if (!j->is_string()) return Fail(key, "expected a string, got " + Describe(*j));
    const std::string v = j->get<std::string>();
    if (rule.non_empty && v.empty()) return Fail(key, "must not be empty");
    if (!rule.choices.empty() &&
        std::find(rule.choices.begin(), rule.choices.end(), v) == rule.choices.end()) {
      return Fail(key, "'" + v + "' is not one of " + JoinChoices(rule.choices));
    }
    value = v;
  }

  void Field(const char* key, std::vector<int>& values, const Rule& rule = {}) {
    const Json* j = Find(key, rule);
    if (!j) return;
    if (!j->is_array()) return Fail(key, "expected an array of integers, got " + Describe(*j));
    std::vector<int> result(j->size());
    for (size_t i = 0; i < j->size(); ++i) {
      const std::string path = ChildPath(path_, key) + "[" + std::to_string(i) + "]";
      if (!ReadInt((*j)[i], path, rule, &result[i])) return;
    }
    values = std::move(result);
  }

  template <class E>
  void Enum(const char* key, E& value, const EnumNames<E>& names, const char* /*help*/ = "") {
    const Json* j = Find(key, {});
    if (!j) return;
    std::vector<std::string> choices;
    for (const auto& entry : names) choices.push_back(entry.second);
    if (!j->is_string()) {
      return Fail(key, "expected one of " + JoinChoices(choices) + ", got " + Describe(*j));
    }
    const std::string name = j->get<std::string>();
    for (const auto& [e, n] : names) {
      if (n == name) {
        value = e;
        return;
      }
    }
    Fail(key, "'" + name + "' is not one of " + JoinChoices(choices));
  }

  template <class T>
  void Object(const char* key, T& value) {
    const Json* j = Find(key, {});
    if (!j) return;
    if (!j->is_object()) return Fail(key, "expected an object, got " + Describe(*j));
    JsonReader sub(*j, ChildPath(path_, key), context_);
    Fields(value, sub);
    sub.Finish();
  }

  template <class T>
  void List(const char* key, std::vector<T>& values) {
    const Json* j = Find(key, {});
    if (!j) return;
    if (!j->is_array()) return Fail(key, "expected an array, got " + Describe(*j));
    std::vector<T> result;
    for (size_t i = 0; i < j->size() && context_->status.ok(); ++i) {
      const std::string path = ChildPath(path_, key) + "[" + std::to_string(i) + "]";
      const Json& item = (*j)[i];
      if (!item.is_object()) {
        context_->Fail(path, "expected an object, got " + Describe(item));
        return;
      }
      T value{};
      JsonReader sub(item, path, context_);
      Fields(value, sub);
      sub.Finish();
      result.push_back(std::move(value));
    }
    values = std::move(result);
  }

  // Reports keys that no field asked for (typos must not pass silently), then a missing
  // required key (a typo in a required key's name is reported as the typo).
  void Finish() {
    for (const auto& [key, value] : object_.items()) {
      if (std::find(known_.begin(), known_.end(), key) != known_.end()) continue;
      std::string what = "unknown key";
      std::string best;
      int best_distance = 3;
      for (const std::string& candidate : known_) {
        const int d = EditDistance(key, candidate);
        if (d < best_distance) best_distance = d, best = candidate;
      }
      if (!best.empty()) what += " (did you mean '" + best + "'?)";
      context_->Fail(ChildPath(path_, key), what);
      return;
    }
    if (!missing_.empty()) Fail(missing_.c_str(), "missing required key");
  }

 private:
  const Json* Find(const char* key, const Rule& rule) {
    known_.push_back(key);
    if (!context_->status.ok()) return nullptr;
    const auto it = object_.find(key);
    if (it == object_.end()) {
      if (rule.required && missing_.empty()) missing_ = key;
      return nullptr;
    }
    return &*it;
  }

  void Fail(const char* key, const std::string& what) {
    context_->Fail(ChildPath(path_, key), what);
  }

  bool ReadInt(const Json& j, const std::string& path, const Rule& rule, int* value) {
    double v = 0;
    if (j.is_number_integer()) {
      v = j.is_number_unsigned() ? static_cast<double>(j.get<unsigned long long>())
                                 : static_cast<double>(j.get<long long>());
    } else if (j.is_number_float() && std::isfinite(j.get<double>()) &&
               j.get<double>() == std::floor(j.get<double>())) {
      v = j.get<double>();  // 20.0 is the integer 20
    } else {
      context_->Fail(path, "expected an integer, got " + Describe(j));
      return false;
    }
    if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max()) {
      context_->Fail(path, "integer out of range");
      return false;
    }
    if (!CheckRange(path, v, rule)) return false;
    *value = static_cast<int>(v);
    return true;
  }

  bool CheckRange(const std::string& path, double v, const Rule& rule) {
    const bool below = rule.min_exclusive ? !(v > rule.min) : !(v >= rule.min);
    if (below || v > rule.max) {
      std::string range;
      if (rule.max == kInf) {
        range = (rule.min_exclusive ? "> " : ">= ") + FormatNumber(rule.min);
      } else {
        range = std::string("in ") + (rule.min_exclusive ? "(" : "[") + FormatNumber(rule.min) +
                ", " + FormatNumber(rule.max) + "]";
      }
      context_->Fail(path, "must be " + range + ", got " + FormatNumber(v));
      return false;
    }
    return true;
  }

  static std::string JoinChoices(const std::vector<std::string>& choices) {
    std::string out;
    for (size_t i = 0; i < choices.size(); ++i) {
      out += (i == 0 ? "\"" : i + 1 == choices.size() ? " or \"" : ", \"") + choices[i] + "\"";
    }
    return out;
  }

  const Json& object_;
  std::string path_;
  ReadContext* context_;
  std::vector<std::string> known_;
  std::string missing_;  // the first required key not found
};

// ---- Parsing the text: malformed JSON and duplicate keys. -----------------------------------

struct DuplicateKeyFinder {
  struct Level {
    bool is_array = false;
    int index = -1;
    std::string key;
    std::set<std::string> keys;
  };
  std::vector<Level> levels;
  std::string duplicate_path;  // first duplicate, "" if none

  std::string Path() const {
    std::string path;
    for (const Level& level : levels) {
      if (level.is_array) {
        path += "[" + std::to_string(level.index) + "]";
      } else {
        path += (path.empty() ? "" : ".") + level.key;
      }
    }
    return path;
  }
  void CountArrayItem() {
    if (!levels.empty() && levels.back().is_array) ++levels.back().index;
  }
  bool operator()(int, Json::parse_event_t event, Json& parsed) {
    switch (event) {
      case Json::parse_event_t::object_start:
      case Json::parse_event_t::array_start:
        CountArrayItem();
        levels.push_back({event == Json::parse_event_t::array_start, -1, "", {}});
        break;
      case Json::parse_event_t::object_end:
      case Json::parse_event_t::array_end:
        if (!levels.empty()) levels.pop_back();
        break;
      case Json::parse_event_t::key:
        if (!levels.empty()) {
          Level& level = levels.back();
          level.key = parsed.get<std::string>();
          if (!level.keys.insert(level.key).second && duplicate_path.empty()) {
            duplicate_path = Path();
          }
        }
        break;
      case Json::parse_event_t::value:
        CountArrayItem();
        break;
    }
    return true;
  }
};

Status ParseJsonText(const std::string& text, const std::string& name, Json* json) {
  DuplicateKeyFinder finder;
  try {
    *json = Json::parse(text, std::ref(finder));
  } catch (const Json::parse_error& e) {
    const size_t byte = std::min<size_t>(e.byte > 0 ? e.byte - 1 : 0, text.size());
    const size_t line = 1 + std::count(text.begin(), text.begin() + byte, '\n');
    const size_t line_start = text.rfind('\n', byte == 0 ? 0 : byte - 1);
    const size_t column =
        line_start == std::string::npos || byte == 0 ? byte + 1 : byte - line_start;
    std::string what = e.what();
    const size_t colon = what.find(": ", what.find("column"));
    if (colon != std::string::npos) what = what.substr(colon + 2);
    return Status::Error(name + ": line " + std::to_string(line) + ", column " +
                         std::to_string(column) + ": malformed JSON: " + what);
  } catch (const Json::exception& e) {
    // Not a syntax error but a value JSON cannot hold here (e.g. 1e999: "number overflow").
    std::string what = e.what();
    const size_t bracket = what.find("] ");
    if (bracket != std::string::npos) what = what.substr(bracket + 2);
    return Status::Error(name + ": malformed JSON: " + what);
  }
  if (!finder.duplicate_path.empty()) {
    return Status::Error(name + ": " + finder.duplicate_path + ": duplicate key");
  }
  return Status::Ok();
}

// ---- --set KEY=VALUE. -----------------------------------------------------------------------

Status ApplyOverride(const std::string& arg, Json* root, ReadContext* context) {
  const size_t eq = arg.find('=');
  if (eq == std::string::npos || eq == 0) {
    return Status::Error("--set " + arg + ": expected KEY=VALUE (e.g. pipeline.update_every=20)");
  }
  const std::string key = arg.substr(0, eq);
  const std::string text = arg.substr(eq + 1);
  Json value = Json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (value.is_discarded()) value = text;  // not JSON: a string

  std::vector<std::string> segments;
  for (size_t start = 0;;) {
    const size_t dot = key.find('.', start);
    segments.push_back(key.substr(start, dot == std::string::npos ? dot : dot - start));
    if (dot == std::string::npos) break;
    start = dot + 1;
  }
  Json* node = root;
  std::string path;
  for (size_t i = 0; i < segments.size(); ++i) {
    const std::string& segment = segments[i];
    const bool last = i + 1 == segments.size();
    if (segment.empty()) return Status::Error("--set " + arg + ": empty name in '" + key + "'");
    if (node->is_object()) {
      path = ChildPath(path, segment);
      if (last) {
        (*node)[segment] = value;
      } else {
        // A missing object is created; unknown names are caught by validation.
        if (!node->contains(segment)) {
          const std::string& next = segments[i + 1];
          if (!next.empty() && next.find_first_not_of("0123456789") == std::string::npos) {
            return Status::Error("--set " + arg + ": " + path + ": no element '" + next +
                                 "' (the file has no " + path + ")");
          }
          (*node)[segment] = Json::object();
        }
        node = &(*node)[segment];
      }
    } else if (node->is_array()) {
      size_t index = 0;
      const bool numeric = segment.find_first_not_of("0123456789") == std::string::npos;
      if (numeric) index = std::stoul(segment);
      if (!numeric || index >= node->size()) {
        return Status::Error("--set " + arg + ": " + path + ": no element '" + segment +
                             "' (array of " + std::to_string(node->size()) + ")");
      }
      path += "[" + segment + "]";
      if (last) {
        (*node)[index] = value;
      } else {
        node = &(*node)[index];
      }
    } else {
      return Status::Error("--set " + arg + ": " + path + ": is a " + Describe(*node) +
                           ", not an object");
    }
  }
  context->overridden[path] = arg;
  return Status::Ok();
}

std::string AbsoluteNormal(const std::string& path) {
  std::error_code ec;
  fs::path absolute = fs::absolute(path, ec);
  if (ec) absolute = path;
  return absolute.lexically_normal().string();
}

// Re-expresses a path written relative to `old_folder` relative to `new_folder`.
std::string Rebase(const std::string& path, const fs::path& old_folder,
                   const fs::path& new_folder) {
  if (path.empty() || IsUrlOrDevice(path) || fs::path(path).is_absolute()) return path;
  if (old_folder == new_folder) return path;
  const fs::path target = (old_folder / path).lexically_normal();
  const fs::path relative = target.lexically_relative(new_folder);
  if (relative.empty()) return target.string();
  std::string result = relative.string();
  if (path.back() == '/' && (result.empty() || result.back() != '/')) result += '/';
  return result;
}

// Version 1 names its one stream at the top level, version 2 lists `streams` instead.
void CheckVersionKeys(const Json& root, const Project& project, ReadContext* context) {
  if (project.fresco_version == 1) {
    if (root.contains("streams")) {
      return context->Fail("streams",
                           "needs \"fresco\": 2 (version 1 names one stream with "
                           "top-level camera, video and poses)");
    }
    for (const char* key : {"camera", "video", "poses"}) {
      if (!root.contains(key)) return context->Fail(key, "missing required key");
    }
    return;
  }
  for (const char* key : kStreamKeys) {
    if (root.contains(key)) {
      return context->Fail(key, std::string("not allowed in version 2 (each entry of streams "
                                            "has its own ") +
                                    key + ")");
    }
  }
  if (!root.contains("streams")) return context->Fail("streams", "missing required key");
  if (project.streams.empty()) return context->Fail("streams", "must list at least one stream");
}

}  // namespace

std::string SamplingModeName(SamplingMode mode) {
  for (const auto& [m, name] : SamplingNames()) {
    if (m == mode) return name;
  }
  return "unknown";
}

std::string BackgroundModeName(BackgroundMode mode) {
  for (const auto& [m, name] : BackgroundModeNames()) {
    if (m == mode) return name;
  }
  return "unknown";
}

bool SamplingModeFromName(const std::string& name, SamplingMode* mode) {
  for (const auto& [m, n] : SamplingNames()) {
    if (n == name) {
      *mode = m;
      return true;
    }
  }
  return false;
}

bool IsUrlOrDevice(const std::string& path) {
  return path.find("://") != std::string::npos || path.rfind("device:", 0) == 0;
}

std::string Project::Resolve(const std::string& relative) const {
  if (relative.empty() || IsUrlOrDevice(relative) || fs::path(relative).is_absolute()) {
    return relative;
  }
  if (file_path.empty()) return relative;
  return (fs::path(file_path).parent_path() / relative).lexically_normal().string();
}

Status CheckOneStream(const Project& project, const std::string& who) {
  const size_t count = project.Streams().size();
  if (count == 1) return Status::Ok();
  const std::string name = project.file_path.empty() ? "project" : project.file_path;
  return Status::Error(name + ": streams: " + std::to_string(count) + " video streams, but " + who +
                       " reads one (fresco run paints several)");
}

std::vector<StreamSpec> Project::Streams() const {
  if (fresco_version >= 2) return streams;
  return {StreamSpec{camera, video, poses, time_offset_s}};
}

std::string Project::StreamKey(int index, const std::string& key) const {
  if (fresco_version < 2) return key;
  return "streams[" + std::to_string(index) + "]." + key;
}

Project Project::ForStream(int index) const {
  const std::vector<StreamSpec> all = Streams();
  if (index < 0 || index >= static_cast<int>(all.size())) {
    throw std::out_of_range("Project::ForStream: no stream " + std::to_string(index));
  }
  Project view = *this;
  view.fresco_version = 1;
  view.camera = all[index].camera;
  view.video = all[index].video;
  view.poses = all[index].poses;
  view.time_offset_s = all[index].time_offset_s;
  view.streams.clear();
  return view;
}

Status ParseProject(const std::string& text, const std::string& name,
                    const std::vector<std::string>& overrides, Project* project) {
  Json root;
  FRESCO_RETURN_IF_ERROR(ParseJsonText(text, name, &root));
  if (!root.is_object()) {
    return Status::Error(name + ": expected a JSON object at the top level, got " + Describe(root));
  }
  ReadContext context;
  context.file = name;
  for (const std::string& arg : overrides) {
    Status applied = ApplyOverride(arg, &root, &context);
    if (!applied.ok()) return Status::Error(name + ": " + applied.message());
  }
  Project result;
  JsonReader reader(root, "", &context);
  Fields(result, reader);
  reader.Finish();
  if (context.status.ok() &&
      (result.fresco_version < kOldestVersion || result.fresco_version > kProjectVersion)) {
    context.Fail("fresco", "unsupported version " + std::to_string(result.fresco_version) +
                               " (this Fresco reads versions " + std::to_string(kOldestVersion) +
                               " and " + std::to_string(kProjectVersion) + ")");
  }
  if (context.status.ok()) CheckVersionKeys(root, result, &context);
  FRESCO_RETURN_IF_ERROR(context.status);
  result.file_path = AbsoluteNormal(name);
  *project = std::move(result);
  return Status::Ok();
}

Status LoadProject(const std::string& path, const std::vector<std::string>& overrides,
                   Project* project) {
  std::string text;
  FRESCO_RETURN_IF_ERROR(ReadFileToString(path, &text));
  return ParseProject(text, path, overrides, project);
}

std::string ProjectToJsonText(const Project& project) {
  Project copy = project;
  Json root;
  JsonWriter writer(&root);
  Fields(copy, writer);
  if (project.fresco_version >= 2) {
    for (const char* key : kStreamKeys) root.erase(key);
  } else {
    root.erase("streams");
  }
  return root.dump(2) + "\n";
}

Status SaveProject(const Project& project, const std::string& path) {
  Project moved = project;
  const std::string new_file = AbsoluteNormal(path);
  if (!project.file_path.empty()) {
    const fs::path old_folder = fs::path(project.file_path).parent_path();
    const fs::path new_folder = fs::path(new_file).parent_path();
    std::vector<std::string*> paths = {&moved.scene, &moved.camera, &moved.video, &moved.poses,
                                       &moved.truth.poses};
    for (StreamSpec& stream : moved.streams) {
      for (std::string* p : {&stream.camera, &stream.video, &stream.poses}) paths.push_back(p);
    }
    for (std::string* p : paths) *p = Rebase(*p, old_folder, new_folder);
  }
  return WriteFileAtomic(path, ProjectToJsonText(moved));
}

// ---- The settings catalogue. ----------------------------------------------------------------

namespace {

// Walks the same Fields() as the reader and writer, recording every scalar setting with its
// rule and help, bound to the fields of the object walked.
class SettingsCollector {
 public:
  SettingsCollector(std::string prefix, std::vector<Setting>* out)
      : prefix_(std::move(prefix)), out_(out) {}

  void Field(const char* key, bool& value, const Rule& rule = {}) {
    Setting& s = Add(key, Setting::Kind::kBool, rule);
    s.flag = &value;
  }
  void Field(const char* key, int& value, const Rule& rule = {}) {
    Setting& s = Add(key, Setting::Kind::kInt, rule);
    s.integer = &value;
  }
  void Field(const char* key, double& value, const Rule& rule = {}) {
    Setting& s = Add(key, Setting::Kind::kNumber, rule);
    s.number = &value;
  }
  void Field(const char* key, std::string& value, const Rule& rule = {}) {
    Setting& s = Add(key, Setting::Kind::kText, rule);
    s.text = &value;
  }
  void Field(const char*, std::vector<int>&, const Rule& = {}) {}  // lists: not a setting
  template <class E>
  void Enum(const char* key, E& value, const EnumNames<E>& names, const char* help = "") {
    Setting& s = Add(key, Setting::Kind::kChoice, Rule{.help = help});
    for (const auto& entry : names) s.choices.push_back(entry.second);
    s.get_choice = [&value, &names] {
      for (size_t i = 0; i < names.size(); ++i)
        if (names[i].first == value) return static_cast<int>(i);
      return 0;
    };
    s.set_choice = [&value, &names](int i) {
      if (i >= 0 && i < static_cast<int>(names.size())) value = names[i].first;
    };
  }
  template <class T>
  void Object(const char* key, T& value) {
    SettingsCollector sub(prefix_ + key + ".", out_);
    Fields(value, sub);
  }
  template <class T>
  void List(const char*, std::vector<T>&) {}  // lists (groups, edits, streams): not settings

 private:
  Setting& Add(const char* key, Setting::Kind kind, const Rule& rule) {
    Setting s;
    s.key = prefix_ + key;
    s.kind = kind;
    s.min = rule.min;
    s.min_exclusive = rule.min_exclusive;
    s.max = rule.max;
    s.choices = rule.choices;
    s.help = rule.help;
    out_->push_back(std::move(s));
    return out_->back();
  }

  std::string prefix_;
  std::vector<Setting>* out_;
};

}  // namespace

namespace {
// Where the listed fields of a struct are, byte by byte (ListedFieldBytes).
struct FieldBytesCollector {
  const char* base;
  std::vector<std::pair<size_t, size_t>>* spans;
  template <class T>
  void Field(const char*, T& value, const Rule& = {}) {
    Add(value);
  }
  template <class E>
  void Enum(const char*, E& value, const EnumNames<E>&, const char*) {
    Add(value);
  }
  template <class T>
  void Object(const char*, T& value) {
    Fields(value, *this);
  }
  template <class T>
  void List(const char*, std::vector<T>& values) {
    Add(values);
  }
  template <class T>
  void Add(const T& value) {
    spans->emplace_back(reinterpret_cast<const char*>(&value) - base, sizeof(T));
  }
};
}  // namespace

std::vector<std::pair<size_t, size_t>> ListedFieldBytes(PipelineOptions* options) {
  std::vector<std::pair<size_t, size_t>> spans;
  FieldBytesCollector collector{reinterpret_cast<const char*>(options), &spans};
  Fields(*options, collector);
  return spans;
}

std::vector<Setting> DescribeSettings(Project* project) {
  std::vector<Setting> settings;
  SettingsCollector pipeline("pipeline.", &settings);
  Fields(project->pipeline, pipeline);
  SettingsCollector grouping("grouping.", &settings);
  Fields(project->grouping, grouping);
  SettingsCollector live("live.", &settings);
  Fields(project->live, live);
  return settings;
}

}  // namespace fresco
