#include "ui/gl/viewport_gl.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "pipeline/render/renderer.h"
#include "ui/core/group_colour.h"
#include "ui/gl/gl.h"
#include "ui/gl/gl_textures.h"

namespace fresco {
namespace {

const char* kMeshVertex = R"(#version 330 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec2 uv;
layout(location = 2) in float group_id;
layout(location = 3) in float triangle_id;
layout(location = 4) in vec3 normal;
layout(location = 5) in float selected;
layout(location = 6) in vec3 group_rgb;
uniform mat4 view_projection;
out vec2 v_uv;
out vec3 v_position;
out vec3 v_normal;
flat out float v_group;
flat out int v_triangle;
flat out float v_selected;
flat out vec3 v_group_rgb;
void main() {
  v_uv = uv;
  v_position = position;
  v_normal = normal;
  v_group = group_id;
  v_triangle = int(triangle_id + 0.5);
  v_selected = selected;
  v_group_rgb = group_rgb;
  gl_Position = view_projection * vec4(position, 1.0);
})";

const char* kMeshFragment = R"(#version 330 core
in vec2 v_uv;
in vec3 v_position;
in vec3 v_normal;
flat in float v_group;
flat in int v_triangle;
flat in float v_selected;
flat in vec3 v_group_rgb;    // the group's stable colour (ui/core/group_colour.h)
uniform int mode;            // 0 painted, 1 groups, 2 frame projected
uniform sampler2D painted;   // this draw's base buffer
uniform sampler2D frame;     // the current frame
uniform mat4 frame_from_local;  // pixel * z = K [R|t] x (pinhole part)
uniform vec2 frame_size;
uniform vec3 eye;
uniform vec3 picked_rgb, picked_stripe_rgb;  // kPickedRgb, kPickedStripeRgb
// View-dependent layers (painted mode): the four whose cameras are nearest this draw's
// chart, their cameras' centres; per pixel the two nearest the viewer's direction among those
// painted there, the third as the cut-off (unstructured lumigraph weights, as
// view_dependent_render.h).
uniform int layered;  // 0 none, 1 to 4 layers bound
uniform sampler2D layer0;
uniform sampler2D layer1;
uniform sampler2D layer2;
uniform sampler2D layer3;
uniform vec3 layer_centre[4];
layout(location = 0) out vec4 colour;
layout(location = 1) out int triangle;
void main() {
  float shade = 0.55 + 0.45 * abs(dot(normalize(v_normal), normalize(eye - v_position)));
  vec3 base = vec3(0.35);
  if (v_group < 0.0) {
    base = vec3(0.25);
  } else if (mode == 1) {
    base = v_group_rgb * shade;
  } else if (mode == 0) {
    vec4 t = texture(painted, v_uv);
    if (layered > 0) {
      vec3 to_eye = normalize(eye - v_position);
      vec4 l[4];
      l[0] = texture(layer0, v_uv);
      l[1] = texture(layer1, v_uv);
      l[2] = texture(layer2, v_uv);
      l[3] = texture(layer3, v_uv);
      // The painted layers' angles, the three smallest in order (a: angle, i: layer).
      float a[3] = float[3](1e9, 1e9, 1e9);
      int i[3] = int[3](-1, -1, -1);
      for (int k = 0; k < 4; ++k) {
        if (k >= layered || l[k].a <= 0.5) continue;
        float ak = acos(clamp(dot(normalize(layer_centre[k] - v_position), to_eye), -1.0, 1.0));
        if (ak < a[0]) {
          a[2] = a[1], i[2] = i[1], a[1] = a[0], i[1] = i[0], a[0] = ak, i[0] = k;
        } else if (ak < a[1]) {
          a[2] = a[1], i[2] = i[1], a[1] = ak, i[1] = k;
        } else if (ak < a[2]) {
          a[2] = ak, i[2] = k;
        }
      }
      if (i[0] >= 0) {
        int n = i[2] >= 0 ? 3 : (i[1] >= 0 ? 2 : 1);
        float cut = n > 2 ? a[2] : 2.0 * a[n - 1] + 1e-3;
        float w0 = max(0.0, 1.0 - a[0] / cut) / max(a[0], 1e-4);
        float w1 = n > 1 ? max(0.0, 1.0 - a[1] / cut) / max(a[1], 1e-4) : 0.0;
        vec3 c0 = l[i[0]].rgb;
        vec3 c1 = n > 1 ? l[i[1]].rgb : c0;
        t = w0 + w1 > 0.0 ? vec4((w0 * c0 + w1 * c1) / (w0 + w1), 1.0) : vec4(c0, 1.0);
      }
    }
    bool checker = (int(floor(gl_FragCoord.x / 8.0) + floor(gl_FragCoord.y / 8.0)) & 1) == 1;
    base = t.a > 0.5 ? t.rgb : vec3(checker ? 0.32 : 0.26) * shade;
  } else {
    vec4 p = frame_from_local * vec4(v_position, 1.0);
    vec2 px = p.xy / p.z;
    if (p.z > 0.0 && px.x >= -0.5 && px.y >= -0.5 && px.x <= frame_size.x - 0.5 &&
        px.y <= frame_size.y - 0.5)
      base = texture(frame, (px + 0.5) / frame_size).rgb;
    else
      base = vec3(0.3) * shade;
  }
  // Picked triangles in white and black stripes (group_colour.h: unlike every group colour),
  // triangles of selected groups tinted cyan (striped).
  bool stripe = (int(floor((gl_FragCoord.x + gl_FragCoord.y) / 6.0)) & 1) == 1;
  if (v_selected > 1.5) base = mix(base, vec3(0.2, 0.9, 1.0), stripe ? 0.65 : 0.4);
  else if (v_selected > 0.5) base = stripe ? picked_rgb : picked_stripe_rgb;
  colour = vec4(base, 1.0);
  triangle = v_triangle;
})";

const char* kLineVertex = R"(#version 330 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 rgb;
uniform mat4 view_projection;
out vec3 v_rgb;
void main() {
  v_rgb = rgb;
  gl_Position = view_projection * vec4(position, 1.0);
})";

const char* kLineFragment = R"(#version 330 core
in vec3 v_rgb;
layout(location = 0) out vec4 colour;
layout(location = 1) out int triangle;
void main() {
  colour = vec4(v_rgb, 1.0);
  triangle = -1;
})";

GLuint Compile(GLenum type, const char* source) {
  const GLuint shader = glCreateShader(type);
  glShaderSource(shader, 1, &source, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048];
    glGetShaderInfoLog(shader, sizeof log, nullptr, log);
    std::fprintf(stderr, "fresco gui: shader: %s\n", log);
  }
  return shader;
}

GLuint Link(const char* vertex, const char* fragment) {
  const GLuint program = glCreateProgram();
  const GLuint vs = Compile(GL_VERTEX_SHADER, vertex), fs = Compile(GL_FRAGMENT_SHADER, fragment);
  glAttachShader(program, vs);
  glAttachShader(program, fs);
  glLinkProgram(program);
  glDeleteShader(vs);
  glDeleteShader(fs);
  return program;
}

// Column-major 4x4 for GL.
using Mat4 = Eigen::Matrix4f;

Mat4 Perspective(float fov_y_rad, float aspect, float near, float far) {
  const float f = 1.0f / std::tan(fov_y_rad / 2);
  Mat4 m = Mat4::Zero();
  m(0, 0) = f / aspect;
  m(1, 1) = f;
  m(2, 2) = (far + near) / (near - far);
  m(2, 3) = 2 * far * near / (near - far);
  m(3, 2) = -1;
  return m;
}

Mat4 LookAt(const Eigen::Vector3f& eye, const Eigen::Vector3f& target, const Eigen::Vector3f& up) {
  const Eigen::Vector3f f = (target - eye).normalized();
  const Eigen::Vector3f s = f.cross(up).normalized();
  const Eigen::Vector3f u = s.cross(f);
  Mat4 m = Mat4::Identity();
  m.block<1, 3>(0, 0) = s.transpose();
  m.block<1, 3>(1, 0) = u.transpose();
  m.block<1, 3>(2, 0) = -f.transpose();
  m(0, 3) = -s.dot(eye);
  m(1, 3) = -u.dot(eye);
  m(2, 3) = f.dot(eye);
  return m;
}

struct Vertex {
  float position[3];
  float uv[2];
  float group;
  float triangle;
  float normal[3];
  float selected;  // 0, 1 (triangle selected), 2 (its group selected)
  float group_rgb[3];
};

struct LineVertex {
  float position[3];
  float rgb[3];
};

// The orbit camera, in the scene's local frame.
struct OrbitView {
  Eigen::Vector3f eye;
  Mat4 view_projection;
  float radius = 0;  // of the model's bounding sphere
};

// The orbit camera, in the scene's local frame; fitted to the model on first use.
OrbitView PlaceOrbit(const RunnerSnapshot& snapshot, ViewportView* view, int width, int height) {
  const SessionGeometry& geo = *snapshot.geometry;
  const Scene& scene = geo.painted_layout;
  Eigen::Vector3d lo, hi;
  scene.Bounds(&lo, &hi);
  const Eigen::Vector3f centre = (0.5 * (lo + hi)).cast<float>();
  const float radius = std::max(1e-3f, static_cast<float>(0.5 * (hi - lo).norm()));
  const float fov = 50.0f * static_cast<float>(M_PI) / 180;
  if (!view->target_set) {
    for (int k = 0; k < 3; ++k) view->target[k] = centre[k];
    view->target_set = true;
  }
  if (view->distance_m <= 0) view->distance_m = 1.3f * radius / std::sin(fov / 2);
  const float yaw = view->yaw_deg * static_cast<float>(M_PI) / 180;
  const float pitch = view->pitch_deg * static_cast<float>(M_PI) / 180;
  const Eigen::Vector3f target(view->target[0], view->target[1], view->target[2]);
  if (view->orbit_geometry_version != snapshot.geometry_version &&
      (!geo.path.empty() || !snapshot.FirstLivePath().empty())) {
    view->orbit = OrbitFrameFromPoses(geo.path.empty() ? snapshot.FirstLivePath() : geo.path);
    view->orbit_geometry_version = snapshot.geometry_version;
  }
  OrbitView orbit;
  orbit.eye = target + view->distance_m * OrbitEyeDirection(view->orbit, yaw, pitch);
  const float near = std::max(1e-3f, 0.01f * view->distance_m);
  orbit.view_projection = Perspective(fov, static_cast<float>(width) / height, near,
                                      10.0f * (view->distance_m + radius)) *
                          LookAt(orbit.eye, target, view->orbit.up);
  orbit.radius = radius;
  return orbit;
}

// The current frame's camera (its stream's, when the project has several).
const Camera& FrameCamera(const RunnerSnapshot& snapshot) {
  const SessionGeometry& geo = *snapshot.geometry;
  return static_cast<size_t>(snapshot.stream) < geo.stream_cameras.size()
             ? geo.stream_cameras[snapshot.stream]
             : geo.camera;
}

// The frame's projection for the preview: pixel * z = K [R|t] x_local (pinhole part).
Eigen::Matrix4f FrameFromLocal(const Camera& cam, const Rigid3d& cam_from_local) {
  Eigen::Matrix4f frame_from_local = Eigen::Matrix4f::Zero();
  Eigen::Matrix3d K;
  K << cam.fx, 0, cam.cx, 0, cam.fy, cam.cy, 0, 0, 1;
  frame_from_local.block<3, 3>(0, 0) = (K * cam_from_local.RotationMatrix()).cast<float>();
  frame_from_local.block<3, 1>(0, 3) = (K * cam_from_local.translation).cast<float>();
  frame_from_local(3, 3) = 1;
  return frame_from_local;
}

void AddLine(const Eigen::Vector3f& a, const Eigen::Vector3f& b, float r, float g, float bl,
             std::vector<LineVertex>* lines) {
  lines->push_back({{a.x(), a.y(), a.z()}, {r, g, bl}});
  lines->push_back({{b.x(), b.y(), b.z()}, {r, g, bl}});
}

// Each stream's path, given and live (stream 0 grey, the others in their own hues).
void AddPaths(const RunnerSnapshot& snapshot, std::vector<LineVertex>* lines) {
  const SessionGeometry& geo = *snapshot.geometry;
  const Scene& scene = geo.painted_layout;
  // The return type spelled out: deduced, it would be an Eigen expression over a temporary.
  auto centre_of = [&](const Rigid3d& cam_from_world) -> Eigen::Vector3f {
    return CamFromLocal(scene, cam_from_world).Centre().cast<float>();
  };
  static constexpr float kStreamColours[][3] = {
      {0.6f, 0.6f, 0.65f}, {0.3f, 0.75f, 1.0f}, {1.0f, 0.45f, 0.8f}, {0.45f, 0.95f, 0.45f}};
  std::vector<std::pair<const std::vector<Rigid3d>*, size_t>> paths;  // (path, stream)
  if (geo.stream_paths.empty()) paths.push_back({&geo.path, 0});
  for (size_t s = 0; s < geo.stream_paths.size(); ++s) paths.push_back({&geo.stream_paths[s], s});
  for (size_t s = 0; s < snapshot.live_paths.size(); ++s)
    paths.push_back({&snapshot.live_paths[s], s});
  for (const auto& [path, stream] : paths) {
    const float* colour = kStreamColours[stream % 4];
    for (size_t i = 1; i < path->size(); ++i)
      AddLine(centre_of((*path)[i - 1]), centre_of((*path)[i]), colour[0], colour[1], colour[2],
              lines);
  }
}

// COLMAP's path (orange) and each flagged frame's offset from its given centre (red).
void AddPoseCheck(const ViewportView& view, const Scene& scene, std::vector<LineVertex>* lines) {
  auto local_of = [&](const Eigen::Vector3d& world) -> Eigen::Vector3f {
    return (world - scene.origin_in_world).cast<float>();
  };
  for (size_t i = 1; i < view.pose_check.size(); ++i)
    AddLine(local_of(view.pose_check[i - 1].colmap), local_of(view.pose_check[i].colmap), 1.0f,
            0.55f, 0.1f, lines);
  for (const ViewportView::PoseCheckMark& mark : view.pose_check)
    if (mark.flagged)
      AddLine(local_of(mark.given), local_of(mark.colmap), 1.0f, 0.15f, 0.15f, lines);
}

// The current camera's frustum (yellow), `depth` deep.
void AddFrustum(const Camera& cam, const Rigid3d& cam_from_local, float depth,
                std::vector<LineVertex>* lines) {
  const Rigid3d local_from_cam = cam_from_local.Inverse();
  const Eigen::Vector3f c = local_from_cam.translation.cast<float>();
  Eigen::Vector3f corners[4];
  const double px[4][2] = {{-0.5, -0.5},
                           {cam.width - 0.5, -0.5},
                           {cam.width - 0.5, cam.height - 0.5},
                           {-0.5, cam.height - 0.5}};
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector3d ray((px[k][0] - cam.cx) / cam.fx, (px[k][1] - cam.cy) / cam.fy, 1.0);
    corners[k] = (local_from_cam * (ray * depth)).cast<float>();
  }
  for (int k = 0; k < 4; ++k) {
    AddLine(c, corners[k], 1.0f, 0.85f, 0.1f, lines);
    AddLine(corners[k], corners[(k + 1) % 4], 1.0f, 0.85f, 0.1f, lines);
  }
}

// Lines: the path (grey), COLMAP's path after a pose verification (orange, flagged frames'
// offsets red), the current camera's frustum (yellow).
std::vector<LineVertex> OverlayLines(const RunnerSnapshot& snapshot, const ViewportView& view,
                                     const Camera& cam, const Rigid3d& cam_from_local,
                                     float radius) {
  std::vector<LineVertex> lines;
  if (view.show_path) AddPaths(snapshot, &lines);
  if (view.show_pose_check && !view.pose_check.empty())
    AddPoseCheck(view, snapshot.geometry->painted_layout, &lines);
  if (view.show_frustum && snapshot.has_pose)
    AddFrustum(cam, cam_from_local, 0.25f * radius, &lines);
  return lines;
}

}  // namespace

struct GlViewport::Impl {
  GLuint mesh_program = 0, line_program = 0;
  GLuint vao = 0, vbo = 0, line_vao = 0, line_vbo = 0;
  GLuint fbo = 0, colour = 0, ids = 0, depth = 0;
  int width = 0, height = 0;
  uint64_t geometry_version = ~0ull;
  std::set<int> selection, selected_groups;
  // Draw ranges: buffer b's triangles are vertices [first[b], first[b] + count[b]).
  std::vector<int> first, count;
  std::vector<Eigen::Vector3f> centre;  // per buffer, the mean of its vertices (local)
  int ungrouped_first = 0, ungrouped_count = 0;
  GlTextures textures;
  bool built = false;

  // Binds the (up to) four view-dependent layers whose cameras are nearest the direction from
  // buffer b's centre to the eye (texture units 2 to 5) and sets the shader's layer uniforms;
  // the shader chooses among them per pixel.
  void BindNearestLayers(const RunnerSnapshot& snapshot, size_t b, const Eigen::Vector3f& eye);
  static constexpr int kLayersBound = 4;
  // The layer uniforms' locations (looked up once, after linking) and the sort's scratch.
  GLint layered_at = -1, layer_centre_at[kLayersBound] = {-1, -1, -1, -1};
  std::vector<std::pair<float, size_t>> nearest_layers;

  // Binds the offscreen framebuffer (colour and triangle ids) and clears it.
  void BeginDraw(int w, int h);
  // Draws the mesh, buffer by buffer, as `view` shows it (painted, groups or the frame
  // projected with `frame_from_local`, for a frame from `frame_camera`).
  void DrawMesh(const RunnerSnapshot& snapshot, const ViewportView& view, const OrbitView& orbit,
                const Camera& frame_camera, const Eigen::Matrix4f& frame_from_local);
  // Draws `lines` over the model.
  void DrawLines(const std::vector<LineVertex>& lines, const Mat4& view_projection);

  void Build() {
    mesh_program = Link(kMeshVertex, kMeshFragment);
    layered_at = glGetUniformLocation(mesh_program, "layered");
    for (int i = 0; i < kLayersBound; ++i)
      layer_centre_at[i] =
          glGetUniformLocation(mesh_program, ("layer_centre[" + std::to_string(i) + "]").c_str());
    line_program = Link(kLineVertex, kLineFragment);
    glGenVertexArrays(1, &vao);
    glGenBuffers(1, &vbo);
    glBindVertexArray(vao);
    glBindBuffer(GL_ARRAY_BUFFER, vbo);
    const GLsizei stride = sizeof(Vertex);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, stride, (void*)offsetof(Vertex, position));
    glVertexAttribPointer(1, 2, GL_FLOAT, GL_FALSE, stride, (void*)offsetof(Vertex, uv));
    glVertexAttribPointer(2, 1, GL_FLOAT, GL_FALSE, stride, (void*)offsetof(Vertex, group));
    glVertexAttribPointer(3, 1, GL_FLOAT, GL_FALSE, stride, (void*)offsetof(Vertex, triangle));
    glVertexAttribPointer(4, 3, GL_FLOAT, GL_FALSE, stride, (void*)offsetof(Vertex, normal));
    glVertexAttribPointer(5, 1, GL_FLOAT, GL_FALSE, stride, (void*)offsetof(Vertex, selected));
    glVertexAttribPointer(6, 3, GL_FLOAT, GL_FALSE, stride, (void*)offsetof(Vertex, group_rgb));
    for (int a = 0; a < 7; ++a) glEnableVertexAttribArray(a);
    glGenVertexArrays(1, &line_vao);
    glGenBuffers(1, &line_vbo);
    glBindVertexArray(line_vao);
    glBindBuffer(GL_ARRAY_BUFFER, line_vbo);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(LineVertex),
                          (void*)offsetof(LineVertex, position));
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, sizeof(LineVertex),
                          (void*)offsetof(LineVertex, rgb));
    glEnableVertexAttribArray(0);
    glEnableVertexAttribArray(1);
    glBindVertexArray(0);
    built = true;
  }

  void Resize(int w, int h) {
    if (w == width && h == height && fbo) return;
    if (fbo) {
      glDeleteFramebuffers(1, &fbo);
      glDeleteTextures(1, &colour);
      glDeleteTextures(1, &ids);
      glDeleteRenderbuffers(1, &depth);
    }
    width = w, height = h;
    glGenFramebuffers(1, &fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glGenTextures(1, &colour);
    glBindTexture(GL_TEXTURE_2D, colour);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, w, h, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, colour, 0);
    glGenTextures(1, &ids);
    glBindTexture(GL_TEXTURE_2D, ids);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_R32I, w, h, 0, GL_RED_INTEGER, GL_INT, nullptr);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_TEXTURE_2D, ids, 0);
    glGenRenderbuffers(1, &depth);
    glBindRenderbuffer(GL_RENDERBUFFER, depth);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, w, h);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
  }

  void Upload(const SessionGeometry& geo, const std::set<int>& selected,
              const std::set<int>& groups_selected) {
    const TriangleMesh& mesh = geo.painted_layout.mesh;
    const int num_buffers = static_cast<int>(geo.groups.size());
    std::vector<std::vector<int>> by_buffer(num_buffers + 1);
    for (int t = 0; t < mesh.NumTriangles(); ++t) {
      const int b =
          t < static_cast<int>(geo.buffer_of_triangle.size()) ? geo.buffer_of_triangle[t] : -1;
      by_buffer[b >= 0 ? b : num_buffers].push_back(t);
    }
    std::vector<Vertex> vertices;
    vertices.reserve(3 * mesh.NumTriangles());
    first.assign(num_buffers, 0);
    count.assign(num_buffers, 0);
    centre.assign(num_buffers, Eigen::Vector3f::Zero());
    for (int b = 0; b <= num_buffers; ++b) {
      const int start = static_cast<int>(vertices.size());
      const std::array<float, 3> rgb =
          GroupColour(b < num_buffers ? StableGroupKey(geo.groups[b]) : -1);
      const bool group_selected = groups_selected.count(b) > 0;
      for (int t : by_buffer[b]) {
        const Eigen::Vector3d n = mesh.Normal(t);
        for (int k = 0; k < 3; ++k) {
          const Eigen::Vector3d p = mesh.Corner(t, k);
          Vertex v{};
          v.position[0] = static_cast<float>(p.x());
          v.position[1] = static_cast<float>(p.y());
          v.position[2] = static_cast<float>(p.z());
          if (t < static_cast<int>(mesh.uvs.size())) {
            v.uv[0] = mesh.uvs[t][k].x();
            v.uv[1] = mesh.uvs[t][k].y();
          }
          v.group = b < num_buffers ? static_cast<float>(b) : -1.0f;
          v.triangle = static_cast<float>(t);
          v.normal[0] = static_cast<float>(n.x());
          v.normal[1] = static_cast<float>(n.y());
          v.normal[2] = static_cast<float>(n.z());
          v.selected = selected.count(t) ? 1.0f : group_selected ? 2.0f : 0.0f;
          for (int c = 0; c < 3; ++c) v.group_rgb[c] = rgb[c];
          vertices.push_back(v);
        }
      }
      if (b < num_buffers) {
        first[b] = start;
        count[b] = static_cast<int>(vertices.size()) - start;
        Eigen::Vector3f sum = Eigen::Vector3f::Zero();
        for (int i = start; i < static_cast<int>(vertices.size()); ++i)
          sum += Eigen::Vector3f(vertices[i].position[0], vertices[i].position[1],
                                 vertices[i].position[2]);
        centre[b] = count[b] > 0 ? Eigen::Vector3f(sum / count[b]) : sum;
      } else {
        ungrouped_first = start;
        ungrouped_count = static_cast<int>(vertices.size()) - start;
      }
    }
    glBindBuffer(GL_ARRAY_BUFFER, vbo);
    glBufferData(GL_ARRAY_BUFFER, vertices.size() * sizeof(Vertex), vertices.data(),
                 GL_STATIC_DRAW);
  }
};

void GlViewport::Impl::BindNearestLayers(const RunnerSnapshot& snapshot, size_t b,
                                         const Eigen::Vector3f& eye) {
  const std::vector<RunnerSnapshot::LayerImages>& layers = *snapshot.layers;
  const Eigen::Vector3f c = centre[b], to_eye = (eye - c).normalized();
  std::vector<std::pair<float, size_t>>& near = nearest_layers;
  near.clear();
  for (size_t k = 0; k < layers.size(); ++k) {
    if (b >= layers[k].bgra.size()) continue;
    const float dot = (layers[k].centre_local - c).normalized().dot(to_eye);
    near.emplace_back(std::acos(std::clamp(dot, -1.0f, 1.0f)), k);
  }
  std::sort(near.begin(), near.end());
  const int bound = static_cast<int>(std::min<size_t>(kLayersBound, near.size()));
  glUniform1i(layered_at, bound);
  if (bound == 0) return;
  for (int i = 0; i < bound; ++i) {
    const RunnerSnapshot::LayerImages& layer = layers[near[i].second];
    glActiveTexture(GL_TEXTURE2 + i);
    glBindTexture(GL_TEXTURE_2D,
                  static_cast<GLuint>(reinterpret_cast<intptr_t>(textures.Get(
                      "layer/" + std::to_string(near[i].second) + "/" + std::to_string(b),
                      layer.bgra[b], snapshot.painted_version))));
    const Eigen::Vector3f& at = layer.centre_local;
    glUniform3f(layer_centre_at[i], at.x(), at.y(), at.z());
  }
  glActiveTexture(GL_TEXTURE0);
}

GlViewport::GlViewport() : impl_(std::make_unique<Impl>()) {}

GlViewport::~GlViewport() {
  if (!impl_->built) return;
  glDeleteProgram(impl_->mesh_program);
  glDeleteProgram(impl_->line_program);
  glDeleteBuffers(1, &impl_->vbo);
  glDeleteBuffers(1, &impl_->line_vbo);
  glDeleteVertexArrays(1, &impl_->vao);
  glDeleteVertexArrays(1, &impl_->line_vao);
  if (impl_->fbo) {
    glDeleteFramebuffers(1, &impl_->fbo);
    glDeleteTextures(1, &impl_->colour);
    glDeleteTextures(1, &impl_->ids);
    glDeleteRenderbuffers(1, &impl_->depth);
  }
}

void GlViewport::Impl::BeginDraw(int w, int h) {
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  const GLenum outputs[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
  glDrawBuffers(2, outputs);
  glViewport(0, 0, w, h);
  const float background[4] = {0.12f, 0.12f, 0.14f, 1.0f};
  const GLint no_triangle[4] = {-1, -1, -1, -1};
  glClearBufferfv(GL_COLOR, 0, background);
  glClearBufferiv(GL_COLOR, 1, no_triangle);
  glClear(GL_DEPTH_BUFFER_BIT);
  glEnable(GL_DEPTH_TEST);
  glDisable(GL_BLEND);
  glDisable(GL_CULL_FACE);
  glDisable(GL_SCISSOR_TEST);
}

void GlViewport::Impl::DrawMesh(const RunnerSnapshot& snapshot, const ViewportView& view,
                                const OrbitView& orbit, const Camera& frame_camera,
                                const Eigen::Matrix4f& frame_from_local) {
  const Camera& cam = frame_camera;
  const Eigen::Vector3f& eye = orbit.eye;
  glUseProgram(mesh_program);
  glUniformMatrix4fv(glGetUniformLocation(mesh_program, "view_projection"), 1, GL_FALSE,
                     orbit.view_projection.data());
  glUniformMatrix4fv(glGetUniformLocation(mesh_program, "frame_from_local"), 1, GL_FALSE,
                     frame_from_local.data());
  glUniform2f(glGetUniformLocation(mesh_program, "frame_size"), static_cast<float>(cam.width),
              static_cast<float>(cam.height));
  glUniform3f(glGetUniformLocation(mesh_program, "eye"), eye.x(), eye.y(), eye.z());
  glUniform1i(glGetUniformLocation(mesh_program, "mode"), static_cast<int>(view.mode));
  glUniform3f(glGetUniformLocation(mesh_program, "picked_rgb"), kPickedRgb[0], kPickedRgb[1],
              kPickedRgb[2]);
  glUniform3f(glGetUniformLocation(mesh_program, "picked_stripe_rgb"), kPickedStripeRgb[0],
              kPickedStripeRgb[1], kPickedStripeRgb[2]);
  glUniform1i(glGetUniformLocation(mesh_program, "painted"), 0);
  glUniform1i(glGetUniformLocation(mesh_program, "frame"), 1);
  glActiveTexture(GL_TEXTURE1);
  const bool projected = view.mode == ViewportView::Mode::kProjected && snapshot.has_pose &&
                         !snapshot.frame_bgr.empty();
  GLuint frame_texture = 0;
  if (projected)
    frame_texture = static_cast<GLuint>(
        reinterpret_cast<intptr_t>(textures.Get("frame", snapshot.frame_bgr, snapshot.version)));
  glBindTexture(GL_TEXTURE_2D, frame_texture);
  glActiveTexture(GL_TEXTURE0);
  glBindVertexArray(vao);
  for (int i = 0; i < kLayersBound; ++i)
    glUniform1i(glGetUniformLocation(mesh_program, ("layer" + std::to_string(i)).c_str()), 2 + i);
  const bool layered = view.mode == ViewportView::Mode::kPainted && view.view_layers &&
                       snapshot.layers && !snapshot.layers->empty();
  glUniform1i(layered_at, 0);
  for (size_t b = 0; b < first.size(); ++b) {
    GLuint texture = 0;
    if (snapshot.painted && b < snapshot.painted->size())
      texture = static_cast<GLuint>(reinterpret_cast<intptr_t>(textures.Get(
          "buffer/" + std::to_string(b), (*snapshot.painted)[b], snapshot.painted_version)));
    if (layered && b < centre.size()) BindNearestLayers(snapshot, b, eye);
    glBindTexture(GL_TEXTURE_2D, texture);
    if (count[b] > 0) glDrawArrays(GL_TRIANGLES, first[b], count[b]);
  }
  if (ungrouped_count > 0) glDrawArrays(GL_TRIANGLES, ungrouped_first, ungrouped_count);
}

void GlViewport::Impl::DrawLines(const std::vector<LineVertex>& lines,
                                 const Mat4& view_projection) {
  glDisable(GL_DEPTH_TEST);  // drawn over the model: a path inside a room stays visible
  glUseProgram(line_program);
  glUniformMatrix4fv(glGetUniformLocation(line_program, "view_projection"), 1, GL_FALSE,
                     view_projection.data());
  glBindVertexArray(line_vao);
  glBindBuffer(GL_ARRAY_BUFFER, line_vbo);
  glBufferData(GL_ARRAY_BUFFER, lines.size() * sizeof(LineVertex), lines.data(), GL_STREAM_DRAW);
  glDrawArrays(GL_LINES, 0, static_cast<GLsizei>(lines.size()));
}

ImTextureID GlViewport::Render(const RunnerSnapshot& snapshot, const AppState& state,
                               ViewportView* view, int width, int height) {
  Impl& m = *impl_;
  if (!m.built) m.Build();
  m.Resize(width, height);
  const SessionGeometry& geo = *snapshot.geometry;
  if (m.geometry_version != snapshot.geometry_version || m.selection != state.selected_triangles ||
      m.selected_groups != state.selected_groups) {
    m.Upload(geo, state.selected_triangles, state.selected_groups);
    m.geometry_version = snapshot.geometry_version;
    m.selection = state.selected_triangles;
    m.selected_groups = state.selected_groups;
  }
  const OrbitView orbit = PlaceOrbit(snapshot, view, width, height);

  GLint previous_fbo = 0, previous_viewport[4];
  glGetIntegerv(GL_FRAMEBUFFER_BINDING, &previous_fbo);
  glGetIntegerv(GL_VIEWPORT, previous_viewport);
  m.BeginDraw(width, height);
  const Rigid3d cam_from_local = CamFromLocal(geo.painted_layout, snapshot.cam_from_world);
  const Camera& cam = FrameCamera(snapshot);
  m.DrawMesh(snapshot, *view, orbit, cam, FrameFromLocal(cam, cam_from_local));
  const std::vector<LineVertex> lines =
      OverlayLines(snapshot, *view, cam, cam_from_local, orbit.radius);
  if (!lines.empty()) m.DrawLines(lines, orbit.view_projection);
  glBindVertexArray(0);
  glUseProgram(0);
  glDisable(GL_DEPTH_TEST);
  glBindFramebuffer(GL_FRAMEBUFFER, previous_fbo);
  glViewport(previous_viewport[0], previous_viewport[1], previous_viewport[2],
             previous_viewport[3]);
  m.textures.EndFrame();
  return reinterpret_cast<ImTextureID>(static_cast<intptr_t>(m.colour));
}

int GlViewport::Pick(int x, int y) {
  Impl& m = *impl_;
  if (!m.fbo || x < 0 || y < 0 || x >= m.width || y >= m.height) return -1;
  GLint previous_fbo = 0;
  glGetIntegerv(GL_FRAMEBUFFER_BINDING, &previous_fbo);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, m.fbo);
  glReadBuffer(GL_COLOR_ATTACHMENT1);
  GLint id = -1;
  glReadPixels(x, y, 1, 1, GL_RED_INTEGER, GL_INT, &id);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, previous_fbo);
  return id;
}

}  // namespace fresco
