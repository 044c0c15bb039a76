#include "ui/gl/gl_textures.h"

#include <opencv2/imgproc.hpp>

namespace fresco {

void UploadTexture(GLuint texture, const cv::Mat& image, GLint magnify) {
  cv::Mat rgba;
  if (image.type() == CV_8UC1)
    cv::cvtColor(image, rgba, cv::COLOR_GRAY2RGBA);
  else if (image.type() == CV_8UC3)
    cv::cvtColor(image, rgba, cv::COLOR_BGR2RGBA);
  else if (image.type() == CV_8UC4)
    cv::cvtColor(image, rgba, cv::COLOR_BGRA2RGBA);
  else {
    cv::Mat grey;
    cv::normalize(image, grey, 0, 255, cv::NORM_MINMAX, CV_8U);
    cv::cvtColor(grey, rgba, cv::COLOR_GRAY2RGBA);
  }
  glBindTexture(GL_TEXTURE_2D, texture);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, magnify);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glPixelStorei(GL_UNPACK_ROW_LENGTH, static_cast<GLint>(rgba.step[0] / 4));
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, rgba.cols, rgba.rows, 0, GL_RGBA, GL_UNSIGNED_BYTE,
               rgba.data);
  glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
}

GlTextures::~GlTextures() {
  for (auto& [key, e] : entries_) glDeleteTextures(1, &e.texture);
}

ImTextureID GlTextures::Get(const std::string& key, const cv::Mat& image, uint64_t version) {
  Entry& e = entries_[key];
  if (e.texture == 0) glGenTextures(1, &e.texture);
  if (e.version != version || e.width != image.cols || e.height != image.rows) {
    if (!image.empty()) UploadTexture(e.texture, image, crisp_pixels_ ? GL_NEAREST : GL_LINEAR);
    e.version = version;
    e.width = image.cols;
    e.height = image.rows;
  }
  e.last_used = frame_;
  return reinterpret_cast<ImTextureID>(static_cast<intptr_t>(e.texture));
}

void GlTextures::EndFrame(int max_age) {
  ++frame_;
  for (auto it = entries_.begin(); it != entries_.end();) {
    if (frame_ - it->second.last_used > max_age) {
      glDeleteTextures(1, &it->second.texture);
      it = entries_.erase(it);
    } else {
      ++it;
    }
  }
}

}  // namespace fresco
