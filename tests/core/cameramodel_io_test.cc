// mrcal .cameramodel files: exact round trips, libmrcal's C reader and mrcal's Python
// reader on what we write, mrcal's own test models, and one-line errors for bad input.
#include "pipeline/core/cameramodel_io.h"

#include <sys/wait.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <sstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/test_support.h"

extern "C" {
#include <mrcal/mrcal.h>
}

namespace fresco {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

// A model with awkward numbers: long mantissas, tiny and huge magnitudes.
CameraModelFile AwkwardModel(LensModel model, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<double> params(LensModelNumParams(model));
  params[0] = 1761.181055123456789 + unit(rng);
  params[1] = 1761.250444987654321 + unit(rng);
  params[2] = 1965.706996 + unit(rng) / 3;
  params[3] = 1087.518797 + unit(rng) / 7;
  for (size_t i = 4; i < params.size(); ++i) params[i] = unit(rng) * std::pow(10.0, -int(i % 7));
  if (params.size() > 6) params[6] = 1.2345678901234567e-13;  // p1: tiny, %f would lose it
  CameraModelFile file;
  file.camera = Camera::FromParams(model, 4000, 2200, params);
  file.cam_from_ref = Rigid3d::FromRt(
      std::array<double, 6>{0.02 + unit(rng) / 9, -0.3, -0.01, 1.0 / 3, 2e5, -3.0}.data());
  return file;
}

void ExpectSameModel(const CameraModelFile& a, const CameraModelFile& b) {
  EXPECT_EQ(a.camera.model, b.camera.model);
  EXPECT_EQ(a.camera.width, b.camera.width);
  EXPECT_EQ(a.camera.height, b.camera.height);
  const std::vector<double> pa = a.camera.Params(), pb = b.camera.Params();
  ASSERT_EQ(pa.size(), pb.size());
  for (size_t i = 0; i < pa.size(); ++i) EXPECT_NEAR(pa[i], pb[i], 1e-12 * std::abs(pa[i]));
  EXPECT_LT(RotationDifferenceDeg(a.cam_from_ref.rotation, b.cam_from_ref.rotation), 1e-12);
  EXPECT_LT((a.cam_from_ref.translation - b.cam_from_ref.translation).norm(), 1e-12);
}

TEST(CameraModelIo, WriteReadRoundTripIsExact) {
  const std::string dir = testing::MakeTempDir("cameramodel");
  for (LensModel model :
       {LensModel::kPinhole, LensModel::kOpenCV4, LensModel::kOpenCV5, LensModel::kOpenCV8}) {
    const CameraModelFile written = AwkwardModel(model, 21 + static_cast<int>(model));
    const std::string path = dir + "/" + LensModelName(model) + ".cameramodel";
    ASSERT_TRUE(WriteCameraModel(path, written).ok());
    CameraModelFile read;
    const Status status = ReadCameraModel(path, &read);
    ASSERT_TRUE(status.ok()) << status.message();
    ExpectSameModel(written, read);
    EXPECT_EQ(read.camera.Params(), written.camera.Params());  // bit-exact
    EXPECT_EQ(read.camera.fold_r2, written.camera.fold_r2);

    // libmrcal's own reader sees the same numbers.
    mrcal_cameramodel_t* mrcal_model = mrcal_read_cameramodel_file(path.c_str());
    ASSERT_NE(mrcal_model, nullptr);
    char name[256];
    ASSERT_TRUE(mrcal_lensmodel_name(name, sizeof(name), &mrcal_model->lensmodel));
    EXPECT_EQ(std::string(name), LensModelName(model));
    const std::vector<double> params = written.camera.Params();
    for (size_t i = 0; i < params.size(); ++i) EXPECT_EQ(mrcal_model->intrinsics[i], params[i]);
    EXPECT_EQ(mrcal_model->imagersize[0], 4000u);
    EXPECT_EQ(mrcal_model->imagersize[1], 2200u);
    double rt[6];
    written.cam_from_ref.ToRt(rt);
    for (int i = 0; i < 6; ++i) EXPECT_EQ(mrcal_model->rt_cam_ref[i], rt[i]);
    mrcal_free_cameramodel(&mrcal_model);
  }
  // Atomic: no temp files left beside the models.
  for (const auto& entry : fs::directory_iterator(dir))
    EXPECT_EQ(entry.path().extension(), ".cameramodel") << entry.path();
}

TEST(CameraModelIo, ColmapCamerasAreWrittenAsTheirMrcalForm) {
  const std::string dir = testing::MakeTempDir("cameramodel");
  CameraModelFile file;
  file.camera = Camera::FromParams(LensModel::kRadial, 640, 480, {500.5, 319.5, 239.5, -0.1, 0.02});
  ASSERT_TRUE(WriteCameraModel(dir + "/radial.cameramodel", file).ok());
  CameraModelFile read;
  ASSERT_TRUE(ReadCameraModel(dir + "/radial.cameramodel", &read).ok());
  EXPECT_EQ(read.camera.model, LensModel::kOpenCV4);
  EXPECT_EQ(read.camera.Params(),
            (std::vector<double>{500.5, 500.5, 319.5, 239.5, -0.1, 0.02, 0, 0}));
}

TEST(CameraModelIo, WriteRefusesInvalidCameraAndKeepsTheOldFile) {
  const std::string dir = testing::MakeTempDir("cameramodel");
  const std::string path = dir + "/cam.cameramodel";
  CameraModelFile good = AwkwardModel(LensModel::kOpenCV8, 3);
  ASSERT_TRUE(WriteCameraModel(path, good).ok());
  const std::string before = testing::ReadText(path);
  CameraModelFile bad = good;
  bad.camera.k2 = std::nan("");
  const Status status = WriteCameraModel(path, bad);
  ASSERT_FALSE(status.ok());
  EXPECT_THAT(status.message(), HasSubstr("cam.cameramodel"));
  EXPECT_THAT(status.message(), HasSubstr("k2"));
  EXPECT_EQ(testing::ReadText(path), before);
}

TEST(CameraModelIo, ReadsMrcalsOwnTestModels) {
  FRESCO_REQUIRE_SHARED_DATA();
  const std::string dir = testing::SharedDataDir() + "/mrcal-cameramodels";
  CameraModelFile model;
  const Status status = ReadCameraModel(dir + "/cam0.opencv8.cameramodel", &model);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(model.camera.model, LensModel::kOpenCV8);
  EXPECT_EQ(model.camera.width, 4000);
  EXPECT_EQ(model.camera.height, 2200);
  EXPECT_EQ(model.camera.Params(),
            (std::vector<double>{1761.181055, 1761.250444, 1965.706996, 1087.518797, -0.01266096516,
                                 0.03590794372, -0.0002547045941, 0.0005275929652, 0.01968883397,
                                 0.01482863541, -0.0562239888, 0.0500223357}));
  double rt[6];
  model.cam_from_ref.ToRt(rt);
  const double expected_rt[6] = {2e-2, -3e-1, -1e-2, 1., 2, -3.};
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(rt[i], expected_rt[i], 1e-15);

  // Same projection as libmrcal with the file's intrinsics, over the whole image.
  mrcal_cameramodel_t* mrcal_model =
      mrcal_read_cameramodel_file((dir + "/cam0.opencv8.cameramodel").c_str());
  ASSERT_NE(mrcal_model, nullptr);
  double max_error_px = 0;
  for (double y = -0.55; y <= 0.55; y += 0.05) {
    for (double x = -1.1; x <= 1.1; x += 0.05) {
      const mrcal_point3_t p{{x * 3, y * 3, 3}};
      mrcal_point2_t q;
      ASSERT_TRUE(mrcal_project(&q, nullptr, nullptr, &p, 1, &mrcal_model->lensmodel,
                                mrcal_model->intrinsics));
      Eigen::Vector2d pixel;
      ASSERT_TRUE(model.camera.Project(Eigen::Vector3d(p.x, p.y, p.z), &pixel));
      max_error_px = std::max(max_error_px, (pixel - Eigen::Vector2d(q.x, q.y)).norm());
    }
  }
  mrcal_free_cameramodel(&mrcal_model);
  EXPECT_LT(max_error_px, 1e-9);

  ASSERT_TRUE(ReadCameraModel(dir + "/cam1.opencv8.cameramodel", &model).ok());
  EXPECT_EQ(model.camera.fx, 1761);
  EXPECT_EQ(model.camera.k6, 0.04);

  // mrcal's splined models are not supported: a clear one-line error.
  const Status splined = ReadCameraModel(dir + "/cam0.splined.cameramodel", &model);
  ASSERT_FALSE(splined.ok());
  EXPECT_THAT(splined.message(), HasSubstr("cam0.splined.cameramodel"));
  EXPECT_THAT(splined.message(), HasSubstr("lensmodel"));
  EXPECT_THAT(splined.message(), HasSubstr("LENSMODEL_SPLINED_STEREOGRAPHIC"));
  EXPECT_THAT(splined.message(), HasSubstr("not supported yet"));
  EXPECT_EQ(splined.message().find('\n'), std::string::npos);
}

std::string RunCommand(const std::string& command, int* exit_code) {
  std::string out;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return out;
  char buffer[4096];
  size_t n;
  while ((n = fread(buffer, 1, sizeof(buffer), pipe)) > 0) out.append(buffer, n);
  const int status = pclose(pipe);
  *exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return out;
}

std::vector<double> ParseNumbers(const std::string& line) {
  std::istringstream in(line);
  std::vector<double> numbers;
  std::string token;
  while (in >> token) numbers.push_back(std::strtod(token.c_str(), nullptr));
  return numbers;
}

TEST(CameraModelIo, MrcalPythonReadsWhatWeWrite) {
  if (std::system("/usr/bin/python3 -c 'import mrcal' >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "/usr/bin/python3 cannot import mrcal (python3-mrcal not installed)";
  const std::string dir = testing::MakeTempDir("cameramodel-py");
  const CameraModelFile written = AwkwardModel(LensModel::kOpenCV8, 5);
  const std::string path = dir + "/cam.cameramodel";
  ASSERT_TRUE(WriteCameraModel(path, written).ok());
  testing::WriteText(dir + "/read.py", R"(import sys
import numpy as np
import mrcal
m = mrcal.cameramodel(sys.argv[1])
lensmodel, intrinsics = m.intrinsics()
print(lensmodel)
print(' '.join(repr(float(x)) for x in intrinsics))
print(' '.join(repr(float(x)) for x in m.extrinsics_rt_fromref()))
print(' '.join(str(int(x)) for x in m.imagersize()))
p = np.array(((0.1, -0.2, 1.0), (1.5, 0.3, 2.0), (-2.0, -1.0, 3.0)))
print(' '.join(repr(float(x)) for x in mrcal.project(p, lensmodel, intrinsics).ravel()))
)");
  int exit_code = -1;
  const std::string out =
      RunCommand("/usr/bin/python3 " + dir + "/read.py " + path + " 2>&1", &exit_code);
  ASSERT_EQ(exit_code, 0) << out;
  std::istringstream lines(out);
  std::string lensmodel, intrinsics, extrinsics, imagersize, projected;
  std::getline(lines, lensmodel);
  std::getline(lines, intrinsics);
  std::getline(lines, extrinsics);
  std::getline(lines, imagersize);
  std::getline(lines, projected);
  EXPECT_EQ(lensmodel, "LENSMODEL_OPENCV8");
  EXPECT_EQ(ParseNumbers(intrinsics), written.camera.Params());  // bit-exact
  double rt[6];
  written.cam_from_ref.ToRt(rt);
  EXPECT_EQ(ParseNumbers(extrinsics), std::vector<double>(rt, rt + 6));
  EXPECT_EQ(ParseNumbers(imagersize), (std::vector<double>{4000, 2200}));
  const std::vector<double> q = ParseNumbers(projected);
  ASSERT_EQ(q.size(), 6u);
  const Eigen::Vector3d points[3] = {{0.1, -0.2, 1.0}, {1.5, 0.3, 2.0}, {-2.0, -1.0, 3.0}};
  for (int i = 0; i < 3; ++i) {
    Eigen::Vector2d pixel;
    ASSERT_TRUE(written.camera.Project(points[i], &pixel));
    EXPECT_NEAR(pixel.x(), q[2 * i], 1e-9);
    EXPECT_NEAR(pixel.y(), q[2 * i + 1], 1e-9);
  }
}

TEST(CameraModelIo, AcceptsMrcalPythonSyntax) {
  // As mrcal's Python writer emits it: comments, trailing commas, extra keys.
  const std::string text = R"(# generated on 2024-01-01 with mrcal-calibrate-cameras
{
    'lensmodel':  'LENSMODEL_OPENCV4',

    # intrinsics are fx,fy,cx,cy,distortion0,distortion1,....
    'intrinsics': [ 1000.5, 1001, 639.5, 479.5, -0.1, 0.01, 1e-4, -2e-4,],

    'valid_intrinsics_region': [
    [ 0, 0 ],
    [ 1279, 0 ],
    [ 1279, 959 ],
    [ 0, 0 ],
],

    # extrinsics are rt_fromref
    'extrinsics': [ 0, 0, 0, 0, 0, 0,],

    'imagersize': [ 1280, 960,],

    'icam_intrinsics': 0,

}
)";
  CameraModelFile model;
  const Status status = ParseCameraModel(text, "python.cameramodel", &model);
  ASSERT_TRUE(status.ok()) << status.message();
  EXPECT_EQ(model.camera.Params(),
            (std::vector<double>{1000.5, 1001, 639.5, 479.5, -0.1, 0.01, 1e-4, -2e-4}));
  EXPECT_EQ(model.camera.width, 1280);
}

struct BadInput {
  std::string file;
  std::string text;
  std::vector<std::string> expected;  // substrings of the message
};

std::string ModelText(const std::string& lensmodel, const std::string& intrinsics,
                      const std::string& extrinsics = "0, 0, 0, 0, 0, 0",
                      const std::string& imagersize = "640, 480") {
  return "{\n    'lensmodel': '" + lensmodel + "',\n    'intrinsics': [ " + intrinsics +
         " ],\n    'extrinsics': [ " + extrinsics + " ],\n    'imagersize': [ " + imagersize +
         " ]\n}\n";
}

TEST(CameraModelIo, BadInputGivesOneLineErrorsNamingFileAndField) {
  const std::string dir = testing::MakeTempDir("cameramodel-bad");
  const std::string cv4 = "500, 500, 320, 240, -0.1, 0.01, 0, 0";
  const std::vector<BadInput> cases = {
      {"malformed.cameramodel",
       "{\n    'lensmodel': 'LENSMODEL_OPENCV4',\n    'intrinsics': [ 1, 2, 3\n",
       {"malformed.cameramodel:", "unexpected end"}},
      {"nobrace.cameramodel",
       "lensmodel = 'LENSMODEL_OPENCV4'\n",
       {"nobrace.cameramodel:1:", "expected '{'"}},
      {"unsupported.cameramodel",
       ModelText("LENSMODEL_CAHVOR", "1, 2, 3, 4, 5, 6, 7, 8, 9"),
       {"unsupported.cameramodel:2: lensmodel: LENSMODEL_CAHVOR is not supported yet",
        "LENSMODEL_OPENCV8"}},
      {"unknown.cameramodel",
       ModelText("LENSMODEL_FOO", cv4),
       {"unknown.cameramodel:2: lensmodel: unknown lens model 'LENSMODEL_FOO'"}},
      {"colmapname.cameramodel",
       ModelText("FULL_OPENCV", cv4),
       {"colmapname.cameramodel:2: lensmodel:", "FULL_OPENCV"}},
      {"count.cameramodel",
       ModelText("LENSMODEL_OPENCV8", cv4 + ", 0, 0, 0"),
       {"count.cameramodel:3: intrinsics: LENSMODEL_OPENCV8 takes 12 values (got 11)"}},
      {"nan.cameramodel",
       ModelText("LENSMODEL_OPENCV4", "500, 500, 320, 240, nan, 0, 0, 0"),
       {"nan.cameramodel:3: intrinsics: k1 must be finite (got nan)"}},
      {"text.cameramodel",
       ModelText("LENSMODEL_OPENCV4", "500, 500, 320, 240, 0, abc, 0, 0"),
       {"text.cameramodel:3: intrinsics: k2 is not a number ('abc')"}},
      {"negative.cameramodel",
       ModelText("LENSMODEL_PINHOLE", "-3, 500, 320, 240"),
       {"negative.cameramodel: intrinsics: fx must be > 0 (got -3)"}},
      {"extrinsics.cameramodel",
       ModelText("LENSMODEL_PINHOLE", "500, 500, 320, 240", "0, 0, 0"),
       {"extrinsics.cameramodel:4: extrinsics:", "takes 6 values (got 3)"}},
      {"size.cameramodel",
       ModelText("LENSMODEL_PINHOLE", "500, 500, 320, 240", "0, 0, 0, 0, 0, 0", "0, 480"),
       {"size.cameramodel:5: imagersize: width must be a positive integer (got 0)"}},
      {"missing.cameramodel",
       "{ 'lensmodel': 'LENSMODEL_PINHOLE', 'intrinsics': [500, 500, 320, 240],"
       " 'imagersize': [640, 480] }",
       {"missing.cameramodel: extrinsics: missing"}},
  };
  for (const BadInput& bad : cases) {
    const std::string path = dir + "/" + bad.file;
    testing::WriteText(path, bad.text);
    CameraModelFile model;
    const Status status = ReadCameraModel(path, &model);
    ASSERT_FALSE(status.ok()) << bad.file;
    EXPECT_EQ(status.message().find('\n'), std::string::npos) << status.message();
    EXPECT_THAT(status.message(), HasSubstr(path)) << bad.file;
    for (const std::string& expected : bad.expected)
      EXPECT_THAT(status.message(), HasSubstr(expected)) << bad.file;
    std::map<int, Camera> cameras;
    EXPECT_FALSE(ReadCameras(path, &cameras).ok()) << bad.file;
  }
  CameraModelFile model;
  const Status missing = ReadCameraModel(dir + "/nope.cameramodel", &model);
  ASSERT_FALSE(missing.ok());
  EXPECT_THAT(missing.message(), HasSubstr(dir + "/nope.cameramodel"));
}

TEST(CameraModelIo, ReadCamerasTakesCameramodelOrColmapCameras) {
  const std::string dir = testing::MakeTempDir("cameras");
  const CameraModelFile written = AwkwardModel(LensModel::kOpenCV5, 9);
  ASSERT_TRUE(WriteCameraModel(dir + "/cam.cameramodel", written).ok());
  std::map<int, Camera> cameras;
  ASSERT_TRUE(ReadCameras(dir + "/cam.cameramodel", &cameras).ok());
  ASSERT_EQ(cameras.size(), 1u);
  ASSERT_EQ(cameras.count(1), 1u);
  EXPECT_EQ(cameras[1].Params(), written.camera.Params());

  // Anything else is a COLMAP cameras.txt (COLMAP's pixel centre is 0.5 off ours).
  testing::WriteText(dir + "/cameras.txt",
                     "# Camera list\n3 SIMPLE_RADIAL 640 480 500 320.5 240.5 -0.05\n");
  cameras.clear();
  const Status status = ReadCameras(dir + "/cameras.txt", &cameras);
  ASSERT_TRUE(status.ok()) << status.message();
  ASSERT_EQ(cameras.count(3), 1u);
  EXPECT_EQ(cameras[3].model, LensModel::kSimpleRadial);
  EXPECT_EQ(cameras[3].cx, 320.0);
  EXPECT_EQ(cameras[3].k1, -0.05);
}

}  // namespace
}  // namespace fresco
