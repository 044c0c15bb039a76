#include "pipeline/poses/bootstrap.h"

#include <cmath>
#include <map>
#include <sstream>

#include <Eigen/SVD>

#include "pipeline/core/atomic_file.h"

namespace fresco {

Status ReadControlPoints(const std::string& path, std::vector<ControlPoint>* points) {
  std::string text;
  FRESCO_RETURN_IF_ERROR(ReadFileToString(path, &text));
  std::istringstream lines(text);
  std::string line;
  points->clear();
  for (int number = 1; std::getline(lines, line); ++number) {
    const size_t hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    std::istringstream fields(line);
    std::vector<std::string> f;
    for (std::string s; fields >> s;) f.push_back(s);
    if (f.empty()) continue;
    const std::string where = path + ":" + std::to_string(number) + ": ";
    if (f.size() < 7 || (f.size() - 4) % 3 != 0) {
      return Status::Error(where + "expected 'NAME X Y Z IMAGE U V [IMAGE U V ...]', got " +
                           std::to_string(f.size()) + " fields");
    }
    ControlPoint p;
    p.name = f[0];
    auto number_of = [&](const std::string& s, const std::string& field, double* v) {
      try {
        size_t used = 0;
        *v = std::stod(s, &used);
        if (used == s.size() && std::isfinite(*v)) return Status::Ok();
      } catch (const std::exception&) {
      }
      return Status::Error(where + field + ": not a number: '" + s + "'");
    };
    for (int i = 0; i < 3; ++i) {
      FRESCO_RETURN_IF_ERROR(number_of(f[1 + i], std::string(1, "XYZ"[i]), &p.point_in_world[i]));
    }
    for (size_t k = 4; k < f.size(); k += 3) {
      ControlObservation o;
      o.image = f[k];
      FRESCO_RETURN_IF_ERROR(number_of(f[k + 1], "U", &o.pixel.x()));
      FRESCO_RETURN_IF_ERROR(number_of(f[k + 2], "V", &o.pixel.y()));
      p.observations.push_back(o);
    }
    points->push_back(p);
  }
  if (points->size() < 3) {
    return Status::Error(path + ": needs at least 3 control points, got " +
                         std::to_string(points->size()));
  }
  return Status::Ok();
}

Status AlignWithControlPoints(const std::vector<ControlPoint>& points, const std::string& what,
                              const ColmapModel& model, const Camera& camera,
                              ControlPointFit* fit) {
  std::map<std::string, const PosedImage*> by_name;
  for (const PosedImage& image : model.images) by_name[image.name] = &image;
  std::vector<Eigen::Vector3d> in_colmap, in_world;
  for (const ControlPoint& p : points) {
    // Linear triangulation: each ray (centre c, direction d) gives (I - d d^T)(x - c) = 0.
    Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
    Eigen::Vector3d b = Eigen::Vector3d::Zero();
    int rays = 0;
    for (const ControlObservation& o : p.observations) {
      const auto it = by_name.find(o.image);
      if (it == by_name.end()) continue;  // not registered
      Eigen::Vector2d normalized;
      if (!camera.Unproject(o.pixel, &normalized)) {
        return Status::Error(what + ": point " + p.name + ": pixel in " + o.image +
                             " does not unproject through the camera");
      }
      const Rigid3d& cam_from_colmap = it->second->cam_from_world;
      const Eigen::Vector3d d =
          (cam_from_colmap.rotation.conjugate() * normalized.homogeneous()).normalized();
      const Eigen::Matrix3d m = Eigen::Matrix3d::Identity() - d * d.transpose();
      a += m;
      b += m * cam_from_colmap.Centre();
      ++rays;
    }
    if (rays < 2) {
      return Status::Error(what + ": point " + p.name + ": seen in " + std::to_string(rays) +
                           " registered image(s), needs 2");
    }
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(a, Eigen::ComputeFullU | Eigen::ComputeFullV);
    const Eigen::Vector3d s = svd.singularValues();
    if (!(s[2] > 1e-9 * s[0])) {
      return Status::Error(what + ": point " + p.name + ": its rays are (nearly) parallel");
    }
    in_colmap.push_back(svd.solve(b));
    in_world.push_back(p.point_in_world);
  }
  FRESCO_RETURN_IF_ERROR(EstimateSimilarity(in_colmap, in_world, what, &fit->world_from_colmap));
  fit->residual_m.clear();
  for (size_t i = 0; i < in_world.size(); ++i) {
    fit->residual_m.push_back((fit->world_from_colmap * in_colmap[i] - in_world[i]).norm());
  }
  return Status::Ok();
}

ColmapModel TransformModel(const ColmapModel& model, const Sim3d& world_from_colmap) {
  ColmapModel out = model;
  for (PosedImage& image : out.images) {
    image.cam_from_world = world_from_colmap.TransformPose(image.cam_from_world);
  }
  for (Point3D& point : out.points) {
    point.xyz = world_from_colmap * point.xyz;
  }
  return out;
}

}  // namespace fresco
