#include "pipeline/paint/scattered_groups.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "pipeline/paint/base_buffer.h"

namespace fresco {
namespace {

// A triangle's extent and centre along the plane's two axes (texels).
struct PlaneBox {
  double a_min = 1e300, a_max = -1e300, b_min = 1e300, b_max = -1e300;

  void Add(const PlaneBox& o) {
    a_min = std::min(a_min, o.a_min), a_max = std::max(a_max, o.a_max);
    b_min = std::min(b_min, o.b_min), b_max = std::max(b_max, o.b_max);
  }
  // Texels of the rectangle with `gutter` around it (as the buffer is sized).
  double Texels(int gutter) const {
    return (std::ceil(a_max - a_min) + 2 * gutter + 1) *
           (std::ceil(b_max - b_min) + 2 * gutter + 1);
  }
};

class Splitter {
 public:
  Splitter(std::vector<PlaneBox> boxes, std::vector<double> areas, int gutter)
      : boxes_(std::move(boxes)), areas_(std::move(areas)), gutter_(gutter) {}

  // Cuts `items` (indices into the boxes, in order) and appends the pieces to `out`.
  void Split(std::vector<int> items, std::vector<std::vector<int>>* out) const {
    std::vector<int> left, right;
    const double whole = BoxOf(items).Texels(gutter_);
    double surface = 0;
    for (int i : items) surface += areas_[i];
    if (items.size() < 2 || surface >= kScatteredFill * whole ||
        whole - Cut(items, &left, &right) < kScatteredCutSavesTexels) {
      out->push_back(std::move(items));
      return;
    }
    Split(std::move(left), out);
    Split(std::move(right), out);
  }

 private:
  PlaneBox BoxOf(const std::vector<int>& items) const {
    PlaneBox box;
    for (int i : items) box.Add(boxes_[i]);
    return box;
  }

  // The cut across either axis, between centres in order along it, whose two rectangles hold
  // the fewest texels: those texels (the sides in `left` and `right`).
  double Cut(const std::vector<int>& items, std::vector<int>* left, std::vector<int>* right) const {
    const size_t n = items.size();
    double best = std::numeric_limits<double>::infinity();
    int best_axis = 0;
    size_t best_at = n / 2;
    std::vector<int> order(n);
    std::vector<double> prefix(n);
    const auto sort_along = [&](int axis) {
      std::iota(order.begin(), order.end(), 0);
      std::stable_sort(order.begin(), order.end(), [&](int x, int y) {
        return Centre(items[x], axis) < Centre(items[y], axis);
      });
    };
    for (int axis = 0; axis < 2; ++axis) {
      sort_along(axis);
      PlaneBox box;
      for (size_t k = 0; k < n; ++k) {
        box.Add(boxes_[items[order[k]]]);
        prefix[k] = box.Texels(gutter_);
      }
      box = PlaneBox();
      for (size_t k = n - 1; k >= 1; --k) {
        box.Add(boxes_[items[order[k]]]);
        const double texels = prefix[k - 1] + box.Texels(gutter_);
        if (texels < best) best = texels, best_axis = axis, best_at = k;
      }
    }
    if (best_axis != 1) sort_along(best_axis);  // `order` is along the last axis sorted
    std::vector<char> goes_left(n, 0);
    for (size_t k = 0; k < best_at; ++k) goes_left[order[k]] = 1;
    for (size_t k = 0; k < n; ++k) (goes_left[k] ? left : right)->push_back(items[k]);
    return best;
  }

  double Centre(int i, int axis) const {
    const PlaneBox& b = boxes_[i];
    return axis == 0 ? b.a_min + b.a_max : b.b_min + b.b_max;
  }

  std::vector<PlaneBox> boxes_;
  std::vector<double> areas_;  // each triangle's, in texels on the plane
  int gutter_ = 0;
};

}  // namespace

std::vector<BaseBufferGroup> SplitScatteredGroup(const TriangleMesh& mesh,
                                                 const BaseBufferGroup& group, double texel_size_m,
                                                 int gutter_texels) {
  if (group.triangles.size() < 2 || !(texel_size_m > 0)) return {group};
  BaseBuffer plane;  // the axes its buffer would have
  ChooseAxes(GroupNormal(mesh, group), &plane);
  const Eigen::Vector3d &u = plane.axis_u, &v = plane.axis_v;
  std::vector<PlaneBox> boxes(group.triangles.size());
  std::vector<double> areas(boxes.size());
  for (size_t i = 0; i < boxes.size(); ++i) {
    Eigen::Vector2d corners[3];
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d p = mesh.Corner(group.triangles[i], k) / texel_size_m;
      corners[k] = Eigen::Vector2d(p.dot(u), p.dot(v));
      PlaneBox corner;
      corner.a_min = corner.a_max = corners[k].x();
      corner.b_min = corner.b_max = corners[k].y();
      boxes[i].Add(corner);
    }
    const Eigen::Vector2d e1 = corners[1] - corners[0], e2 = corners[2] - corners[0];
    areas[i] = 0.5 * std::abs(e1.x() * e2.y() - e1.y() * e2.x());
  }
  std::vector<std::vector<int>> pieces;
  std::vector<int> all(boxes.size());
  std::iota(all.begin(), all.end(), 0);
  Splitter(std::move(boxes), std::move(areas), gutter_texels).Split(std::move(all), &pieces);
  std::vector<BaseBufferGroup> out;
  for (const std::vector<int>& piece : pieces) {
    BaseBufferGroup part;
    part.texel_size_m = group.texel_size_m;
    for (int i : piece) part.triangles.push_back(group.triangles[i]);
    out.push_back(std::move(part));
  }
  return out;
}

}  // namespace fresco
