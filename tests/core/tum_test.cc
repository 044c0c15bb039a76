// TUM trajectories: camera-to-world in the file, cam_from_world in memory; round trip,
// names by order, strict errors with line numbers, and ReadPoses' format detection.
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pipeline/core/poses.h"
#include "tests/test_support.h"

namespace fresco {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

std::string ReadError(const std::string& text) {
  const std::string path = testing::MakeTempDir("tum") + "/traj.txt";
  testing::WriteText(path, text);
  std::vector<PosedImage> poses;
  const Status status = ReadTumTrajectory(path, &poses);
  EXPECT_FALSE(status.ok());
  EXPECT_THAT(status.message(), StartsWith(path + ":"));
  return status.message().substr(path.size() - std::string("traj.txt").size());
}

TEST(TumTest, FileHoldsCameraToWorld) {
  const std::string path = testing::MakeTempDir("tum") + "/traj.txt";
  // A camera at (1, 2, 3) turned 90 degrees about world z.
  testing::WriteText(path,
                     "# timestamp tx ty tz qx qy qz qw\n"
                     "1.5 1 2 3 0 0 0.7071067811865476 0.7071067811865476\n");
  std::vector<PosedImage> poses;
  const Status status = ReadTumTrajectory(path, &poses);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(poses.size(), 1u);
  const Rigid3d& cam_from_world = poses[0].cam_from_world;
  EXPECT_TRUE(cam_from_world.Centre().isApprox(Eigen::Vector3d(1, 2, 3), 1e-15));
  EXPECT_TRUE((cam_from_world * Eigen::Vector3d(1, 2, 3)).isZero(1e-15));
  // The camera's x axis points along world y.
  EXPECT_TRUE((cam_from_world.rotation.conjugate() * Eigen::Vector3d::UnitX())
                  .isApprox(Eigen::Vector3d::UnitY(), 1e-15));
  EXPECT_EQ(poses[0].timestamp_s, 1.5);
  EXPECT_EQ(poses[0].name, "000000");
  EXPECT_EQ(poses[0].image_id, 0);
}

TEST(TumTest, RoundTrip) {
  const std::string dir = testing::MakeTempDir("tum");
  std::vector<PosedImage> poses;
  for (int i = 0; i < 12; ++i) {
    PosedImage pose;
    pose.timestamp_s = 1700000000.0 + i / 30.0;
    const Rigid3d world_from_cam(
        Eigen::Quaterniond(Eigen::AngleAxisd(0.2 * i, Eigen::Vector3d(0.3, -1, 0.2).normalized())),
        Eigen::Vector3d(651234.5 + i, 5412345.25, 100.0 / 3.0));
    pose.cam_from_world = world_from_cam.Inverse();
    poses.push_back(pose);
  }
  ASSERT_TRUE(WriteTumTrajectory(dir + "/traj.txt", poses).ok());
  std::vector<PosedImage> read;
  const Status status = ReadTumTrajectory(dir + "/traj.txt", &read);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(read.size(), poses.size());
  for (size_t i = 0; i < poses.size(); ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "%06d", static_cast<int>(i));
    EXPECT_EQ(read[i].name, name);
    EXPECT_EQ(read[i].timestamp_s, poses[i].timestamp_s);
    EXPECT_NEAR(read[i].cam_from_world.rotation.angularDistance(poses[i].cam_from_world.rotation),
                0, 1e-12);
    // Map-scale camera centres survive to well below a millimetre.
    EXPECT_LT((read[i].cam_from_world.Centre() - poses[i].cam_from_world.Centre()).norm(), 1e-8);
  }
  // Timestamps stay plain decimals.
  EXPECT_THAT(testing::ReadText(dir + "/traj.txt"), HasSubstr("\n1700000000 651234.5 "));
}

TEST(TumTest, CommentsBlankLinesAndNonUnitQuaternions) {
  const std::string path = testing::MakeTempDir("tum") + "/traj.txt";
  testing::WriteText(path,
                     "# header\n\n0 0 0 0 0 0 0 2\n  # indented comment\r\n"
                     "0.1 0 0 1 0 0 0 1\r\n");
  std::vector<PosedImage> poses;
  ASSERT_TRUE(ReadTumTrajectory(path, &poses).ok());
  ASSERT_EQ(poses.size(), 2u);
  EXPECT_DOUBLE_EQ(poses[0].cam_from_world.rotation.w(), 1.0);
  EXPECT_EQ(poses[1].name, "000001");
  EXPECT_EQ(poses[1].cam_from_world.translation, Eigen::Vector3d(0, 0, -1));
}

TEST(TumTest, ErrorsNameLineAndField) {
  const std::string header = "# timestamp tx ty tz qx qy qz qw\n0 0 0 0 0 0 0 1\n";
  EXPECT_EQ(ReadError(header + "0.1 0 nan 0 0 0 0 1\n"), "traj.txt:3: ty: not finite (nan)");
  EXPECT_EQ(ReadError(header + "0.1 0 0 0 0 0 0 NaN\n"), "traj.txt:3: qw: not finite (NaN)");
  EXPECT_EQ(ReadError(header + "0.1 0 0 0 0 0 0 -inf\n"), "traj.txt:3: qw: not finite (-inf)");
  EXPECT_EQ(ReadError(header + "abc 0 0 0 0 0 0 1\n"),
            "traj.txt:3: timestamp: not a number ('abc')");
  EXPECT_EQ(ReadError(header + "0.1 0 0 0 0 0 0 0\n"),
            "traj.txt:3: quaternion: zero norm, not a rotation");
  EXPECT_EQ(ReadError(header + "0.1 0 0 0 0 0 1\n"),
            "traj.txt:3: expected 'timestamp tx ty tz qx qy qz qw' (8 fields), got 7 fields");
  EXPECT_EQ(ReadError(header + "0.1 0 0 0 0,0 0 1\n"),
            "traj.txt:3: expected 'timestamp tx ty tz qx qy qz qw' (8 fields), got 7 fields");
}

TEST(TumTest, MissingFileIsNamed) {
  std::vector<PosedImage> poses;
  const Status status = ReadTumTrajectory("/nonexistent/traj.txt", &poses);
  EXPECT_EQ(status.message(), "/nonexistent/traj.txt: no such file");
}

TEST(TumTest, ReadPosesDetectsTum) {
  const std::string dir = testing::MakeTempDir("tum");
  testing::WriteText(dir + "/poses.txt", "# tum\n0 1 2 3 0 0 0 1\n0.033 1 2 3 0 0 0 1\n");
  std::vector<PosedImage> poses;
  bool is_tum = false;
  Status status = ReadPoses(dir + "/poses.txt", &poses, &is_tum);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_TRUE(is_tum);
  EXPECT_EQ(poses.size(), 2u);
  // A TUM file with a NaN is still read (and rejected) as TUM, naming the line.
  testing::WriteText(dir + "/bad.txt", "0 1 2 3 0 0 0 1\n0.033 1 2 nan 0 0 0 1\n");
  status = ReadPoses(dir + "/bad.txt", &poses, &is_tum);
  EXPECT_EQ(status.message(), dir + "/bad.txt:2: tz: not finite (nan)");
  testing::WriteText(dir + "/typo.txt", "0 1 2 3 0 0 x 1\n");
  status = ReadPoses(dir + "/typo.txt", &poses, &is_tum);
  EXPECT_EQ(status.message(), dir + "/typo.txt:1: qz: not a number ('x')");
  // A COLMAP images.txt is not mistaken for TUM.
  testing::WriteText(dir + "/images.txt", "1 1 0 0 0 1 2 3 1 a.png\n\n");
  status = ReadPoses(dir + "/images.txt", &poses, &is_tum);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_FALSE(is_tum);
  EXPECT_EQ(poses[0].name, "a.png");
}

}  // namespace
}  // namespace fresco
