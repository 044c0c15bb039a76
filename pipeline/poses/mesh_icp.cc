#include "pipeline/poses/mesh_icp.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

namespace fresco {
namespace {

struct Sample {
  Eigen::Vector3d point, normal;
};

// Area-weighted samples on every triangle (world coordinates), about `spacing` apart.
std::vector<Sample> SampleMesh(const Scene& scene, double spacing) {
  const TriangleMesh& mesh = scene.mesh;
  std::vector<Sample> samples;
  for (int t = 0; t < mesh.NumTriangles(); ++t) {
    const Eigen::Vector3d normal = mesh.Normal(t);
    if (normal.isZero()) continue;
    const Eigen::Vector3d a = scene.WorldFromLocal(mesh.Corner(t, 0));
    const Eigen::Vector3d ab = mesh.Corner(t, 1) - mesh.Corner(t, 0);
    const Eigen::Vector3d ac = mesh.Corner(t, 2) - mesh.Corner(t, 0);
    // A regular grid in barycentric coordinates, fine enough for the longest edge.
    const double longest = std::max({ab.norm(), ac.norm(), (ac - ab).norm()});
    const int n = std::max(1, static_cast<int>(std::ceil(longest / spacing)));
    for (int i = 0; i <= n; ++i) {
      for (int j = 0; i + j <= n; ++j) {
        samples.push_back({a + (i * ab + j * ac) / n, normal});
      }
    }
  }
  return samples;
}

// Nearest sample within a radius: a hash of cubic cells of that size.
class VoxelHash {
 public:
  VoxelHash(const std::vector<Sample>* samples, double cell) : samples_(samples), cell_(cell) {
    for (size_t i = 0; i < samples->size(); ++i) {
      cells_[Key(Cell((*samples)[i].point))].push_back(static_cast<int>(i));
    }
  }
  // Index of the nearest sample within `cell` of p, -1 for none.
  int Nearest(const Eigen::Vector3d& p, double* distance) const {
    const Eigen::Vector3i c = Cell(p);
    int best = -1;
    double best_d2 = cell_ * cell_;
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it = cells_.find(Key(c + Eigen::Vector3i(dx, dy, dz)));
          if (it == cells_.end()) continue;
          for (int i : it->second) {
            const double d2 = ((*samples_)[i].point - p).squaredNorm();
            if (d2 < best_d2) best_d2 = d2, best = i;
          }
        }
    *distance = std::sqrt(best_d2);
    return best;
  }

 private:
  Eigen::Vector3i Cell(const Eigen::Vector3d& p) const {
    return (p / cell_).array().floor().cast<int>();
  }
  static int64_t Key(const Eigen::Vector3i& c) {
    return (static_cast<int64_t>(c.x()) * 73856093) ^ (static_cast<int64_t>(c.y()) * 19349663) ^
           (static_cast<int64_t>(c.z()) * 83492791);
  }
  const std::vector<Sample>* samples_;
  double cell_;
  std::unordered_map<int64_t, std::vector<int>> cells_;
};

double MedianOf(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

using Vec7 = Eigen::Matrix<double, 7, 1>;
using Mat7 = Eigen::Matrix<double, 7, 7>;

// Most points lie close to a sample: a fine hash answers them, the coarse one the rest.
struct SampleIndex {
  const VoxelHash *fine, *coarse;
  int Nearest(const Eigen::Vector3d& p, double* distance) const {
    const int i = fine->Nearest(p, distance);
    return i >= 0 ? i : coarse->Nearest(p, distance);
  }
};

// What the alignment matches the points to.
struct IcpProblem {
  const std::vector<Eigen::Vector3d>& points_in_colmap;
  const std::vector<Sample>& samples;
  const SampleIndex& hash;
  double spacing = 0;
  const MeshIcpOptions& options;
};

// Each point's distance (along the sample's normal) from its nearest sample under `w`.
std::vector<double> PlaneDistances(const IcpProblem& problem, const Sim3d& w) {
  std::vector<double> d;
  for (const Eigen::Vector3d& p : problem.points_in_colmap) {
    double distance = 0.0;
    const Eigen::Vector3d x = w * p;
    const int i = problem.hash.Nearest(x, &distance);
    if (i >= 0) d.push_back(std::abs(problem.samples[i].normal.dot(x - problem.samples[i].point)));
  }
  return d;
}

// Pairs: each point with its nearest sample; far pairs (3x the median) rejected.
struct Pairs {
  std::vector<Eigen::Vector3d> world;  // the points under the current transform
  std::vector<int> nearest;            // their nearest samples (-1: none)
  std::vector<double> distance;        // and the distances to them
  std::vector<double> found;           // the distances of the points with a sample
  double cutoff = 0;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // of the pairs' points
  int count = 0;

  bool Kept(size_t i) const { return nearest[i] >= 0 && distance[i] <= cutoff; }
};

void FindPairs(const IcpProblem& problem, const Sim3d& current, Pairs* pairs) {
  const std::vector<Eigen::Vector3d>& points = problem.points_in_colmap;
  pairs->nearest.assign(points.size(), -1);
  pairs->distance.assign(points.size(), 0.0);
  pairs->found.clear();
  for (size_t i = 0; i < points.size(); ++i) {
    pairs->world[i] = current * points[i];
    pairs->nearest[i] = problem.hash.Nearest(pairs->world[i], &pairs->distance[i]);
    if (pairs->nearest[i] >= 0) pairs->found.push_back(pairs->distance[i]);
  }
  pairs->cutoff = std::max(3.0 * MedianOf(pairs->found), 1e-3 * problem.spacing);
  pairs->centre = Eigen::Vector3d::Zero();
  pairs->count = 0;
  for (size_t i = 0; i < pairs->world.size(); ++i) {
    if (pairs->Kept(i)) pairs->centre += pairs->world[i], ++pairs->count;
  }
}

// The Huber-weighted normal equations of the residuals n.(x' - q) with
// x' = x + sigma (x - c) + omega x (x - c) + tau, about the pairs' centre c. Returns the mean
// squared distance of the pairs' points from their centre.
double NormalEquations(const IcpProblem& problem, const Pairs& pairs, double huber, Mat7* a,
                       Vec7* b) {
  double spread2 = 0.0;
  *a = Mat7::Zero();
  *b = Vec7::Zero();
  for (size_t i = 0; i < pairs.world.size(); ++i) {
    if (!pairs.Kept(i)) continue;
    const Sample& s = problem.samples[pairs.nearest[i]];
    const Eigen::Vector3d d = pairs.world[i] - pairs.centre;
    spread2 += d.squaredNorm() / pairs.count;
    Vec7 j;
    j << d.cross(s.normal), s.normal, s.normal.dot(d);
    const double r = s.normal.dot(pairs.world[i] - s.point);
    const double w = std::abs(r) <= huber ? 1.0 : huber / std::abs(r);
    *a += w * j * j.transpose();
    *b -= w * r * j;
  }
  return spread2;
}

// One Gauss-Newton step from `current`; `converged` when the step is negligible.
Status IcpStep(const IcpProblem& problem, Pairs* pairs, Sim3d* current, bool* converged,
               MeshIcpResult* result) {
  FindPairs(problem, *current, pairs);
  result->pairs = pairs->count;
  if (pairs->count < problem.options.min_pairs) {
    return Status::Error("mesh ICP: only " + std::to_string(pairs->count) +
                         " sparse points lie near the model (within max_distance_m), needs " +
                         std::to_string(problem.options.min_pairs));
  }
  pairs->centre /= pairs->count;
  const Eigen::Vector3d& centre = pairs->centre;
  const double huber = std::max(0.5 * MedianOf(pairs->found), 1e-6);
  Mat7 a;
  Vec7 b;
  const double spread2 = NormalEquations(problem, *pairs, huber, &a, &b);
  if (!problem.options.estimate_scale) {
    a.row(6).setZero(), a.col(6).setZero(), a(6, 6) = 1.0, b(6) = 0.0;
  }
  a.diagonal() += Vec7::Constant(1e-9 * a.diagonal().maxCoeff());
  const Vec7 x = a.ldlt().solve(b);
  if (!x.allFinite()) return Status::Error("mesh ICP: the linear system is degenerate");
  // The update D(y) = (1 + sigma) R(omega) (y - c) + c + tau, composed after `current`.
  const Eigen::Vector3d omega = x.head<3>(), tau = x.segment<3>(3);
  const double step_scale = 1.0 + x(6);
  const Eigen::Quaterniond step_rotation =
      omega.norm() > 0 ? Eigen::Quaterniond(Eigen::AngleAxisd(omega.norm(), omega.normalized()))
                       : Eigen::Quaterniond::Identity();
  Sim3d next;
  next.scale = step_scale * current->scale;
  next.rotation = (step_rotation * current->rotation).normalized();
  next.translation = step_scale * (step_rotation * (current->translation - centre)) + centre + tau;
  *current = next;
  ++result->iterations;
  const double radius = std::max(std::sqrt(spread2), 1e-9);
  *converged = omega.norm() + std::abs(x(6)) + tau.norm() / radius < 1e-6;
  return Status::Ok();
}

}  // namespace

Status MeshIcpOptions::Check() const {
  if (!(max_distance_m > 0)) return Status::Error("max_distance_m: must be > 0");
  if (!(sample_spacing_m >= 0)) return Status::Error("sample_spacing_m: must be >= 0");
  if (max_samples < 1000) return Status::Error("max_samples: must be >= 1000");
  if (iterations < 1) return Status::Error("iterations: must be >= 1");
  if (min_pairs < 7) return Status::Error("min_pairs: must be >= 7");
  return Status::Ok();
}

Status AlignPointsToMesh(const std::vector<Eigen::Vector3d>& points_in_colmap, const Scene& scene,
                         const Sim3d& initial, const MeshIcpOptions& options,
                         MeshIcpResult* result) {
  FRESCO_RETURN_IF_ERROR(options.Check());
  double area = 0.0;
  for (int t = 0; t < scene.mesh.NumTriangles(); ++t) area += scene.mesh.Area(t);
  if (!(area > 0)) return Status::Error("mesh ICP: the scene has no triangles with area");
  double spacing =
      options.sample_spacing_m > 0 ? options.sample_spacing_m : 0.125 * options.max_distance_m;
  // About 2 samples per spacing^2 of area on a barycentric grid: keep within max_samples.
  spacing = std::max(spacing, std::sqrt(2.0 * area / options.max_samples));
  const std::vector<Sample> samples = SampleMesh(scene, spacing);
  const VoxelHash fine(&samples, std::min(2.0 * spacing, options.max_distance_m));
  const VoxelHash coarse(&samples, options.max_distance_m);
  const SampleIndex hash{&fine, &coarse};
  const IcpProblem problem{points_in_colmap, samples, hash, spacing, options};

  Sim3d current = initial;
  Pairs pairs;
  pairs.world.resize(points_in_colmap.size());
  result->median_distance_before_m = MedianOf(PlaneDistances(problem, current));
  result->iterations = 0;
  for (int iteration = 0; iteration < options.iterations; ++iteration) {
    bool converged = false;
    FRESCO_RETURN_IF_ERROR(IcpStep(problem, &pairs, &current, &converged, result));
    if (converged) break;
  }
  result->world_from_colmap = current;
  result->median_distance_after_m = MedianOf(PlaneDistances(problem, current));
  return Status::Ok();
}

}  // namespace fresco
