// COLMAP's text model (cameras.txt, images.txt, points3D.txt), read strictly and written
// with full precision. COLMAP puts the centre of the top-left pixel at (0.5,0.5); Fresco at
// (0,0): principal points and 2D points shift by -0.5 on read and +0.5 on write.
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "pipeline/core/atomic_file.h"
#include "pipeline/core/poses.h"
#include "pipeline/core/text_lines.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;
using text::FormatDouble;
using text::LineParser;

constexpr double kColmapPixelShift = 0.5;  // COLMAP pixel centre minus ours

std::string Join(const std::string& folder, const char* name) {
  return (fs::path(folder) / name).string();
}

// The COLMAP model with the same parameters as `model` (mrcal's OPENCV4/5/8 and pinhole).
LensModel ColmapEquivalent(LensModel model) {
  switch (model) {
    case LensModel::kPinhole:
      return LensModel::kColmapPinhole;
    case LensModel::kOpenCV4:
      return LensModel::kColmapOpenCV;
    case LensModel::kOpenCV5:
    case LensModel::kOpenCV8:
      return LensModel::kFullOpenCV;
    default:
      return model;
  }
}

Status ParseCameraLine(const std::string& path, const text::Line& line, int* camera_id,
                       Camera* camera) {
  const LineParser parser(path, line.number);
  const auto fields = text::SplitFields(line.text);
  if (fields.size() < 4) {
    return parser.Error("", "expected 'CAMERA_ID MODEL WIDTH HEIGHT PARAMS[]', got " +
                                std::to_string(fields.size()) + " fields");
  }
  FRESCO_RETURN_IF_ERROR(parser.Int(fields[0], "CAMERA_ID", camera_id));
  LensModel model;
  const std::string model_name(fields[1]);
  if (!LensModelFromName(model_name, &model) || !IsColmapModel(model)) {
    return parser.Error("MODEL", "unsupported camera model '" + model_name +
                                     "' (supported: SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, "
                                     "RADIAL, OPENCV, FULL_OPENCV)");
  }
  int width = 0, height = 0;
  FRESCO_RETURN_IF_ERROR(parser.Int(fields[2], "WIDTH", &width));
  FRESCO_RETURN_IF_ERROR(parser.Int(fields[3], "HEIGHT", &height));
  if (width <= 0) return parser.Error("WIDTH", "must be positive");
  if (height <= 0) return parser.Error("HEIGHT", "must be positive");
  const int expected = LensModelNumParams(model);
  const int got = static_cast<int>(fields.size()) - 4;
  if (got != expected) {
    return parser.Error("PARAMS", model_name + " takes " + std::to_string(expected) +
                                      " parameters, got " + std::to_string(got));
  }
  std::vector<double> params(expected);
  for (int i = 0; i < expected; ++i) {
    FRESCO_RETURN_IF_ERROR(
        parser.Double(fields[4 + i], "PARAMS[" + std::to_string(i) + "]", &params[i]));
  }
  *camera = Camera::FromParams(model, width, height, params);
  camera->cx -= kColmapPixelShift;
  camera->cy -= kColmapPixelShift;
  return camera->Validate(parser.Where() + "camera " + std::to_string(*camera_id));
}

Status ParsePoseFields(const LineParser& parser, const std::vector<std::string_view>& fields,
                       PosedImage* image) {
  FRESCO_RETURN_IF_ERROR(parser.Int(fields[0], "IMAGE_ID", &image->image_id));
  static const char* kNames[7] = {"QW", "QX", "QY", "QZ", "TX", "TY", "TZ"};
  double v[7];
  for (int i = 0; i < 7; ++i) {
    FRESCO_RETURN_IF_ERROR(parser.Double(fields[1 + i], kNames[i], &v[i]));
  }
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  FRESCO_RETURN_IF_ERROR(text::NormalizedQuaternion(parser, v[0], v[1], v[2], v[3], &q));
  image->cam_from_world = Rigid3d(q, Eigen::Vector3d(v[4], v[5], v[6]));
  FRESCO_RETURN_IF_ERROR(parser.Int(fields[8], "CAMERA_ID", &image->camera_id));
  return Status::Ok();
}

// The image's NAME: everything after the CAMERA_ID field (names may hold spaces).
std::string_view NameField(std::string_view line, const std::string_view& camera_id_field) {
  const size_t after =
      static_cast<size_t>(camera_id_field.data() - line.data()) + camera_id_field.size();
  return text::Trim(line.substr(after));
}

Status ParsePointsLine(const std::string& path, const text::Line& line, PosedImage* image) {
  const LineParser parser(path, line.number);
  const auto fields = text::SplitFields(line.text);
  if (fields.size() % 3 != 0) {
    return parser.Error("POINTS2D", "expected (X, Y, POINT3D_ID) triples, got " +
                                        std::to_string(fields.size()) + " fields");
  }
  const size_t n = fields.size() / 3;
  image->points2d.resize(n);
  image->point3d_ids.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const std::string index = "POINTS2D[" + std::to_string(i) + "]";
    double x = 0, y = 0;
    FRESCO_RETURN_IF_ERROR(parser.Double(fields[3 * i], index + ".X", &x));
    FRESCO_RETURN_IF_ERROR(parser.Double(fields[3 * i + 1], index + ".Y", &y));
    FRESCO_RETURN_IF_ERROR(
        parser.Int64(fields[3 * i + 2], index + ".POINT3D_ID", &image->point3d_ids[i]));
    image->points2d[i] = Eigen::Vector2d(x - kColmapPixelShift, y - kColmapPixelShift);
  }
  return Status::Ok();
}

}  // namespace

Status ReadColmapCameras(const std::string& path, std::map<int, Camera>* cameras) {
  std::string contents;
  FRESCO_RETURN_IF_ERROR(ReadFileToString(path, &contents));
  return ParseColmapCameras(contents, path, cameras);
}

Status ParseColmapCameras(const std::string& contents, const std::string& path, std::map<int, Camera>* cameras) {
  std::map<int, Camera> result;
  std::map<int, int> line_of_id;
  for (const text::Line& line : text::SplitLines(contents)) {
    if (text::IsBlankOrComment(line.text)) continue;
    int camera_id = -1;
    Camera camera;
    FRESCO_RETURN_IF_ERROR(ParseCameraLine(path, line, &camera_id, &camera));
    if (line_of_id.count(camera_id)) {
      return LineParser(path, line.number)
          .Error("CAMERA_ID", "duplicate id " + std::to_string(camera_id) + " (first at line " +
                                  std::to_string(line_of_id[camera_id]) + ")");
    }
    line_of_id[camera_id] = line.number;
    result[camera_id] = camera;
  }
  *cameras = std::move(result);
  return Status::Ok();
}

Status ReadColmapImages(const std::string& path, std::vector<PosedImage>* images) {
  std::string contents;
  FRESCO_RETURN_IF_ERROR(ReadFileToString(path, &contents));
  return ParseColmapImages(contents, path, images);
}

Status ParseColmapImages(const std::string& contents, const std::string& path, std::vector<PosedImage>* images) {
  const std::vector<text::Line> lines = text::SplitLines(contents);
  std::vector<PosedImage> result;
  std::map<int, int> line_of_id;
  std::map<std::string, int> line_of_name;
  for (size_t i = 0; i < lines.size(); ++i) {
    const text::Line& line = lines[i];
    if (text::IsBlankOrComment(line.text)) continue;
    const LineParser parser(path, line.number);
    const auto fields = text::SplitFields(line.text);
    if (fields.size() < 10) {
      return parser.Error("", "expected 'IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME', got " +
                                  std::to_string(fields.size()) + " fields");
    }
    PosedImage image;
    FRESCO_RETURN_IF_ERROR(ParsePoseFields(parser, fields, &image));
    image.name = std::string(NameField(line.text, fields[8]));
    if (line_of_id.count(image.image_id)) {
      return parser.Error("IMAGE_ID", "duplicate id " + std::to_string(image.image_id) +
                                          " (first at line " +
                                          std::to_string(line_of_id[image.image_id]) + ")");
    }
    if (line_of_name.count(image.name)) {
      return parser.Error("NAME", "duplicate name '" + image.name + "' (first at line " +
                                      std::to_string(line_of_name[image.name]) + ")");
    }
    line_of_id[image.image_id] = line.number;
    line_of_name[image.name] = line.number;
    // The very next line holds the 2D points, even when it is empty; a file may end
    // without it.
    if (i + 1 < lines.size()) {
      ++i;
      const text::Line& points = lines[i];
      if (!text::Trim(points.text).empty() && text::Trim(points.text).front() == '#') {
        return LineParser(path, points.number)
            .Error("POINTS2D", "expected the 2D points of image " + std::to_string(image.image_id) +
                                   " (may be empty), got a "
                                   "comment");
      }
      FRESCO_RETURN_IF_ERROR(ParsePointsLine(path, points, &image));
    }
    result.push_back(std::move(image));
  }
  *images = std::move(result);
  return Status::Ok();
}

Status ReadColmapPoints(const std::string& path, std::vector<Point3D>* points) {
  std::string contents;
  FRESCO_RETURN_IF_ERROR(ReadFileToString(path, &contents));
  return ParseColmapPoints(contents, path, points);
}

Status ParseColmapPoints(const std::string& contents, const std::string& path, std::vector<Point3D>* points) {
  std::vector<Point3D> result;
  std::map<long long, int> line_of_id;
  for (const text::Line& line : text::SplitLines(contents)) {
    if (text::IsBlankOrComment(line.text)) continue;
    const LineParser parser(path, line.number);
    const auto fields = text::SplitFields(line.text);
    if (fields.size() < 8 || (fields.size() - 8) % 2 != 0) {
      return parser.Error("",
                          "expected 'POINT3D_ID X Y Z R G B ERROR' then (IMAGE_ID, "
                          "POINT2D_IDX) pairs, got " +
                              std::to_string(fields.size()) + " fields");
    }
    Point3D point;
    FRESCO_RETURN_IF_ERROR(parser.Int64(fields[0], "POINT3D_ID", &point.id));
    static const char* kXyz[3] = {"X", "Y", "Z"};
    static const char* kRgb[3] = {"R", "G", "B"};
    for (int k = 0; k < 3; ++k) {
      FRESCO_RETURN_IF_ERROR(parser.Double(fields[1 + k], kXyz[k], &point.xyz[k]));
    }
    for (int k = 0; k < 3; ++k) {
      FRESCO_RETURN_IF_ERROR(parser.Int(fields[4 + k], kRgb[k], &point.rgb[k]));
      if (point.rgb[k] < 0 || point.rgb[k] > 255) {
        return parser.Error(kRgb[k], "outside 0..255 (" + std::to_string(point.rgb[k]) + ")");
      }
    }
    FRESCO_RETURN_IF_ERROR(parser.Double(fields[7], "ERROR", &point.error));
    for (size_t k = 8; k < fields.size(); k += 2) {
      const std::string index = "TRACK[" + std::to_string((k - 8) / 2) + "]";
      int image_id = 0, point2d_index = 0;
      FRESCO_RETURN_IF_ERROR(parser.Int(fields[k], index + ".IMAGE_ID", &image_id));
      FRESCO_RETURN_IF_ERROR(parser.Int(fields[k + 1], index + ".POINT2D_IDX", &point2d_index));
      point.track.emplace_back(image_id, point2d_index);
    }
    if (line_of_id.count(point.id)) {
      return parser.Error("POINT3D_ID", "duplicate id " + std::to_string(point.id) +
                                            " (first at line " +
                                            std::to_string(line_of_id[point.id]) + ")");
    }
    line_of_id[point.id] = line.number;
    result.push_back(std::move(point));
  }
  *points = std::move(result);
  return Status::Ok();
}

Status ReadColmapModel(const std::string& folder, ColmapModel* model) {
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) return Status::Error(folder + ": no such folder");
  ColmapModel result;
  const std::string cameras_path = Join(folder, "cameras.txt");
  const std::string images_path = Join(folder, "images.txt");
  const std::string points_path = Join(folder, "points3D.txt");
  FRESCO_RETURN_IF_ERROR(ReadColmapCameras(cameras_path, &result.cameras));
  FRESCO_RETURN_IF_ERROR(ReadColmapImages(images_path, &result.images));
  if (fs::exists(points_path, ec)) {
    FRESCO_RETURN_IF_ERROR(ReadColmapPoints(points_path, &result.points));
  }
  for (const PosedImage& image : result.images) {
    if (!result.cameras.count(image.camera_id)) {
      return Status::Error(images_path + ": image '" + image.name + "' (IMAGE_ID " +
                           std::to_string(image.image_id) + "): CAMERA_ID " +
                           std::to_string(image.camera_id) + " is not in " + cameras_path);
    }
  }
  *model = std::move(result);
  return Status::Ok();
}

Status ColmapCameraParams(const Camera& source, const std::string& what,
                          std::string* model_name, std::vector<double>* params) {
  Camera camera = source;
  camera.model = ColmapEquivalent(source.model);
  if (!IsColmapModel(camera.model)) {
    return Status::Error(what + ": lens model " + LensModelName(source.model) +
                         " has no COLMAP equivalent");
  }
  camera.cx += kColmapPixelShift;
  camera.cy += kColmapPixelShift;
  *model_name = LensModelName(camera.model);
  *params = camera.Params();
  return Status::Ok();
}

Status WriteColmapCameras(const std::string& path, const std::map<int, Camera>& cameras) {
  std::string out =
      "# Camera list with one line of data per camera:\n"
      "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
      "# Number of cameras: " +
      std::to_string(cameras.size()) + "\n";
  for (const auto& [camera_id, source] : cameras) {
    std::string model_name;
    std::vector<double> params;
    FRESCO_RETURN_IF_ERROR(  // a camera COLMAP cannot hold: this file cannot be written
        ColmapCameraParams(source, path + ": camera " + std::to_string(camera_id), &model_name,
                           &params)
            .Reclassified(StatusKind::kOutput));
    out += std::to_string(camera_id) + " " + model_name + " " + std::to_string(source.width) +
           " " + std::to_string(source.height);
    for (double p : params) text::AppendField(&out, FormatDouble(p));
    out += "\n";
  }
  return WriteFileAtomic(path, out);
}

Status WriteColmapImages(const std::string& path, const std::vector<PosedImage>& images) {
  size_t observations = 0;
  for (const PosedImage& image : images) observations += image.points2d.size();
  std::string out =
      "# Image list with two lines of data per image:\n"
      "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n"
      "#   POINTS2D[] as (X, Y, POINT3D_ID)\n"
      "# Number of images: " +
      std::to_string(images.size()) + ", mean observations per image: " +
      FormatDouble(images.empty() ? 0.0 : double(observations) / images.size()) + "\n";
  for (const PosedImage& image : images) {
    if (image.name.empty() || image.name.find('\n') != std::string::npos) {
      return Status::OutputError(path + ": image " + std::to_string(image.image_id) +
                                 ": NAME must be one non-empty line");
    }
    if (image.points2d.size() != image.point3d_ids.size()) {
      return Status::Internal(path + ": image '" + image.name +
                              "': points2d and point3d_ids differ in length");
    }
    const Eigen::Quaterniond& q = image.cam_from_world.rotation;
    const Eigen::Vector3d& t = image.cam_from_world.translation;
    out += std::to_string(image.image_id);
    for (double v : {q.w(), q.x(), q.y(), q.z(), t.x(), t.y(), t.z()}) {
      text::AppendField(&out, FormatDouble(v));
    }
    text::AppendField(&out, std::to_string(image.camera_id));
    text::AppendField(&out, image.name);
    out += '\n';
    for (size_t i = 0; i < image.points2d.size(); ++i) {
      if (i > 0) out += " ";
      out += FormatDouble(image.points2d[i].x() + kColmapPixelShift) + " " +
             FormatDouble(image.points2d[i].y() + kColmapPixelShift) + " " +
             std::to_string(image.point3d_ids[i]);
    }
    out += "\n";
  }
  return WriteFileAtomic(path, out);
}

Status WriteColmapPoints(const std::string& path, const std::vector<Point3D>& points) {
  double track_length = 0;
  for (const Point3D& point : points) track_length += point.track.size();
  std::string out =
      "# 3D point list with one line of data per point:\n"
      "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n"
      "# Number of points: " +
      std::to_string(points.size()) +
      ", mean track length: " + FormatDouble(points.empty() ? 0.0 : track_length / points.size()) +
      "\n";
  for (const Point3D& point : points) {
    out += std::to_string(point.id);
    for (int k = 0; k < 3; ++k) text::AppendField(&out, FormatDouble(point.xyz[k]));
    for (int k = 0; k < 3; ++k) text::AppendField(&out, std::to_string(point.rgb[k]));
    text::AppendField(&out, FormatDouble(point.error));
    for (const auto& [image_id, point2d_index] : point.track) {
      text::AppendField(&out, std::to_string(image_id));
      text::AppendField(&out, std::to_string(point2d_index));
    }
    out += "\n";
  }
  return WriteFileAtomic(path, out);
}

Status WriteColmapModel(const std::string& folder, const ColmapModel& model) {
  FRESCO_RETURN_IF_ERROR(MakeDirectories(folder));
  FRESCO_RETURN_IF_ERROR(WriteColmapCameras(Join(folder, "cameras.txt"), model.cameras));
  FRESCO_RETURN_IF_ERROR(WriteColmapImages(Join(folder, "images.txt"), model.images));
  return WriteColmapPoints(Join(folder, "points3D.txt"), model.points);
}

Status ReadPoses(const std::string& path, std::vector<PosedImage>* poses, bool* is_tum) {
  std::error_code ec;
  std::string file = path;
  if (fs::is_directory(path, ec)) {
    file = Join(path, "images.txt");
    if (!fs::exists(file, ec)) {
      return Status::Error(path + ": folder holds no images.txt (expected a COLMAP text model)");
    }
  }
  std::string contents;
  FRESCO_RETURN_IF_ERROR(ReadFileToString(file, &contents));
  // Decide by the first data line: a TUM line is 8 numbers; anything else is read (and
  // reported on) as COLMAP images.txt.
  bool tum = false;
  for (const text::Line& line : text::SplitLines(contents)) {
    if (text::IsBlankOrComment(line.text)) continue;
    const auto fields = text::SplitFields(line.text);
    if (fields.size() == 8) {
      tum = true;
      double value;
      for (const auto& field : fields) tum = tum && text::ParseDouble(field, &value);
      // "1 2 3 4 5 6 7 name" is a broken COLMAP line rather than a TUM line.
      if (!tum && fs::path(file).filename() != "images.txt") {
        tum = text::ParseDouble(fields[0], &value);  // report TUM errors for TUM files
      }
    }
    break;
  }
  if (is_tum) *is_tum = tum;
  return tum ? ReadTumTrajectory(file, poses) : ReadColmapImages(file, poses);
}

}  // namespace fresco
