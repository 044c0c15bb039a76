// TUM trajectories: `timestamp tx ty tz qx qy qz qw` per line, world_from_cam (the camera's
// position and orientation in the world), '#' comments. PosedImage keeps cam_from_world, so
// poses are inverted on read and write. Poses are named "%06d" by their order.
#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

#include "pipeline/core/atomic_file.h"
#include "pipeline/core/poses.h"
#include "pipeline/core/text_lines.h"

namespace fresco {
namespace {

std::string TumName(int index) {
  char name[32];
  std::snprintf(name, sizeof(name), "%06d", index);
  return name;
}

}  // namespace

Status ParseTumLine(const std::string& source, int line_number, std::string_view line,
                    bool* is_pose, double* timestamp_s, Rigid3d* world_from_cam) {
  *is_pose = false;
  if (text::IsBlankOrComment(line)) return Status::Ok();
  const text::LineParser parser(source, line_number);
  const auto fields = text::SplitFields(line);
  if (fields.size() != 8) {
    return parser.Error("", "expected 'timestamp tx ty tz qx qy qz qw' (8 fields), got " +
                                std::to_string(fields.size()) + " fields");
  }
  static const char* kNames[8] = {"timestamp", "tx", "ty", "tz", "qx", "qy", "qz", "qw"};
  double v[8];
  for (int i = 0; i < 8; ++i) {
    FRESCO_RETURN_IF_ERROR(parser.Double(fields[i], kNames[i], &v[i]));
  }
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  FRESCO_RETURN_IF_ERROR(text::NormalizedQuaternion(parser, v[7], v[4], v[5], v[6], &q));
  *world_from_cam = Rigid3d(q, Eigen::Vector3d(v[1], v[2], v[3]));
  *timestamp_s = v[0];
  *is_pose = true;
  return Status::Ok();
}

Status ReadTumTrajectory(const std::string& path, std::vector<PosedImage>* poses) {
  std::string contents;
  FRESCO_RETURN_IF_ERROR(ReadFileToString(path, &contents));
  return ParseTumTrajectory(contents, path, poses);
}

Status ParseTumTrajectory(const std::string& contents, const std::string& path,
                          std::vector<PosedImage>* poses) {
  std::vector<PosedImage> result;
  for (const text::Line& line : text::SplitLines(contents)) {
    bool is_pose = false;
    double timestamp_s = 0;
    Rigid3d world_from_cam;
    FRESCO_RETURN_IF_ERROR(
        ParseTumLine(path, line.number, line.text, &is_pose, &timestamp_s, &world_from_cam));
    if (!is_pose) continue;
    PosedImage pose;
    const int index = static_cast<int>(result.size());
    pose.image_id = index;
    pose.camera_id = -1;  // the project's only camera
    pose.name = TumName(index);
    pose.timestamp_s = timestamp_s;
    pose.cam_from_world = world_from_cam.Inverse();
    result.push_back(std::move(pose));
  }
  *poses = std::move(result);
  return Status::Ok();
}

Status WriteTumTrajectory(const std::string& path, const std::vector<PosedImage>& poses) {
  std::string out = "# timestamp tx ty tz qx qy qz qw (camera to world)\n";
  for (const PosedImage& pose : poses) {
    const Rigid3d world_from_cam = pose.cam_from_world.Inverse();
    const Eigen::Quaterniond& q = world_from_cam.rotation;
    const Eigen::Vector3d& t = world_from_cam.translation;
    out += text::FormatDouble(pose.timestamp_s);
    for (double v : {t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w()}) {
      text::AppendField(&out, text::FormatDouble(v));
    }
    out += "\n";
  }
  return WriteFileAtomic(path, out);
}

}  // namespace fresco
