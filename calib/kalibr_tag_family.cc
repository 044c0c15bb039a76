#include "calib/kalibr_tag_family.h"

#include <apriltag/apriltag.h>
#include <apriltag/tag36h11.h>

namespace fresco::calib {

KalibrTagFamily::KalibrTagFamily() {
  base_ = tag36h11_create();
  family_ = new apriltag_family_t(*base_);
  family_->impl = nullptr;
  family_->width_at_border = base_->width_at_border + 2;
  family_->total_width = base_->total_width + 2;
  bit_x_.assign(base_->bit_x, base_->bit_x + base_->nbits);
  bit_y_.assign(base_->bit_y, base_->bit_y + base_->nbits);
  for (uint32_t& x : bit_x_) ++x;
  for (uint32_t& y : bit_y_) ++y;
  family_->bit_x = bit_x_.data();
  family_->bit_y = bit_y_.data();
}

KalibrTagFamily::~KalibrTagFamily() {
  delete family_;  // the detector frees family_->impl when it is destroyed
  tag36h11_destroy(base_);
}

int KalibrTagFamily::black_bits() const { return family_->width_at_border; }
int KalibrTagFamily::num_codes() const { return static_cast<int>(family_->ncodes); }

}  // namespace fresco::calib
