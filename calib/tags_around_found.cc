#include "calib/tags_around_found.h"

#include <algorithm>
#include <cmath>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

namespace fresco::calib {
namespace {

constexpr int kNeighbourReach = 2;    // found tags within this many places on the board
constexpr int kMinNeighbourTags = 2;  // 8 corners: a well-posed homography
constexpr double kPatchTagPx = 80.0;  // the tag's edge in the resampled patch
constexpr double kMaxOffEdge = 1.0 / 3;  // accepted distance from the prediction, tag edges
constexpr int kMaxRounds = 4;
constexpr int kRefineHalfWindowPx = 6;  // cornerSubPix on the patch (a tag edge: kPatchTagPx)
// The patch reaches this far around the tag (tag edges), or half the gap if more: tight first
// (no neighbour's black in view), then wider (room for a prediction that is off).
constexpr double kMarginEdges[] = {0.15, 0.45};

cv::Point2d Apply(const cv::Matx33d& h, const cv::Point2d& p) {
  const cv::Vec3d q = h * cv::Vec3d(p.x, p.y, 1.0);
  return {q[0] / q[2], q[1] / q[2]};
}

// Looks for tag `id` in the patch around where the board homography `board_to_image` puts it.
bool LookForTag(const cv::Mat& gray, const BoardSpec& spec, const TagDetector& detect, int id,
                const cv::Matx33d& board_to_image, double margin_edges, TagQuad* quad) {
  const Eigen::Vector3d origin = CornerPosition(spec, 4 * id);  // corner 0: least x and y
  const double edge = spec.square_m, margin = std::max(0.5 * spec.spacing, margin_edges) * edge;
  const double metres_per_px = edge / kPatchTagPx;
  // Patch pixel -> board metres -> image pixel. The board's y runs up the upright tag (corner
  // 0, the least x and y, is the tag's bottom left): the patch's rows run down it.
  const cv::Matx33d patch_to_board(metres_per_px, 0, origin.x() - margin, 0, -metres_per_px,
                                   origin.y() + edge + margin, 0, 0, 1);
  const cv::Matx33d patch_to_image = board_to_image * patch_to_board;
  // The tag's predicted corners must lie in the image.
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector3d c = CornerPosition(spec, 4 * id + k);
    const cv::Point2d p = Apply(board_to_image, {c.x(), c.y()});
    if (!(p.x >= 0 && p.y >= 0 && p.x <= gray.cols - 1 && p.y <= gray.rows - 1)) return false;
  }
  const int side = static_cast<int>(std::ceil((edge + 2 * margin) / metres_per_px));
  cv::Mat patch;
  cv::warpPerspective(gray, patch, cv::Mat(patch_to_image), cv::Size(side, side),
                      cv::INTER_LINEAR | cv::WARP_INVERSE_MAP, cv::BORDER_REPLICATE);
  // As the second look does: if the black squares where the gaps cross merge with the tag's
  // black, thinning the black cuts them apart.
  std::vector<TagQuad> quads = detect(patch);
  if (std::none_of(quads.begin(), quads.end(), [&](const TagQuad& q) { return q.id == id; })) {
    cv::Mat thinned;
    cv::dilate(patch, thinned, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(3, 3)));
    quads = detect(thinned);
  }
  for (const TagQuad& q : quads) {
    if (q.id != id) continue;
    TagQuad out;
    out.id = id;
    out.border_bits = q.border_bits;  // the board's border (BorderBitsOf) counts every tag's
    // A tag cut by the patch's edge has false corners there: only whole tags count (a wider
    // patch is tried next).
    bool near = true;
    const double inside = 0.05 * edge / metres_per_px;
    for (int k = 0; k < 4 && near; ++k)
      near = std::min(q.p[k].x(), q.p[k].y()) >= inside &&
             std::max(q.p[k].x(), q.p[k].y()) <= side - 1 - inside;
    if (!near) continue;
    // Corners found on the thinned patch sit inside the tag's true black square: refined on
    // the patch itself (where the tag's corner meets the gap's black square, a saddle).
    std::vector<cv::Point2f> corners;
    for (int k = 0; k < 4; ++k)
      corners.emplace_back(static_cast<float>(q.p[k].x()), static_cast<float>(q.p[k].y()));
    cv::cornerSubPix(patch, corners, cv::Size(kRefineHalfWindowPx, kRefineHalfWindowPx),
                     cv::Size(-1, -1),
                     cv::TermCriteria(cv::TermCriteria::EPS | cv::TermCriteria::COUNT, 40, 1e-3));
    for (int k = 0; k < 4 && near; ++k) {
      const cv::Point2d board = Apply(patch_to_board, {corners[k].x, corners[k].y});
      const Eigen::Vector3d expected = CornerPosition(spec, 4 * id + k);
      near = std::hypot(board.x - expected.x(), board.y - expected.y()) <= kMaxOffEdge * edge;
      const cv::Point2d image = Apply(patch_to_image, {corners[k].x, corners[k].y});
      out.p[k] = Eigen::Vector2d(image.x, image.y);
    }
    if (!near) continue;
    *quad = out;
    return true;
  }
  return false;
}

}  // namespace

int FindTagsAroundFound(const cv::Mat& gray, const BoardSpec& spec, const TagDetector& detect,
                        std::map<int, TagQuad>* found) {
  const int num_ids = spec.cols * spec.rows;
  int added = 0;
  // How many found neighbours each missing tag was last tried with: found tags only grow, so
  // the same count is the same neighbours, the same homography and the same answer.
  std::vector<int> tried_with(num_ids, 0);
  for (int round = 0; round < kMaxRounds && static_cast<int>(found->size()) < num_ids; ++round) {
    std::map<int, TagQuad> new_tags;
    for (int id = 0; id < num_ids; ++id) {
      if (found->count(id)) continue;
      const int col = id % spec.cols, row = id / spec.cols;
      std::vector<cv::Point2f> board, image;
      int tags = 0;
      for (int dr = -kNeighbourReach; dr <= kNeighbourReach; ++dr)
        for (int dc = -kNeighbourReach; dc <= kNeighbourReach; ++dc) {
          const int r = row + dr, c = col + dc;
          if (r < 0 || c < 0 || r >= spec.rows || c >= spec.cols) continue;
          const auto it = found->find(r * spec.cols + c);
          if (it == found->end()) continue;
          ++tags;
          for (int k = 0; k < 4; ++k) {
            const Eigen::Vector3d b = CornerPosition(spec, 4 * it->first + k);
            board.emplace_back(static_cast<float>(b.x()), static_cast<float>(b.y()));
            image.emplace_back(static_cast<float>(it->second.p[k].x()),
                               static_cast<float>(it->second.p[k].y()));
          }
        }
      if (tags < kMinNeighbourTags || tags == tried_with[id]) continue;
      tried_with[id] = tags;
      const cv::Mat h = cv::findHomography(board, image, 0);
      if (h.empty()) continue;
      TagQuad quad;
      for (double margin : kMarginEdges) {
        if (!LookForTag(gray, spec, detect, id, cv::Matx33d(h), margin, &quad)) continue;
        new_tags.emplace(id, quad);
        break;
      }
    }
    if (new_tags.empty()) break;
    added += static_cast<int>(new_tags.size());
    found->insert(new_tags.begin(), new_tags.end());
  }
  return added;
}

}  // namespace fresco::calib
