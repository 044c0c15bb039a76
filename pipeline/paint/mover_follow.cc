#include "pipeline/paint/mover_follow.h"

#include <algorithm>
#include <memory>

#include <opencv2/imgproc.hpp>

namespace fresco {
namespace {

constexpr int kBins = 16 * 16 * 16;
constexpr int kMinBlobPx = 8;
// A blob is followed only when at most this share of the pixels around it (its box grown by a
// third) have its colours: else its colours do not tell it from the background.
constexpr double kMostAlikeAround = 0.3;

// A blob's box grown by a third of its size on every side (at least 2 pixels), within `image`:
// where it is compared with what is around it, and looked for in the next frame.
cv::Rect GrownBox(const cv::Rect& box, const cv::Rect& image) {
  const int margin = std::max(2, std::max(box.width, box.height) / 3);
  return cv::Rect(box.x - margin, box.y - margin, box.width + 2 * margin, box.height + 2 * margin) &
         image;
}

struct Blob {
  cv::Rect box;
  std::shared_ptr<const ColourSet> colours;
  int area = 0;
  int age = 0;  // frames followed from the frame the masks found it in
};

std::vector<Blob> BlobsOf(const cv::Mat& bgr, const cv::Mat& mask) {
  std::vector<Blob> blobs;
  cv::Mat labels, stats, centroids;
  const int count = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8, CV_32S);
  // Colours from each blob's inside: its edge pixels mix in the background's.
  cv::Mat inside;
  cv::erode(mask, inside, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(3, 3)));
  for (int label = 1; label < count; ++label) {
    Blob b;
    b.area = stats.at<int>(label, cv::CC_STAT_AREA);
    if (b.area < kMinBlobPx) continue;
    b.box =
        cv::Rect(stats.at<int>(label, cv::CC_STAT_LEFT), stats.at<int>(label, cv::CC_STAT_TOP),
                 stats.at<int>(label, cv::CC_STAT_WIDTH), stats.at<int>(label, cv::CC_STAT_HEIGHT));
    const cv::Mat pixels = (labels(b.box) == label) & inside(b.box);
    b.colours =
        std::make_shared<ColourSet>(ColourSet::Of(bgr(b.box), pixels, std::max(2, b.area / 200)));
    const cv::Rect around = GrownBox(b.box, cv::Rect(0, 0, bgr.cols, bgr.rows));
    int ring = 0, alike = 0;  // pixels around the blob, and of them those of its colours
    for (int y = around.y; y < around.br().y; ++y)
      for (int x = around.x; x < around.br().x; ++x) {
        if (mask.at<uchar>(y, x)) continue;
        ++ring;
        alike += b.colours->Contains(bgr.at<cv::Vec3b>(y, x));
      }
    if (ring > 0 && alike > kMostAlikeAround * ring) continue;
    blobs.push_back(b);
  }
  return blobs;
}

// `from`'s blobs looked for in `frame`; what they gather joins `mask`. Returns the blobs
// followed there, one frame older.
std::vector<Blob> Follow(const FollowFrame& frame, const std::vector<Blob>& from, int frames_away,
                         cv::Mat* mask) {
  std::vector<Blob> followed;
  const cv::Rect image(0, 0, frame.bgr.cols, frame.bgr.rows);
  for (const Blob& b : from) {
    if (b.age >= frames_away) continue;
    const cv::Rect box = GrownBox(b.box, image);
    if (box.empty()) continue;
    cv::Mat gathered(box.size(), CV_8U, cv::Scalar(0));
    int count = 0;
    for (int y = box.y; y < box.br().y; ++y)
      for (int x = box.x; x < box.br().x; ++x)
        if (frame.joinable.at<uchar>(y, x) && b.colours->Contains(frame.bgr.at<cv::Vec3b>(y, x))) {
          gathered.at<uchar>(y - box.y, x - box.x) = 255;
          ++count;
        }
    // Specks of its colours in a textured background are not the mover.
    cv::Mat labels, stats, centroids;
    const int parts =
        cv::connectedComponentsWithStats(gathered, labels, stats, centroids, 8, CV_32S);
    for (int part = 1; part < parts; ++part)
      if (stats.at<int>(part, cv::CC_STAT_AREA) < kMinBlobPx) {
        gathered.setTo(0, labels == part);
        count -= stats.at<int>(part, cv::CC_STAT_AREA);
      }
    if (count < b.area / 2 || count > 2 * b.area) continue;
    (*mask)(box).setTo(255, gathered);
    Blob next = b;
    const cv::Rect where = cv::boundingRect(gathered);
    next.box = cv::Rect(where.x + box.x, where.y + box.y, where.width, where.height);
    next.area = count;
    next.age = b.age + 1;
    followed.push_back(next);
  }
  return followed;
}

}  // namespace

ColourSet ColourSet::Of(const cv::Mat& bgr, const cv::Mat& pixels, int min_count) {
  std::vector<int> counts(kBins, 0);
  for (int y = 0; y < bgr.rows; ++y)
    for (int x = 0; x < bgr.cols; ++x)
      if (pixels.at<uchar>(y, x)) ++counts[Bin(bgr.at<cv::Vec3b>(y, x))];
  ColourSet set;
  set.bins_.assign(kBins, 0);
  for (int bin = 0; bin < kBins; ++bin) {
    if (counts[bin] < min_count) continue;
    const int c0 = bin / 256, c1 = bin / 16 % 16, c2 = bin % 16;
    for (int d0 = std::max(0, c0 - 1); d0 <= std::min(15, c0 + 1); ++d0)
      for (int d1 = std::max(0, c1 - 1); d1 <= std::min(15, c1 + 1); ++d1)
        for (int d2 = std::max(0, c2 - 1); d2 <= std::min(15, c2 + 1); ++d2)
          set.bins_[d0 * 256 + d1 * 16 + d2] = 1;
  }
  return set;
}

void FollowMovers(const std::vector<FollowFrame>& frames, int frames_away,
                  std::vector<cv::Mat>* masks) {
  const int n = static_cast<int>(frames.size());
  if (frames_away <= 0 || static_cast<int>(masks->size()) != n) return;
  // The blobs the masks found (what following adds is not found again: it would follow on).
  std::vector<std::vector<Blob>> found(n);
  for (int f = 0; f < n; ++f)
    if (!frames[f].bgr.empty() && !(*masks)[f].empty())
      found[f] = BlobsOf(frames[f].bgr, (*masks)[f]);
  for (int direction : {1, -1}) {
    std::vector<Blob> carried;
    for (int step = 0; step < n; ++step) {
      const int f = direction > 0 ? step : n - 1 - step;
      if (frames[f].bgr.empty() || (*masks)[f].empty()) {
        carried.clear();
        continue;
      }
      std::vector<Blob> next = Follow(frames[f], carried, frames_away, &(*masks)[f]);
      next.insert(next.end(), found[f].begin(), found[f].end());
      carried = std::move(next);
    }
  }
}

}  // namespace fresco
