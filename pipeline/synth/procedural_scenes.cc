#include "pipeline/synth/procedural_scenes.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "pipeline/synth/random.h"

namespace fresco {
namespace {

cv::Scalar RandomColour(SynthRandom* random, double lo = 20, double hi = 235) {
  return cv::Scalar(random->Uniform(lo, hi), random->Uniform(lo, hi), random->Uniform(lo, hi), 255);
}

// Smooth noise that wraps around the borders (tiles seamlessly): random values on a coarse
// grid, tiled 3 x 3, blurred, and the middle tile kept. CV_32F, roughly zero mean, unit std.
cv::Mat WrappingNoise(int width, int height, int cells_x, int cells_y, SynthRandom* random) {
  cv::Mat coarse(cells_y, cells_x, CV_32F);
  for (int y = 0; y < cells_y; ++y) {
    for (int x = 0; x < cells_x; ++x) coarse.at<float>(y, x) = static_cast<float>(random->Normal());
  }
  cv::Mat tiled;
  cv::repeat(coarse, 3, 3, tiled);
  // Cubic interpolation of the tiled grid is smooth, and wraps because the middle tile's
  // borders interpolate from the neighbouring copies.
  cv::Mat big;
  cv::resize(tiled, big, cv::Size(3 * width, 3 * height), 0, 0, cv::INTER_CUBIC);
  cv::Mat middle = big(cv::Rect(width, height, width, height)).clone();
  cv::Scalar mean, stddev;
  cv::meanStdDev(middle, mean, stddev);
  middle = (middle - mean[0]) / std::max(stddev[0], 1e-6);
  return middle;
}

// Per-pixel noise in [-1, 1], CV_32F.
cv::Mat PixelNoise(int width, int height, SynthRandom* random) {
  cv::Mat noise(height, width, CV_32F);
  for (int y = 0; y < height; ++y) {
    float* row = noise.ptr<float>(y);
    for (int x = 0; x < width; ++x) row[x] = static_cast<float>(random->Uniform(-1.0, 1.0));
  }
  return noise;
}

// rgba += gain * noise (same on all three colour channels), saturating.
void AddNoise(const cv::Mat& noise, double gain, cv::Mat* rgba) {
  for (int y = 0; y < rgba->rows; ++y) {
    cv::Vec4b* row = rgba->ptr<cv::Vec4b>(y);
    const float* n = noise.ptr<float>(y);
    for (int x = 0; x < rgba->cols; ++x) {
      for (int c = 0; c < 3; ++c) row[x][c] = cv::saturate_cast<uchar>(row[x][c] + gain * n[x]);
    }
  }
}

}  // namespace

cv::Mat MakeCheckerTexture(int width_px, int height_px, int squares_x, int squares_y,
                           const cv::Vec4b& a, const cv::Vec4b& b) {
  cv::Mat rgba(height_px, width_px, CV_8UC4);
  for (int y = 0; y < height_px; ++y) {
    const int sy = y * squares_y / height_px;
    cv::Vec4b* row = rgba.ptr<cv::Vec4b>(y);
    for (int x = 0; x < width_px; ++x) {
      const int sx = x * squares_x / width_px;
      row[x] = ((sx + sy) % 2 == 0) ? a : b;
    }
  }
  return rgba;
}

namespace {

// Smooth coloured noise (one field per channel) around a random base colour.
cv::Mat NoiseBackground(int width_px, int height_px, SynthRandom* random) {
  cv::Mat rgba(height_px, width_px, CV_8UC4);
  std::array<cv::Mat, 3> fields;
  for (auto& f : fields) f = WrappingNoise(width_px, height_px, 6, 6, random);
  const cv::Vec3d base(random->Uniform(90, 170), random->Uniform(90, 170), random->Uniform(90, 170));
  for (int y = 0; y < height_px; ++y) {
    cv::Vec4b* row = rgba.ptr<cv::Vec4b>(y);
    for (int x = 0; x < width_px; ++x) {
      for (int c = 0; c < 3; ++c) {
        row[x][c] = cv::saturate_cast<uchar>(base[c] + 28.0 * fields[c].at<float>(y, x));
      }
      row[x][3] = 255;
    }
  }
  return rgba;
}

// `shapes` shapes with corners (rectangles filled and outlined, disks, triangles), each of
// size Uniform(min_size, max_size) * scale pixels (at least 2), in random colours.
void DrawShapes(int shapes, double scale, double min_size, double max_size, SynthRandom* random,
                cv::Mat* rgba) {
  const int width_px = rgba->cols, height_px = rgba->rows;
  for (int i = 0; i < shapes; ++i) {
    const cv::Point p(random->UniformInt(0, width_px - 1), random->UniformInt(0, height_px - 1));
    const int size = std::max(2, static_cast<int>(random->Uniform(min_size, max_size) * scale));
    const cv::Scalar colour = RandomColour(random);
    switch (random->UniformInt(0, 4)) {
      case 0:
      case 1: {
        const int w = std::max(2, static_cast<int>(size * random->Uniform(0.5, 1.8)));
        cv::rectangle(*rgba, cv::Rect(p.x, p.y, w, size), colour, cv::FILLED);
        break;
      }
      case 2:
        cv::rectangle(*rgba, cv::Rect(p.x, p.y, size, size), colour, std::max(1, size / 6));
        break;
      case 3:
        cv::circle(*rgba, p, size / 2 + 1, colour, cv::FILLED, cv::LINE_AA);
        break;
      default: {
        const cv::Point q(p.x + random->UniformInt(-2 * size, 2 * size),
                          p.y + random->UniformInt(-2 * size, 2 * size));
        const cv::Point r(p.x + random->UniformInt(-2 * size, 2 * size),
                          p.y + random->UniformInt(-2 * size, 2 * size));
        std::vector<cv::Point> tri = {p, q, r};
        cv::fillConvexPoly(*rgba, tri, colour, cv::LINE_AA);
        break;
      }
    }
  }
}

}  // namespace

cv::Mat MakeFeatureTexture(int width_px, int height_px, unsigned seed) {
  SynthRandom random(seed, 101);
  cv::Mat rgba = NoiseBackground(width_px, height_px, &random);
  const double scale = std::min(width_px, height_px);
  const int shapes = std::max(12, static_cast<int>(width_px * height_px / 1000.0));
  DrawShapes(shapes, scale, 0.01, 0.08, &random, &rgba);
  cv::Mat fine = PixelNoise(width_px, height_px, &random);
  AddNoise(fine, 6.0, &rgba);
  return rgba;
}

cv::Mat MakeDenseFeatureTexture(int width_px, int height_px, double min_shape_px,
                                double max_shape_px, unsigned seed) {
  SynthRandom random(seed, 102);
  cv::Mat rgba = NoiseBackground(width_px, height_px, &random);
  // About three layers of shapes over every pixel: no patch is plain.
  const double mean_area = 0.6 * std::pow(0.5 * (min_shape_px + max_shape_px), 2);
  const int shapes = std::max(4, static_cast<int>(3.0 * width_px * height_px / mean_area));
  DrawShapes(shapes, 1.0, min_shape_px, max_shape_px, &random, &rgba);
  cv::Mat fine = PixelNoise(width_px, height_px, &random);
  AddNoise(fine, 6.0, &rgba);
  return rgba;
}

cv::Mat MakeFacadeTexture(int width_px, int height_px, int floors, int columns, unsigned seed) {
  SynthRandom random(seed, 202);
  floors = std::max(1, floors);
  columns = std::max(1, columns);
  static const cv::Vec3d kWallColours[] = {{196, 164, 132}, {220, 205, 180}, {170, 96, 78},
                                           {205, 200, 190}, {150, 160, 170}, {225, 190, 120},
                                           {180, 140, 160}, {140, 150, 120}};
  const cv::Vec3d wall = kWallColours[random.UniformInt(0, 7)] * random.Uniform(0.85, 1.1);
  cv::Mat rgba(height_px, width_px, CV_8UC4);
  cv::Mat smooth = WrappingNoise(width_px, height_px, 8, 8, &random);
  for (int y = 0; y < height_px; ++y) {
    cv::Vec4b* row = rgba.ptr<cv::Vec4b>(y);
    for (int x = 0; x < width_px; ++x) {
      const double shade = 1.0 + 0.06 * smooth.at<float>(y, x);
      for (int c = 0; c < 3; ++c) row[x][c] = cv::saturate_cast<uchar>(wall[c] * shade);
      row[x][3] = 255;
    }
  }
  // Plinth: the bottom part of the ground floor.
  const double floor_h = height_px / static_cast<double>(floors);
  const int plinth_top = height_px - static_cast<int>(0.18 * floor_h);
  cv::rectangle(rgba, cv::Point(0, plinth_top), cv::Point(width_px - 1, height_px - 1),
                cv::Scalar(wall[0] * 0.55, wall[1] * 0.55, wall[2] * 0.55, 255), cv::FILLED);
  // Cornice lines between floors.
  for (int f = 1; f < floors; ++f) {
    const int y = static_cast<int>(f * floor_h);
    cv::rectangle(rgba, cv::Point(0, y - 2), cv::Point(width_px - 1, y + 1),
                  cv::Scalar(wall[0] * 0.8, wall[1] * 0.8, wall[2] * 0.8, 255), cv::FILLED);
  }
  const double col_w = width_px / static_cast<double>(columns);
  const cv::Scalar frame_colour =
      random.Uniform() < 0.5 ? cv::Scalar(240, 240, 235, 255) : cv::Scalar(70, 60, 55, 255);
  const int door_column = random.UniformInt(0, columns - 1);
  for (int f = 0; f < floors; ++f) {
    for (int c = 0; c < columns; ++c) {
      const bool ground = f == floors - 1;
      const bool door = ground && c == door_column;
      const double w = col_w * (door ? 0.5 : 0.45);
      const double h = floor_h * (door ? 0.75 : 0.55);
      const int x0 = static_cast<int>(c * col_w + 0.5 * (col_w - w));
      const int y0 = door ? static_cast<int>((f + 1) * floor_h - h)
                          : static_cast<int>(f * floor_h + 0.22 * floor_h);
      const cv::Rect window(x0, y0, std::max(2, static_cast<int>(w)),
                            std::max(2, static_cast<int>(h)));
      // Glass: dark blue-grey with a random reflection gradient; doors are wood.
      const double tone = random.Uniform(0.6, 1.2);
      const cv::Scalar glass = door ? cv::Scalar(110 * tone, 70 * tone, 45 * tone, 255)
                                    : cv::Scalar(55 * tone, 70 * tone, 90 * tone, 255);
      cv::rectangle(rgba, window, glass, cv::FILLED);
      if (!door) {
        const cv::Point a(window.x + window.width / 5, window.y + window.height - 2);
        const cv::Point b(window.x + window.width - 2, window.y + window.height / 4);
        cv::line(rgba, a, b, cv::Scalar(150 * tone, 165 * tone, 180 * tone, 255),
                 std::max(1, window.width / 10), cv::LINE_AA);
        // Mullion and transom.
        const int bar = std::max(1, window.width / 16);
        cv::rectangle(rgba,
                      cv::Rect(window.x + window.width / 2 - bar / 2, window.y, bar, window.height),
                      frame_colour, cv::FILLED);
        cv::rectangle(rgba, cv::Rect(window.x, window.y + window.height / 3, window.width, bar),
                      frame_colour, cv::FILLED);
        // Sill.
        cv::rectangle(
            rgba,
            cv::Rect(window.x - bar, window.y + window.height, window.width + 2 * bar, 2 * bar),
            cv::Scalar(wall[0] * 0.7, wall[1] * 0.7, wall[2] * 0.7, 255), cv::FILLED);
      }
      cv::rectangle(rgba, window, frame_colour, std::max(1, window.width / 14));
    }
  }
  cv::Mat fine = PixelNoise(width_px, height_px, &random);
  AddNoise(fine, 8.0, &rgba);
  return rgba;
}

cv::Mat MakeAsphaltTexture(int width_px, int height_px, unsigned seed) {
  SynthRandom random(seed, 303);
  cv::Mat smooth = WrappingNoise(width_px, height_px, 5, 5, &random);
  cv::Mat rgba(height_px, width_px, CV_8UC4);
  for (int y = 0; y < height_px; ++y) {
    cv::Vec4b* row = rgba.ptr<cv::Vec4b>(y);
    for (int x = 0; x < width_px; ++x) {
      const double v = 78.0 + 10.0 * smooth.at<float>(y, x);
      row[x] = cv::Vec4b(cv::saturate_cast<uchar>(v), cv::saturate_cast<uchar>(v),
                         cv::saturate_cast<uchar>(v * 1.03), 255);
    }
  }
  cv::Mat fine = PixelNoise(width_px, height_px, &random);
  AddNoise(fine, 18.0, &rgba);
  const int specks = width_px * height_px / 150;
  for (int i = 0; i < specks; ++i) {
    const int x = random.UniformInt(0, width_px - 1), y = random.UniformInt(0, height_px - 1);
    const uchar v = static_cast<uchar>(random.Uniform() < 0.5 ? random.UniformInt(150, 220)
                                                              : random.UniformInt(20, 45));
    rgba.at<cv::Vec4b>(y, x) = cv::Vec4b(v, v, v, 255);
  }
  return rgba;
}

cv::Mat RgbaFromImage(const cv::Mat& image) {
  if (image.empty()) return {};
  cv::Mat rgba;
  switch (image.channels()) {
    case 1:
      cv::cvtColor(image, rgba, cv::COLOR_GRAY2RGBA);
      break;
    case 3:
      cv::cvtColor(image, rgba, cv::COLOR_BGR2RGBA);
      break;
    default:
      cv::cvtColor(image, rgba, cv::COLOR_BGRA2RGBA);
      break;
  }
  return rgba;
}

// ---- SceneBuilder ----

int SceneBuilder::AddTexture(const cv::Mat& rgba, const std::string& name, TextureWrap wrap) {
  Texture texture;
  texture.rgba = rgba;
  texture.wrap_s = texture.wrap_t = wrap;
  texture.name = name;
  scene_->textures.push_back(texture);
  return static_cast<int>(scene_->textures.size()) - 1;
}

int SceneBuilder::AddMaterial(int texture, const std::string& name, const Eigen::Vector4d& factor) {
  Material material;
  material.base_color_texture = texture;
  material.base_color_factor = factor;
  material.name = name;
  scene_->materials.push_back(material);
  return static_cast<int>(scene_->materials.size()) - 1;
}

void SceneBuilder::AddQuad(const std::array<Eigen::Vector3d, 4>& corners, int material,
                           double repeat_u, double repeat_v, int subdivide) {
  TriangleMesh& mesh = scene_->mesh;
  const int n = std::max(1, subdivide);
  const int first = static_cast<int>(mesh.vertices.size());
  // Grid (n+1)^2: s along bottom-left -> bottom-right, t along bottom -> top.
  for (int j = 0; j <= n; ++j) {
    const double t = j / static_cast<double>(n);
    for (int i = 0; i <= n; ++i) {
      const double s = i / static_cast<double>(n);
      mesh.vertices.push_back((1 - s) * (1 - t) * corners[0] + s * (1 - t) * corners[1] +
                              s * t * corners[2] + (1 - s) * t * corners[3]);
    }
  }
  auto uv = [&](int i, int j) {
    return Eigen::Vector2f(static_cast<float>(repeat_u * i / n),
                           static_cast<float>(repeat_v * (1.0 - j / static_cast<double>(n))));
  };
  auto index = [&](int i, int j) { return first + j * (n + 1) + i; };
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      // (i,j) bottom-left, (i+1,j) bottom-right, (i+1,j+1) top-right, (i,j+1) top-left.
      mesh.triangles.emplace_back(index(i, j), index(i + 1, j), index(i + 1, j + 1));
      mesh.uvs.push_back({uv(i, j), uv(i + 1, j), uv(i + 1, j + 1)});
      mesh.triangles.emplace_back(index(i, j), index(i + 1, j + 1), index(i, j + 1));
      mesh.uvs.push_back({uv(i, j), uv(i + 1, j + 1), uv(i, j + 1)});
      for (int k = 0; k < 2; ++k) {
        mesh.material.push_back(material);
        mesh.has_uv.push_back(true);
      }
    }
  }
}

void SceneBuilder::AddBox(const Eigen::Vector3d& a, const Eigen::Vector3d& b, int side_material,
                          int top_material, bool with_bottom, double metres_per_repeat) {
  using V = Eigen::Vector3d;
  const V d = b - a;
  auto repeat = [&](double extent) {
    return metres_per_repeat > 0 ? std::max(1.0, std::round(extent / metres_per_repeat)) : 1.0;
  };
  // -Z face, +Z face, +X face, -X face (seen from outside, upright).
  AddQuad({V(b.x(), a.y(), a.z()), V(a.x(), a.y(), a.z()), V(a.x(), b.y(), a.z()),
           V(b.x(), b.y(), a.z())},
          side_material, repeat(d.x()), repeat(d.y()));
  AddQuad({V(a.x(), a.y(), b.z()), V(b.x(), a.y(), b.z()), V(b.x(), b.y(), b.z()),
           V(a.x(), b.y(), b.z())},
          side_material, repeat(d.x()), repeat(d.y()));
  AddQuad({V(b.x(), a.y(), b.z()), V(b.x(), a.y(), a.z()), V(b.x(), b.y(), a.z()),
           V(b.x(), b.y(), b.z())},
          side_material, repeat(d.z()), repeat(d.y()));
  AddQuad({V(a.x(), a.y(), a.z()), V(a.x(), a.y(), b.z()), V(a.x(), b.y(), b.z()),
           V(a.x(), b.y(), a.z())},
          side_material, repeat(d.z()), repeat(d.y()));
  // Top (seen from above, image top towards -Z).
  AddQuad({V(a.x(), b.y(), b.z()), V(b.x(), b.y(), b.z()), V(b.x(), b.y(), a.z()),
           V(a.x(), b.y(), a.z())},
          top_material, repeat(d.x()), repeat(d.z()));
  if (with_bottom) {
    AddQuad({V(b.x(), a.y(), b.z()), V(a.x(), a.y(), b.z()), V(a.x(), a.y(), a.z()),
             V(b.x(), a.y(), a.z())},
            top_material, repeat(d.x()), repeat(d.z()));
  }
}

// ---- Cube room ----

const char* CubeRoomFaceName(int face) {
  static const char* kNames[kCubeRoomFaces] = {"floor", "ceiling", "north",
                                               "east",  "south",   "west"};
  return face >= 0 && face < kCubeRoomFaces ? kNames[face] : "?";
}

Status CubeRoomOptions::Check() const {
  if (!size_m.allFinite() || size_m.minCoeff() <= 0.0) {
    return Status::Error("cube room: size_m must be three positive numbers");
  }
  for (int f = 0; f < kCubeRoomFaces; ++f) {
    if (!repeat[f].allFinite() || repeat[f].minCoeff() <= 0.0) {
      return Status::Error(std::string("cube room: repeat of ") + CubeRoomFaceName(f) +
                           " must be positive");
    }
    if (!images[f].empty() && images[f].depth() != CV_8U) {
      return Status::Error(std::string("cube room: image of ") + CubeRoomFaceName(f) +
                           " is not 8-bit");
    }
  }
  if (procedural_texture_px < 8 || procedural_texture_px > 8192) {
    return Status::Error("cube room: procedural_texture_px must be in [8, 8192]");
  }
  return Status::Ok();
}

Status MakeCubeRoomScene(const CubeRoomOptions& options, Scene* scene) {
  FRESCO_RETURN_IF_ERROR(options.Check());
  *scene = Scene();
  SceneBuilder builder(scene);
  using V = Eigen::Vector3d;
  const double w = 0.5 * options.size_m.x(), h = options.size_m.y(), d = 0.5 * options.size_m.z();
  // Corners per face (bottom-left, bottom-right, top-right, top-left seen from inside).
  const std::array<std::array<V, 4>, kCubeRoomFaces> faces = {{
      {V(-w, 0, d), V(w, 0, d), V(w, 0, -d), V(-w, 0, -d)},    // floor, image top to -Z
      {V(w, h, d), V(-w, h, d), V(-w, h, -d), V(w, h, -d)},    // ceiling
      {V(-w, 0, -d), V(w, 0, -d), V(w, h, -d), V(-w, h, -d)},  // north (-Z)
      {V(w, 0, -d), V(w, 0, d), V(w, h, d), V(w, h, -d)},      // east (+X)
      {V(w, 0, d), V(-w, 0, d), V(-w, h, d), V(w, h, d)},      // south (+Z)
      {V(-w, 0, d), V(-w, 0, -d), V(-w, h, -d), V(-w, h, d)},  // west (-X)
  }};
  for (int f = 0; f < kCubeRoomFaces; ++f) {
    cv::Mat rgba = RgbaFromImage(options.images[f]);
    if (rgba.empty()) {
      rgba = MakeFeatureTexture(options.procedural_texture_px, options.procedural_texture_px,
                                options.seed * 17u + static_cast<unsigned>(f));
    }
    const std::string name =
        options.texture_names[f].empty() ? CubeRoomFaceName(f) : options.texture_names[f];
    const int texture = builder.AddTexture(rgba, name);
    const int material = builder.AddMaterial(texture, CubeRoomFaceName(f));
    builder.AddQuad(faces[f], material, options.repeat[f].x(), options.repeat[f].y());
  }
  return Status::Ok();
}

// ---- Street ----

Status StreetOptions::Check() const {
  if (!(length_m > 1.0) || !(street_width_m > 1.0) || !std::isfinite(length_m) ||
      !std::isfinite(street_width_m)) {
    return Status::Error("street: length_m and street_width_m must be > 1");
  }
  if (buildings_per_side < 1 || buildings_per_side > 100) {
    return Status::Error("street: buildings_per_side must be in [1, 100]");
  }
  if (!(min_height_m > 0.0) || !(max_height_m >= min_height_m) || !std::isfinite(max_height_m)) {
    return Status::Error("street: need 0 < min_height_m <= max_height_m");
  }
  if (texture_px < 16 || texture_px > 4096) {
    return Status::Error("street: texture_px must be in [16, 4096]");
  }
  return Status::Ok();
}

Status MakeStreetScene(const StreetOptions& options, Scene* scene) {
  FRESCO_RETURN_IF_ERROR(options.Check());
  *scene = Scene();
  SceneBuilder builder(scene);
  SynthRandom random(options.seed, 404);
  using V = Eigen::Vector3d;
  const double half_l = 0.5 * options.length_m, half_w = 0.5 * options.street_width_m;
  const double pavement = std::min(2.5, 0.25 * options.street_width_m);
  const double ground_half_l = half_l + 10.0;

  // Road: asphalt with a dashed centre line, one texture tile per 8 m along x.
  const double tile_m = 8.0;
  const double road_w = 2.0 * (half_w - pavement);
  const int road_px_w = 1024;
  const int road_px_h = std::max(16, static_cast<int>(road_px_w * road_w / tile_m));
  cv::Mat road = MakeAsphaltTexture(road_px_w, road_px_h, options.seed);
  const int line_h = std::max(2, static_cast<int>(0.12 / road_w * road_px_h));
  cv::rectangle(road, cv::Rect(road_px_w / 8, road_px_h / 2 - line_h / 2, road_px_w / 2, line_h),
                cv::Scalar(225, 225, 215, 255), cv::FILLED);
  for (int side = -1; side <= 1; side += 2) {
    const int y = road_px_h / 2 + side * (road_px_h / 2 - 2 * line_h);
    cv::rectangle(road, cv::Rect(0, y - line_h / 2, road_px_w, line_h),
                  cv::Scalar(215, 215, 205, 255), cv::FILLED);
  }
  const int road_material = builder.AddMaterial(builder.AddTexture(road, "road"), "road");
  builder.AddQuad(
      {V(-ground_half_l, 0, half_w - pavement), V(ground_half_l, 0, half_w - pavement),
       V(ground_half_l, 0, -(half_w - pavement)), V(-ground_half_l, 0, -(half_w - pavement))},
      road_material, std::round(2.0 * ground_half_l / tile_m), 1.0);

  // Pavements: light paving slabs, 0.5 m each, one texture tile per 2 m.
  cv::Mat slabs = MakeFeatureTexture(512, 512, options.seed + 7);
  {
    cv::Mat grey;
    cv::cvtColor(slabs, grey, cv::COLOR_RGBA2GRAY);
    grey = grey * 0.35 + 110;
    cv::cvtColor(grey, slabs, cv::COLOR_GRAY2RGBA);
    for (int k = 0; k <= 4; ++k) {
      const int p = std::min(511, k * 128);
      cv::line(slabs, cv::Point(p, 0), cv::Point(p, 511), cv::Scalar(70, 70, 70, 255), 3);
      cv::line(slabs, cv::Point(0, p), cv::Point(511, p), cv::Scalar(70, 70, 70, 255), 3);
    }
  }
  const int slab_material = builder.AddMaterial(builder.AddTexture(slabs, "pavement"), "pavement");
  for (int side = -1; side <= 1; side += 2) {
    const double z_in = side * (half_w - pavement), z_out = side * (half_w + 12.0);
    const double z_near = side > 0 ? z_in : z_out, z_far = side > 0 ? z_out : z_in;
    builder.AddQuad({V(-ground_half_l, 0, z_far), V(ground_half_l, 0, z_far),
                     V(ground_half_l, 0, z_near), V(-ground_half_l, 0, z_near)},
                    slab_material, std::round(2.0 * ground_half_l / 2.0),
                    std::max(1.0, std::round(std::abs(z_far - z_near) / 2.0)));
  }

  // Buildings: each row splits the length into random widths with a few alleys.
  cv::Mat roof = MakeAsphaltTexture(256, 256, options.seed + 11);
  const int roof_material = builder.AddMaterial(builder.AddTexture(roof, "roof"), "roof");
  int building = 0;
  for (int side = -1; side <= 1; side += 2) {
    std::vector<double> widths(options.buildings_per_side);
    double total = 0.0;
    for (double& w : widths) total += (w = random.Uniform(0.7, 1.3));
    double x = -half_l;
    for (int b = 0; b < options.buildings_per_side; ++b, ++building) {
      const double span = widths[b] / total * options.length_m;
      const double gap = (b > 0 && random.Uniform() < 0.35) ? random.Uniform(1.0, 2.0) : 0.0;
      const double x0 = x + gap, x1 = x + span;
      x += span;
      if (x1 - x0 < 1.0) continue;
      const double height = random.Uniform(options.min_height_m, options.max_height_m);
      const double depth = random.Uniform(8.0, 12.0);
      const int floors = std::max(1, static_cast<int>(height / 3.2));
      const int columns = std::max(1, static_cast<int>((x1 - x0) / 2.6));
      const int tex_w = options.texture_px;
      const int tex_h = std::clamp(static_cast<int>(tex_w * height / (x1 - x0)), 16, 4096);
      cv::Mat facade = MakeFacadeTexture(tex_w, tex_h, floors, columns,
                                         options.seed * 31u + static_cast<unsigned>(building));
      const std::string name = "facade_" + std::to_string(building);
      const int material = builder.AddMaterial(builder.AddTexture(facade, name), name);
      const double z_front = side * half_w, z_back = side * (half_w + depth);
      builder.AddBox(V(x0, 0, std::min(z_front, z_back)), V(x1, height, std::max(z_front, z_back)),
                     material, roof_material);
    }
  }
  return Status::Ok();
}

// ---- Small test scenes ----

Scene MakeTexturedPlaneScene(double width_m, double height_m, const cv::Mat& texture_rgba) {
  Scene scene;
  SceneBuilder builder(&scene);
  const cv::Mat rgba = texture_rgba.empty() ? MakeCheckerTexture(256, 256, 8, 8) : texture_rgba;
  const int material = builder.AddMaterial(builder.AddTexture(rgba, "plane"), "plane");
  const double w = 0.5 * width_m, h = 0.5 * height_m;
  using V = Eigen::Vector3d;
  builder.AddQuad({V(-w, -h, 0), V(w, -h, 0), V(w, h, 0), V(-w, h, 0)}, material);
  return scene;
}

Scene MakeTexturedCubeScene(double edge_m, const cv::Mat& texture_rgba) {
  Scene scene;
  SceneBuilder builder(&scene);
  const cv::Mat rgba = texture_rgba.empty() ? MakeFeatureTexture(256, 256, 5) : texture_rgba;
  const int material = builder.AddMaterial(builder.AddTexture(rgba, "cube"), "cube");
  const double e = 0.5 * edge_m;
  builder.AddBox(Eigen::Vector3d(-e, -e, -e), Eigen::Vector3d(e, e, e), material, material,
                 /*with_bottom=*/true);
  return scene;
}

}  // namespace fresco
