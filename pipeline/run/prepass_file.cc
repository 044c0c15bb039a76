#include "pipeline/run/prepass_file.h"

#include <algorithm>
#include <array>
#include <cstdint>

#include <opencv2/imgcodecs.hpp>

#include "pipeline/core/atomic_file.h"
#include "pipeline/core/image_codecs.h"
#include "pipeline/paint/mover_masks.h"
#include "pipeline/run/shard.h"

namespace fresco {
namespace {

using nlohmann::json;

constexpr int kPrepassFormat = 2;
constexpr char kBase64[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

std::string Base64(const std::vector<uchar>& bytes) {
  std::string text;
  for (size_t i = 0; i < bytes.size(); i += 3) {
    const size_t n = std::min<size_t>(3, bytes.size() - i);
    unsigned v = bytes[i] << 16 | (n > 1 ? bytes[i + 1] << 8 : 0) | (n > 2 ? bytes[i + 2] : 0);
    for (size_t k = 0; k < 4; ++k) text += k <= n ? kBase64[(v >> (18 - 6 * k)) & 63] : '=';
  }
  return text;
}

bool FromBase64(const std::string& text, std::vector<uchar>* bytes) {
  static const std::array<int8_t, 256> kValue = [] {
    std::array<int8_t, 256> value;
    value.fill(-1);
    for (int i = 0; i < 64; ++i) value[static_cast<uchar>(kBase64[i])] = static_cast<int8_t>(i);
    return value;
  }();
  if (text.size() % 4 != 0) return false;
  bytes->clear();
  bytes->reserve(text.size() / 4 * 3);
  for (size_t i = 0; i < text.size(); i += 4) {
    unsigned v = 0;
    int pad = 0;
    for (size_t k = 0; k < 4; ++k) {
      const char c = text[i + k];
      const int value = kValue[static_cast<uchar>(c)];
      if (c == '=')
        ++pad;
      else if (value < 0 || pad > 0)
        return false;
      v = v << 6 | static_cast<unsigned>(std::max(value, 0));
    }
    if (pad > 2 || (pad > 0 && i + 4 != text.size())) return false;
    for (int k = 0; k < 3 - pad; ++k) bytes->push_back(static_cast<uchar>(v >> (16 - 8 * k)));
  }
  return true;
}

json PoseJson(const Rigid3d& pose) {
  const Eigen::Quaterniond& q = pose.rotation;
  const Eigen::Vector3d& t = pose.translation;
  return {q.w(), q.x(), q.y(), q.z(), t.x(), t.y(), t.z()};
}

// Bad input naming the file and the field.
Status Bad(const std::string& path, const std::string& field, const std::string& what) {
  return Status::Error(path + ": " + field + ": " + what);
}

// Triangle numbers as one base64 string of their differences (zigzag LEB128 varints): every
// shard reads the layout, and a JSON parser takes a character at a time (a chart's triangles
// mostly follow each other closely: a byte or two each, against 7 characters as numbers).
std::string PackNumbers(const std::vector<int>& numbers) {
  std::vector<uchar> bytes;
  bytes.reserve(numbers.size() * 2);
  int64_t previous = 0;
  for (const int n : numbers) {
    const int64_t delta = n - previous;
    previous = n;
    uint64_t v =
        delta < 0 ? ~(static_cast<uint64_t>(delta) << 1) : static_cast<uint64_t>(delta) << 1;
    for (; v >= 0x80; v >>= 7) bytes.push_back(static_cast<uchar>(v | 0x80));
    bytes.push_back(static_cast<uchar>(v));
  }
  return Base64(bytes);
}

// The numbers PackNumbers wrote; false if `text` is not such a list.
bool UnpackNumbers(const std::string& text, std::vector<int>* numbers) {
  std::vector<uchar> bytes;
  if (!FromBase64(text, &bytes)) return false;
  numbers->clear();
  int64_t previous = 0;
  for (size_t at = 0; at < bytes.size();) {
    uint64_t v = 0;
    for (int shift = 0;; shift += 7) {
      if (at == bytes.size() || shift > 35) return false;
      v |= static_cast<uint64_t>(bytes[at] & 0x7f) << shift;
      if (!(bytes[at++] & 0x80)) break;
    }
    const int64_t n =
        previous + ((v & 1) ? ~static_cast<int64_t>(v >> 1) : static_cast<int64_t>(v >> 1));
    if (n < INT32_MIN || n > INT32_MAX) return false;
    numbers->push_back(static_cast<int>(n));
    previous = n;
  }
  return true;
}

// The buffers' layout (PaintSession::Layout): exact, the texel size's double as written.
json LayoutJson(const BufferLayout& layout) {
  json buffers = json::array();
  for (const BufferRecipe& r : layout.recipes)
    buffers.push_back({{"placed", PackNumbers(r.placed)},
                       {"folded", PackNumbers(r.folded)},
                       {"group_texel_size_m", r.group_texel_size_m},
                       {"surface_texels", r.num_surface_texels}});
  return {{"texel_size_m", layout.texel_size_m},
          {"folds_split", layout.folds_split},
          {"buffers", buffers}};
}

// Parses the file (without its layout unless `with_layout`: most of it, read once) and checks
// it was written for `project` and its settings.
Status ReadHeader(const std::string& path, const Project& project, bool with_layout, json* file) {
  std::string text;
  FRESCO_RETURN_IF_ERROR(ReadFileToString(path, &text));
  const json::parser_callback_t skip_layout = [](int depth, json::parse_event_t event,
                                                 json& parsed) {
    return !(depth == 1 && event == json::parse_event_t::key && parsed == "layout");
  };
  *file = json::parse(text, with_layout ? nullptr : skip_layout, /*allow_exceptions=*/false);
  if (file->is_discarded() || !file->is_object())
    return Status::Error(path + ": not a pre-pass file (fresco run --prepass writes them)");
  if (file->value("fresco_prepass", 0) != kPrepassFormat)
    return Bad(path, "fresco_prepass", "not format " + std::to_string(kPrepassFormat));
  const std::string hash = SettingsHash(project);
  if (file->value("settings_hash", std::string()) != hash)
    return Bad(path, "settings_hash",
               "written for another project or other settings (" +
                   file->value("settings_hash", std::string("none")) + ", not " + hash + " of " +
                   project.file_path + ")");
  return Status::Ok();
}

}  // namespace

Status ReadPrepassLayout(const std::string& path, const Project& project, int num_triangles,
                         std::optional<BufferLayout>* layout) {
  layout->reset();
  json file;
  FRESCO_RETURN_IF_ERROR(ReadHeader(path, project, /*with_layout=*/true, &file));
  if (!file.contains("layout")) return Status::Ok();
  BufferLayout out;
  try {
    const json& l = file["layout"];
    out.texel_size_m = l.at("texel_size_m").get<double>();
    out.folds_split = l.at("folds_split").get<int>();
    for (const json& b : l.at("buffers")) {
      BufferRecipe r;
      if (!UnpackNumbers(b.at("placed").get_ref<const std::string&>(), &r.placed) ||
          !UnpackNumbers(b.at("folded").get_ref<const std::string&>(), &r.folded))
        return Bad(path, "layout.buffers[" + std::to_string(out.recipes.size()) + "]",
                   "not lists of triangle numbers");
      r.group_texel_size_m = b.at("group_texel_size_m").get<double>();
      r.num_surface_texels = b.at("surface_texels").get<int>();
      out.recipes.push_back(std::move(r));
    }
  } catch (const std::exception& e) {
    return Bad(path, "layout", std::string("not a layout of charts (") + e.what() + ")");
  }
  if (!(out.texel_size_m > 0)) return Bad(path, "layout.texel_size_m", "not positive");
  for (size_t b = 0; b < out.recipes.size(); ++b) {
    const BufferRecipe& r = out.recipes[b];
    bool ok = !r.placed.empty();
    for (int t : r.placed) ok = ok && t >= 0 && t < num_triangles;
    if (!ok)
      return Bad(path, "layout.buffers[" + std::to_string(b) + "].placed",
                 "not triangles of the mesh (" + std::to_string(num_triangles) + ")");
  }
  *layout = std::move(out);
  return Status::Ok();
}

bool NeedsWholeCapturePrepass(const Project& project) {
  return !IsLiveProject(project) &&
         (project.pipeline.refine.joint || NeedsMoversAcrossViews(project.pipeline.background));
}

json PoseAdjustSummaryJson(const PoseAdjustResult& a) {
  return {{"applied", a.applied},
          {"not_run", a.not_run},
          {"matches", a.matches},
          {"inliers", a.inliers},
          {"check_matches", a.check_matches},
          {"check_before_px", a.check_before_px},
          {"check_after_px", a.check_after_px},
          {"check_one_end_px", a.check_one_end_px},
          {"check_seconds", a.check_seconds},
          {"rms_before_px", a.rms_before_px},
          {"rms_after_px", a.rms_after_px},
          {"median_rotation_deg", a.median_rotation_deg},
          {"median_translation_m", a.median_translation_m},
          {"rotation_prior_deg", a.rotation_prior_deg},
          {"translation_prior_m", a.translation_prior_m},
          {"decided_on_frames", a.decided_on_frames},
          {"seconds", a.seconds}};
}

Status WritePrepassFile(const std::string& path, const Project& project, const PaintJob& job) {
  json file = {{"fresco_prepass", kPrepassFormat},
               {"project", project.file_path},
               {"settings_hash", SettingsHash(project)}};
  file["layout"] = LayoutJson(job.session->Layout());
  const PaintJob::PrepassDecisions& d = job.prepass;
  if (job.joint_poses) {
    file["joint_poses"] = PoseAdjustSummaryJson(*job.joint_poses);
    file["joint_poses"]["frames"] = job.joint_poses->cam_from_local.size();
  }
  if (job.mover_masks) {
    const MoverMaskResult& m = *job.mover_masks;
    file["movers_across_views"] = {{"not_run", m.not_run},
                                   {"judged", m.judged},
                                   {"flagged", m.flagged},
                                   {"compact", m.compact},
                                   {"frames_judged", m.frames_judged},
                                   {"seconds", m.seconds}};
  }
  if (d.pose_check) {
    const auto& [ratio, threshold, frames] = *d.pose_check;
    file["pose_check"] = {ratio, threshold, frames};
  }
  if (d.background_across_views)
    file["background_across_views"] = {d.background_across_views->first,
                                       d.background_across_views->second};
  // Every pose as painting takes it (the joint check writes each frame's, applied or not), and
  // each frame's movers (PNG: lossless).
  const bool poses = job.joint_poses && job.joint_poses->not_run.empty();
  file["streams"] = json::array();
  for (const Capture& capture : job.captures) {
    json stream = json::object();
    if (poses) {
      stream["poses"] = json::array();
      for (const PosedImage& pose : capture.poses)
        stream["poses"].push_back(PoseJson(pose.cam_from_world));
    }
    json movers = json::object();
    for (size_t i = 0; i < capture.movers.size(); ++i) {
      if (capture.movers[i].empty()) continue;
      std::vector<uchar> png;
      if (!EncodeImageBytes(".png", capture.movers[i], &png))
        return Status::Failed(path + ": could not encode the movers of pose " + std::to_string(i));
      movers[std::to_string(i)] = Base64(png);
    }
    stream["movers"] = movers;
    stream["movers_size"] = capture.movers.size();
    file["streams"].push_back(stream);
  }
  return WriteFileAtomic(path, file.dump() + "\n");
}

Status ReadPrepassFile(const std::string& path, const Project& project, PaintJob* job) {
  json file;
  FRESCO_RETURN_IF_ERROR(ReadHeader(path, project, /*with_layout=*/false, &file));
  try {
    const json& streams = file.at("streams");
    if (!streams.is_array() || streams.size() != job->captures.size())
      return Bad(path, "streams", "not one entry per stream of " + project.file_path);
    for (size_t s = 0; s < streams.size(); ++s) {
      Capture& capture = job->captures[s];
      const std::string at = "streams[" + std::to_string(s) + "]";
      if (streams[s].contains("poses")) {
        const json& poses = streams[s]["poses"];
        if (poses.size() != capture.poses.size())
          return Bad(path, at + ".poses",
                     std::to_string(poses.size()) + " poses, the capture has " +
                         std::to_string(capture.poses.size()));
        for (size_t i = 0; i < poses.size(); ++i) {
          const std::vector<double> v = poses[i].get<std::vector<double>>();
          if (v.size() != 7) return Bad(path, at + ".poses", "a pose is 7 numbers");
          capture.poses[i].cam_from_world = Rigid3d(Eigen::Quaterniond(v[0], v[1], v[2], v[3]),
                                                    Eigen::Vector3d(v[4], v[5], v[6]));
        }
      }
      const size_t size = streams[s].value("movers_size", size_t{0});
      if (size > capture.poses.size())
        return Bad(path, at + ".movers_size", "more than the capture's poses");
      capture.movers.assign(size, cv::Mat());
      for (const auto& [index, base64] : streams[s].at("movers").items()) {
        const size_t i = std::stoul(index);
        std::vector<uchar> png;
        if (i >= size || !FromBase64(base64.get<std::string>(), &png))
          return Bad(path, at + ".movers." + index, "not a pose's movers");
        capture.movers[i] = DecodeImageBytes(png.data(), png.size(), cv::IMREAD_UNCHANGED);
        if (capture.movers[i].empty()) return Bad(path, at + ".movers." + index, "not a PNG");
      }
    }
    if (file.contains("joint_poses")) {
      const json& a = file["joint_poses"];
      PoseAdjustResult r;
      r.applied = a.at("applied");
      r.not_run = a.at("not_run");
      r.matches = a.at("matches"), r.inliers = a.at("inliers");
      r.check_matches = a.at("check_matches");
      r.check_before_px = a.at("check_before_px"), r.check_after_px = a.at("check_after_px");
      r.check_one_end_px = a.at("check_one_end_px"), r.check_seconds = a.at("check_seconds");
      r.rms_before_px = a.at("rms_before_px"), r.rms_after_px = a.at("rms_after_px");
      r.median_rotation_deg = a.at("median_rotation_deg");
      r.median_translation_m = a.at("median_translation_m");
      r.rotation_prior_deg = a.at("rotation_prior_deg");
      r.translation_prior_m = a.at("translation_prior_m");
      r.decided_on_frames = a.at("decided_on_frames"), r.seconds = a.at("seconds");
      r.cam_from_local.resize(a.at("frames").get<size_t>());  // the count (poses: the captures')
      job->joint_poses = r;
    }
    if (file.contains("movers_across_views")) {
      const json& m = file["movers_across_views"];
      MoverMaskResult r;
      r.not_run = m.at("not_run");
      r.judged = m.at("judged"), r.flagged = m.at("flagged"), r.seconds = m.at("seconds");
      r.compact = m.value("compact", 0LL);
      r.frames_judged = m.value("frames_judged", 0);
      job->mover_masks = r;
    }
    // The decisions, in the pre-pass's order.
    if (file.contains("pose_check")) {
      const json& c = file["pose_check"];
      job->prepass.pose_check = {c.at(0).get<double>(), c.at(1).get<double>(), c.at(2).get<int>()};
      const auto& [ratio, threshold, frames] = *job->prepass.pose_check;
      job->session->SetRefinePoseCheck(ratio, threshold, frames);
    }
    if (file.contains("background_across_views")) {
      const json& b = file["background_across_views"];
      job->prepass.background_across_views = {b.at(0).get<double>(), b.at(1).get<int>()};
      job->session->DecideBackgroundAcrossViews(b.at(0).get<double>(), b.at(1).get<int>());
    }
  } catch (const std::exception& e) {
    return Bad(path, "content", std::string("not a pre-pass file's (") + e.what() + ")");
  }
  job->prepass.ran = NeedsWholeCapturePrepass(project);
  return Status::Ok();
}

}  // namespace fresco
