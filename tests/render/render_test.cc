// Tests of the CPU rasterizer and renderer against ground truth computed independently:
// Camera::Project of known surface points, a brute-force double-precision ray cast of the same
// rays, analytic floor intersections, and textures that must come back texel for texel.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "pipeline/core/camera.h"
#include "pipeline/core/scene.h"
#include "pipeline/render/rasterizer.h"
#include "pipeline/render/renderer.h"
#include "tests/test_support.h"

namespace fresco {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

Camera PinholeCamera(int width, int height, double f) {
  return Camera::FromParams(LensModel::kPinhole, width, height,
                            {f, f, (width - 1) / 2.0, (height - 1) / 2.0});
}

// OPENCV8 with strong barrel distortion (k1 = -0.3) plus tangential and rational terms.
Camera DistortedCamera() {
  return Camera::FromParams(
      LensModel::kOpenCV8, 320, 240,
      {200.0, 205.0, 161.3, 118.7, -0.3, 0.08, 1e-3, -5e-4, -0.005, 0.01, 0.0, 0.0});
}

// cam_from_world for a camera at `eye` looking at `target` (image y down ~ -up).
Rigid3d LookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
               const Eigen::Vector3d& up = Eigen::Vector3d::UnitY()) {
  const Eigen::Vector3d z = (target - eye).normalized();
  const Eigen::Vector3d x = z.cross(up).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d r;
  r.row(0) = x;
  r.row(1) = y;
  r.row(2) = z;
  return Rigid3d::FromMatrix(r, -(r * eye));
}

int AddTriangle(TriangleMesh* mesh, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                const Eigen::Vector3d& c, int material = 0) {
  const int base = static_cast<int>(mesh->vertices.size());
  mesh->vertices.insert(mesh->vertices.end(), {a, b, c});
  mesh->triangles.emplace_back(base, base + 1, base + 2);
  mesh->uvs.push_back({Eigen::Vector2f::Zero(), Eigen::Vector2f::Zero(), Eigen::Vector2f::Zero()});
  mesh->material.push_back(material);
  mesh->has_uv.push_back(false);
  return mesh->NumTriangles() - 1;
}

// A quad a, b, c, d (counter-clockwise seen from the front) with UVs (u0,v0)-(u1,v1).
void AddQuad(TriangleMesh* mesh, const Eigen::Vector3d corners[4], const Eigen::Vector2f uvs[4],
             int material = 0) {
  const int base = static_cast<int>(mesh->vertices.size());
  for (int k = 0; k < 4; ++k) mesh->vertices.push_back(corners[k]);
  mesh->triangles.emplace_back(base, base + 1, base + 2);
  mesh->triangles.emplace_back(base, base + 2, base + 3);
  mesh->uvs.push_back({uvs[0], uvs[1], uvs[2]});
  mesh->uvs.push_back({uvs[0], uvs[2], uvs[3]});
  for (int k = 0; k < 2; ++k) {
    mesh->material.push_back(material);
    mesh->has_uv.push_back(true);
  }
}

// An nx x ny grid of squares of side `cell_m` in the plane through `origin` spanned by `du`
// and `dv` (unit vectors), two triangles per cell.
void AddGrid(TriangleMesh* mesh, const Eigen::Vector3d& origin, const Eigen::Vector3d& du,
             const Eigen::Vector3d& dv, int nx, int ny, double cell_m) {
  const int base = static_cast<int>(mesh->vertices.size());
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) mesh->vertices.push_back(origin + cell_m * (i * du + j * dv));
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const int v00 = base + j * (nx + 1) + i, v10 = v00 + 1, v01 = v00 + nx + 1, v11 = v01 + 1;
      mesh->triangles.emplace_back(v00, v10, v11);
      mesh->triangles.emplace_back(v00, v11, v01);
      for (int k = 0; k < 2; ++k) {
        mesh->uvs.push_back(
            {Eigen::Vector2f::Zero(), Eigen::Vector2f::Zero(), Eigen::Vector2f::Zero()});
        mesh->material.push_back(0);
        mesh->has_uv.push_back(false);
      }
    }
  }
}

struct Hit {
  int id = -1;
  double z = kInf;
};

// Brute force: the nearest triangle along ray (x, y, 1) (Moller-Trumbore in double, ties to
// the smallest id), with depth >= near_m.
Hit CastRay(const TriangleMesh& mesh, const Rigid3d& cam_from_local, const Eigen::Vector3d& d,
            double near_m, bool cull) {
  Hit best;
  for (int tri = 0; tri < mesh.NumTriangles(); ++tri) {
    const Eigen::Vector3d v0 = cam_from_local * mesh.Corner(tri, 0);
    const Eigen::Vector3d v1 = cam_from_local * mesh.Corner(tri, 1);
    const Eigen::Vector3d v2 = cam_from_local * mesh.Corner(tri, 2);
    const Eigen::Vector3d e1 = v1 - v0, e2 = v2 - v0;
    if (cull && e1.cross(e2).dot(v0) > 0) continue;
    const Eigen::Vector3d p = d.cross(e2);
    const double det = e1.dot(p);
    if (det == 0.0) continue;
    const Eigen::Vector3d s = -v0;
    const double u = s.dot(p) / det;
    if (u < 0 || u > 1) continue;
    const Eigen::Vector3d q = s.cross(e1);
    const double v = d.dot(q) / det;
    if (v < 0 || u + v > 1) continue;
    const double z = e2.dot(q) / det * d.z();
    if (z < near_m) continue;
    if (z < best.z) best = {tri, z};
  }
  return best;
}

struct BruteForceComparison {
  int samples = 0;                   // valid rays
  int hits = 0;                      // rays the brute force says hit something
  int id_mismatches = 0;             // different triangle (ray on a shared edge: either is right)
  double max_depth_rel_error = 0.0;  // where the ids agree
};

BruteForceComparison CompareWithBruteForce(const Rasterizer& rasterizer, const TriangleMesh& mesh,
                                           const Rigid3d& cam_from_local, const RasterOutput& out) {
  BruteForceComparison c;
  for (int r = 0; r < out.triangle_id.rows; ++r) {
    for (int col = 0; col < out.triangle_id.cols; ++col) {
      const Eigen::Vector2f ray = rasterizer.Ray(col, r);
      const int id = out.triangle_id.at<int>(r, col);
      if (!std::isfinite(ray.x())) {
        EXPECT_EQ(id, -1) << "NaN ray hit at " << col << "," << r;
        continue;
      }
      ++c.samples;
      const Hit hit = CastRay(mesh, cam_from_local, Eigen::Vector3d(ray.x(), ray.y(), 1.0),
                              rasterizer.options().near_m, rasterizer.options().cull_back_faces);
      if (hit.id >= 0) ++c.hits;
      if (hit.id != id) {
        ++c.id_mismatches;
        continue;
      }
      if (hit.id >= 0) {
        const double z = out.depth.at<float>(r, col);
        c.max_depth_rel_error = std::max(c.max_depth_rel_error, std::abs(z - hit.z) / hit.z);
      }
    }
  }
  return c;
}

// Triangles whose centroids sit on chosen pixel centres' rays at chosen depths: after
// rendering, each such pixel must show its triangle at exactly that depth.
void CheckCentroidsLandOnTheirPixels(const Camera& camera) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> depth_m(0.8, 9.0), angle(-0.6, 0.6);
  TriangleMesh mesh;
  struct Expected {
    int tri, u, v;
    double z;
  };
  std::vector<Expected> expected;
  const int step = 24;
  for (int v = step / 2; v < camera.height; v += step) {
    for (int u = step / 2; u < camera.width; u += step) {
      Eigen::Vector2d normalized;
      ASSERT_TRUE(camera.Unproject(Eigen::Vector2d(u, v), &normalized));
      const double z = depth_m(rng);
      const Eigen::Vector3d centroid(normalized.x() * z, normalized.y() * z, z);
      // A triangle about 6 px across around the centroid, tilted randomly.
      const double size = 6.0 / camera.fx * z;
      const Eigen::Vector3d n =
          Eigen::Vector3d(angle(rng), angle(rng), -1.0).normalized();  // towards the camera
      const Eigen::Vector3d a = n.cross(Eigen::Vector3d::UnitY()).normalized();
      const Eigen::Vector3d b = n.cross(a);
      const Eigen::Vector3d c0 = size * a, c1 = size * (-0.5 * a + 0.866 * b),
                            c2 = size * (-0.5 * a - 0.866 * b);
      const int tri = AddTriangle(&mesh, centroid + c0, centroid + c1, centroid + c2);
      expected.push_back({tri, u, v, z});
      // Sanity: the centroid projects back onto the pixel.
      Eigen::Vector2d pixel;
      ASSERT_TRUE(camera.Project(centroid, &pixel));
      ASSERT_NEAR(pixel.x(), u, 1e-6);
      ASSERT_NEAR(pixel.y(), v, 1e-6);
    }
  }
  Rasterizer rasterizer(camera, RasterOptions());
  RasterOutput out;
  rasterizer.Rasterize(mesh, Rigid3d(), &out);
  ASSERT_EQ(out.depth.cols, camera.width);
  ASSERT_EQ(out.depth.rows, camera.height);
  for (const Expected& e : expected) {
    EXPECT_EQ(out.triangle_id.at<int>(e.v, e.u), e.tri) << "pixel " << e.u << "," << e.v;
    EXPECT_NEAR(out.depth.at<float>(e.v, e.u), e.z, 1e-5 * e.z) << "pixel " << e.u << "," << e.v;
    const cv::Vec2f bary = out.bary.at<cv::Vec2f>(e.v, e.u);
    EXPECT_NEAR(bary[0], 1.0 / 3.0, 1e-4);  // the centroid
    EXPECT_NEAR(bary[1], 1.0 / 3.0, 1e-4);
  }
  // And nothing else is drawn far from the triangles: the coverage matches their size.
  const int covered = cv::countNonZero(out.triangle_id >= 0);
  // (equilateral, circumradius 6 px: ~47 px each, less when tilted or compressed by the lens)
  EXPECT_GT(covered, static_cast<int>(expected.size()) * 20);
  EXPECT_LT(covered, static_cast<int>(expected.size()) * 60);
}

TEST(RasterizerTest, CentroidsLandOnTheirPixelsPinhole) {
  CheckCentroidsLandOnTheirPixels(PinholeCamera(320, 240, 250.0));
}

TEST(RasterizerTest, CentroidsLandOnTheirPixelsDistorted) {
  CheckCentroidsLandOnTheirPixels(DistortedCamera());
}

// A tilted grid (a "checker" of triangles) and a box seen through the strongly distorted
// lens: every pixel's triangle and depth agree with a brute-force ray cast, and the grid's
// corners, projected with Camera::Project, sit where the triangle ids change.
TEST(RasterizerTest, DistortedLensMatchesBruteForceAndProjection) {
  const Camera camera = DistortedCamera();
  TriangleMesh mesh;
  const Eigen::Vector3d origin(-2.5, -2.0, 3.0);
  const Eigen::Vector3d du = Eigen::Vector3d(1.0, 0.0, 0.35).normalized();
  const Eigen::Vector3d dv = Eigen::Vector3d(0.0, 1.0, 0.2).normalized();
  AddGrid(&mesh, origin, du, dv, 10, 8, 0.5);
  const int grid_triangles = mesh.NumTriangles();
  // A box in front of part of the grid.
  AddGrid(&mesh, Eigen::Vector3d(-0.3, -0.3, 2.0), Eigen::Vector3d::UnitX(),
          Eigen::Vector3d::UnitY(), 2, 2, 0.3);
  Rasterizer rasterizer(camera, RasterOptions());
  RasterOutput out;
  rasterizer.Rasterize(mesh, Rigid3d(), &out);
  const BruteForceComparison c = CompareWithBruteForce(rasterizer, mesh, Rigid3d(), out);
  EXPECT_GT(c.hits, c.samples / 3);
  EXPECT_LE(c.id_mismatches, c.samples / 10000 + 2);
  EXPECT_LT(c.max_depth_rel_error, 1e-5);

  // Grid corners not hidden by the box: the 4 pixels around the projected corner show
  // triangles of the cells around that corner, and the corner's pixel depth is right.
  int checked = 0;
  for (int j = 1; j < 8; ++j) {
    for (int i = 1; i < 10; ++i) {
      const Eigen::Vector3d corner = origin + 0.5 * (i * du + j * dv);
      Eigen::Vector2d pixel;
      if (!camera.Project(corner, &pixel)) continue;
      const int u0 = static_cast<int>(std::floor(pixel.x())),
                v0 = static_cast<int>(std::floor(pixel.y()));
      if (u0 < 1 || v0 < 1 || u0 + 2 >= camera.width || v0 + 2 >= camera.height) continue;
      // The triangles touching this corner: cells (i-1..i, j-1..j).
      std::vector<int> around;
      for (int cj = j - 1; cj <= j; ++cj)
        for (int ci = i - 1; ci <= i; ++ci)
          around.insert(around.end(), {2 * (cj * 10 + ci), 2 * (cj * 10 + ci) + 1});
      bool hidden = false;
      for (int dv_px = 0; dv_px <= 1; ++dv_px)
        for (int du_px = 0; du_px <= 1; ++du_px)
          hidden |= out.triangle_id.at<int>(v0 + dv_px, u0 + du_px) >= grid_triangles;
      if (hidden) continue;
      // Which quadrant each pixel around the corner falls in decides its cell.
      for (int dv_px = 0; dv_px <= 1; ++dv_px) {
        for (int du_px = 0; du_px <= 1; ++du_px) {
          const int id = out.triangle_id.at<int>(v0 + dv_px, u0 + du_px);
          EXPECT_NE(std::find(around.begin(), around.end(), id), around.end())
              << "corner " << i << "," << j << " pixel " << u0 + du_px << "," << v0 + dv_px;
        }
      }
      // The 4 pixels around a corner cover at least 3 distinct triangles of its 8 (the
      // corner is inside their square), unless the corner is within rounding of a pixel
      // centre row/column.
      std::vector<int> ids;
      for (int dv_px = 0; dv_px <= 1; ++dv_px)
        for (int du_px = 0; du_px <= 1; ++du_px)
          ids.push_back(out.triangle_id.at<int>(v0 + dv_px, u0 + du_px));
      std::sort(ids.begin(), ids.end());
      ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
      EXPECT_GE(ids.size(), 3u) << "corner " << i << "," << j;
      ++checked;
    }
  }
  EXPECT_GT(checked, 20);
}

// A huge floor triangle that passes under and behind the camera: only the part in front is
// drawn (every pixel below the horizon that the analytic intersection puts inside the
// triangle, nothing above it), and a far near plane cuts exactly at its depth.
TEST(RasterizerTest, NearPlaneClipsFloorPassingBehindCamera) {
  const Camera camera = PinholeCamera(320, 240, 200.0);
  const double height_m = 1.5;  // floor at camera y = +1.5 (y points down)
  TriangleMesh mesh;
  const Eigen::Vector2d a(-300.0, -200.0), b(0.0, 400.0), c(300.0, -200.0);  // (x, z)
  AddTriangle(&mesh, {a.x(), height_m, a.y()}, {b.x(), height_m, b.y()}, {c.x(), height_m, c.y()});
  auto inside = [&](double x, double z) {
    auto side = [](const Eigen::Vector2d& p, const Eigen::Vector2d& q, double x, double z) {
      return (q.x() - p.x()) * (z - p.y()) - (q.y() - p.y()) * (x - p.x());
    };
    const double s0 = side(a, b, x, z), s1 = side(b, c, x, z), s2 = side(c, a, x, z);
    return (s0 >= 0 && s1 >= 0 && s2 >= 0) || (s0 <= 0 && s1 <= 0 && s2 <= 0);
  };
  for (const double near_m : {1e-3, 6.0}) {
    RasterOptions options;
    options.near_m = near_m;
    Rasterizer rasterizer(camera, options);
    RasterOutput out;
    rasterizer.Rasterize(mesh, Rigid3d(), &out);
    int wrong = 0, drawn = 0, expected_drawn = 0;
    for (int r = 0; r < camera.height; ++r) {
      for (int col = 0; col < camera.width; ++col) {
        const Eigen::Vector2f ray = rasterizer.Ray(col, r);
        double expected_z = kInf;
        if (ray.y() > 0) {
          const double z = height_m / ray.y();
          if (z >= near_m && inside(ray.x() * z, z)) expected_z = z;
        }
        const int id = out.triangle_id.at<int>(r, col);
        drawn += id >= 0;
        expected_drawn += std::isfinite(expected_z);
        if ((id >= 0) != std::isfinite(expected_z)) {
          ++wrong;
        } else if (id >= 0) {
          EXPECT_NEAR(out.depth.at<float>(r, col), expected_z, 1e-5 * expected_z);
        }
      }
    }
    EXPECT_EQ(wrong, 0) << "near " << near_m;
    EXPECT_GT(expected_drawn, camera.width * 10);
    EXPECT_EQ(drawn, expected_drawn);
    // Nothing at or above the horizon row (cy = 119.5: rows 0..119 look up).
    EXPECT_EQ(cv::countNonZero(out.triangle_id.rowRange(0, 120) >= 0), 0);
  }
}

long ResidentKb() {  // this process's resident memory (VmRSS), kB
  FILE* f = std::fopen("/proc/self/status", "r");
  long kb = -1;
  char line[256];
  while (f && std::fgets(line, sizeof line, f))
    if (!std::strncmp(line, "VmRSS:", 6)) kb = std::atol(line + 6);
  if (f) std::fclose(f);
  return kb;
}

// A one-off rasterization of a large mesh (the automatic texel size sees the whole scene)
// leaves set-ups of ~110 bytes per triangle in the calling thread's buffers;
// ReleaseThreadScratch gives them back, and rasterizing again still works.
#if defined(__SANITIZE_ADDRESS__)
constexpr bool kAddressSanitizer = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kAddressSanitizer = true;
#else
constexpr bool kAddressSanitizer = false;
#endif
#else
constexpr bool kAddressSanitizer = false;
#endif

TEST(RasterizerTest, ReleaseThreadScratchGivesTheSetUpsBack) {
  const Camera camera = PinholeCamera(80, 60, 60.0);
  TriangleMesh mesh;  // 605,000 small triangles on a wall 2 m in front, all in view
  const int cells = 550;
  for (int j = 0; j < cells; ++j)
    for (int i = 0; i < cells; ++i) {
      // Just inside the view (+-1.33 m by +-1 m at 2 m): none of it is culled.
      const double x = -1.3 + 2.6 * i / cells, y = -0.975 + 1.95 * j / cells;
      const double dx = 2.6 / cells, dy = 1.95 / cells;
      AddTriangle(&mesh, {x, y, 2.0}, {x + dx, y, 2.0}, {x, y + dy, 2.0});
      AddTriangle(&mesh, {x + dx, y, 2.0}, {x + dx, y + dy, 2.0}, {x, y + dy, 2.0});
    }
  const Rasterizer rasterizer(camera, RasterOptions());
  RasterOutput out;
  rasterizer.Rasterize(mesh, Rigid3d(), &out);
  const int covered = cv::countNonZero(out.triangle_id >= 0);
  const long before_kb = ResidentKb();
  Rasterizer::ReleaseThreadScratch();
  const long after_kb = ResidentKb();
  // AddressSanitizer keeps freed memory in quarantine (resident): there only the second
  // rasterization below is checked; the normal build checks the memory given back.
  if (!kAddressSanitizer) {
    EXPECT_GT(before_kb - after_kb, 40000) << before_kb << " -> " << after_kb << " kB";
  }
  rasterizer.Rasterize(mesh, Rigid3d(), &out);
  EXPECT_EQ(cv::countNonZero(out.triangle_id >= 0), covered);
  EXPECT_GT(covered, camera.width * camera.height * 9 / 10);
}

// Triangles with one or two corners behind the camera, seen from all sides: brute force
// agrees everywhere (no wrap-around artefacts from corners behind the eye).
TEST(RasterizerTest, TrianglesCrossingTheCameraPlaneMatchBruteForce) {
  const Camera camera = PinholeCamera(160, 120, 100.0);
  TriangleMesh mesh;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> xy(-4.0, 4.0), z(-3.0, 6.0);
  for (int i = 0; i < 40; ++i) {
    AddTriangle(&mesh, {xy(rng), xy(rng), z(rng)}, {xy(rng), xy(rng), z(rng)},
                {xy(rng), xy(rng), z(rng)});
  }
  for (const double near_m : {1e-3, 0.5}) {
    RasterOptions options;
    options.near_m = near_m;
    Rasterizer rasterizer(camera, options);
    RasterOutput out;
    rasterizer.Rasterize(mesh, Rigid3d(), &out);
    const BruteForceComparison c = CompareWithBruteForce(rasterizer, mesh, Rigid3d(), out);
    EXPECT_GT(c.hits, c.samples / 4);
    EXPECT_LE(c.id_mismatches, 2);
    EXPECT_LT(c.max_depth_rel_error, 1e-5);
  }
}

// The depth-only path (what the painting's occlusion test uses) gives the full path's depth
// to float rounding of 1/z, including where triangles cross the near plane and through a
// distorted lens; both are +inf exactly where no surface is.
void ExpectDepthOnlyMatchesFull(const Camera& camera, const TriangleMesh& mesh, double near_m) {
  RasterOptions options;
  options.near_m = near_m;
  const Rasterizer rasterizer(camera, options);
  RasterOutput full;
  rasterizer.Rasterize(mesh, Rigid3d(), &full);
  // Given a view into a larger image (rows not contiguous): replaced by an image of its own.
  cv::Mat larger(camera.height + 2, camera.width + 3, CV_32F, cv::Scalar(-1));
  cv::Mat depth = larger(cv::Rect(1, 1, camera.width, camera.height));
  rasterizer.RasterizeDepth(mesh, Rigid3d(), &depth);
  ASSERT_TRUE(depth.isContinuous());
  ASSERT_EQ(depth.type(), CV_32F);
  ASSERT_EQ(depth.size(), full.depth.size());
  int hits = 0, differ = 0;
  for (int r = 0; r < depth.rows; ++r) {
    for (int c = 0; c < depth.cols; ++c) {
      const float a = full.depth.at<float>(r, c), b = depth.at<float>(r, c);
      ASSERT_EQ(std::isinf(a), std::isinf(b)) << "sample " << c << "," << r;
      if (std::isinf(a)) continue;
      ++hits;
      differ += std::abs(a - b) > 1e-6f * a;
    }
  }
  EXPECT_GT(hits, depth.rows * depth.cols / 5);
  EXPECT_EQ(differ, 0);
}

TEST(RasterizerTest, DepthOnlyMatchesFullRaster) {
  TriangleMesh crossing;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> xy(-4.0, 4.0), z(-3.0, 6.0);
  for (int i = 0; i < 40; ++i)
    AddTriangle(&crossing, {xy(rng), xy(rng), z(rng)}, {xy(rng), xy(rng), z(rng)},
                {xy(rng), xy(rng), z(rng)});
  for (const double near_m : {1e-3, 0.5})
    ExpectDepthOnlyMatchesFull(PinholeCamera(160, 120, 100.0), crossing, near_m);
  TriangleMesh grid;
  AddGrid(&grid, Eigen::Vector3d(-2.5, -2.0, 3.0), Eigen::Vector3d(1.0, 0.0, 0.35).normalized(),
          Eigen::Vector3d(0.0, 1.0, 0.2).normalized(), 10, 8, 0.5);
  AddGrid(&grid, Eigen::Vector3d(-0.3, -0.3, 2.0), Eigen::Vector3d::UnitX(),
          Eigen::Vector3d::UnitY(), 2, 2, 0.3);
  ExpectDepthOnlyMatchesFull(DistortedCamera(), grid, 1e-3);
}

// Depth for a window of the image only (what a shard's charts read): bit for bit the whole
// image's inside the window, for windows inside, across the image's edges and outside it,
// with and without supersampling; fewer triangles are set up (the rest of the image may stay
// empty). Many small triangles, so that most lie beside a window.
TEST(RasterizerTest, DepthInAWindowIsTheWholeImagesThere) {
  TriangleMesh mesh;
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> xy(-3.0, 3.0), z(1.5, 6.0), d(-0.08, 0.08);
  for (int i = 0; i < 4000; ++i) {
    const Eigen::Vector3d a(xy(rng), xy(rng), z(rng));
    AddTriangle(&mesh, a, a + Eigen::Vector3d(d(rng), d(rng), d(rng)),
                a + Eigen::Vector3d(d(rng), d(rng), d(rng)));
  }
  const Camera camera = PinholeCamera(160, 120, 100.0);
  for (const int supersample : {1, 2}) {
    RasterOptions options;
    options.supersample = supersample;
    const Rasterizer rasterizer(camera, options);
    cv::Mat whole;
    rasterizer.RasterizeDepth(mesh, Rigid3d(), &whole);
    for (const cv::Rect window : {cv::Rect(40, 30, 50, 40), cv::Rect(-20, 100, 60, 50),
                                  cv::Rect(150, -5, 30, 20), cv::Rect(0, 0, 160, 120)}) {
      cv::Mat part;
      rasterizer.RasterizeDepth(mesh, Rigid3d(), &part, window);
      const cv::Rect inside = cv::Rect(window.x * supersample, window.y * supersample,
                                       window.width * supersample, window.height * supersample) &
                              cv::Rect(0, 0, whole.cols, whole.rows);
      ASSERT_FALSE(inside.empty());
      EXPECT_EQ(cv::norm(part(inside), whole(inside), cv::NORM_INF), 0)
          << "window " << window << " supersample " << supersample;
      EXPECT_GT(cv::countNonZero(whole(inside) < 1e30f), 0) << window;  // some surface
      if (window.width < 100) {  // triangles far from the window were not set up
        cv::Mat left_empty = (part >= 1e30f) & (whole < 1e30f);
        EXPECT_GT(cv::countNonZero(left_empty), whole.total() / 10) << window;
      }
    }
    cv::Mat none;
    rasterizer.RasterizeDepth(mesh, Rigid3d(), &none, cv::Rect(-50, -50, 10, 10));
    EXPECT_EQ(cv::countNonZero(none < 1e30f), 0);  // a window outside the image: no surface
  }
}

// A large mesh in runs of nearby triangles all around the camera (in view, behind it,
// beside the frustum): runs outside the view are culled whole, and the result is still
// exactly the brute force's; moving the vertices in place is noticed (no stale culling).
TEST(RasterizerTest, CulledRunsOfTrianglesMatchBruteForce) {
  const Camera camera = PinholeCamera(64, 48, 40.0);
  TriangleMesh mesh;
  std::mt19937 rng(11);
  std::normal_distribution<double> direction(0.0, 1.0);
  std::uniform_real_distribution<double> offset(-0.25, 0.25);
  for (int run = 0; run < 24; ++run) {  // 24 runs of 128 triangles
    Eigen::Vector3d centre(direction(rng), direction(rng), direction(rng));
    centre = 3.0 * centre.normalized();
    for (int i = 0; i < 128; ++i) {
      const Eigen::Vector3d a = centre + Eigen::Vector3d(offset(rng), offset(rng), offset(rng));
      AddTriangle(&mesh, a, a + Eigen::Vector3d(offset(rng), offset(rng), offset(rng)),
                  a + Eigen::Vector3d(offset(rng), offset(rng), offset(rng)));
    }
  }
  const Rasterizer rasterizer(camera, RasterOptions());
  for (int pass = 0; pass < 2; ++pass) {
    RasterOutput out;
    rasterizer.Rasterize(mesh, Rigid3d(), &out);
    const BruteForceComparison c = CompareWithBruteForce(rasterizer, mesh, Rigid3d(), out);
    EXPECT_GT(c.hits, c.samples / 50) << "pass " << pass;
    EXPECT_LE(c.id_mismatches, 2) << "pass " << pass;
    EXPECT_LT(c.max_depth_rel_error, 1e-5) << "pass " << pass;
    // Turn the mesh half-way round in place: what was behind the camera comes into view.
    for (Eigen::Vector3d& v : mesh.vertices) v = Eigen::Vector3d(-v.x(), v.y(), -v.z());
  }
}

TEST(RasterizerTest, BackFaceCulling) {
  const Camera camera = PinholeCamera(100, 80, 100.0);
  TriangleMesh mesh;
  // Seen from the camera at the origin: (0,0,2) (0,1,2) (1,0,2) is counter-clockwise about
  // its normal (0,0,-1), which points at the camera: a front face.
  const int front = AddTriangle(&mesh, {-0.6, -0.5, 2.0}, {-0.6, 0.5, 2.0}, {-0.1, -0.5, 2.0});
  const int back = AddTriangle(&mesh, {0.1, -0.5, 2.0}, {0.6, -0.5, 2.0}, {0.1, 0.5, 2.0});
  EXPECT_LT(mesh.Normal(front).z(), 0);
  EXPECT_GT(mesh.Normal(back).z(), 0);
  for (const bool cull : {false, true}) {
    RasterOptions options;
    options.cull_back_faces = cull;
    Rasterizer rasterizer(camera, options);
    RasterOutput out;
    rasterizer.Rasterize(mesh, Rigid3d(), &out);
    const int front_px = cv::countNonZero(out.triangle_id == front);
    const int back_px = cv::countNonZero(out.triangle_id == back);
    // Each triangle covers half of a 25 x 50 px rectangle.
    EXPECT_NEAR(front_px, 625, 30);
    EXPECT_EQ(back_px, cull ? 0 : front_px);
  }
}

// Rasterizers of one camera share its ray table: each rasterizer's rays are still its own
// camera's (Camera::Unproject of the sample's position), whatever was built before it, for
// cameras that differ in one distortion term only, and at another supersampling.
TEST(RasterizerTest, EachRasterizerHasItsOwnCamerasRays) {
  const Camera a = DistortedCamera();
  Camera b = a;
  b.k1 = -0.29;
  b.UpdateFoldR2();
  const auto expect_rays_of = [](const Camera& camera, int n, const Rasterizer& rasterizer) {
    for (const auto& [col, row] : {std::pair{0, 0}, {17, 203}, {160 * n, 120 * n}, {301, 9}}) {
      Eigen::Vector2d normalized;
      ASSERT_TRUE(camera.Unproject(Eigen::Vector2d(col / n + ((col % n) + 0.5) / n - 0.5,
                                                   row / n + ((row % n) + 0.5) / n - 0.5),
                                   &normalized));
      const Eigen::Vector2f ray = rasterizer.Ray(col, row);
      EXPECT_EQ(ray.x(), static_cast<float>(normalized.x())) << col << ", " << row;
      EXPECT_EQ(ray.y(), static_cast<float>(normalized.y())) << col << ", " << row;
    }
  };
  const Rasterizer first_a(a, RasterOptions());
  const Rasterizer first_b(b, RasterOptions());
  const Rasterizer again_a(a, RasterOptions());
  const Rasterizer a_twice(a, RasterOptions{1e-3, false, 2});
  expect_rays_of(a, 1, first_a);
  expect_rays_of(b, 1, first_b);
  expect_rays_of(a, 1, again_a);
  expect_rays_of(a, 2, a_twice);
  EXPECT_NE(first_a.Ray(17, 203), first_b.Ray(17, 203));
}

// A closed cube seen from outside: with and without culling, the same pixels, and culling
// never lets the far side show through (watertight, no cracks along shared edges).
TEST(RasterizerTest, ClosedCubeIsWatertight) {
  const Camera camera = PinholeCamera(200, 150, 180.0);
  TriangleMesh mesh;
  const Eigen::Vector3d p[8] = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                                {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
  const int faces[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4},
                           {2, 3, 7, 6}, {0, 4, 7, 3}, {1, 2, 6, 5}};  // outward CCW
  for (const auto& f : faces) {
    AddTriangle(&mesh, p[f[0]], p[f[1]], p[f[2]]);
    AddTriangle(&mesh, p[f[0]], p[f[2]], p[f[3]]);
  }
  for (int k = 0; k < mesh.NumTriangles(); ++k) {
    const Eigen::Vector3d c = (mesh.Corner(k, 0) + mesh.Corner(k, 1) + mesh.Corner(k, 2)) / 3;
    ASSERT_GT(mesh.Normal(k).dot(c), 0) << "face " << k << " not outward";
  }
  const Rigid3d cam_from_world = LookAt({3.0, -2.5, -4.0}, Eigen::Vector3d::Zero());
  RasterOutput with_cull, without_cull;
  RasterOptions options;
  Rasterizer(camera, options).Rasterize(mesh, cam_from_world, &without_cull);
  options.cull_back_faces = true;
  Rasterizer culling(camera, options);
  culling.Rasterize(mesh, cam_from_world, &with_cull);
  EXPECT_EQ(cv::countNonZero(with_cull.triangle_id != without_cull.triangle_id), 0);
  cv::Mat diff;
  cv::absdiff(with_cull.depth, without_cull.depth, diff);
  diff.setTo(0, with_cull.triangle_id < 0);
  double max_diff = 0;
  cv::minMaxLoc(diff, nullptr, &max_diff);
  EXPECT_EQ(max_diff, 0.0);
  // Inside the silhouette (a convex blob), every pixel is covered.
  const BruteForceComparison c = CompareWithBruteForce(culling, mesh, cam_from_world, with_cull);
  EXPECT_GT(c.hits, 2000);
  EXPECT_LE(c.id_mismatches, c.hits / 200);  // rays exactly on cube edges may pick either
  cv::Mat covered = with_cull.triangle_id >= 0, filled = covered.clone();
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(covered.clone(), contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
  ASSERT_EQ(contours.size(), 1u);
  cv::drawContours(filled, contours, 0, cv::Scalar(255), cv::FILLED);
  EXPECT_EQ(cv::countNonZero(filled != covered), 0) << "holes in the cube";
}

TEST(RasterizerTest, SupersampleRaysAtSubpixelOffsets) {
  const Camera camera = PinholeCamera(40, 30, 50.0);
  for (const int n : {1, 2, 3, 4}) {
    RasterOptions options;
    options.supersample = n;
    Rasterizer rasterizer(camera, options);
    for (const auto& [col, row] :
         {std::pair{0, 0}, std::pair{7, 3}, std::pair{40 * n - 1, 30 * n - 1}}) {
      const double px = col / n + ((col % n) + 0.5) / n - 0.5;
      const double py = row / n + ((row % n) + 0.5) / n - 0.5;
      const Eigen::Vector2f ray = rasterizer.Ray(col, row);
      EXPECT_NEAR(ray.x(), (px - camera.cx) / camera.fx, 1e-6);
      EXPECT_NEAR(ray.y(), (py - camera.cy) / camera.fy, 1e-6);
    }
    // Sample 0 of pixel 0 sits at -0.5 + 0.5/N.
    EXPECT_NEAR(rasterizer.Ray(0, 0).x(), (-0.5 + 0.5 / n - camera.cx) / camera.fx, 1e-7);
    TriangleMesh mesh;
    AddTriangle(&mesh, {-1, -1, 2}, {-1, 1, 2}, {1, -1, 2});
    RasterOutput out;
    rasterizer.Rasterize(mesh, Rigid3d(), &out);
    EXPECT_EQ(out.depth.cols, 40 * n);
    EXPECT_EQ(out.depth.rows, 30 * n);
  }
  EXPECT_THROW(Rasterizer(camera, RasterOptions{1e-3, false, 5}), std::invalid_argument);
  EXPECT_THROW(Rasterizer(camera, RasterOptions{0.0, false, 1}), std::invalid_argument);
}

TEST(RasterizerTest, RaysTheLensCannotUnprojectNeverHit) {
  // So strong a barrel that the image corners lie beyond the fold: no ray there.
  const Camera camera =
      Camera::FromParams(LensModel::kOpenCV4, 200, 150, {80.0, 80.0, 99.5, 74.5, -0.6, 0.0, 0, 0});
  Rasterizer rasterizer(camera, RasterOptions());
  EXPECT_FALSE(std::isfinite(rasterizer.Ray(0, 0).x()));
  EXPECT_TRUE(std::isfinite(rasterizer.Ray(100, 75).x()));
  TriangleMesh mesh;  // a wall covering every direction in front of the camera
  AddTriangle(&mesh, {-1e3, -1e3, 1.0}, {-1e3, 1e3, 1.0}, {1e3, 0.0, 1.0});
  RasterOutput out;
  rasterizer.Rasterize(mesh, Rigid3d(), &out);
  int nan_rays = 0;
  for (int r = 0; r < 150; ++r) {
    for (int c = 0; c < 200; ++c) {
      const bool valid = std::isfinite(rasterizer.Ray(c, r).x());
      nan_rays += !valid;
      EXPECT_EQ(out.triangle_id.at<int>(r, c) >= 0, valid) << c << "," << r;
    }
  }
  EXPECT_GT(nan_rays, 100);
}

// Many overlapping random triangles: two renders are bit-identical, and identical with one
// thread and with the default thread count.
// Through a distorted lens (rays in buckets) and a pinhole (rays on a grid, depth scanned
// directly, each task into an inverse-depth buffer of its own, merged by maximum), full and
// depth-only: bit-identical every run, on any number of threads, with exact depth ties
// (coplanar duplicates) resolved the same way.
void ExpectDeterministicAcrossRunsAndThreads(const Camera& camera) {
  TriangleMesh mesh;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> xy(-3.0, 3.0), z(0.5, 6.0), jitter(-0.4, 0.4);
  for (int i = 0; i < 3000; ++i) {
    const Eigen::Vector3d c(xy(rng), xy(rng), z(rng));
    AddTriangle(&mesh, c + Eigen::Vector3d(jitter(rng), jitter(rng), jitter(rng)),
                c + Eigen::Vector3d(jitter(rng), jitter(rng), jitter(rng)),
                c + Eigen::Vector3d(jitter(rng), jitter(rng), jitter(rng)));
  }
  // Coplanar duplicates: exact depth ties must resolve the same way every time.
  for (int i = 0; i < 50; ++i) {
    const int t = i * 7;
    AddTriangle(&mesh, mesh.Corner(t, 0), mesh.Corner(t, 1), mesh.Corner(t, 2));
  }
  RasterOptions options;
  options.supersample = 2;
  Rasterizer rasterizer(camera, options);
  const int default_threads = cv::getNumThreads();
  RasterOutput a, b, single;
  cv::Mat depth_a, depth_b, depth_single;
  rasterizer.Rasterize(mesh, Rigid3d(), &a);
  rasterizer.Rasterize(mesh, Rigid3d(), &b);
  rasterizer.RasterizeDepth(mesh, Rigid3d(), &depth_a);
  rasterizer.RasterizeDepth(mesh, Rigid3d(), &depth_b);
  cv::setNumThreads(1);
  rasterizer.Rasterize(mesh, Rigid3d(), &single);
  rasterizer.RasterizeDepth(mesh, Rigid3d(), &depth_single);
  cv::setNumThreads(default_threads);
  for (const RasterOutput* other : {&b, &single}) {
    EXPECT_EQ(cv::countNonZero(a.triangle_id != other->triangle_id), 0);
    EXPECT_EQ(std::memcmp(a.depth.data, other->depth.data, a.depth.total() * 4), 0);
    EXPECT_EQ(std::memcmp(a.bary.data, other->bary.data, a.bary.total() * 8), 0);
  }
  for (const cv::Mat* other : {&depth_b, &depth_single})
    EXPECT_EQ(std::memcmp(depth_a.data, other->data, depth_a.total() * 4), 0);
  EXPECT_GT(cv::countNonZero(a.triangle_id >= 0), static_cast<int>(a.triangle_id.total() / 2));
}

TEST(RasterizerTest, DeterministicAcrossRunsAndThreadsDistorted) {
  ExpectDeterministicAcrossRunsAndThreads(DistortedCamera());
}

TEST(RasterizerTest, DeterministicAcrossRunsAndThreadsPinhole) {
  ExpectDeterministicAcrossRunsAndThreads(PinholeCamera(320, 240, 250.0));
}

// ---------------------------------------------------------------------------------------
// Renderer

Texture MakeTexture(int width, int height, unsigned seed) {
  Texture texture;
  texture.rgba.create(height, width, CV_8UC4);
  cv::RNG rng(seed);
  rng.fill(texture.rgba, cv::RNG::UNIFORM, 0, 256);
  std::vector<cv::Mat> channels;
  cv::split(texture.rgba, channels);
  channels[3].setTo(255);
  cv::merge(channels, texture.rgba);
  return texture;
}

TEST(SampleTextureTest, TexelCentresWrapModesAndPremultipliedAlpha) {
  Texture t;
  t.rgba = cv::Mat(2, 4, CV_8UC4);
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 4; ++i) t.rgba.at<cv::Vec4b>(j, i) = cv::Vec4b(i * 60, j * 200, 7, 255);
  auto red = [&](double u, double v, TextureFilter f) {
    return SampleTexture(t, {u, v}, f)[0] * 255.0;
  };
  // Texel centres at (i + 0.5) / W: bilinear gives the texel exactly.
  EXPECT_NEAR(red(2.5 / 4, 0.25, TextureFilter::kBilinear), 120.0, 1e-9);
  EXPECT_NEAR(SampleTexture(t, {0.125, 0.75}, TextureFilter::kBilinear)[1] * 255, 200.0, 1e-9);
  // Halfway between texel 1 and 2.
  EXPECT_NEAR(red(0.5, 0.25, TextureFilter::kBilinear), 90.0, 1e-9);
  EXPECT_NEAR(red(0.49, 0.25, TextureFilter::kNearest), 60.0, 1e-9);
  EXPECT_NEAR(red(0.51, 0.25, TextureFilter::kNearest), 120.0, 1e-9);
  // REPEAT: u = 1.125 is texel 0; between texel 3 and texel 0 across the seam.
  EXPECT_NEAR(red(1.125, 0.25, TextureFilter::kBilinear), 0.0, 1e-9);
  EXPECT_NEAR(red(1.0, 0.25, TextureFilter::kBilinear), 90.0, 1e-9);
  EXPECT_NEAR(red(-0.875, 0.25, TextureFilter::kNearest), 0.0, 1e-9);
  // CLAMP: beyond the edge, the edge texel.
  t.wrap_s = TextureWrap::kClampToEdge;
  EXPECT_NEAR(red(1.0, 0.25, TextureFilter::kBilinear), 180.0, 1e-9);
  EXPECT_NEAR(red(-3.0, 0.25, TextureFilter::kNearest), 0.0, 1e-9);
  EXPECT_NEAR(red(7.0, 0.25, TextureFilter::kNearest), 180.0, 1e-9);
  // MIRRORED_REPEAT: texels 0 1 2 3 | 3 2 1 0 | 0 1 ...
  t.wrap_s = TextureWrap::kMirroredRepeat;
  EXPECT_NEAR(red(1.125, 0.25, TextureFilter::kNearest), 180.0, 1e-9);
  EXPECT_NEAR(red(1.875, 0.25, TextureFilter::kNearest), 0.0, 1e-9);
  EXPECT_NEAR(red(2.125, 0.25, TextureFilter::kNearest), 0.0, 1e-9);
  EXPECT_NEAR(red(-0.125, 0.25, TextureFilter::kNearest), 0.0, 1e-9);
  EXPECT_NEAR(red(-0.375, 0.25, TextureFilter::kNearest), 60.0, 1e-9);
  EXPECT_NEAR(red(1.0, 0.25, TextureFilter::kBilinear), 180.0, 1e-9);
  // Premultiplied: an unpainted texel (alpha 0, colour 255) next to a painted one (colour
  // 60): halfway between them the colour stays 60 and the alpha is one half.
  t.wrap_s = TextureWrap::kRepeat;
  t.rgba.at<cv::Vec4b>(0, 0) = cv::Vec4b(255, 255, 255, 0);
  const Eigen::Vector4d half = SampleTexture(t, {0.25, 0.25}, TextureFilter::kBilinear);
  EXPECT_NEAR(half[0] * 255, 60.0, 1e-9);
  EXPECT_NEAR(half[3], 0.5, 1e-9);
  const Eigen::Vector4d none = SampleTexture(t, {0.125, 0.25}, TextureFilter::kBilinear);
  EXPECT_EQ(none[3], 0.0);
  // Absurd UVs never crash.
  SampleTexture(t, {std::nan(""), 1e300}, TextureFilter::kBilinear);
  SampleTexture(t, {-1e300, kInf}, TextureFilter::kNearest);
}

// A head-on textured plane whose texels line up with the pixels: the render reproduces the
// texture (bilinear and nearest).
TEST(RendererTest, HeadOnTexturedPlaneReproducesTexture) {
  const int width = 96, height = 64;
  const double f = 120.0, z = 3.0;
  const Camera camera = PinholeCamera(width, height, f);
  Scene scene;
  scene.textures.push_back(MakeTexture(width, height, 5));
  Material material;
  material.base_color_texture = 0;
  scene.materials.push_back(material);
  // Pixel edges -0.5 .. width-0.5 map to UV 0 .. 1, so pixel centres hit texel centres.
  auto at = [&](double px, double py) {
    return Eigen::Vector3d((px - camera.cx) / f * z, (py - camera.cy) / f * z, z);
  };
  const Eigen::Vector3d corners[4] = {at(-0.5, -0.5), at(-0.5, height - 0.5),
                                      at(width - 0.5, height - 0.5), at(width - 0.5, -0.5)};
  const Eigen::Vector2f uvs[4] = {{0, 0}, {0, 1}, {1, 1}, {1, 0}};
  AddQuad(&scene.mesh, corners, uvs);
  ASSERT_LT(scene.mesh.Normal(0).z(), 0) << "quad must face the camera";
  for (const TextureFilter filter : {TextureFilter::kBilinear, TextureFilter::kNearest}) {
    RenderOptions options;
    options.filter = filter;
    Renderer renderer(camera, options);
    RenderOutput out;
    renderer.Render(scene, Rigid3d(), &out);
    ASSERT_EQ(out.rgba.type(), CV_8UC4);
    ASSERT_EQ(out.rgba.size(), cv::Size(width, height));
    const double psnr = cv::PSNR(out.rgba, scene.textures[0].rgba);
    EXPECT_GE(psnr, 40.0);
    EXPECT_EQ(cv::countNonZero(out.triangle_id < 0), 0);
    EXPECT_NEAR(out.depth.at<float>(10, 10), z, 1e-5 * z);
  }
}

TEST(RendererTest, OneRasterShadedWithEachTextureMatchesRenderingEach) {
  // A tilted textured quad, shaded from one rasterization with two textures in turn: each as
  // Render with that texture to the bit (how the `update: auto` decision scores candidates).
  const int width = 80, height = 60;
  const double f = 90.0;
  const Camera camera = PinholeCamera(width, height, f);
  Scene scene;
  scene.textures.push_back(MakeTexture(40, 30, 5));
  Material material;
  material.base_color_texture = 0;
  scene.materials.push_back(material);
  const Eigen::Vector3d corners[4] = {
      {-1.2, -0.8, 2.5}, {-1.0, 0.9, 3.5}, {1.1, 0.8, 4.0}, {1.0, -0.9, 2.8}};
  const Eigen::Vector2f uvs[4] = {{0, 0}, {0, 1}, {1, 1}, {1, 0}};
  AddQuad(&scene.mesh, corners, uvs);
  for (const int n : {1, 2}) {
    RenderOptions options;
    options.raster.supersample = n;
    const Renderer renderer(camera, options);
    RasterOutput raster;
    renderer.RasterizeScene(scene, Rigid3d(), &raster);
    for (const int seed : {5, 9}) {
      scene.textures[0] = MakeTexture(40, 30, seed);
      RenderOutput whole;
      renderer.Render(scene, Rigid3d(), &whole);
      cv::Mat shaded;
      renderer.ShadeScene(scene, raster, &shaded);
      ASSERT_GT(cv::countNonZero(whole.triangle_id >= 0), width * height / 4) << n;
      EXPECT_EQ(cv::norm(shaded, whole.rgba, cv::NORM_INF), 0)
          << "supersample " << n << ", texture " << seed;
    }
  }
}

TEST(RendererTest, AlphaMaterialColourAndNoBleeding) {
  const Camera camera = PinholeCamera(64, 48, 60.0);
  Scene scene;
  // Texture: left half painted green, right half unpainted (alpha 0) but coloured magenta.
  Texture texture;
  texture.rgba = cv::Mat(8, 8, CV_8UC4, cv::Scalar(0, 200, 0, 255));
  texture.rgba.colRange(4, 8).setTo(cv::Scalar(255, 0, 255, 0));
  texture.wrap_s = texture.wrap_t = TextureWrap::kClampToEdge;
  scene.textures.push_back(texture);
  Material textured;
  textured.base_color_texture = 0;
  textured.base_color_factor = Eigen::Vector4d(1.0, 0.5, 1.0, 1.0);
  Material plain;
  plain.base_color_factor = Eigen::Vector4d(0.2, 0.4, 0.6, 1.0);
  scene.materials = {textured, plain};
  // Left: a textured quad filling the left half of the image; right: an untextured quad.
  const double z = 2.0;
  auto at = [&](double px, double py) {
    return Eigen::Vector3d((px - camera.cx) / 60.0 * z, (py - camera.cy) / 60.0 * z, z);
  };
  const Eigen::Vector3d left[4] = {at(-0.5, -0.5), at(-0.5, 47.5), at(31.5, 47.5), at(31.5, -0.5)};
  const Eigen::Vector2f uvs[4] = {{0, 0}, {0, 1}, {1, 1}, {1, 0}};
  AddQuad(&scene.mesh, left, uvs, 0);
  const Eigen::Vector3d right[4] = {at(40, 10), at(40, 30), at(60, 30), at(60, 10)};
  AddQuad(&scene.mesh, right, uvs, 1);
  scene.mesh.has_uv[2] = scene.mesh.has_uv[3] = false;
  for (const int n : {1, 2, 3}) {
    RenderOptions options;
    options.raster.supersample = n;
    Renderer renderer(camera, options);
    RenderOutput out;
    renderer.Render(scene, Rigid3d(), &out);
    int painted = 0, transparent = 0;
    for (int c = 0; c < 32; ++c) {
      const cv::Vec4b p = out.rgba.at<cv::Vec4b>(20, c);
      if (p[3] == 255) {
        ++painted;
        // Green 200 x factor 0.5 = 100, never any magenta.
        EXPECT_EQ(p, cv::Vec4b(0, 100, 0, 255)) << "n " << n << " col " << c;
      } else {
        ++transparent;
        EXPECT_EQ(p, cv::Vec4b(0, 0, 0, 0));
      }
    }
    // Columns 0..15 painted (texels 0..3 -> 16 px), 16..31 not.
    EXPECT_EQ(painted, 16) << "n " << n;
    EXPECT_EQ(transparent, 16);
    // Untextured quad: the material colour.
    EXPECT_EQ(out.rgba.at<cv::Vec4b>(20, 50), cv::Vec4b(51, 102, 153, 255));
    // Background.
    EXPECT_EQ(out.rgba.at<cv::Vec4b>(5, 50), cv::Vec4b(0, 0, 0, 0));
    EXPECT_EQ(out.triangle_id.at<int>(5, 50), -1);
    EXPECT_EQ(out.triangle_id.size(), cv::Size(64, 48));
    EXPECT_TRUE(std::isinf(out.depth.at<float>(5, 50)));
    EXPECT_NEAR(out.depth.at<float>(20, 50), z, 1e-5);
  }
}

TEST(RendererTest, SupersamplingAveragesEdges) {
  // A black quad whose vertical edge crosses pixel column 10 at its centre: with 1x the
  // pixel is all-or-nothing; with 4x it is the mean of the covered half (alpha from the
  // covered fraction, colour from the covered samples only).
  const Camera camera = PinholeCamera(20, 10, 20.0);
  Scene scene;
  Material white;
  scene.materials.push_back(white);
  auto at = [&](double px, double py) {
    return Eigen::Vector3d((px - camera.cx) / 20.0, (py - camera.cy) / 20.0, 1.0);
  };
  const Eigen::Vector3d corners[4] = {at(-5, -5), at(-5, 15), at(10.25, 15), at(10.25, -5)};
  const Eigen::Vector2f uvs[4] = {{0, 0}, {0, 1}, {1, 1}, {1, 0}};
  AddQuad(&scene.mesh, corners, uvs);
  scene.mesh.has_uv.assign(2, false);
  for (const int n : {1, 2, 3, 4}) {
    RenderOptions options;
    options.raster.supersample = n;
    RenderOutput out;
    Renderer(camera, options).Render(scene, Rigid3d(), &out);
    // Pixel 10 spans [9.5, 10.5]; the edge at 10.25 covers 3/4 of it.
    EXPECT_EQ(out.rgba.at<cv::Vec4b>(5, 10), cv::Vec4b(255, 255, 255, 255)) << n;
    EXPECT_EQ(out.rgba.at<cv::Vec4b>(5, 11)[3], 0) << n;
    EXPECT_EQ(out.triangle_id.at<int>(5, 10) >= 0, true) << n;
    EXPECT_EQ(out.triangle_id.at<int>(5, 11), -1) << n;
  }
}

// Map-scale coordinates: the same scene 1e6 m away renders the same, because the origin is
// composed in double before anything goes to float.
TEST(RendererTest, FarFromOriginRendersLikeNearOrigin) {
  const Camera camera = PinholeCamera(120, 90, 100.0);
  Scene near_scene;
  near_scene.materials.push_back(Material());
  AddGrid(&near_scene.mesh, {-1, -1, 0}, Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), 8, 8,
          0.25);
  Scene far_scene = near_scene;
  far_scene.origin_in_world = Eigen::Vector3d(654321.125, 4321987.5, 123.25);
  const Rigid3d near_pose = LookAt({0.7, -0.4, -3.0}, {0.1, 0.0, 0.0});
  const Rigid3d far_pose = LookAt(far_scene.origin_in_world + Eigen::Vector3d(0.7, -0.4, -3.0),
                                  far_scene.origin_in_world + Eigen::Vector3d(0.1, 0.0, 0.0));
  RenderOutput a, b;
  Renderer renderer(camera, RenderOptions());
  renderer.Render(near_scene, near_pose, &a);
  renderer.Render(far_scene, far_pose, &b);
  EXPECT_LE(cv::countNonZero(a.triangle_id != b.triangle_id), 3);
  cv::Mat diff;
  cv::absdiff(a.depth, b.depth, diff);
  diff.setTo(0, (a.triangle_id < 0) | (b.triangle_id < 0));
  double max_diff = 0;
  cv::minMaxLoc(diff, nullptr, &max_diff);
  EXPECT_LT(max_diff, 1e-4);
  EXPECT_GT(cv::countNonZero(a.triangle_id >= 0), 3000);
  const Rigid3d cam_from_local = CamFromLocal(far_scene, far_pose);
  // The look-at target (local (0.1, 0, 0)) is straight ahead at the eye's distance.
  const double distance = Eigen::Vector3d(0.6, 0.4, 3.0).norm();
  EXPECT_LT((cam_from_local * Eigen::Vector3d(0.1, 0, 0) - Eigen::Vector3d(0, 0, distance)).norm(),
            1e-6);
}

// ---------------------------------------------------------------------------------------
// Shared glTF models

struct ModelView {
  Scene scene;
  Rigid3d cam_from_world;
};

// Loads a shared model and places a camera looking at its centre from a diagonal.
ModelView LoadModelView(const std::string& relative, const Camera& camera) {
  ModelView view;
  const std::string path = testing::SharedDataDir() + "/gltf/" + relative;
  const Status status = LoadGltfScene(path, SceneLoadOptions(), &view.scene);
  EXPECT_TRUE(status.ok()) << status.message();
  Eigen::Vector3d lo, hi;
  view.scene.Bounds(&lo, &hi);
  const Eigen::Vector3d centre_world = view.scene.WorldFromLocal(0.5 * (lo + hi));
  const double radius = 0.5 * (hi - lo).norm();
  // Distance so the bounding sphere spans ~70% of the image height.
  const double distance = radius / std::tan(std::atan(0.35 * camera.height / camera.fy));
  const Eigen::Vector3d eye =
      centre_world + distance * Eigen::Vector3d(0.55, 0.45, 0.7).normalized();
  view.cam_from_world = LookAt(eye, centre_world);
  return view;
}

class SharedModelTest : public ::testing::TestWithParam<const char*> {};

TEST_P(SharedModelTest, RendersWithSensibleCoverage) {
  FRESCO_REQUIRE_SHARED_DATA();
  const Camera camera = PinholeCamera(160, 120, 150.0);
  const ModelView view = LoadModelView(GetParam(), camera);
  ASSERT_GT(view.scene.mesh.NumTriangles(), 0);
  RenderOptions options;
  options.raster.supersample = 2;
  RenderOutput out;
  Renderer(camera, options).Render(view.scene, view.cam_from_world, &out);
  std::vector<cv::Mat> channels;
  cv::split(out.rgba, channels);
  const double coverage = cv::countNonZero(channels[3]) / static_cast<double>(out.rgba.total());
  const double hit = cv::countNonZero(out.triangle_id >= 0) / static_cast<double>(out.rgba.total());
  EXPECT_GT(coverage, 0.08) << GetParam();
  EXPECT_LT(coverage, 0.9) << GetParam();
  EXPECT_NEAR(coverage, hit, 0.05) << GetParam();
  // Not a flat colour: the texture (or shading of materials) shows.
  cv::Scalar mean, stddev;
  cv::meanStdDev(out.rgba, mean, stddev, channels[3]);
  EXPECT_GT(stddev[0] + stddev[1] + stddev[2], 1.0) << GetParam();
  // Depths are positive and within the bounding sphere's range.
  double min_depth = 0;
  cv::minMaxLoc(out.depth, &min_depth);
  EXPECT_GT(min_depth, 0.0);
}

INSTANTIATE_TEST_SUITE_P(Models, SharedModelTest,
                         ::testing::Values("Cube/glTF/Cube.gltf",
                                           "BoxTextured/glTF/BoxTextured.gltf",
                                           "BoxTextured/glTF-Binary/BoxTextured.glb",
                                           "Avocado/glTF/Avocado.gltf",
                                           "CesiumMilkTruck/glTF/CesiumMilkTruck.gltf"));

// BoxTextured at 64 x 48 against the checked-in reference (FRESCO_UPDATE_REFERENCE=1
// rewrites it).
TEST(SharedModelReferenceTest, BoxTexturedMatchesReference) {
  FRESCO_REQUIRE_SHARED_DATA();
  const Camera camera = PinholeCamera(64, 48, 55.0);
  const ModelView view = LoadModelView("BoxTextured/glTF/BoxTextured.gltf", camera);
  RenderOptions options;
  options.raster.supersample = 3;
  RenderOutput out;
  Renderer(camera, options).Render(view.scene, view.cam_from_world, &out);
  cv::Mat bgra;
  cv::cvtColor(out.rgba, bgra, cv::COLOR_RGBA2BGRA);
  const std::string reference =
      testing::SourceDir() + "/tests/render/reference/BoxTextured_64x48.png";
  if (std::getenv("FRESCO_UPDATE_REFERENCE")) {
    ASSERT_TRUE(cv::imwrite(reference, bgra));
    GTEST_SKIP() << "reference rewritten: " << reference;
  }
  const cv::Mat expected = cv::imread(reference, cv::IMREAD_UNCHANGED);
  ASSERT_FALSE(expected.empty()) << reference;
  ASSERT_EQ(expected.type(), CV_8UC4);
  ASSERT_EQ(expected.size(), bgra.size());
  EXPECT_GE(cv::PSNR(bgra, expected), 35.0);
}

}  // namespace
}  // namespace fresco
