// PLY and OBJ scenes through Assimp, and LoadScene, which picks the reader by extension.
// Assimp trusts a PLY header's element counts (a short binary file gives garbage face indices,
// an absurd count allocates for minutes), so the file's length is checked against the header
// first; face indices are checked here before triangulation reads vertices through them;
// finite values, degenerate triangles, the UV convention and materials are handled here while
// Assimp's meshes are concatenated in file order.
#include "pipeline/core/mesh_scene.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <sstream>
#include <vector>

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <assimp/Importer.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "pipeline/core/image_io.h"

namespace fresco {
namespace {

namespace fs = std::filesystem;

std::string LowercaseExtension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

// Bytes one value of a PLY scalar type takes in a binary file; 0 for an unknown type.
int PlyTypeSize(const std::string& type) {
  static const std::map<std::string, int> kSizes = {
      {"char", 1},   {"int8", 1},    {"uchar", 1},  {"uint8", 1},  {"short", 2}, {"int16", 2},
      {"ushort", 2}, {"uint16", 2},  {"int", 4},    {"int32", 4},  {"uint", 4},  {"uint32", 4},
      {"float", 4},  {"float32", 4}, {"double", 8}, {"float64", 8}};
  const auto it = kSizes.find(type);
  return it == kSizes.end() ? 0 : it->second;
}

struct PlyProperty {
  int size = 0;       // bytes of a scalar, or of a list's length field
  int item_size = 0;  // bytes of a list item; 0 for a scalar
};
struct PlyElement {
  std::string name;
  unsigned long long count = 0;
  std::vector<PlyProperty> properties;
};

// Reads a PLY header; false when this cannot (Assimp then reports what is wrong).
bool ReadPlyHeader(std::istream& in, bool* binary, bool* big_endian,
                   std::vector<PlyElement>* elements) {
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream words(line);
    std::string keyword, word;
    words >> keyword >> word;
    if (keyword == "format") {
      *binary = word != "ascii";
      *big_endian = word == "binary_big_endian";
    } else if (keyword == "element") {
      elements->push_back({word, 0, {}});
      if (!(words >> elements->back().count)) return false;
    } else if (keyword == "property") {
      if (elements->empty()) return false;
      PlyProperty property;
      if (word == "list") {
        std::string count_type, item_type;
        words >> count_type >> item_type;
        property.size = PlyTypeSize(count_type);
        property.item_size = PlyTypeSize(item_type);
        if (property.item_size == 0) return false;
      } else {
        property.size = PlyTypeSize(word);
      }
      if (property.size == 0) return false;
      elements->back().properties.push_back(property);
    } else if (keyword == "end_header") {
      return true;
    }
  }
  return false;
}

// Checks that a PLY file holds as much as its header promises, since Assimp does not (it
// reads garbage face indices past the end, and allocates for minutes for an absurd count):
// binary, every element read through (list lengths included); ASCII, at least one character
// and a separator per value. A header this cannot read is left to Assimp to report.
Status CheckPlyLength(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  bool binary = false, big_endian = false;
  std::vector<PlyElement> elements;
  if (!ReadPlyHeader(in, &binary, &big_endian, &elements)) return Status::Ok();
  if (!binary) {
    std::error_code ec;
    const auto file_bytes = fs::file_size(path, ec);
    const double body_bytes = static_cast<double>(file_bytes) - static_cast<double>(in.tellg());
    double values = 0.0;  // double: 2^64 elements times their properties cannot overflow
    for (const PlyElement& element : elements) {
      values += static_cast<double>(element.count) * element.properties.size();
    }
    if (ec || 2.0 * values - 1.0 <= body_bytes) return Status::Ok();
    return Status::Error(
        path + ": truncated PLY: its header promises " +
        std::to_string(static_cast<unsigned long long>(values)) + " values, more than the " +
        std::to_string(static_cast<long long>(body_bytes)) + " bytes after the header can hold");
  }
  for (const PlyElement& element : elements) {
    if (element.properties.empty()) continue;
    for (unsigned long long i = 0; i < element.count; ++i) {
      for (const PlyProperty& property : element.properties) {
        if (property.item_size == 0) {
          in.ignore(property.size);
          continue;
        }
        unsigned char bytes[8] = {};
        in.read(reinterpret_cast<char*>(bytes), property.size);
        unsigned long long length = 0;
        for (int b = 0; b < property.size; ++b) {
          length |= static_cast<unsigned long long>(bytes[big_endian ? property.size - 1 - b : b])
                    << (8 * b);
        }
        constexpr auto kMax = static_cast<unsigned long long>(
            std::numeric_limits<std::streamsize>::max());  // ignore(): read to the end
        in.ignore(static_cast<std::streamsize>(
            length > kMax / property.item_size ? kMax : length * property.item_size));
      }
      if (!in.good()) {  // ignore() past the end sets only eofbit
        return Status::Error(path + ": truncated PLY: it ends in " + element.name + " " +
                             std::to_string(i) + " of the " + std::to_string(element.count) +
                             " its header promises");
      }
    }
  }
  return Status::Ok();
}

// Assimp's error message on one line.
std::string OneLine(std::string text) {
  std::replace(text.begin(), text.end(), '\n', ' ');
  std::replace(text.begin(), text.end(), '\r', ' ');
  while (!text.empty() && text.back() == ' ') text.pop_back();
  return text.empty() ? "unknown error" : text;
}

// An image file (grey, BGR or BGRA as OpenCV reads it; 8 or 16 bits) as RGBA8.
Status ReadTextureRgba(const std::string& path, cv::Mat* rgba) {
  cv::Mat image;
  FRESCO_RETURN_IF_ERROR(ReadImage(path, &image, cv::IMREAD_UNCHANGED));
  if (image.depth() == CV_16U) image.convertTo(image, CV_8U, 1.0 / 257.0);
  const int channels = image.channels();
  if (image.depth() != CV_8U || (channels != 1 && channels != 3 && channels != 4)) {
    return Status::Error(path + ": expected an 8- or 16-bit grey, RGB or RGBA image");
  }
  static constexpr int kToRgba[5] = {-1, cv::COLOR_GRAY2RGBA, -1, cv::COLOR_BGR2RGBA,
                                     cv::COLOR_BGRA2RGBA};
  cv::cvtColor(image, *rgba, kToRgba[channels]);
  return Status::Ok();
}

// "mesh 2 'name': " when there are several meshes (OBJ groups), "" for one.
std::string MeshContext(const aiScene& ai, unsigned m) {
  if (ai.mNumMeshes <= 1) return "";
  return "mesh " + std::to_string(m) + " '" + ai.mMeshes[m]->mName.C_Str() + "': ";
}

// Every face index names a vertex of its mesh (Assimp's PLY reader does not check).
Status CheckFaceIndices(const std::string& path, const aiScene& ai) {
  for (unsigned m = 0; m < ai.mNumMeshes; ++m) {
    const aiMesh& mesh = *ai.mMeshes[m];
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      const aiFace& face = mesh.mFaces[f];
      for (unsigned k = 0; k < face.mNumIndices; ++k) {
        if (face.mIndices[k] >= mesh.mNumVertices) {
          return Status::Error(path + ": " + MeshContext(ai, m) + "face " + std::to_string(f) +
                               ": vertex " + std::to_string(face.mIndices[k]) + " out of range (" +
                               std::to_string(mesh.mNumVertices) + " vertices)");
        }
      }
    }
  }
  return Status::Ok();
}

// Fills a Scene from Assimp's meshes, in their order (the file's for PLY and OBJ).
class MeshSceneBuilder {
 public:
  MeshSceneBuilder(const std::string& path, const SceneLoadOptions& options, const aiScene& ai,
                   Scene* scene)
      : path_(path), options_(options), ai_(ai), scene_(*scene) {}

  Status Build() {
    Material white;
    white.name = "default";
    scene_.materials.push_back(white);
    for (unsigned m = 0; m < ai_.mNumMeshes; ++m) FRESCO_RETURN_IF_ERROR(AddMesh(m));
    if (scene_.mesh.triangles.empty()) {
      return Error("no triangles (" + std::to_string(scene_.skipped_primitives) +
                   " point/line faces skipped, " + std::to_string(scene_.dropped_degenerate) +
                   " degenerate triangles dropped)");
    }
    // Local origin: the vertices (world coordinates so far) as a (3, V) matrix.
    std::vector<Eigen::Vector3d>& vertices = scene_.mesh.vertices;
    const Eigen::Map<const Eigen::Matrix3Xd> world(vertices[0].data(), 3,
                                                   static_cast<Eigen::Index>(vertices.size()));
    scene_.origin_in_world =
        options_.recentre
            ? Eigen::Vector3d(0.5 * (world.rowwise().minCoeff() + world.rowwise().maxCoeff()))
            : Eigen::Vector3d::Zero();
    for (Eigen::Vector3d& v : vertices) v -= scene_.origin_in_world;
    return Status::Ok();
  }

 private:
  Status Error(const std::string& what) const { return Status::Error(path_ + ": " + what); }

  // Appends mesh `m`'s triangles (file order) and the vertices they use (vertex order).
  Status AddMesh(unsigned m) {
    const aiMesh& mesh = *ai_.mMeshes[m];
    const std::string where = MeshContext(ai_, m);
    const bool has_uv = mesh.HasTextureCoords(0);
    auto position = [&](unsigned v) {
      const aiVector3D& p = mesh.mVertices[v];
      return Eigen::Vector3d(p.x, p.y, p.z);
    };
    std::vector<int> new_index(mesh.mNumVertices, -1);
    std::vector<unsigned> kept;  // face indices
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      const aiFace& face = mesh.mFaces[f];
      if (face.mNumIndices != 3) {  // points and lines: polygons are triangulated by now
        ++scene_.skipped_primitives;
        continue;
      }
      for (unsigned k = 0; k < 3; ++k) {
        const unsigned v = face.mIndices[k];
        if (!position(v).allFinite()) {
          return Error(where + "vertex " + std::to_string(v) + " is not finite");
        }
        const aiVector3D* uv = has_uv ? &mesh.mTextureCoords[0][v] : nullptr;
        if (uv && !(std::isfinite(uv->x) && std::isfinite(uv->y))) {
          return Error(where + "the UV of vertex " + std::to_string(v) + " is not finite");
        }
      }
      const Eigen::Vector3d corner0 = position(face.mIndices[0]);
      const double area =
          0.5 *
          (position(face.mIndices[1]) - corner0).cross(position(face.mIndices[2]) - corner0).norm();
      if (!(area >= options_.min_triangle_area_m2)) {
        ++scene_.dropped_degenerate;
        continue;
      }
      for (unsigned k = 0; k < 3; ++k) new_index[face.mIndices[k]] = 0;
      kept.push_back(f);
    }
    if (kept.empty()) return Status::Ok();

    TriangleMesh& out = scene_.mesh;
    out.vertices.reserve(out.vertices.size() + mesh.mNumVertices);
    out.triangles.reserve(out.triangles.size() + kept.size());
    out.uvs.reserve(out.uvs.size() + kept.size());
    out.material.reserve(out.material.size() + kept.size());
    out.has_uv.reserve(out.has_uv.size() + kept.size());
    for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
      if (new_index[v] < 0) continue;
      new_index[v] = static_cast<int>(out.vertices.size());
      out.vertices.push_back(position(v));
    }
    const int material = MaterialFor(mesh.mMaterialIndex);
    for (unsigned f : kept) {
      const unsigned* corners = mesh.mFaces[f].mIndices;
      out.triangles.emplace_back(new_index[corners[0]], new_index[corners[1]],
                                 new_index[corners[2]]);
      std::array<Eigen::Vector2f, 3> uvs;
      for (int k = 0; k < 3; ++k) {
        const aiVector3D* uv = has_uv ? &mesh.mTextureCoords[0][corners[k]] : nullptr;
        // The file's v = 0 is the image's bottom, glTF's the top.
        uvs[k] = uv ? Eigen::Vector2f(uv->x, 1.0f - uv->y) : Eigen::Vector2f::Zero();
      }
      out.uvs.push_back(uvs);
      out.material.push_back(material);
      out.has_uv.push_back(has_uv);
    }
    return Status::Ok();
  }

  // The scene material for Assimp material `index`: a textured white one when the file's
  // material has a diffuse texture that can be read, else the default (0).
  int MaterialFor(unsigned index) {
    const auto found = material_of_.find(index);
    if (found != material_of_.end()) return found->second;
    int material = 0;
    aiString file;
    if (index < ai_.mNumMaterials &&
        ai_.mMaterials[index]->GetTexture(aiTextureType_DIFFUSE, 0, &file) == AI_SUCCESS) {
      const std::string name = ai_.mMaterials[index]->GetName().C_Str();
      const int texture = TextureFor(file.C_Str(), "material '" + name + "'");
      if (texture >= 0) {
        Material textured;
        textured.name = name;
        textured.base_color_texture = texture;
        material = static_cast<int>(scene_.materials.size());
        scene_.materials.push_back(textured);
      }
    }
    material_of_[index] = material;
    return material;
  }

  // The scene texture for an image file named by a material (relative to the model's folder;
  // Windows separators accepted), decoded once; -1 with a warning when it cannot be read.
  int TextureFor(std::string file, const std::string& material) {
    std::replace(file.begin(), file.end(), '\\', '/');
    const std::string image_path = (fs::path(path_).parent_path() / file).string();
    const auto found = texture_of_.find(image_path);
    if (found != texture_of_.end()) return found->second;
    Texture texture;
    texture.name = fs::path(file).filename().string();
    const Status read = file.rfind('*', 0) == 0
                            ? Status::Error(file + ": embedded textures are not read")
                            : ReadTextureRgba(image_path, &texture.rgba);
    int index = -1;
    if (read.ok()) {
      index = static_cast<int>(scene_.textures.size());
      scene_.textures.push_back(std::move(texture));
    } else {
      scene_.warnings.push_back(material + ": texture not used: " + read.message());
    }
    texture_of_[image_path] = index;
    return index;
  }

  const std::string& path_;
  const SceneLoadOptions& options_;
  const aiScene& ai_;
  Scene& scene_;
  std::map<unsigned, int> material_of_;    // Assimp material -> Scene::materials index
  std::map<std::string, int> texture_of_;  // image path -> Scene::textures index or -1
};

// A plain binary little-endian PLY, the kind OpenMVS and COLMAP write (vertices with scalar
// properties, float x, y, z among them; one face element of triangles, its only property a
// list of 8-bit counts and 32-bit indices; no texture), read into the aiScene Assimp's PLY
// reader makes of it: one mesh, the vertices and faces in the file's order. Without Assimp's
// parsing of the header and of each value (a third of a run's set-up on a 175k-triangle
// mesh). False for any other file (or one shorter than its header says): Assimp reads it.
bool ReadPlainBinaryPly(const std::string& path, aiScene* ai) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  if (!std::getline(in, line) || line != "ply") return false;
  int vertex_bytes = 0, xyz_offset[3] = {-1, -1, -1};
  unsigned long long num_vertices = 0, num_faces = 0;
  int element = -1;  // 0 vertex, 1 face
  bool format = false, face_list = false;
  while (std::getline(in, line)) {
    std::istringstream words(line);
    std::string keyword, a, b, c, d;
    words >> keyword >> a;
    if (keyword == "format") {
      if (a != "binary_little_endian") return false;
      format = true;
    } else if (keyword == "comment") {
      if (line.find("TextureFile") != std::string::npos) return false;
    } else if (keyword == "element") {
      words >> b;
      const unsigned long long count = std::strtoull(b.c_str(), nullptr, 10);
      if (a == "vertex" && element == -1) {
        element = 0, num_vertices = count;
      } else if (a == "face" && element == 0) {
        element = 1, num_faces = count;
      } else {
        return false;
      }
    } else if (keyword == "property" && element == 0) {
      words >> b;
      const int size = PlyTypeSize(a);
      if (size == 0 || a == "list") return false;
      for (int k = 0; k < 3; ++k)
        if (b == std::string(1, "xyz"[k])) {
          if (a != "float" && a != "float32") return false;
          xyz_offset[k] = vertex_bytes;
        }
      if (b == "u" || b == "v" || b == "s" || b == "t" || b.rfind("texture", 0) == 0) return false;
      vertex_bytes += size;
    } else if (keyword == "property" && element == 1) {
      words >> b >> c >> d;
      if (face_list || a != "list" || PlyTypeSize(b) != 1 || PlyTypeSize(c) != 4 ||
          (c != "int" && c != "int32" && c != "uint" && c != "uint32") ||
          (d != "vertex_indices" && d != "vertex_index"))
        return false;
      face_list = true;
    } else if (keyword == "end_header") {
      break;
    } else if (keyword != "obj_info") {
      return false;
    }
  }
  if (!format || element != 1 || !face_list || xyz_offset[0] < 0 || xyz_offset[1] < 0 ||
      xyz_offset[2] < 0 || num_faces == 0)
    return false;
  std::error_code ec;
  const unsigned long long file_bytes = fs::file_size(path, ec);
  const std::streamoff header = in.tellg();
  if (ec || header < 0) return false;
  // Every face a triangle: 13 bytes each.
  const unsigned long long body = num_vertices * vertex_bytes + num_faces * 13;
  if (num_vertices > (1ULL << 31) || num_faces > (1ULL << 31) ||
      file_bytes != static_cast<unsigned long long>(header) + body)
    return false;
  std::string bytes(body, '\0');
  if (!in.read(bytes.data(), static_cast<std::streamsize>(body))) return false;
  const char* face_bytes = bytes.data() + num_vertices * vertex_bytes;
  for (unsigned long long f = 0; f < num_faces; ++f)
    if (static_cast<unsigned char>(face_bytes[13 * f]) != 3) return false;
  auto mesh = std::make_unique<aiMesh>();
  mesh->mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
  mesh->mNumVertices = static_cast<unsigned>(num_vertices);
  mesh->mVertices = new aiVector3D[num_vertices];
  for (unsigned long long v = 0; v < num_vertices; ++v) {
    const char* vertex = bytes.data() + v * vertex_bytes;
    float xyz[3];
    for (int k = 0; k < 3; ++k) std::memcpy(&xyz[k], vertex + xyz_offset[k], sizeof(float));
    mesh->mVertices[v] = aiVector3D(xyz[0], xyz[1], xyz[2]);
  }
  mesh->mNumFaces = static_cast<unsigned>(num_faces);
  mesh->mFaces = new aiFace[num_faces];
  for (unsigned long long f = 0; f < num_faces; ++f) {
    aiFace& face = mesh->mFaces[f];
    face.mNumIndices = 3;
    face.mIndices = new unsigned[3];
    std::memcpy(face.mIndices, face_bytes + 13 * f + 1, 3 * sizeof(unsigned));
  }
  ai->mNumMeshes = 1;
  ai->mMeshes = new aiMesh*[1];
  ai->mMeshes[0] = mesh.release();
  return true;
}

Status BuildMeshScene(const std::string& path, const SceneLoadOptions& options, const aiScene& ai,
                      Scene* scene) {
  Scene loaded;
  loaded.source_path = path;
  MeshSceneBuilder builder(path, options, ai, &loaded);
  FRESCO_RETURN_IF_ERROR(builder.Build());
  *scene = std::move(loaded);
  return Status::Ok();
}

Status LoadMeshScene(const std::string& path, const SceneLoadOptions& options, bool through_assimp,
                     Scene* scene) {
  if (!(options.min_triangle_area_m2 >= 0.0)) {
    return Status::Error(path + ": min_triangle_area_m2 must be >= 0");
  }
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return Status::Error(path + ": file not found");
  const std::string ext = LowercaseExtension(path);
  // A plain binary PLY is read here (its length checked exactly), any other through Assimp.
  aiScene plain;
  if (ext == ".ply" && !through_assimp && ReadPlainBinaryPly(path, &plain)) {
    FRESCO_RETURN_IF_ERROR(CheckFaceIndices(path, plain));
    return BuildMeshScene(path, options, plain, scene);
  }
  if (ext == ".ply") FRESCO_RETURN_IF_ERROR(CheckPlyLength(path));
  // Face indices are checked before triangulation reads vertices through them (it crashed on
  // a truncated binary PLY before the length check). No other step: none that reorders faces,
  // welds vertices or changes coordinates.
  Assimp::Importer importer;
  const aiScene* ai = importer.ReadFile(path, 0);
  if (ai) FRESCO_RETURN_IF_ERROR(CheckFaceIndices(path, *ai));
  if (ai) ai = importer.ApplyPostProcessing(aiProcess_Triangulate);
  if (!ai) {
    std::string format = ext.empty() ? "mesh" : ext.substr(1);
    for (char& c : format) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    return Status::Error(path + ": cannot read " + format + ": " +
                         OneLine(importer.GetErrorString()));
  }
  return BuildMeshScene(path, options, *ai, scene);
}

}  // namespace

Status LoadMeshScene(const std::string& path, const SceneLoadOptions& options, Scene* scene) {
  return LoadMeshScene(path, options, /*through_assimp=*/false, scene);
}

Status LoadMeshSceneThroughAssimp(const std::string& path, const SceneLoadOptions& options,
                                  Scene* scene) {
  return LoadMeshScene(path, options, /*through_assimp=*/true, scene);
}

Status LoadScene(const std::string& path, const SceneLoadOptions& options, Scene* scene) {
  const std::string ext = LowercaseExtension(path);
  if (ext == ".gltf" || ext == ".glb") return LoadGltfScene(path, options, scene);
  if (ext == ".ply" || ext == ".obj") return LoadMeshScene(path, options, scene);
  return Status::Error(path + ": unknown scene format '" + ext +
                       "' (glTF .gltf/.glb, PLY .ply or OBJ .obj)");
}

}  // namespace fresco
