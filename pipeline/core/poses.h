// Camera poses and the files that hold them.
//  - COLMAP text model: cameras.txt, images.txt, points3D.txt. images.txt holds
//    cam_from_world (x_cam = R(q) x_world + t); COLMAP's pixel centre is (0.5,0.5), ours is
//    (0,0): cameras and 2D points are shifted by 0.5 when read and written.
//  - TUM trajectory: `timestamp tx ty tz qx qy qz qw`, world_from_cam, '#' comments.
#pragma once

#include <map>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "pipeline/core/camera.h"
#include "pipeline/core/rigid3.h"
#include "pipeline/core/status.h"

namespace fresco {

struct PosedImage {
  int image_id = -1;
  int camera_id = -1;
  std::string name;
  double timestamp_s = 0.0;  // TUM only
  Rigid3d cam_from_world;
  std::vector<Eigen::Vector2d> points2d;  // (0,0) convention
  std::vector<long long> point3d_ids;     // -1 where none
};

struct Point3D {
  long long id = -1;
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();
  Eigen::Vector3i rgb = Eigen::Vector3i::Zero();
  double error = 0.0;
  std::vector<std::pair<int, int>> track;  // (image_id, point2d_index)
};

struct ColmapModel {
  std::map<int, Camera> cameras;  // by CAMERA_ID
  std::vector<PosedImage> images;  // in file order
  std::vector<Point3D> points;
};

Status ReadColmapCameras(const std::string& path, std::map<int, Camera>* cameras);
Status ReadColmapImages(const std::string& path, std::vector<PosedImage>* images);
Status ReadColmapPoints(const std::string& path, std::vector<Point3D>* points);
// The same from text already in memory; `path` names the source in messages.
Status ParseColmapCameras(const std::string& contents, const std::string& path,
                          std::map<int, Camera>* cameras);
Status ParseColmapImages(const std::string& contents, const std::string& path,
                         std::vector<PosedImage>* images);
Status ParseColmapPoints(const std::string& contents, const std::string& path,
                         std::vector<Point3D>* points);
// `folder` holds cameras.txt, images.txt and (optionally) points3D.txt.
Status ReadColmapModel(const std::string& folder, ColmapModel* model);
// The COLMAP model name and parameters (COLMAP order and pixel convention, principal point
// shifted by +0.5) for `camera`; mrcal models map to their COLMAP equivalent. `what` names
// the camera in the error when there is none.
Status ColmapCameraParams(const Camera& camera, const std::string& what,
                          std::string* model_name, std::vector<double>* params);
Status WriteColmapCameras(const std::string& path, const std::map<int, Camera>& cameras);
Status WriteColmapImages(const std::string& path, const std::vector<PosedImage>& images);
Status WriteColmapPoints(const std::string& path, const std::vector<Point3D>& points);
Status WriteColmapModel(const std::string& folder, const ColmapModel& model);

// One TUM line (`timestamp tx ty tz qx qy qz qw`, world_from_cam); blank lines and '#'
// comments set `is_pose` false. Errors read "SOURCE:LINE: FIELD: what is wrong".
Status ParseTumLine(const std::string& source, int line_number, std::string_view line,
                    bool* is_pose, double* timestamp_s, Rigid3d* world_from_cam);
Status ReadTumTrajectory(const std::string& path, std::vector<PosedImage>* poses);
// The same from text already in memory; `path` names the source in messages.
Status ParseTumTrajectory(const std::string& contents, const std::string& path,
                          std::vector<PosedImage>* poses);
Status WriteTumTrajectory(const std::string& path, const std::vector<PosedImage>& poses);

// Reads poses from a COLMAP images.txt, a COLMAP model folder, or a TUM file (decided by
// content: a COLMAP images.txt line has 10 fields with an integer id and a name).
Status ReadPoses(const std::string& path, std::vector<PosedImage>* poses, bool* is_tum);

}  // namespace fresco
