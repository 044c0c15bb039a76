// Built-in scenes made in memory: the paper's cube room (fig. 8), an outdoor street of façades,
// and small test scenes (a textured plane, a textured cube), plus procedural textures for
// when no image is given. All are deterministic for a seed. World frame = glTF frame:
// right-handed, +Y up, metres. Faces are quads of two counter-clockwise triangles whose
// normals point towards where they are meant to be seen from (inwards for the room).
#pragma once

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "pipeline/core/scene.h"
#include "pipeline/core/status.h"

namespace fresco {

// ---- Procedural textures (CV_8UC4, RGBA, sRGB) ----

// A checkerboard of `squares_x` x `squares_y` squares alternating `a` and `b` (RGBA).
cv::Mat MakeCheckerTexture(int width_px, int height_px, int squares_x, int squares_y,
                           const cv::Vec4b& a = cv::Vec4b(235, 235, 235, 255),
                           const cv::Vec4b& b = cv::Vec4b(30, 30, 30, 255));
// Smooth coloured noise with many sharp-cornered rectangles, disks and lines on it: every
// region has texture and corners (Harris/refinement find features), no two areas alike.
cv::Mat MakeFeatureTexture(int width_px, int height_px, unsigned seed);
// The same kind of shapes, sized in pixels (Uniform(min_shape_px, max_shape_px)) and about
// three layers deep over the whole image, whatever its size: dense corners at a chosen scale
// (e.g. textures sized in texels per metre, seen at a known distance).
cv::Mat MakeDenseFeatureTexture(int width_px, int height_px, double min_shape_px,
                                double max_shape_px, unsigned seed);
// A building façade: wall colour with fine noise, a grid of windows (`floors` x `columns`)
// with frames and sills, a darker plinth. Deterministic for `seed`.
cv::Mat MakeFacadeTexture(int width_px, int height_px, int floors, int columns, unsigned seed);
// Asphalt-like grey noise with specks (tiles seamlessly when wrapped).
cv::Mat MakeAsphaltTexture(int width_px, int height_px, unsigned seed);
// Converts an image read by OpenCV (gray, BGR or BGRA, 8-bit) to RGBA. Empty in -> empty out.
cv::Mat RgbaFromImage(const cv::Mat& image);

// ---- Building scenes face by face ----

// Adds textures, materials and quads to a Scene. The scene's origin stays (0,0,0).
class SceneBuilder {
 public:
  explicit SceneBuilder(Scene* scene) : scene_(scene) {}
  // Adds a texture (CV_8UC4 RGBA); returns its index.
  int AddTexture(const cv::Mat& rgba, const std::string& name,
                 TextureWrap wrap = TextureWrap::kRepeat);
  // Adds a material with a texture (-1 for none) and an RGBA factor; returns its index.
  int AddMaterial(int texture, const std::string& name,
                  const Eigen::Vector4d& factor = Eigen::Vector4d::Ones());
  // Adds a quad with corners bottom-left, bottom-right, top-right, top-left as seen from its
  // front (counter-clockwise: the normal faces the viewer). UVs span (0,0) top-left to
  // (repeat_u, repeat_v) bottom-right, so the image reads upright and unmirrored from the
  // front. `subdivide` splits it into an n x n grid of quads.
  void AddQuad(const std::array<Eigen::Vector3d, 4>& corners, int material, double repeat_u = 1,
               double repeat_v = 1, int subdivide = 1);
  // Adds an axis-aligned box [min, max] with outward faces; the bottom face only when
  // `with_bottom`. Side faces use `side_material`, the top `top_material`.
  void AddBox(const Eigen::Vector3d& min_corner, const Eigen::Vector3d& max_corner,
              int side_material, int top_material, bool with_bottom = false,
              double metres_per_repeat = 0.0);

 private:
  Scene* scene_;
};

// ---- The cube room (paper fig. 8) ----

enum CubeRoomFace { kRoomFloor = 0, kRoomCeiling, kRoomNorth, kRoomEast, kRoomSouth, kRoomWest };
constexpr int kCubeRoomFaces = 6;
// "floor", "ceiling", "north" (-Z wall), "east" (+X), "south" (+Z), "west" (-X).
const char* CubeRoomFaceName(int face);

struct CubeRoomOptions {
  // Inside size (x width, y height, z depth), metres. The floor is at y = 0, the room is
  // centred on x = z = 0.
  Eigen::Vector3d size_m = Eigen::Vector3d(4.0, 3.0, 4.0);
  // Per face (CubeRoomFace order): an image (any OpenCV 8-bit layout; empty = a procedural
  // feature texture) and how many times it repeats across the face (u, v).
  std::array<cv::Mat, kCubeRoomFaces> images;
  std::array<Eigen::Vector2d, kCubeRoomFaces> repeat = {
      Eigen::Vector2d(1, 1), Eigen::Vector2d(1, 1), Eigen::Vector2d(1, 1),
      Eigen::Vector2d(1, 1), Eigen::Vector2d(1, 1), Eigen::Vector2d(1, 1)};
  // Names given to the textures (e.g. the image files), CubeRoomFace order; "" = face name.
  std::array<std::string, kCubeRoomFaces> texture_names;
  int procedural_texture_px = 512;
  unsigned seed = 1;

  Status Check() const;
};
// Six inward-facing quads; one texture and one material per face.
Status MakeCubeRoomScene(const CubeRoomOptions& options, Scene* scene);

// ---- An outdoor street ----

struct StreetOptions {
  double length_m = 40.0;        // along x, centred on 0
  double street_width_m = 10.0;  // between the façade rows (z = ±width/2)
  int buildings_per_side = 5;
  double min_height_m = 6.0, max_height_m = 14.0;
  int texture_px = 512;  // façade texture width
  unsigned seed = 1;

  Status Check() const;
};
// Ground plane (asphalt, with pavements) and two rows of box buildings with window façades.
Status MakeStreetScene(const StreetOptions& options, Scene* scene);

// ---- Small test scenes ----

// A width x height plane in z = 0 centred on the origin, normal +Z (seen from +Z looking
// towards -Z), with `texture` (RGBA; empty = checker 8x8) stretched once across it:
// UV (0,0) at (-w/2, +h/2), UV (1,1) at (+w/2, -h/2).
Scene MakeTexturedPlaneScene(double width_m, double height_m, const cv::Mat& texture_rgba = {});
// A cube of edge `edge_m` centred on the origin, faces outward, `texture` on each face
// (empty = a feature texture).
Scene MakeTexturedCubeScene(double edge_m, const cv::Mat& texture_rgba = {});

}  // namespace fresco
