// ImageTextures on OpenGL: one texture per key, re-uploaded when the version changes;
// textures not asked for in a while are deleted.
#pragma once

#include <map>
#include <string>

#include "ui/core/panel.h"
#include "ui/gl/gl.h"

namespace fresco {

class GlTextures : public ImageTextures {
 public:
  // `crisp_pixels`: magnified images show their pixels as squares (the panels' image views,
  // zoomed in to read pixels) instead of blending them (the 3D view's textures).
  explicit GlTextures(bool crisp_pixels = false) : crisp_pixels_(crisp_pixels) {}
  ~GlTextures() override;
  ImTextureID Get(const std::string& key, const cv::Mat& image, uint64_t version) override;
  // Called once per UI frame: deletes textures unused for `max_age` frames.
  void EndFrame(int max_age = 120);

 private:
  struct Entry {
    GLuint texture = 0;
    uint64_t version = 0;
    int width = 0, height = 0;
    int last_used = 0;
  };
  std::map<std::string, Entry> entries_;
  int frame_ = 0;
  bool crisp_pixels_ = false;
};

// Uploads a CV_8UC1/3/4 image (BGR order) into `texture` as RGBA; `magnify`: the
// magnification filter (GL_LINEAR or GL_NEAREST).
void UploadTexture(GLuint texture, const cv::Mat& image, GLint magnify = GL_LINEAR);

}  // namespace fresco
