// glTF 2.0 scenes. Loading: tinygltf parses the file (and decodes images); everything it
// does not check (indices, accessor bounds, strides, sparse accessors, finite positions
// and UVs, missing images) is validated here while the node hierarchy is flattened into one
// triangle mesh in double precision. Saving: the JSON is written with nlohmann::json, the
// geometry into one .bin and each texture into its own PNG, every file atomically.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <string_view>
#include <tuple>

#include <tiny_gltf.h>
#include <Eigen/Geometry>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "pipeline/core/atomic_file.h"
#include "pipeline/core/image_codecs.h"
#include "pipeline/core/scene.h"

namespace fresco {
namespace {

// Fresco's own extension for view-dependent layers (scene.h, ViewLayerTextures).
constexpr const char* kViewLayersExtension = "FRESCO_view_layers";

namespace fs = std::filesystem;

// Joins the non-empty lines of `text` with "; " (tinygltf reports several lines).
std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
    if (!line.empty()) lines.push_back(line);
  }
  return lines;
}
std::string OneLine(const std::string& text) {
  std::string out;
  for (const std::string& line : Lines(text)) out += (out.empty() ? "" : "; ") + line;
  return out;
}

int NumComponents(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR:
      return 1;
    case TINYGLTF_TYPE_VEC2:
      return 2;
    case TINYGLTF_TYPE_VEC3:
      return 3;
    case TINYGLTF_TYPE_VEC4:
      return 4;
    default:
      return -1;
  }
}

int ComponentSize(int component_type) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return 4;
    default:
      return -1;
  }
}

bool IsIndexType(int component_type) {
  return component_type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
         component_type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT ||
         component_type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
}

// One component, little-endian (glTF's byte order, and the host's on supported platforms).
double ReadComponent(const unsigned char* p, int component_type) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
      return static_cast<int8_t>(*p);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return *p;
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      int16_t v;
      std::memcpy(&v, p, 2);
      return v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      uint16_t v;
      std::memcpy(&v, p, 2);
      return v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
      uint32_t v;
      std::memcpy(&v, p, 4);
      return v;
    }
    case TINYGLTF_COMPONENT_TYPE_FLOAT: {
      float v;
      std::memcpy(&v, p, 4);
      return v;
    }
    default:
      return 0.0;
  }
}

// glTF's normalized integer -> float rules.
double Normalize(double v, int component_type) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
      return std::max(v / 127.0, -1.0);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return v / 255.0;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
      return std::max(v / 32767.0, -1.0);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return v / 65535.0;
    default:
      return v;
  }
}

TextureWrap WrapFromGltf(int mode, bool* known) {
  *known = true;
  switch (mode) {
    case TINYGLTF_TEXTURE_WRAP_REPEAT:
      return TextureWrap::kRepeat;
    case TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE:
      return TextureWrap::kClampToEdge;
    case TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT:
      return TextureWrap::kMirroredRepeat;
    default:
      *known = false;
      return TextureWrap::kRepeat;
  }
}

int WrapToGltf(TextureWrap wrap) {
  switch (wrap) {
    case TextureWrap::kClampToEdge:
      return TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
    case TextureWrap::kMirroredRepeat:
      return TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT;
    case TextureWrap::kRepeat:
      break;
  }
  return TINYGLTF_TEXTURE_WRAP_REPEAT;
}

// Decoded image (any component count, 8 or 16 bits) -> CV_8UC4 RGBA. Empty `problem` = ok.
cv::Mat ImageToRgba8(const tinygltf::Image& image, std::string* problem) {
  const int w = image.width, h = image.height, c = image.component;
  const int bytes = image.bits == 16 ? 2 : image.bits == 8 ? 1 : 0;
  if (image.image.empty() || w <= 0 || h <= 0) {
    *problem = "was not loaded (missing file or undecodable image)";
    return {};
  }
  if (bytes == 0 || c < 1 || c > 4) {
    *problem = "has an unsupported format (" + std::to_string(c) + " components, " +
               std::to_string(image.bits) + " bits)";
    return {};
  }
  if (image.image.size() != static_cast<size_t>(w) * h * c * bytes) {
    *problem = "has " + std::to_string(image.image.size()) + " bytes of pixels, expected " +
               std::to_string(static_cast<size_t>(w) * h * c * bytes);
    return {};
  }
  cv::Mat rgba(h, w, CV_8UC4);
  const unsigned char* src = image.image.data();
  auto value = [&](size_t i) -> uint8_t {
    if (bytes == 1) return src[i];
    uint16_t v;
    std::memcpy(&v, src + 2 * i, 2);
    return static_cast<uint8_t>((static_cast<uint32_t>(v) * 255u + 32767u) / 65535u);
  };
  for (int y = 0; y < h; ++y) {
    cv::Vec4b* row = rgba.ptr<cv::Vec4b>(y);
    for (int x = 0; x < w; ++x) {
      const size_t i = (static_cast<size_t>(y) * w + x) * c;
      switch (c) {
        case 1:
          row[x] = {value(i), value(i), value(i), 255};
          break;
        case 2:
          row[x] = {value(i), value(i), value(i), value(i + 1)};
          break;
        case 3:
          row[x] = {value(i), value(i + 1), value(i + 2), 255};
          break;
        default:
          row[x] = {value(i), value(i + 1), value(i + 2), value(i + 3)};
          break;
      }
    }
  }
  return rgba;
}

// Values of one accessor, as doubles (normalization applied), row-major (count, components).
struct AccessorValues {
  size_t count = 0;
  int components = 0;
  int component_type = 0;
  std::vector<double> values;
  double At(size_t i, int c) const { return values[i * components + c]; }
};

class GltfLoader {
 public:
  GltfLoader(const std::string& path, const SceneLoadOptions& options, const tinygltf::Model& model,
             Scene* scene)
      : path_(path), options_(options), model_(model), scene_(*scene) {}

  Status Load() {
    for (const std::string& ext : model_.extensionsRequired) {
      if (ext != "KHR_mesh_quantization" && ext != "KHR_materials_unlit") {
        return Error("requires glTF extension " + ext + ", which is not supported");
      }
    }
    for (const std::string& ext : model_.extensionsUsed) {
      if (ext != "KHR_mesh_quantization" && ext != "KHR_materials_unlit" &&
          ext != kViewLayersExtension) {
        scene_.warnings.push_back("glTF extension " + ext + " ignored");
      }
    }
    FRESCO_RETURN_IF_ERROR(CheckMaterials());
    on_path_.assign(model_.nodes.size(), 0);
    std::vector<int> roots;
    if (!model_.scenes.empty()) {
      int scene_index = model_.defaultScene;
      if (scene_index < 0 || scene_index >= static_cast<int>(model_.scenes.size())) {
        scene_index = 0;
      }
      roots = model_.scenes[scene_index].nodes;
    } else {
      std::vector<char> is_child(model_.nodes.size(), 0);
      for (const auto& node : model_.nodes) {
        for (int child : node.children) {
          if (child >= 0 && child < static_cast<int>(is_child.size())) is_child[child] = 1;
        }
      }
      for (size_t n = 0; n < model_.nodes.size(); ++n) {
        if (!is_child[n]) roots.push_back(static_cast<int>(n));
      }
    }
    if (model_.scenes.empty() && model_.nodes.empty()) {
      // No hierarchy at all: every mesh once, untransformed.
      for (size_t m = 0; m < model_.meshes.size(); ++m) {
        FRESCO_RETURN_IF_ERROR(AddMesh(static_cast<int>(m), Eigen::Matrix4d::Identity()));
      }
    }
    for (int root : roots) {
      FRESCO_RETURN_IF_ERROR(VisitNode(root, Eigen::Matrix4d::Identity(), 0));
    }
    TriangleMesh& mesh = scene_.mesh;
    if (mesh.triangles.empty()) {
      return Error("no triangles (" + std::to_string(scene_.skipped_primitives) +
                   " points/lines primitives skipped, " +
                   std::to_string(scene_.dropped_degenerate) + " degenerate triangles dropped)");
    }
    // Local origin in double, then vertices relative to it.
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector3d hi = -lo;
    for (const Eigen::Vector3d& p : world_vertices_) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    scene_.origin_in_world =
        options_.recentre ? Eigen::Vector3d(0.5 * (lo + hi)) : Eigen::Vector3d::Zero();
    mesh.vertices.resize(world_vertices_.size());
    for (size_t i = 0; i < world_vertices_.size(); ++i) {
      mesh.vertices[i] = world_vertices_[i] - scene_.origin_in_world;
      if (!mesh.vertices[i].allFinite()) {
        return Error("vertex " + std::to_string(i) + " is not finite relative to the centre");
      }
    }
    return FinishMaterials();
  }

 private:
  Status Error(const std::string& what) const { return Status::Error(path_ + ": " + what); }

  // The FRESCO_view_layers extension's layers, textures as glTF texture indices; none (and a
  // warning) when it is malformed.
  void ReadViewLayers(std::vector<ViewLayerTextures>* layers) {
    const auto ext = model_.extensions.find(kViewLayersExtension);
    if (ext == model_.extensions.end()) return;
    const auto drop = [&](const std::string& why) {
      layers->clear();
      scene_.warnings.push_back(std::string("extensions.") + kViewLayersExtension + ": " + why +
                                "; view layers ignored");
    };
    const tinygltf::Value& value = ext->second;
    if (!value.IsObject() || !value.Has("layers") || !value.Get("layers").IsArray())
      return drop("expected {\"layers\": [...]}");
    const tinygltf::Value& list = value.Get("layers");
    const int num_textures = static_cast<int>(model_.textures.size());
    for (size_t k = 0; k < list.ArrayLen(); ++k) {
      const tinygltf::Value& layer = list.Get(static_cast<int>(k));
      const std::string where = "layers[" + std::to_string(k) + "]";
      if (!layer.IsObject() || !layer.Has("centre") || !layer.Has("textures"))
        return drop(where + ": expected {\"centre\": [x, y, z], \"textures\": [...]}");
      const tinygltf::Value& centre = layer.Get("centre");
      const tinygltf::Value& textures = layer.Get("textures");
      if (!centre.IsArray() || centre.ArrayLen() != 3 || !textures.IsArray() ||
          textures.ArrayLen() != model_.materials.size())
        return drop(where + ": centre needs 3 numbers and textures one entry per material");
      ViewLayerTextures out;
      for (int i = 0; i < 3; ++i) {
        if (!centre.Get(i).IsNumber()) return drop(where + ".centre: not a number");
        out.centre_world[i] = centre.Get(i).GetNumberAsDouble();
      }
      if (!out.centre_world.allFinite()) return drop(where + ".centre: not finite");
      for (size_t m = 0; m < textures.ArrayLen(); ++m) {
        const tinygltf::Value& t = textures.Get(static_cast<int>(m));
        const double index = t.IsNumber() ? t.GetNumberAsDouble() : -2.0;
        if (index != std::floor(index) || index < -1 || index >= num_textures)
          return drop(where + ".textures[" + std::to_string(m) + "]: not -1 or a texture index");
        out.material_texture.push_back(static_cast<int>(index));
      }
      layers->push_back(std::move(out));
    }
  }

  // The layers' glTF texture indices mapped to Scene::textures, into scene_.view_layers; a
  // texture that could not be read drops the layers (with a warning).
  void MapViewLayers(const std::map<int, int>& scene_texture,
                     const std::map<int, std::string>& texture_problem,
                     std::vector<ViewLayerTextures>* layers) {
    for (ViewLayerTextures& layer : *layers)
      for (int& t : layer.material_texture) {
        if (t < 0) continue;
        const auto found = scene_texture.find(t);
        if (found == scene_texture.end()) {
          const auto problem = texture_problem.find(t);
          scene_.warnings.push_back(
              std::string("extensions.") + kViewLayersExtension + ": " +
              (problem != texture_problem.end() ? problem->second : "a texture is missing") +
              "; view layers ignored");
          return;
        }
        t = found->second;
      }
    scene_.view_layers = std::move(*layers);
  }

  std::string MeshName(int mesh) const {
    const std::string& name = model_.meshes[mesh].name;
    return name.empty() ? "mesh " + std::to_string(mesh) : "mesh '" + name + "'";
  }
  std::string NodeName(int node) const {
    const std::string& name = model_.nodes[node].name;
    return name.empty() ? "node " + std::to_string(node) : "node '" + name + "'";
  }
  std::string MaterialName(int material) const {
    const std::string& name = model_.materials[material].name;
    return name.empty() ? "material " + std::to_string(material) : "material '" + name + "'";
  }

  // Materials' factors and texture references (before geometry: primitives read the UV set
  // of their material's base colour texture).
  Status CheckMaterials() {
    for (size_t m = 0; m < model_.materials.size(); ++m) {
      const auto& pbr = model_.materials[m].pbrMetallicRoughness;
      if (pbr.baseColorFactor.size() != 4) {
        return Error(MaterialName(static_cast<int>(m)) + ": baseColorFactor has " +
                     std::to_string(pbr.baseColorFactor.size()) + " values, expected 4");
      }
      for (double v : pbr.baseColorFactor) {
        if (!std::isfinite(v)) {
          return Error(MaterialName(static_cast<int>(m)) + ": baseColorFactor is not finite");
        }
      }
      const int texture = pbr.baseColorTexture.index;
      if (texture >= static_cast<int>(model_.textures.size())) {
        return Error(MaterialName(static_cast<int>(m)) + ": baseColorTexture " +
                     std::to_string(texture) + " does not exist (" +
                     std::to_string(model_.textures.size()) + " textures)");
      }
      if (texture >= 0 && pbr.baseColorTexture.texCoord < 0) {
        return Error(MaterialName(static_cast<int>(m)) + ": negative texCoord");
      }
    }
    return Status::Ok();
  }

  // Checks bufferView `view` against its buffer; returns its bytes.
  Status ViewBytes(int view, const std::string& context, const unsigned char** data, size_t* length,
                   size_t* stride) const {
    if (view < 0 || view >= static_cast<int>(model_.bufferViews.size())) {
      return Error(context + ": bufferView " + std::to_string(view) + " does not exist (" +
                   std::to_string(model_.bufferViews.size()) + " bufferViews)");
    }
    const tinygltf::BufferView& bv = model_.bufferViews[view];
    if (bv.buffer < 0 || bv.buffer >= static_cast<int>(model_.buffers.size())) {
      return Error(context + ": bufferView " + std::to_string(view) + ": buffer " +
                   std::to_string(bv.buffer) + " does not exist");
    }
    const auto& buffer = model_.buffers[bv.buffer].data;
    if (bv.byteOffset > buffer.size() || bv.byteLength > buffer.size() - bv.byteOffset) {
      return Error(context + ": bufferView " + std::to_string(view) +
                   " is out of bounds of buffer " + std::to_string(bv.buffer) + " (offset " +
                   std::to_string(bv.byteOffset) + " + length " + std::to_string(bv.byteLength) +
                   " > " + std::to_string(buffer.size()) + " bytes)");
    }
    *data = buffer.data() + bv.byteOffset;
    *length = bv.byteLength;
    *stride = bv.byteStride;
    return Status::Ok();
  }

  // Reads accessor `index` (strided, sparse, normalized) into doubles, checking bounds.
  Status ReadAccessor(int index, const std::string& context, AccessorValues* out) const {
    if (index < 0 || index >= static_cast<int>(model_.accessors.size())) {
      return Error(context + ": accessor " + std::to_string(index) + " does not exist (" +
                   std::to_string(model_.accessors.size()) + " accessors)");
    }
    const tinygltf::Accessor& acc = model_.accessors[index];
    const std::string where = context + ": accessor " + std::to_string(index);
    const int components = NumComponents(acc.type);
    const int component_size = ComponentSize(acc.componentType);
    if (components < 0)
      return Error(where + ": unsupported accessor type " + std::to_string(acc.type));
    if (component_size < 0) {
      return Error(where + ": unsupported componentType " + std::to_string(acc.componentType));
    }
    constexpr size_t kMaxValues = size_t{1} << 28;
    if (acc.count > kMaxValues / components) {
      return Error(where + ": count " + std::to_string(acc.count) + " is too large");
    }
    const size_t element_size = static_cast<size_t>(component_size) * components;
    out->count = acc.count;
    out->components = components;
    out->component_type = acc.componentType;
    if (acc.bufferView >= 0) {
      const unsigned char* data = nullptr;
      size_t length = 0, view_stride = 0;
      FRESCO_RETURN_IF_ERROR(ViewBytes(acc.bufferView, where, &data, &length, &view_stride));
      const size_t stride = view_stride ? view_stride : element_size;
      if (stride < element_size) {
        return Error(where + ": byteStride " + std::to_string(stride) +
                     " is smaller than the element size " + std::to_string(element_size));
      }
      if (acc.count > 0 && (acc.byteOffset > length || length - acc.byteOffset < element_size ||
                            (acc.count - 1) > (length - acc.byteOffset - element_size) / stride)) {
        const double needed = static_cast<double>(acc.byteOffset) +
                              static_cast<double>(acc.count - 1) * stride + element_size;
        std::ostringstream msg;
        msg << where << ": out of bounds of bufferView " << acc.bufferView << " (needs "
            << static_cast<uint64_t>(needed) << " bytes, has " << length << ")";
        return Error(msg.str());
      }
      out->values.resize(acc.count * components);
      for (size_t i = 0; i < acc.count; ++i) {
        const unsigned char* element = data + acc.byteOffset + i * stride;
        for (int c = 0; c < components; ++c) {
          out->values[i * components + c] =
              ReadComponent(element + c * component_size, acc.componentType);
        }
      }
    } else {
      // glTF: no bufferView = zeros (then sparse values). Nothing in the file backs them, so
      // a 200-byte file could ask for gigabytes (a hand-made input run through
      // tests/fuzz/gltf_fuzz): capped.
      constexpr size_t kMaxZeroValues = size_t{1} << 24;
      if (acc.count * components > kMaxZeroValues) {
        return Error(where + ": count " + std::to_string(acc.count) +
                     " without a bufferView is too large (at most " +
                     std::to_string(kMaxZeroValues / components) + ")");
      }
      out->values.assign(acc.count * components, 0.0);
    }
    if (acc.sparse.isSparse) {
      const auto& sparse = acc.sparse;
      const std::string sparse_where = where + ": sparse";
      if (sparse.count < 0 || static_cast<size_t>(sparse.count) > acc.count) {
        return Error(sparse_where + ": count " + std::to_string(sparse.count) + " is outside [0, " +
                     std::to_string(acc.count) + "]");
      }
      if (!IsIndexType(sparse.indices.componentType)) {
        return Error(sparse_where + ": indices componentType " +
                     std::to_string(sparse.indices.componentType) + " is not u8/u16/u32");
      }
      const size_t n = static_cast<size_t>(sparse.count);
      const size_t index_size = ComponentSize(sparse.indices.componentType);
      const unsigned char *indices = nullptr, *values = nullptr;
      size_t indices_length = 0, values_length = 0, unused_stride = 0;
      FRESCO_RETURN_IF_ERROR(ViewBytes(sparse.indices.bufferView, sparse_where + " indices",
                                       &indices, &indices_length, &unused_stride));
      FRESCO_RETURN_IF_ERROR(ViewBytes(sparse.values.bufferView, sparse_where + " values", &values,
                                       &values_length, &unused_stride));
      if (sparse.indices.byteOffset < 0 || sparse.values.byteOffset < 0 ||
          static_cast<size_t>(sparse.indices.byteOffset) + n * index_size > indices_length ||
          static_cast<size_t>(sparse.values.byteOffset) + n * element_size > values_length) {
        return Error(sparse_where + ": indices or values out of bounds of their bufferView");
      }
      indices += sparse.indices.byteOffset;
      values += sparse.values.byteOffset;
      for (size_t k = 0; k < n; ++k) {
        const double target = ReadComponent(indices + k * index_size, sparse.indices.componentType);
        if (target >= static_cast<double>(acc.count)) {
          return Error(sparse_where + ": index " + std::to_string(static_cast<uint64_t>(target)) +
                       " out of range (" + std::to_string(acc.count) + " elements)");
        }
        const size_t i = static_cast<size_t>(target);
        for (int c = 0; c < components; ++c) {
          out->values[i * components + c] =
              ReadComponent(values + k * element_size + c * component_size, acc.componentType);
        }
      }
    }
    if (acc.normalized) {
      for (double& v : out->values) v = Normalize(v, acc.componentType);
    }
    return Status::Ok();
  }

  Status LocalTransform(int node_index, Eigen::Matrix4d* parent_from_node) const {
    const tinygltf::Node& node = model_.nodes[node_index];
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    if (!node.matrix.empty()) {
      if (node.matrix.size() != 16) {
        return Error(NodeName(node_index) + ": matrix has " + std::to_string(node.matrix.size()) +
                     " values, expected 16");
      }
      for (int c = 0; c < 4; ++c) {
        for (int r = 0; r < 4; ++r) m(r, c) = node.matrix[c * 4 + r];  // column-major
      }
    } else {
      if ((!node.translation.empty() && node.translation.size() != 3) ||
          (!node.rotation.empty() && node.rotation.size() != 4) ||
          (!node.scale.empty() && node.scale.size() != 3)) {
        return Error(NodeName(node_index) + ": translation/rotation/scale has the wrong length");
      }
      Eigen::Vector3d t = Eigen::Vector3d::Zero(), s = Eigen::Vector3d::Ones();
      Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
      if (!node.translation.empty())
        t = {node.translation[0], node.translation[1], node.translation[2]};
      if (!node.scale.empty()) s = {node.scale[0], node.scale[1], node.scale[2]};
      if (!node.rotation.empty()) {
        // glTF stores (x, y, z, w).
        q = Eigen::Quaterniond(node.rotation[3], node.rotation[0], node.rotation[1],
                               node.rotation[2]);
        if (!(q.norm() > 0.0)) {
          return Error(NodeName(node_index) + ": rotation quaternion is zero");
        }
        q.normalize();
      }
      m.topLeftCorner<3, 3>() = q.toRotationMatrix() * s.asDiagonal();
      m.topRightCorner<3, 1>() = t;
    }
    if (!m.allFinite()) return Error(NodeName(node_index) + ": transform is not finite");
    *parent_from_node = m;
    return Status::Ok();
  }

  Status VisitNode(int node_index, const Eigen::Matrix4d& world_from_parent, int depth) {
    if (node_index < 0 || node_index >= static_cast<int>(model_.nodes.size())) {
      return Error("node " + std::to_string(node_index) + " does not exist (" +
                   std::to_string(model_.nodes.size()) + " nodes)");
    }
    if (on_path_[node_index] || depth > 1000) {
      return Error(NodeName(node_index) + ": the node hierarchy has a cycle");
    }
    on_path_[node_index] = 1;
    Eigen::Matrix4d parent_from_node;
    FRESCO_RETURN_IF_ERROR(LocalTransform(node_index, &parent_from_node));
    const Eigen::Matrix4d world_from_node = world_from_parent * parent_from_node;
    const tinygltf::Node& node = model_.nodes[node_index];
    if (node.mesh >= 0) {
      if (node.mesh >= static_cast<int>(model_.meshes.size())) {
        return Error(NodeName(node_index) + ": mesh " + std::to_string(node.mesh) +
                     " does not exist (" + std::to_string(model_.meshes.size()) + " meshes)");
      }
      if (node.skin >= 0) {
        scene_.warnings.push_back(NodeName(node_index) +
                                  ": skinning ignored (mesh placed by the node transform)");
      }
      FRESCO_RETURN_IF_ERROR(AddMesh(node.mesh, world_from_node));
    }
    for (int child : node.children) {
      FRESCO_RETURN_IF_ERROR(VisitNode(child, world_from_node, depth + 1));
    }
    on_path_[node_index] = 0;
    return Status::Ok();
  }

  Status AddMesh(int mesh_index, const Eigen::Matrix4d& world_from_mesh) {
    const auto& primitives = model_.meshes[mesh_index].primitives;
    for (size_t p = 0; p < primitives.size(); ++p) {
      FRESCO_RETURN_IF_ERROR(AddPrimitive(mesh_index, static_cast<int>(p), world_from_mesh));
    }
    return Status::Ok();
  }

  Status AddPrimitive(int mesh_index, int prim_index, const Eigen::Matrix4d& world_from_mesh) {
    const tinygltf::Primitive& prim = model_.meshes[mesh_index].primitives[prim_index];
    const std::string context = MeshName(mesh_index) + " primitive " + std::to_string(prim_index);
    const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
    if (mode >= TINYGLTF_MODE_POINTS && mode <= TINYGLTF_MODE_LINE_STRIP) {
      ++scene_.skipped_primitives;
      scene_.warnings.push_back(context + ": mode " + std::to_string(mode) +
                                " (points/lines) skipped");
      return Status::Ok();
    }
    if (mode > TINYGLTF_MODE_TRIANGLE_FAN || mode < 0) {
      return Error(context + ": unknown mode " + std::to_string(mode));
    }
    if (prim.material >= static_cast<int>(model_.materials.size())) {
      return Error(context + ": material " + std::to_string(prim.material) + " does not exist (" +
                   std::to_string(model_.materials.size()) + " materials)");
    }

    // Positions.
    const auto position_it = prim.attributes.find("POSITION");
    if (position_it == prim.attributes.end()) return Error(context + ": no POSITION attribute");
    AccessorValues positions;
    FRESCO_RETURN_IF_ERROR(ReadAccessor(position_it->second, context + ": POSITION", &positions));
    if (positions.components != 3) return Error(context + ": POSITION is not VEC3");
    const size_t num_vertices = positions.count;

    // Indices (u8/u16/u32), or implicit 0..n-1.
    std::vector<uint32_t> indices;
    if (prim.indices >= 0) {
      AccessorValues index_values;
      FRESCO_RETURN_IF_ERROR(ReadAccessor(prim.indices, context + ": indices", &index_values));
      if (index_values.components != 1 || !IsIndexType(index_values.component_type)) {
        return Error(context + ": indices must be SCALAR u8/u16/u32 (componentType " +
                     std::to_string(index_values.component_type) + ")");
      }
      indices.resize(index_values.count);
      for (size_t i = 0; i < index_values.count; ++i) {
        const double v = index_values.values[i];
        if (v >= static_cast<double>(num_vertices)) {
          return Error(context + ": index " + std::to_string(static_cast<uint64_t>(v)) +
                       " out of range (" + std::to_string(num_vertices) + " vertices)");
        }
        indices[i] = static_cast<uint32_t>(v);
      }
    } else {
      indices.resize(num_vertices);
      for (size_t i = 0; i < num_vertices; ++i) indices[i] = static_cast<uint32_t>(i);
    }

    // Triangles (strips and fans converted, as in the glTF spec).
    std::vector<std::array<uint32_t, 3>> triangles;
    const size_t n = indices.size();
    if (mode == TINYGLTF_MODE_TRIANGLES) {
      if (n % 3 != 0) {
        return Error(context + ": " + std::to_string(n) +
                     " indices is not a multiple of 3 for TRIANGLES");
      }
      for (size_t i = 0; i + 2 < n; i += 3) {
        triangles.push_back({indices[i], indices[i + 1], indices[i + 2]});
      }
    } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
      for (size_t i = 0; i + 2 < n; ++i) {
        if (i % 2 == 0) {
          triangles.push_back({indices[i], indices[i + 1], indices[i + 2]});
        } else {
          triangles.push_back({indices[i], indices[i + 2], indices[i + 1]});
        }
      }
    } else {  // fan
      for (size_t i = 0; i + 2 < n; ++i) {
        triangles.push_back({indices[i + 1], indices[i + 2], indices[0]});
      }
    }

    // UVs: the set the material's base colour texture uses (TEXCOORD_0 by default).
    int uv_set = 0;
    if (prim.material >= 0) {
      const auto& info = model_.materials[prim.material].pbrMetallicRoughness.baseColorTexture;
      if (info.index >= 0) uv_set = info.texCoord;
    }
    AccessorValues uvs;
    const std::string uv_name = "TEXCOORD_" + std::to_string(uv_set);
    const auto uv_it = prim.attributes.find(uv_name);
    const bool has_uv = uv_it != prim.attributes.end();
    if (has_uv) {
      FRESCO_RETURN_IF_ERROR(ReadAccessor(uv_it->second, context + ": " + uv_name, &uvs));
      if (uvs.components != 2) return Error(context + ": " + uv_name + " is not VEC2");
      if (uvs.count != num_vertices) {
        return Error(context + ": " + uv_name + " has " + std::to_string(uvs.count) +
                     " elements but POSITION has " + std::to_string(num_vertices));
      }
    }

    // Drop degenerate triangles (area measured in the world), fix winding for mirroring
    // transforms, and keep only used vertices (in their original order).
    const Eigen::Matrix3d linear = world_from_mesh.topLeftCorner<3, 3>();
    const Eigen::Vector3d translation = world_from_mesh.topRightCorner<3, 1>();
    const bool mirrored = linear.determinant() < 0.0;
    auto position = [&](uint32_t i) {
      return Eigen::Vector3d(positions.At(i, 0), positions.At(i, 1), positions.At(i, 2));
    };
    std::vector<int> new_index(num_vertices, -1);
    std::vector<std::array<uint32_t, 3>> kept;
    kept.reserve(triangles.size());
    auto uv = [&](uint32_t i) {
      return Eigen::Vector2f(static_cast<float>(uvs.At(i, 0)), static_cast<float>(uvs.At(i, 1)));
    };
    for (auto tri : triangles) {
      for (uint32_t v : tri) {
        if (!position(v).allFinite()) {
          return Error(context + ": POSITION " + std::to_string(v) + " is not finite");
        }
        if (!(linear * position(v) + translation).allFinite()) {
          return Error(context + ": POSITION " + std::to_string(v) +
                       " is not finite after the node transform");
        }
        if (has_uv && !uv(v).allFinite()) {  // as float: 1e300 is finite only as a double
          return Error(context + ": " + uv_name + " " + std::to_string(v) + " is not finite");
        }
      }
      const Eigen::Vector3d e1 = linear * (position(tri[1]) - position(tri[0]));
      const Eigen::Vector3d e2 = linear * (position(tri[2]) - position(tri[0]));
      const double area = 0.5 * e1.cross(e2).norm();
      if (!(area >= options_.min_triangle_area_m2)) {
        ++scene_.dropped_degenerate;
        continue;
      }
      if (mirrored) std::swap(tri[1], tri[2]);
      for (uint32_t v : tri) new_index[v] = 0;
      kept.push_back(tri);
    }
    int next = static_cast<int>(world_vertices_.size());
    for (size_t v = 0; v < num_vertices; ++v) {
      if (new_index[v] < 0) continue;
      new_index[v] = next++;
      world_vertices_.push_back(linear * position(static_cast<uint32_t>(v)) + translation);
    }
    TriangleMesh& mesh = scene_.mesh;
    for (const auto& tri : kept) {
      mesh.triangles.emplace_back(new_index[tri[0]], new_index[tri[1]], new_index[tri[2]]);
      std::array<Eigen::Vector2f, 3> corner_uvs;
      for (int k = 0; k < 3; ++k) {
        corner_uvs[k] = has_uv ? uv(tri[k]) : Eigen::Vector2f::Zero();
      }
      mesh.uvs.push_back(corner_uvs);
      mesh.material.push_back(prim.material);  // -1 = default, resolved in FinishMaterials
      mesh.has_uv.push_back(has_uv);
    }
    return Status::Ok();
  }

  // Materials (1:1 with the file's, plus a default white one when needed) and the base
  // colour textures they use, decoded to RGBA8.
  Status FinishMaterials() {
    TriangleMesh& mesh = scene_.mesh;
    std::vector<char> material_used(model_.materials.size(), 0);
    bool needs_default = model_.materials.empty();
    for (int m : mesh.material) {
      if (m < 0) {
        needs_default = true;
      } else {
        material_used[m] = 1;
      }
    }
    // Textures referenced by materials, in the file's texture order.
    std::set<int> referenced;
    for (const auto& material : model_.materials) {
      if (material.pbrMetallicRoughness.baseColorTexture.index >= 0) {
        referenced.insert(material.pbrMetallicRoughness.baseColorTexture.index);
      }
    }
    std::vector<ViewLayerTextures> layers;  // glTF texture indices until mapped below
    ReadViewLayers(&layers);
    for (const ViewLayerTextures& layer : layers)
      for (int t : layer.material_texture)
        if (t >= 0) referenced.insert(t);
    std::map<int, int> scene_texture;  // glTF texture -> Scene::textures index
    std::map<int, std::string> texture_problem;
    for (int t : referenced) {
      const tinygltf::Texture& texture = model_.textures[t];
      const std::string where = "texture " + std::to_string(t);
      if (texture.source < 0 || texture.source >= static_cast<int>(model_.images.size())) {
        texture_problem[t] = where + ": image " + std::to_string(texture.source) +
                             " does not exist (" + std::to_string(model_.images.size()) +
                             " images)";
        continue;
      }
      const tinygltf::Image& image = model_.images[texture.source];
      std::string problem;
      cv::Mat rgba = ImageToRgba8(image, &problem);
      if (!problem.empty()) {
        texture_problem[t] = where + ": image " + std::to_string(texture.source) +
                             (image.uri.empty() ? "" : " '" + image.uri + "'") + " " + problem;
        continue;
      }
      Texture out;
      out.rgba = rgba;
      out.name = !texture.name.empty() ? texture.name
                 : !image.name.empty() ? image.name
                                       : fs::path(image.uri).filename().string();
      if (texture.sampler >= 0) {
        if (texture.sampler >= static_cast<int>(model_.samplers.size())) {
          return Error(where + ": sampler " + std::to_string(texture.sampler) + " does not exist");
        }
        const tinygltf::Sampler& sampler = model_.samplers[texture.sampler];
        bool known_s = true, known_t = true;
        out.wrap_s = WrapFromGltf(sampler.wrapS, &known_s);
        out.wrap_t = WrapFromGltf(sampler.wrapT, &known_t);
        if (!known_s || !known_t) {
          scene_.warnings.push_back(where + ": unknown wrap mode, using REPEAT");
        }
      }
      scene_texture[t] = static_cast<int>(scene_.textures.size());
      scene_.textures.push_back(std::move(out));
    }

    for (size_t m = 0; m < model_.materials.size(); ++m) {
      const tinygltf::Material& in = model_.materials[m];
      const auto& pbr = in.pbrMetallicRoughness;
      Material out;
      out.name = in.name;
      out.double_sided = in.doubleSided;
      out.base_color_factor = Eigen::Vector4d(pbr.baseColorFactor[0], pbr.baseColorFactor[1],
                                              pbr.baseColorFactor[2], pbr.baseColorFactor[3]);
      const int t = pbr.baseColorTexture.index;
      if (t >= 0) {
        if (scene_texture.count(t)) {
          out.base_color_texture = scene_texture[t];
        } else if (material_used[m]) {
          return Error(MaterialName(static_cast<int>(m)) + ": " + texture_problem[t]);
        } else {
          scene_.warnings.push_back(MaterialName(static_cast<int>(m)) +
                                    " (unused): " + texture_problem[t]);
        }
      }
      scene_.materials.push_back(std::move(out));
    }
    MapViewLayers(scene_texture, texture_problem, &layers);
    if (needs_default) {
      const int default_material = static_cast<int>(scene_.materials.size());
      Material white;
      white.name = "default";
      scene_.materials.push_back(white);
      for (ViewLayerTextures& layer : scene_.view_layers) layer.material_texture.push_back(-1);
      for (int& m : mesh.material) {
        if (m < 0) m = default_material;
      }
    }
    return Status::Ok();
  }

  const std::string& path_;
  const SceneLoadOptions& options_;
  const tinygltf::Model& model_;
  Scene& scene_;
  std::vector<Eigen::Vector3d> world_vertices_;  // double, before recentring
  std::vector<char> on_path_;                    // cycle detection
};

bool HasGlbMagic(const std::string& bytes) {
  return bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
}

// tinygltf reads `extras` and `extensions` values recursively, one stack frame per level:
// deep nesting ("[[[[...") overflowed the stack (a hand-made input run through
// tests/fuzz/gltf_fuzz). Real glTF nests about ten levels.
constexpr int kMaxJsonDepth = 128;

// The deepest nesting of arrays and objects in `json` (brackets inside strings do not count).
int JsonNestingDepth(std::string_view json) {
  int depth = 0, deepest = 0;
  bool in_string = false;
  for (size_t i = 0; i < json.size(); ++i) {
    const char c = json[i];
    if (in_string) {
      if (c == '\\') {
        ++i;
      } else if (c == '"') {
        in_string = false;
      }
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      deepest = std::max(deepest, ++depth);
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return deepest;
}

// The JSON text of a glTF file: all of it, or a GLB's JSON chunk (empty when the GLB header
// is broken: tinygltf reports that).
std::string_view GltfJson(const std::string& bytes, bool binary) {
  if (!binary) return bytes;
  uint32_t length = 0;
  if (bytes.size() < 20) return {};
  std::memcpy(&length, bytes.data() + 12, 4);
  if (length > bytes.size() - 20) return {};
  return std::string_view(bytes).substr(20, length);
}

// tinygltf hands an image stored in a bufferView to the image loader without checking that
// the view lies inside its buffer: a GLB whose JSON declares a buffer shorter than the view
// made stb_image read past the end. While parsing, only images read from a URI (whole files
// or data URIs, in bounds) are decoded; the others are decoded by DecodeBufferViewImages.
bool DecodeUriImagesOnly(tinygltf::Image* image, int index, std::string* err, std::string* warn,
                         int width, int height, const unsigned char* bytes, int size, void*) {
  if (image->bufferView != -1) return true;
  return tinygltf::LoadImageData(image, index, err, warn, width, height, bytes, size, nullptr);
}

// Decodes the images stored in bufferViews once each view is known to lie in its buffer
// (tinygltf has checked that the view and buffer indices exist).
Status DecodeBufferViewImages(const std::string& path, tinygltf::Model* model) {
  for (size_t i = 0; i < model->images.size(); ++i) {
    tinygltf::Image& image = model->images[i];
    if (image.bufferView == -1) continue;
    const tinygltf::BufferView& view = model->bufferViews[static_cast<size_t>(image.bufferView)];
    const tinygltf::Buffer& buffer = model->buffers[static_cast<size_t>(view.buffer)];
    const std::string where = path + ": images[" + std::to_string(i) + "]: bufferViews[" +
                              std::to_string(image.bufferView) + "]";
    const size_t size = buffer.data.size();
    if (view.byteOffset > size || view.byteLength > size - view.byteOffset) {
      return Status::Error(where + " (bytes " + std::to_string(view.byteOffset) + " + " +
                           std::to_string(view.byteLength) + ") runs past the end of buffers[" +
                           std::to_string(view.buffer) + "] (" + std::to_string(size) + " bytes)");
    }
    if (view.byteLength > static_cast<size_t>(std::numeric_limits<int>::max())) {
      return Status::Error(where + ": image larger than 2 GB");
    }
    std::string err, warn;
    if (!tinygltf::LoadImageData(&image, static_cast<int>(i), &err, &warn, image.width,
                                 image.height, buffer.data.data() + view.byteOffset,
                                 static_cast<int>(view.byteLength), nullptr)) {
      std::string why = OneLine(err);
      return Status::Error(where + ": cannot decode the image" + (why.empty() ? "" : ": " + why));
    }
  }
  return Status::Ok();
}

}  // namespace

Status LoadGltfScene(const std::string& path, const SceneLoadOptions& options, Scene* scene) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return Status::Error(path + ": file not found");
  std::string bytes;
  FRESCO_RETURN_IF_ERROR(ReadFileToString(path, &bytes));
  return ParseGltfScene(bytes, path, fs::path(path).parent_path().string(), options, scene);
}

Status ParseGltfScene(const std::string& bytes, const std::string& path,
                      const std::string& base_dir, const SceneLoadOptions& options, Scene* scene) {
  if (!(options.min_triangle_area_m2 >= 0.0)) {
    return Status::Error(path + ": min_triangle_area_m2 must be >= 0");
  }
  if (bytes.size() > std::numeric_limits<unsigned int>::max()) {
    return Status::Error(path + ": larger than 4 GB, which tinygltf cannot read");
  }
  tinygltf::TinyGLTF io;
  io.SetImageLoader(DecodeUriImagesOnly, nullptr);
  tinygltf::Model model;
  std::string err, warn;
  const bool binary = HasGlbMagic(bytes);
  if (JsonNestingDepth(GltfJson(bytes, binary)) > kMaxJsonDepth) {
    return Status::Error(path + ": cannot parse " + (binary ? "GLB" : "glTF") +
                         ": JSON nested more than " + std::to_string(kMaxJsonDepth) +
                         " levels deep");
  }
  const auto length = static_cast<unsigned int>(bytes.size());
  const bool parsed =
      binary ? io.LoadBinaryFromMemory(&model, &err, &warn,
                                       reinterpret_cast<const unsigned char*>(bytes.data()), length,
                                       base_dir)
             : io.LoadASCIIFromString(&model, &err, &warn, bytes.data(), length, base_dir);
  if (!parsed) {
    std::string why = OneLine(err);
    if (why.empty()) why = OneLine(warn);
    return Status::Error(path + ": cannot parse " + (binary ? "GLB" : "glTF") + ": " +
                         (why.empty() ? "unknown error" : why));
  }
  FRESCO_RETURN_IF_ERROR(DecodeBufferViewImages(path, &model));
  Scene loaded;
  loaded.source_path = path;
  for (const std::string& line : Lines(warn)) loaded.warnings.push_back(line);
  GltfLoader loader(path, options, model, &loaded);
  FRESCO_RETURN_IF_ERROR(loader.Load());
  *scene = std::move(loaded);
  return Status::Ok();
}

// ---------------------------------------------------------------------------------------
// Saving

namespace {

using Json = nlohmann::ordered_json;

// A file-name-safe, URI-safe version of `stem` (no percent-encoding needed).
std::string SafeStem(const std::string& stem) {
  std::string out;
  for (char c : stem) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '_' || c == '-' || c == '.';
    out += ok ? c : '_';
  }
  return out.empty() ? "scene" : out;
}

class BinaryWriter {
 public:
  // Appends `bytes` as a new bufferView (4-byte aligned); returns its index.
  int AddView(const void* bytes, size_t size, int target, Json* views) {
    while (data_.size() % 4 != 0) data_.push_back('\0');
    Json view = {{"buffer", 0}, {"byteOffset", data_.size()}, {"byteLength", size}};
    if (target) view["target"] = target;
    data_.append(static_cast<const char*>(bytes), size);
    views->push_back(view);
    return static_cast<int>(views->size()) - 1;
  }
  const std::string& data() const { return data_; }
  // Room for `bytes` in all. An upper bound costs no memory beyond what is written: the
  // pages never written are never touched. It saves the copy each doubling would make.
  void Reserve(size_t bytes) { data_.reserve(bytes); }

 private:
  std::string data_;
};

bool TriangleHasUv(const TriangleMesh& mesh, int t) {
  return !mesh.uvs.empty() && (mesh.has_uv.empty() || mesh.has_uv[t]);
}

int TriangleMaterial(const TriangleMesh& mesh, int t) {
  return mesh.material.empty() ? 0 : mesh.material[t];
}

// The scene's materials, or one default material when it has none.
std::vector<Material> MaterialsToSave(const Scene& scene) {
  std::vector<Material> materials = scene.materials;
  if (materials.empty()) {
    materials.emplace_back();
    materials.back().name = "default";
  }
  return materials;
}

// Why the mesh's per-triangle arrays or its vertices cannot be saved ("" when they can).
std::string MeshArraysProblem(const TriangleMesh& mesh) {
  const int num_triangles = mesh.NumTriangles();
  if (num_triangles == 0) return "cannot save a scene with no triangles";
  if (!mesh.uvs.empty() && static_cast<int>(mesh.uvs.size()) != num_triangles) {
    return "mesh has " + std::to_string(mesh.uvs.size()) + " uv triples for " +
           std::to_string(num_triangles) + " triangles";
  }
  if (!mesh.has_uv.empty() && static_cast<int>(mesh.has_uv.size()) != num_triangles) {
    return "mesh has_uv has the wrong size";
  }
  if (!mesh.material.empty() && static_cast<int>(mesh.material.size()) != num_triangles) {
    return "mesh material has the wrong size";
  }
  for (size_t v = 0; v < mesh.vertices.size(); ++v) {
    if (!mesh.vertices[v].allFinite()) return "vertex " + std::to_string(v) + " is not finite";
  }
  return "";
}

// Why a triangle cannot be saved ("" when all can): its vertices, UVs and material.
std::string TrianglesProblem(const TriangleMesh& mesh, size_t num_materials) {
  const int num_vertices = static_cast<int>(mesh.vertices.size());
  for (int t = 0; t < mesh.NumTriangles(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const int v = mesh.triangles[t][k];
      if (v < 0 || v >= num_vertices) {
        return "triangle " + std::to_string(t) + ": vertex " + std::to_string(v) +
               " out of range (" + std::to_string(num_vertices) + " vertices)";
      }
      if (TriangleHasUv(mesh, t) && !mesh.uvs[t][k].allFinite()) {
        return "triangle " + std::to_string(t) + ": uv is not finite";
      }
    }
    const int m = TriangleMaterial(mesh, t);
    if (m < 0 || m >= static_cast<int>(num_materials)) {
      return "triangle " + std::to_string(t) + ": material " + std::to_string(m) +
             " out of range (" + std::to_string(num_materials) + " materials)";
    }
  }
  return "";
}

// Why the materials, view layers or textures cannot be saved ("" when they can).
std::string TexturingProblem(const Scene& scene, const std::vector<Material>& materials) {
  for (size_t m = 0; m < materials.size(); ++m) {
    const int t = materials[m].base_color_texture;
    if (t < -1 || t >= static_cast<int>(scene.textures.size())) {
      return "material " + std::to_string(m) + ": texture " + std::to_string(t) +
             " out of range (" + std::to_string(scene.textures.size()) + " textures)";
    }
    if (!materials[m].base_color_factor.allFinite()) {
      return "material " + std::to_string(m) + ": base_color_factor is not finite";
    }
  }
  for (size_t k = 0; k < scene.view_layers.size(); ++k) {
    const ViewLayerTextures& layer = scene.view_layers[k];
    if (layer.material_texture.size() != scene.materials.size() ||
        !layer.centre_world.allFinite()) {
      return "view layer " + std::to_string(k) +
             ": needs a finite centre and a texture entry per material";
    }
    for (int t : layer.material_texture)
      if (t < -1 || t >= static_cast<int>(scene.textures.size()))
        return "view layer " + std::to_string(k) + ": texture " + std::to_string(t) +
               " out of range (" + std::to_string(scene.textures.size()) + " textures)";
  }
  for (size_t t = 0; t < scene.textures.size(); ++t) {
    const cv::Mat& rgba = scene.textures[t].rgba;
    if (rgba.empty() || rgba.type() != CV_8UC4) {
      return "texture " + std::to_string(t) + " '" + scene.textures[t].name +
             "': expected a non-empty CV_8UC4 RGBA image";
    }
  }
  return "";
}

// Why the scene cannot be saved with `materials` ("" when it can), checked before anything
// is written.
std::string SavingProblem(const Scene& scene, const std::vector<Material>& materials) {
  if (std::string why = MeshArraysProblem(scene.mesh); !why.empty()) return why;
  if (!scene.origin_in_world.allFinite()) return "origin_in_world is not finite";
  if (std::string why = TrianglesProblem(scene.mesh, materials.size()); !why.empty()) return why;
  return TexturingProblem(scene, materials);
}

// The root's asset, scene and its one node (carrying the origin).
Json RootWithNode(const Scene& scene) {
  Json root;
  root["asset"] = {{"version", "2.0"}, {"generator", "Fresco"}};
  root["scene"] = 0;
  Json default_scene = Json::object();
  default_scene["nodes"] = Json::array({0});
  root["scenes"] = Json::array({default_scene});
  Json node = {{"name", "fresco_origin"}, {"mesh", 0}};
  if (!scene.origin_in_world.isZero(0.0)) {
    node["translation"] = {scene.origin_in_world.x(), scene.origin_in_world.y(),
                           scene.origin_in_world.z()};
  }
  root["nodes"] = Json::array({node});
  return root;
}

// The triangles of each primitive: one per material and UV presence, in the order they
// first appear, each keeping the mesh's order of triangles.
std::vector<std::vector<int>> PrimitiveTriangles(const TriangleMesh& mesh) {
  std::map<std::pair<int, bool>, int> primitive_of_key;
  std::vector<std::vector<int>> primitive_triangles;
  for (int t = 0; t < mesh.NumTriangles(); ++t) {
    const auto key = std::make_pair(TriangleMaterial(mesh, t), TriangleHasUv(mesh, t));
    auto it = primitive_of_key.find(key);
    if (it == primitive_of_key.end()) {
      it = primitive_of_key.emplace(key, static_cast<int>(primitive_triangles.size())).first;
      primitive_triangles.emplace_back();
    }
    primitive_triangles[it->second].push_back(t);
  }
  return primitive_triangles;
}

// One primitive's vertex arrays and indices.
struct PrimitiveArrays {
  std::vector<Eigen::Vector3f> positions;
  std::vector<Eigen::Vector2f> uvs;
  std::vector<uint32_t> indices;
};

// The vertices and indices of the triangles `run`: the vertices they use in the mesh's
// order, split where a vertex has different UVs on different corners. `slot` (one per mesh
// vertex, all -1) is scratch, left all -1.
PrimitiveArrays BuildPrimitive(const TriangleMesh& mesh, const std::vector<int>& run, bool has_uv,
                               std::vector<int>* slot_of_vertex) {
  std::vector<int>& slot = *slot_of_vertex;
  std::vector<int> used;
  for (int t : run) {
    for (int k = 0; k < 3; ++k) {
      const int v = mesh.triangles[t][k];
      if (slot[v] == -1) {
        slot[v] = -2;
        used.push_back(v);
      }
    }
  }
  std::sort(used.begin(), used.end());
  for (size_t i = 0; i < used.size(); ++i) slot[used[i]] = static_cast<int>(i);
  // Split vertices are appended: room for a vertex per corner (untouched where unused).
  const size_t max_vertices = has_uv ? 3 * run.size() : used.size();
  PrimitiveArrays out;
  std::vector<Eigen::Vector3f>& positions = out.positions;
  positions.resize(used.size());
  positions.reserve(max_vertices);
  for (size_t i = 0; i < used.size(); ++i) positions[i] = mesh.vertices[used[i]].cast<float>();
  std::vector<Eigen::Vector2f>& uvs = out.uvs;
  uvs.assign(used.size(), Eigen::Vector2f::Zero());
  uvs.reserve(max_vertices);
  std::vector<char> uv_set(used.size(), 0);
  std::map<std::tuple<int, float, float>, int> splits;
  out.indices.reserve(3 * run.size());
  for (int t : run) {
    for (int k = 0; k < 3; ++k) {
      const int v = mesh.triangles[t][k];
      int index = slot[v];
      if (has_uv) {
        const Eigen::Vector2f& uv = mesh.uvs[t][k];
        if (!uv_set[index]) {
          uvs[index] = uv;
          uv_set[index] = 1;
        } else if (uvs[index] != uv) {
          const auto key = std::make_tuple(v, uv.x(), uv.y());
          auto it = splits.find(key);
          if (it == splits.end()) {
            it = splits.emplace(key, static_cast<int>(positions.size())).first;
            positions.push_back(positions[index]);
            uvs.push_back(uv);
            uv_set.push_back(1);
          }
          index = it->second;
        }
      }
      out.indices.push_back(static_cast<uint32_t>(index));
    }
  }
  for (int v : used) slot[v] = -1;
  return out;
}

// The buffer views and accessors of one primitive's arrays; returns the primitive.
Json WritePrimitive(const PrimitiveArrays& arrays, int material, bool has_uv, BinaryWriter* bin,
                    Json* views, Json* accessors) {
  const std::vector<Eigen::Vector3f>& positions = arrays.positions;
  Eigen::Vector3f lo = positions[0], hi = positions[0];
  for (const auto& p : positions) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  Json attributes;
  const int count = static_cast<int>(positions.size());
  const int position_view =
      bin->AddView(positions.data(), positions.size() * sizeof(Eigen::Vector3f), 34962, views);
  accessors->push_back({{"bufferView", position_view},
                        {"componentType", TINYGLTF_COMPONENT_TYPE_FLOAT},
                        {"count", count},
                        {"type", "VEC3"},
                        {"min", {lo.x(), lo.y(), lo.z()}},
                        {"max", {hi.x(), hi.y(), hi.z()}}});
  attributes["POSITION"] = accessors->size() - 1;
  if (has_uv) {
    const int uv_view =
        bin->AddView(arrays.uvs.data(), arrays.uvs.size() * sizeof(Eigen::Vector2f), 34962, views);
    accessors->push_back({{"bufferView", uv_view},
                          {"componentType", TINYGLTF_COMPONENT_TYPE_FLOAT},
                          {"count", count},
                          {"type", "VEC2"}});
    attributes["TEXCOORD_0"] = accessors->size() - 1;
  }
  const int index_view =
      bin->AddView(arrays.indices.data(), arrays.indices.size() * sizeof(uint32_t), 34963, views);
  accessors->push_back({{"bufferView", index_view},
                        {"componentType", TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT},
                        {"count", arrays.indices.size()},
                        {"type", "SCALAR"}});
  return {{"attributes", attributes},
          {"indices", accessors->size() - 1},
          {"material", material},
          {"mode", TINYGLTF_MODE_TRIANGLES}};
}

// Geometry: one primitive per material and UV presence (in the order they first appear),
// each with its own vertices (split where a vertex has different UVs on different
// corners). Within a primitive, triangles and vertices keep their order. (Charts on an
// atlas of several pages interleave materials in the mesh's order: a primitive per run
// would make 10^5 primitives, which viewers load badly.) Adds the mesh, accessors, views
// and the buffer `bin_name` to `root`; the buffer's bytes go to `bin`.
void AddGeometry(const TriangleMesh& mesh, const std::string& bin_name, Json* root,
                 BinaryWriter* bin) {
  const int num_triangles = mesh.NumTriangles();
  const std::vector<std::vector<int>> primitive_triangles = PrimitiveTriangles(mesh);
  Json views = Json::array(), accessors = Json::array(), primitives = Json::array();
  // At most a vertex per corner (position, uv) and an index, plus each view's alignment.
  bin->Reserve(static_cast<size_t>(num_triangles) * 3 *
                   (sizeof(Eigen::Vector3f) + sizeof(Eigen::Vector2f) + sizeof(uint32_t)) +
               12 * primitive_triangles.size());
  std::vector<int> slot(mesh.vertices.size(), -1);
  for (const std::vector<int>& run : primitive_triangles) {
    const int material = TriangleMaterial(mesh, run[0]);
    const bool has_uv = TriangleHasUv(mesh, run[0]);
    const PrimitiveArrays arrays = BuildPrimitive(mesh, run, has_uv, &slot);
    primitives.push_back(WritePrimitive(arrays, material, has_uv, bin, &views, &accessors));
  }
  Json json_mesh = Json::object();
  json_mesh["name"] = "fresco_mesh";
  json_mesh["primitives"] = primitives;
  (*root)["meshes"] = Json::array({json_mesh});
  (*root)["accessors"] = accessors;
  (*root)["bufferViews"] = views;
  Json buffer = Json::object();
  buffer["uri"] = bin_name;
  buffer["byteLength"] = bin->data().size();
  (*root)["buffers"] = Json::array({buffer});
}

Json MaterialsJson(const std::vector<Material>& materials) {
  Json json_materials = Json::array();
  for (const Material& material : materials) {
    Json pbr = {{"baseColorFactor",
                 {material.base_color_factor[0], material.base_color_factor[1],
                  material.base_color_factor[2], material.base_color_factor[3]}}};
    if (material.base_color_texture >= 0) {
      pbr["baseColorTexture"] = {{"index", material.base_color_texture}};
    }
    pbr["metallicFactor"] = 0.0;  // painted colour is diffuse, not metal
    pbr["roughnessFactor"] = 1.0;
    Json out;
    if (!material.name.empty()) out["name"] = material.name;
    out["pbrMetallicRoughness"] = pbr;
    out["doubleSided"] = material.double_sided;
    json_materials.push_back(out);
  }
  return json_materials;
}

// Textures: PNG files beside the .gltf (RGBA, so alpha round-trips exactly), each written
// as soon as it is encoded (one encoded page in memory at a time), before the .gltf. Adds
// the images, samplers and textures to `root`; `path` is the .gltf's.
Status WriteTextures(const Scene& scene, const std::string& path, const std::string& stem,
                     Json* root) {
  const fs::path dir = fs::path(path).parent_path();
  Json images = Json::array(), samplers = Json::array(), textures = Json::array();
  for (size_t t = 0; t < scene.textures.size(); ++t) {
    const Texture& texture = scene.textures[t];
    const std::string png_name = stem + "_texture" + std::to_string(t) + ".png";
    cv::Mat bgra;
    cv::cvtColor(texture.rgba, bgra, cv::COLOR_RGBA2BGRA);
    std::vector<unsigned char> png;
    if (!EncodeImageBytes(".png", bgra, &png)) {
      return Status::Internal(path + ": texture " + std::to_string(t) + ": PNG encoding failed");
    }
    bgra.release();
    FRESCO_RETURN_IF_ERROR(
        WriteFileAtomicWith((dir / png_name).string(), [&](const std::string& temp) {
          std::ofstream file(temp, std::ios::binary);
          file.write(reinterpret_cast<const char*>(png.data()),
                     static_cast<std::streamsize>(png.size()));
          file.close();
          return file.good() ? Status::Ok() : Status::OutputError(temp + ": cannot write");
        }));
    Json image = {{"uri", png_name}};
    if (!texture.name.empty()) image["name"] = texture.name;
    images.push_back(image);
    samplers.push_back(
        {{"wrapS", WrapToGltf(texture.wrap_s)}, {"wrapT", WrapToGltf(texture.wrap_t)}});
    Json json_texture = {{"sampler", t}, {"source", t}};
    if (!texture.name.empty()) json_texture["name"] = texture.name;
    textures.push_back(json_texture);
  }
  (*root)["images"] = images;
  (*root)["samplers"] = samplers;
  (*root)["textures"] = textures;
  return Status::Ok();
}

// The view layers as Fresco's extension.
void AddViewLayers(const Scene& scene, Json* root) {
  Json layers = Json::array();
  for (const ViewLayerTextures& layer : scene.view_layers) {
    const Eigen::Vector3d& c = layer.centre_world;
    layers.push_back({{"centre", {c.x(), c.y(), c.z()}}, {"textures", layer.material_texture}});
  }
  (*root)["extensionsUsed"] = Json::array({kViewLayersExtension});
  (*root)["extensions"][kViewLayersExtension] = {{"layers", layers}};
}

}  // namespace

Status SaveGltfScene(const Scene& scene, const std::string& path) {
  // Validate the scene before writing anything. A scene that cannot be saved is a broken
  // invariant: the loaders and the painter make only saveable ones.
  const std::vector<Material> materials = MaterialsToSave(scene);
  if (const std::string why = SavingProblem(scene, materials); !why.empty()) {
    return Status::Internal(path + ": " + why);
  }

  const fs::path gltf_path(path);
  const fs::path dir = gltf_path.parent_path();
  const std::string stem = SafeStem(gltf_path.stem().string());
  if (!dir.empty()) FRESCO_RETURN_IF_ERROR(MakeDirectories(dir.string()));

  Json root = RootWithNode(scene);
  const std::string bin_name = stem + ".bin";
  BinaryWriter bin;
  AddGeometry(scene.mesh, bin_name, &root, &bin);
  root["materials"] = MaterialsJson(materials);
  if (!scene.textures.empty()) FRESCO_RETURN_IF_ERROR(WriteTextures(scene, path, stem, &root));
  if (!scene.view_layers.empty()) AddViewLayers(scene, &root);

  // Dependencies first, the .gltf last: a reader never sees a .gltf whose files are missing.
  FRESCO_RETURN_IF_ERROR(WriteFileAtomic((dir / bin_name).string(), bin.data()));
  return WriteFileAtomic(path, root.dump(2) + "\n");
}

Status SaveGltfTextures(const Scene& scene, const std::string& path) {
  const fs::path dir = fs::path(path).parent_path();
  if (!dir.empty()) FRESCO_RETURN_IF_ERROR(MakeDirectories(dir.string()));
  Json unused;
  return WriteTextures(scene, path, SafeStem(fs::path(path).stem().string()), &unused);
}

}  // namespace fresco
