// Kalibr's AprilGrid prints tag36h11 with a 2-bit black border (the original AprilTags C++
// library's layout), where the apriltag 3 library's tag36h11 has a 1-bit border. This is the
// apriltag library's own tag36h11 (same codes) with the layout widened by one bit on each
// side: data bits moved in by one, black square 10 bits wide. The detector then finds the
// outer black square, whose corners are Kalibr's tag corners (TAG_M apart), and
// apriltag_to_image draws Kalibr's tags.
#pragma once

#include <cstdint>
#include <vector>

struct apriltag_family;

namespace fresco::calib {

class KalibrTagFamily {
 public:
  KalibrTagFamily();
  ~KalibrTagFamily();
  KalibrTagFamily(const KalibrTagFamily&) = delete;
  KalibrTagFamily& operator=(const KalibrTagFamily&) = delete;

  apriltag_family* get() { return family_; }
  int black_bits() const;  // 10: the black square's width in bits
  int num_codes() const;

 private:
  apriltag_family* base_ = nullptr;    // tag36h11_create()
  apriltag_family* family_ = nullptr;  // the widened copy
  std::vector<uint32_t> bit_x_, bit_y_;
};

}  // namespace fresco::calib
