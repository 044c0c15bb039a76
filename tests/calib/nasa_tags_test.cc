// The NASA AprilTag photos (../shared/data/apriltag-detection-nasa, issue 56's real sets): 3
// photos, 799x533 JPEG, of many small tag36h11 tags (all id 0, the library's own 1-bit
// border) on cubes and rovers, with the apriltag library's reference detections (id and four
// corners a line). Not a calibration board: what each of the two detectors Fresco runs on
// every view (calib/detect.h) reads there, matched to the reference tags by their centres,
// and how far their unrefined corners are from the reference's. Skipped without the data.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "calib/detect.h"

namespace fresco::calib {
namespace {

namespace fs = std::filesystem;

fs::path NasaDir() { return fs::path(FRESCO_NASA_SHARED_DATA) / "apriltag-detection-nasa"; }

// "0, (x y), (x y), (x y), (x y)" a line.
std::vector<TagQuad> ReadReference(const fs::path& txt) {
  std::vector<TagQuad> out;
  std::ifstream in(txt);
  for (std::string line; std::getline(in, line);) {
    TagQuad q;
    double v[8];
    if (std::sscanf(line.c_str(), "%d, (%lf %lf), (%lf %lf), (%lf %lf), (%lf %lf)", &q.id, &v[0],
                    &v[1], &v[2], &v[3], &v[4], &v[5], &v[6], &v[7]) != 9)
      continue;
    for (int k = 0; k < 4; ++k) q.p[k] = Eigen::Vector2d(v[2 * k], v[2 * k + 1]);
    out.push_back(q);
  }
  return out;
}

Eigen::Vector2d Centre(const TagQuad& q) { return 0.25 * (q.p[0] + q.p[1] + q.p[2] + q.p[3]); }

struct Matched {
  int read = 0, matched = 0;          // tags read; of them, on a reference tag
  std::vector<double> corner_err_px;  // matched tags' corners, same order as the reference
};

// A tag read matches the reference tag whose centre is within a quarter of its edge.
Matched Match(const std::vector<TagQuad>& read, const std::vector<TagQuad>& reference) {
  Matched m;
  m.read = static_cast<int>(read.size());
  for (const TagQuad& r : reference) {
    const double edge = (r.p[1] - r.p[0]).norm();
    const auto near = std::find_if(read.begin(), read.end(), [&](const TagQuad& q) {
      return q.id == r.id && (Centre(q) - Centre(r)).norm() < 0.25 * edge;
    });
    if (near == read.end()) continue;
    ++m.matched;
    for (int k = 0; k < 4; ++k) m.corner_err_px.push_back((near->p[k] - r.p[k]).norm());
  }
  return m;
}

double Median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

TEST(NasaAprilTagPhotosTest, BothDetectorsReadTheReferenceTags) {
  if (!fs::is_directory(NasaDir()))
    GTEST_SKIP() << NasaDir() << " is absent: real-data check skipped";
  std::vector<fs::path> photos;
  for (const auto& entry : fs::directory_iterator(NasaDir()))
    if (entry.path().extension() == ".jpg") photos.push_back(entry.path());
  std::sort(photos.begin(), photos.end());
  ASSERT_EQ(photos.size(), 3u);
  int reference_tags = 0, library_matched = 0, aruco_matched = 0, library_read = 0, aruco_read = 0;
  std::vector<double> library_err, aruco_err;
  for (const fs::path& photo : photos) {
    const std::vector<TagQuad> reference = ReadReference(fs::path(photo).replace_extension(".txt"));
    ASSERT_FALSE(reference.empty()) << photo;
    const cv::Mat gray = cv::imread(photo.string(), cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(gray.empty()) << photo;
    DetectOptions options;  // Fresco's defaults, every tag of id 0 kept
    options.keep_repeated_ids = true;
    const Matched library = Match(DetectTagsApriltag(gray, 1, options), reference);
    // aruco with the border these tags have (its defaults otherwise, unrefined).
    const Matched aruco = Match(DetectTagsAruco(gray, 1, 1), reference);
    std::printf(
        "%s: %zu reference tags; apriltag library read %d (%d on a reference tag, corners "
        "median %.3f px from it), aruco read %d (%d, median %.3f px)\n",
        photo.filename().c_str(), reference.size(), library.read, library.matched,
        Median(library.corner_err_px), aruco.read, aruco.matched, Median(aruco.corner_err_px));
    reference_tags += static_cast<int>(reference.size());
    library_read += library.read, aruco_read += aruco.read;
    library_matched += library.matched, aruco_matched += aruco.matched;
    library_err.insert(library_err.end(), library.corner_err_px.begin(),
                       library.corner_err_px.end());
    aruco_err.insert(aruco_err.end(), aruco.corner_err_px.begin(), aruco.corner_err_px.end());
  }
  std::printf(
      "all: %d reference tags; library %d read, %d matched (median %.3f px); aruco %d "
      "read, %d matched (median %.3f px)\n",
      reference_tags, library_read, library_matched, Median(library_err), aruco_read, aruco_matched,
      Median(aruco_err));
  // Measured: 47 reference tags; the library 45 read, all on a reference tag, corners median
  // 0.33 px from it (refine_edges on, quad_decimate 1: not the reference's settings); aruco
  // (1-bit border, unrefined) 22 read, 20 matched, median 1.0 px.
  EXPECT_GE(library_matched, 44);
  EXPECT_EQ(library_read, library_matched);
  EXPECT_LT(Median(library_err), 0.5);
  EXPECT_GE(aruco_matched, 18);
  EXPECT_LT(Median(aruco_err), 1.5);
}

}  // namespace
}  // namespace fresco::calib
