// `fresco poses verify|bootstrap` end to end with the real `colmap` program (skipped with a
// message when it is not on PATH): a small synthetic capture of `builtin:blocks` (boxes on a
// ground, every face its own dense feature texture; a half orbit: parallax everywhere) with
// errors injected into chosen given poses (every one flagged, no clean frame flagged;
// bootstrapped poses close to the truth, aligned from the given poses or from control
// points), the real Sceaux castle photos against their OpenMVG poses, and CLI errors.
// COLMAP runs once for the synthetic suite (by the verify run); the bootstrap tests reuse its
// reconstruction (--colmap-model).
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <map>
#include <regex>
#include <set>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "pipeline/core/poses.h"
#include "pipeline/core/project.h"
#include "pipeline/core/run_process.h"
#include "pipeline/core/scene.h"
#include "pipeline/poses/bootstrap.h"
#include "pipeline/synth/synthesize.h"
#include "tests/poses/colmap_capture.h"
#include "tests/poses/perturbed_pose.h"
#include "tests/test_support.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;
using testing::ControlPointsText;
using testing::MakeTempDir;
using testing::Perturbed;
using testing::ReadText;
using testing::RunFresco;
using testing::WriteText;

constexpr int kFrames = 16;
// Frames with injected errors: 1 deg, 2 % of the scene size, and both.
const std::set<int> kRotated = {4, 11};
const std::set<int> kMoved = {8, 11};

class PosesColmapTest : public ::testing::Test {
 protected:
  // The capture, its given poses (the truth but for the chosen frames), and one
  // `fresco poses verify` run (COLMAP's only run in this suite).
  static void SetUpTestSuite() {
    if (FindProgram("colmap").empty()) return;
    dir_ = new std::string(MakeTempDir("poses-colmap"));
    const std::string capture = Capture();
    const auto r = testing::SynthBlocks(capture, kFrames);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    scene_size_m_ = testing::SceneSizeM(capture);
    std::vector<PosedImage> poses;
    ASSERT_TRUE(ReadColmapImages(capture + "/truth/images.txt", &poses).ok());
    ASSERT_EQ(poses.size(), static_cast<size_t>(kFrames));
    for (int i = 0; i < kFrames; ++i) {
      const double rotation = kRotated.count(i) ? 1.0 : 0.0;
      const double position = kMoved.count(i) ? 0.02 * scene_size_m_ : 0.0;
      poses[i].cam_from_world =
          Perturbed(poses[i].cam_from_world, rotation, position, Eigen::Vector3d(1, -2, 0.5 + i));
    }
    ASSERT_TRUE(WriteColmapImages(capture + "/sparse/images.txt", poses).ok());
    // A temporary folder of the run's own: where COLMAP's log would go were it not kept in the
    // workspace (ColmapLogsStayInTheWorkspace).
    fs::create_directories(TempFolder());
    const char* tmpdir = std::getenv("TMPDIR");
    const std::string saved = tmpdir ? tmpdir : "";
    setenv("TMPDIR", TempFolder().c_str(), 1);
    verify_ = new testing::CommandResult(
        RunFresco({"poses", "verify", Project(), "--out", VerifyDir(), "--threads", "2"}));
    if (tmpdir)
      setenv("TMPDIR", saved.c_str(), 1);
    else
      unsetenv("TMPDIR");
  }
  static void TearDownTestSuite() {
    delete dir_;
    delete verify_;
  }
  void SetUp() override {
    FRESCO_REQUIRE_COLMAP();
    ASSERT_NE(verify_, nullptr);
    ASSERT_EQ(verify_->exit_code, 0) << verify_->err;
  }
  static std::string Capture() { return *dir_ + "/capture"; }
  static std::string Project() { return Capture() + "/project.json"; }
  static std::string VerifyDir() { return *dir_ + "/verify"; }
  static std::string TempFolder() { return *dir_ + "/tmp"; }
  static std::string ColmapModel() { return VerifyDir() + "/colmap/sparse_txt/0"; }
  static std::vector<PosedImage> Truth() {
    std::vector<PosedImage> truth;
    EXPECT_TRUE(ReadColmapImages(Capture() + "/truth/images.txt", &truth).ok());
    return truth;
  }
  // Largest rotation (deg) and centre (m) error of the bootstrapped poses in DIR.
  static void BootstrapErrors(const std::string& dir, int* posed, double* rotation_deg,
                              double* position_m) {
    std::vector<PosedImage> got;
    ASSERT_TRUE(ReadColmapImages(dir + "/sparse/images.txt", &got).ok());
    const testing::PoseErrors e = testing::CompareWithTruth(got, Truth());
    *posed = e.posed;
    *rotation_deg = e.max_rotation_deg;
    *position_m = e.max_position_m;
  }
  static std::string* dir_;
  static testing::CommandResult* verify_;
  static double scene_size_m_;
};
std::string* PosesColmapTest::dir_ = nullptr;
testing::CommandResult* PosesColmapTest::verify_ = nullptr;
double PosesColmapTest::scene_size_m_ = 0.0;

TEST_F(PosesColmapTest, VerifyFlagsEveryInjectedErrorAndNoCleanFrame) {
  const std::string out = VerifyDir();
  EXPECT_NE(verify_->err.find("colmap"), std::string::npos) << "progress: " << verify_->err;
  const nlohmann::json v = nlohmann::json::parse(ReadText(out + "/verify.json"));
  EXPECT_EQ(v["registered"], kFrames);
  ASSERT_EQ(v["frames"].size(), static_cast<size_t>(kFrames));
  EXPECT_NEAR(v["scene_size_m"].get<double>(), scene_size_m_, 1e-6);
  EXPECT_DOUBLE_EQ(v["thresholds"]["rotation_deg"].get<double>(), 0.5);
  EXPECT_NEAR(v["thresholds"]["position_m"].get<double>(), 0.01 * scene_size_m_, 1e-6);
  // The wrong frames do not support the fit; clean ones may be left out too (the adaptive
  // thresholds are 3x the median error: when COLMAP is very precise, 8 of 16 frames were kept
  // in one clean-clone CI run, every flag still right), which does no harm as long as the
  // clean majority carries the fit.
  EXPECT_LE(v["alignment"]["inliers"].get<int>(), kFrames - 3);
  EXPECT_GE(v["alignment"]["inliers"].get<int>(), kFrames / 2);
  for (int i = 0; i < kFrames; ++i) {
    const nlohmann::json& f = v["frames"][i];
    EXPECT_EQ(f["name"], SynthFrameName(i));
    const bool injected = kRotated.count(i) || kMoved.count(i);
    EXPECT_EQ(f["flagged"].get<bool>(), injected) << "frame " << i << ": " << f.dump();
    if (injected) {
      EXPECT_FALSE(f["inlier"].get<bool>()) << i;
    }
    if (kRotated.count(i)) {
      EXPECT_NEAR(f["rotation_error_deg"].get<double>(), 1.0, 0.2) << i;
    }
    if (kMoved.count(i)) {
      EXPECT_NEAR(f["position_error_m"].get<double>(), 0.02 * scene_size_m_, 0.002 * scene_size_m_)
          << i;
    }
  }
  // Agreement on the clean frames (README figures): well inside the thresholds.
  EXPECT_LT(v["agreement_unflagged"]["max_rotation_error_deg"].get<double>(), 0.2);
  EXPECT_LT(v["agreement_unflagged"]["max_position_error_m"].get<double>(), 0.002 * scene_size_m_);
  std::cout << "synthetic verify: " << v["agreement_unflagged"].dump() << " colmap "
            << v["colmap"]["step_seconds"].dump() << "\n";
  EXPECT_TRUE(fs::is_regular_file(out + "/verify.png"));
  EXPECT_TRUE(fs::is_regular_file(out + "/colmap/commands.txt"));
  EXPECT_NE(ReadText(out + "/colmap/commands.txt").find("--SiftExtraction.use_gpu 0"),
            std::string::npos);
  EXPECT_TRUE(fs::is_regular_file(out + "/colmap/logs/03_mapper.log"));
}

// Frames between keyframes are registered to the keyframes' reconstruction and judged too:
// with keyframes every 20 degrees only the even frames (and the last) are reconstructed, and
// frame 11 (1 degree and 2 % of the scene off), between two of them, is still flagged; every
// frame is compared, no clean one flagged. (Before, the frames between keyframes were not
// compared at all: frame 11 went unseen.)
TEST_F(PosesColmapTest, FramesBetweenKeyframesAreRegisteredAndJudgedToo) {
  const std::string out = *dir_ + "/verify-keyframes";
  const auto r = RunFresco({"poses", "verify", Project(), "--out", out, "--threads", "2",
                            "--keyframe-rotation-deg", "20", "--keyframe-step", "1"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("9 of 16 frames reconstructed as keyframes, 7 of the other 7 registered"),
            std::string::npos)
      << r.out;
  const nlohmann::json v = nlohmann::json::parse(ReadText(out + "/verify.json"));
  EXPECT_EQ(v["registered"], kFrames);
  ASSERT_EQ(v["frames"].size(), static_cast<size_t>(kFrames));
  for (int i = 0; i < kFrames; ++i) {
    const nlohmann::json& f = v["frames"][i];
    EXPECT_TRUE(f["registered"].get<bool>()) << i;
    const bool injected = kRotated.count(i) || kMoved.count(i);
    EXPECT_EQ(f["flagged"].get<bool>(), injected) << "frame " << i << ": " << f.dump();
  }
  EXPECT_NEAR(v["frames"][11]["rotation_error_deg"].get<double>(), 1.0, 0.2);
  EXPECT_TRUE(fs::is_regular_file(out + "/colmap/logs/07_image_registrator.log"));
  // The progress counts the registration's steps too (it said 5 steps, then went past them).
  EXPECT_TRUE(std::regex_search(r.err, std::regex(R"(colmap: 6/8 \([0-9.]+s\) image_registrator)")))
      << r.err;
}

// COLMAP logs through glog, which writes files of its own into the temporary folder (a dozen
// a run, never removed) unless told to log to stderr: its log goes into the workspace's step
// logs instead.
TEST_F(PosesColmapTest, ColmapLogsStayInTheWorkspace) {
  int colmap_files = 0;
  for (const auto& entry : fs::directory_iterator(TempFolder()))
    colmap_files += entry.path().filename().string().rfind("colmap", 0) == 0;
  EXPECT_EQ(colmap_files, 0) << "COLMAP wrote logs into " << TempFolder();
  const std::string mapper_log = ReadText(VerifyDir() + "/colmap/logs/03_mapper.log");
  // glog's lines: "[IWEF]yyyymmdd hh:mm:ss.uuuuuu threadid file:line] msg".
  const std::regex glog_line(R"((^|\n)[IWEF]\d{8} \d\d:\d\d:\d\d\.\d+ +\d+ [^ \n]+:\d+\] )");
  EXPECT_TRUE(std::regex_search(mapper_log, glog_line)) << mapper_log.substr(0, 2000);
}

TEST_F(PosesColmapTest, BootstrapFromRoughPosesIsCloseToTheTruth) {
  const std::string out = *dir_ + "/bootstrap";
  const std::string before = ReadText(Project());
  const auto r = RunFresco(
      {"poses", "bootstrap", Project(), "--out", out, "--colmap-model", ColmapModel(), "--quiet"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(ReadText(Project()), before);  // the input is never touched
  int posed = 0;
  double rotation_deg = 0, position_m = 0;
  BootstrapErrors(out, &posed, &rotation_deg, &position_m);
  EXPECT_EQ(posed, kFrames);
  EXPECT_LT(rotation_deg, 0.2);
  EXPECT_LT(position_m, 0.01 * scene_size_m_);
  std::cout << "bootstrap (given poses): max " << rotation_deg << " deg, " << position_m
            << " m of a " << scene_size_m_ << " m scene\n";
  // The new project loads and points at the new poses.
  fresco::Project p;
  ASSERT_TRUE(LoadProject(out + "/project.json", {}, &p).ok());
  EXPECT_EQ(fs::canonical(p.Resolve(p.poses)), fs::canonical(out + "/sparse/images.txt"));
  EXPECT_EQ(fs::canonical(p.Resolve(p.video)), fs::canonical(Capture() + "/frames"));
  const nlohmann::json b = nlohmann::json::parse(ReadText(out + "/bootstrap.json"));
  EXPECT_EQ(b["aligned_with"], "given_poses");
  // The three wrong poses do not support the fit: the moved ones (17 cm off) are within
  // the default inlier threshold (2 % of the scene) but not within the adaptive one, nor
  // is the one rotated by 1 deg (default 2 deg).
  EXPECT_LE(b["inliers"].get<int>(), kFrames - 3);
  EXPECT_GE(b["inliers"].get<int>(), kFrames - 5);
}

TEST_F(PosesColmapTest, BootstrapFromControlPointsWithoutPoses) {
  // A copy of the project whose poses file holds no poses; 5 control points (on the ground
  // and above it) seen in 2-3 frames each (pixels: true projections).
  const std::string dir = *dir_ + "/control";
  fs::create_directories(dir);
  Camera camera;
  {
    std::map<int, Camera> cameras;
    ASSERT_TRUE(ReadColmapCameras(Capture() + "/sparse/cameras.txt", &cameras).ok());
    camera = cameras.begin()->second;
  }
  const std::vector<Eigen::Vector3d> world = testing::BlocksControlPoints();
  int points = 0;
  const std::string text = ControlPointsText(world, world, Truth(), camera, &points);
  ASSERT_GE(points, 3) << text;
  WriteText(dir + "/control.txt", text);
  WriteText(dir + "/empty_images.txt", "# no poses\n");
  fresco::Project p;
  ASSERT_TRUE(LoadProject(Project(), {}, &p).ok());
  p.poses = dir + "/empty_images.txt";
  p.truth.poses.clear();
  ASSERT_TRUE(SaveProject(p, dir + "/project.json").ok());
  // Without control points there is nothing to align with.
  const auto none = RunFresco({"poses", "bootstrap", dir + "/project.json", "--out", dir + "/none",
                               "--colmap-model", ColmapModel(), "--quiet"});
  EXPECT_EQ(none.exit_code, 1);
  EXPECT_NE(none.err.find("--control-points"), std::string::npos) << none.err;
  const auto r = RunFresco({"poses", "bootstrap", dir + "/project.json", "--out", dir + "/out",
                            "--control-points", dir + "/control.txt", "--colmap-model",
                            ColmapModel(), "--quiet"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  int posed = 0;
  double rotation_deg = 0, position_m = 0;
  BootstrapErrors(dir + "/out", &posed, &rotation_deg, &position_m);
  EXPECT_EQ(posed, kFrames);
  EXPECT_LT(rotation_deg, 0.2);
  EXPECT_LT(position_m, 0.01 * scene_size_m_);
  std::cout << "bootstrap (control points): max " << rotation_deg << " deg, " << position_m
            << " m\n";

  // Control points measured roughly (each 6-10 cm off): the alignment is off; ICP of
  // COLMAP's sparse points to the mesh (--refine-mesh) brings it back.
  std::vector<Eigen::Vector3d> rough = world;
  for (size_t k = 0; k < rough.size(); ++k) {
    const double sign = k % 2 ? 1.0 : -1.0;
    rough[k] += Eigen::Vector3d(0.06 * sign, 0.08, -0.07 * sign);
  }
  WriteText(dir + "/rough.txt", ControlPointsText(world, rough, Truth(), camera, &points));
  double plain_rotation = 0, plain_position = 0, icp_rotation = 0, icp_position = 0;
  for (const bool icp : {false, true}) {
    const std::string out = dir + (icp ? "/rough-icp" : "/rough");
    std::vector<std::string> args = {
        "poses",       "bootstrap",        dir + "/project.json", "--out",
        out,           "--control-points", dir + "/rough.txt",    "--colmap-model",
        ColmapModel(), "--quiet"};
    if (icp) args.push_back("--refine-mesh");
    const auto rr = RunFresco(args);
    ASSERT_EQ(rr.exit_code, 0) << rr.err;
    BootstrapErrors(out, &posed, icp ? &icp_rotation : &plain_rotation,
                    icp ? &icp_position : &plain_position);
  }
  std::cout << "bootstrap (rough control points): max " << plain_rotation << " deg, "
            << plain_position << " m; with mesh ICP " << icp_rotation << " deg, " << icp_position
            << " m\n";
  EXPECT_GT(plain_position, 0.03);  // the rough points do move it
  // ICP fixes the position; the rotation stays what COLMAP's own model gives (0.17-0.18 deg
  // off in the worst frame with exact control points, varying from run to run: COLMAP is not
  // deterministic), so it is bounded relative to that, not by a fixed figure (one CI run:
  // 0.180 exact, 0.204 with ICP).
  EXPECT_LT(icp_rotation, rotation_deg + 0.1);
  EXPECT_LT(icp_position, 0.01 * scene_size_m_);
  EXPECT_LT(icp_position, 0.5 * plain_position);
  const nlohmann::json b = nlohmann::json::parse(ReadText(dir + "/rough-icp/bootstrap.json"));
  EXPECT_GT(b["mesh_icp"]["pairs"].get<int>(), 1000);
  EXPECT_LT(b["mesh_icp"]["median_distance_after_m"].get<double>(),
            b["mesh_icp"]["median_distance_before_m"].get<double>());
}

TEST(PosesCli, ErrorsAreClear) {
  const std::string dir = MakeTempDir("poses-cli");
  const auto no_sub = RunFresco({"poses"});
  EXPECT_EQ(no_sub.exit_code, 2);
  EXPECT_NE(no_sub.err.find("verify"), std::string::npos) << no_sub.err;
  const auto missing = RunFresco({"poses", "verify", dir + "/nope.json", "--out", dir + "/o"});
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.err.find("nope.json"), std::string::npos) << missing.err;
  const auto no_out = RunFresco({"poses", "verify", dir + "/nope.json"});
  EXPECT_EQ(no_out.exit_code, 2);
  const auto bad_matcher = RunFresco(
      {"poses", "bootstrap", dir + "/nope.json", "--out", dir + "/o", "--matcher", "vocab"});
  EXPECT_EQ(bad_matcher.exit_code, 2);
}

TEST(PosesCli, MissingColmapProgramIsAClearError) {
  const std::string dir = MakeTempDir("poses-nocolmap") + "/capture";
  const auto synth = RunFresco({"synth", "--scene", "builtin:plane", "--out", dir, "--frames", "4",
                                "--size", "64x48", "--supersample", "1"});
  ASSERT_EQ(synth.exit_code, 0) << synth.err;
  const auto r = RunFresco({"poses", "verify", dir + "/project.json", "--out", dir + "/v",
                            "--colmap", "/nonexistent/colmap"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("/nonexistent/colmap: program not found"), std::string::npos) << r.err;
  const auto no_model = RunFresco({"poses", "verify", dir + "/project.json", "--out", dir + "/v",
                                   "--colmap-model", dir + "/no-model"});
  EXPECT_EQ(no_model.exit_code, 2);
  EXPECT_NE(no_model.err.find("no-model: --colmap-model: no such folder"), std::string::npos)
      << no_model.err;
}

// Real photos: the Sceaux castle (10 images, 1416x1064) and the poses OpenMVG estimated.
// OpenMVG's units are arbitrary: the scene size is the OpenMVS mesh's bounding-box diagonal
// (10.26 units, measured from openmvs_original/scene_mesh.ply).
TEST(PosesReal, SceauxCastleAgreesWithOpenMvg) {
  FRESCO_REQUIRE_SHARED_DATA();
  FRESCO_REQUIRE_COLMAP();
  const std::string data = testing::SharedDataDir() + "/sceaux-castle-openmvs";
  if (!fs::is_directory(data)) GTEST_SKIP() << data << " is absent: skipped";
  const std::string dir = MakeTempDir("poses-sceaux");
  WriteText(dir + "/project.json",
            nlohmann::json({{"fresco", 1},
                            {"scene", "no-scene.gltf"},
                            {"camera", data + "/colmap_sparse_txt/cameras.txt"},
                            {"video", data + "/images"},
                            {"poses", data + "/colmap_sparse_txt/images.txt"}})
                .dump());
  const auto r = RunFresco({"poses", "verify", dir + "/project.json", "--out", dir + "/out",
                            "--scene-size-m", "10.26", "--max-image-size", "1000"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json v = nlohmann::json::parse(ReadText(dir + "/out/verify.json"));
  EXPECT_EQ(v["registered"], 10);
  EXPECT_EQ(v["flagged"], 0) << v.dump(1);
  double max_rotation = 0, max_position = 0;
  for (const auto& f : v["frames"]) {
    max_rotation = std::max(max_rotation, f["rotation_error_deg"].get<double>());
    max_position = std::max(max_position, f["position_error_m"].get<double>());
  }
  EXPECT_LT(max_rotation, 0.2);
  EXPECT_LT(max_position, 0.02);  // 0.2 % of the scene size
  std::cout << "sceaux: max " << max_rotation << " deg, " << max_position << " units; colmap "
            << v["colmap"]["seconds"] << " s\n";
}

}  // namespace
}  // namespace fresco
