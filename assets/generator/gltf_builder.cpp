#include "gltf_builder.h"

#include <stb_image_write.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <glm/gtc/matrix_transform.hpp>

namespace pxf::scenegen {
namespace {

using Object = tinygltf::Value::Object;

// JSON numbers are written with the shortest round-trip form; rounding to 6 decimals keeps the
// .gltf readable (0.1 rather than 0.10000000149011612).
double tidy(double v) {
  double r = std::round(v * 1e6) / 1e6;
  return r == 0.0 ? 0.0 : r;  // no "-0"
}

std::vector<double> tidy(std::initializer_list<float> values) {
  std::vector<double> out;
  for (float v : values) out.push_back(tidy(v));
  return out;
}

tinygltf::Value number(float v) { return tinygltf::Value(tidy(v)); }

// PNGs are written by stb (deterministic zlib stream); the model only records the file name.
bool writePng(const std::string* basePath, const std::string* fileName, const tinygltf::Image* image,
              bool /*embed*/, std::string* outUri, void* /*user*/) {
  const std::string path = (std::filesystem::path(*basePath) / *fileName).string();
  *outUri = *fileName;
  return stbi_write_png(path.c_str(), image->width, image->height, image->component,
                        image->image.data(), image->width * image->component) != 0;
}

}  // namespace

MaterialDesc plainMaterial(const std::string& name, const glm::vec3& color, float roughness) {
  MaterialDesc desc;
  desc.name = name;
  desc.baseColor = glm::vec4(color, 1.0f);
  desc.roughness = roughness;
  return desc;
}

SceneBuilder::SceneBuilder(std::string name) : name_(std::move(name)) {
  model_.asset.version = "2.0";
  model_.asset.generator = "pxf scenegen (assets/generator)";
  model_.buffers.emplace_back();
  model_.buffers[0].uri = name_ + ".bin";
  tinygltf::Scene scene;
  scene.name = name_;
  model_.scenes.push_back(scene);
  model_.defaultScene = 0;
}

void SceneBuilder::useExtension(const std::string& extension) {
  auto& used = model_.extensionsUsed;
  if (std::find(used.begin(), used.end(), extension) == used.end()) used.push_back(extension);
}

int SceneBuilder::addTexture(ByteImage image, const std::string& fileStem) {
  if (model_.samplers.empty()) {  // one repeating, trilinear sampler shared by every texture
    tinygltf::Sampler sampler;
    sampler.magFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
    sampler.minFilter = TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_LINEAR;
    model_.samplers.push_back(sampler);
  }
  tinygltf::Image gltfImage;
  gltfImage.name = fileStem;
  gltfImage.uri = fileStem + ".png";
  gltfImage.width = image.width;
  gltfImage.height = image.height;
  gltfImage.component = image.channels;
  gltfImage.bits = 8;
  gltfImage.pixel_type = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
  gltfImage.image = std::move(image.data);
  model_.images.push_back(std::move(gltfImage));
  tinygltf::Texture texture;
  texture.sampler = 0;
  texture.source = int(model_.images.size()) - 1;
  model_.textures.push_back(texture);
  return int(model_.textures.size()) - 1;
}

tinygltf::TextureInfo SceneBuilder::textureInfo(int texture, const MaterialDesc& desc) {
  tinygltf::TextureInfo info;
  info.index = texture;
  if (desc.uvScale != glm::vec2(1.0f)) {
    useExtension("KHR_texture_transform");
    Object transform;
    transform["scale"] = tinygltf::Value(tinygltf::Value::Array{number(desc.uvScale.x), number(desc.uvScale.y)});
    info.extensions["KHR_texture_transform"] = tinygltf::Value(transform);
  }
  return info;
}

int SceneBuilder::addMaterial(const MaterialDesc& d) {
  tinygltf::Material m;
  m.name = d.name;
  auto& pbr = m.pbrMetallicRoughness;
  pbr.baseColorFactor = tidy({d.baseColor.r, d.baseColor.g, d.baseColor.b, d.baseColor.a});
  pbr.metallicFactor = tidy(d.metallic);
  pbr.roughnessFactor = tidy(d.roughness);
  if (d.baseColorTexture >= 0) pbr.baseColorTexture = textureInfo(d.baseColorTexture, d);
  if (d.metallicRoughnessTexture >= 0) pbr.metallicRoughnessTexture = textureInfo(d.metallicRoughnessTexture, d);
  if (d.normalTexture >= 0) {
    tinygltf::TextureInfo info = textureInfo(d.normalTexture, d);
    m.normalTexture.index = info.index;
    m.normalTexture.scale = tidy(d.normalScale);
    m.normalTexture.extensions = info.extensions;
  }
  m.emissiveFactor = tidy({d.emissive.r, d.emissive.g, d.emissive.b});
  if (d.emissiveStrength != 1.0f) {
    useExtension("KHR_materials_emissive_strength");
    m.extensions["KHR_materials_emissive_strength"] =
        tinygltf::Value(Object{{"emissiveStrength", number(d.emissiveStrength)}});
  }
  if (d.transmission > 0.0f) {
    useExtension("KHR_materials_transmission");
    m.extensions["KHR_materials_transmission"] =
        tinygltf::Value(Object{{"transmissionFactor", number(d.transmission)}});
  }
  if (d.transmission > 0.0f || d.ior != 1.5f) {
    useExtension("KHR_materials_ior");
    m.extensions["KHR_materials_ior"] = tinygltf::Value(Object{{"ior", number(d.ior)}});
  }
  if (d.useSpecular) {
    useExtension("KHR_materials_specular");
    Object specular{{"specularFactor", number(d.specular)},
                    {"specularColorFactor", tinygltf::Value(tinygltf::Value::Array{
                        number(d.specularColor.r), number(d.specularColor.g), number(d.specularColor.b)})}};
    if (d.specularTexture >= 0) {
      Object info{{"index", tinygltf::Value(d.specularTexture)}};
      tinygltf::TextureInfo transformed = textureInfo(d.specularTexture, d);
      if (!transformed.extensions.empty())
        info["extensions"] = tinygltf::Value(Object(transformed.extensions.begin(), transformed.extensions.end()));
      specular["specularTexture"] = tinygltf::Value(info);
    }
    m.extensions["KHR_materials_specular"] = tinygltf::Value(specular);
  }
  m.doubleSided = d.doubleSided;
  if (d.alphaMask) {
    m.alphaMode = "MASK";
    m.alphaCutoff = tidy(d.alphaCutoff);
  }
  model_.materials.push_back(m);
  return int(model_.materials.size()) - 1;
}

int SceneBuilder::addAccessor(const void* bytes, size_t byteCount, size_t count, int componentType,
                              int type, int target) {
  auto& buffer = model_.buffers[0].data;
  while (buffer.size() % 4 != 0) buffer.push_back(0);  // every accessor starts 4-byte aligned
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = buffer.size();
  view.byteLength = byteCount;
  view.target = target;
  const auto* begin = static_cast<const unsigned char*>(bytes);
  buffer.insert(buffer.end(), begin, begin + byteCount);
  model_.bufferViews.push_back(view);
  tinygltf::Accessor accessor;
  accessor.bufferView = int(model_.bufferViews.size()) - 1;
  accessor.componentType = componentType;
  accessor.type = type;
  accessor.count = count;
  model_.accessors.push_back(accessor);
  return int(model_.accessors.size()) - 1;
}

int SceneBuilder::addMesh(const std::string& name, const MeshData& data, int material) {
  tinygltf::Primitive primitive;
  primitive.mode = TINYGLTF_MODE_TRIANGLES;
  primitive.material = material;
  const size_t n = data.positions.size();
  int position = addAccessor(data.positions.data(), n * sizeof(glm::vec3), n, TINYGLTF_COMPONENT_TYPE_FLOAT,
                             TINYGLTF_TYPE_VEC3, TINYGLTF_TARGET_ARRAY_BUFFER);
  glm::vec3 lo(INFINITY), hi(-INFINITY);
  for (const glm::vec3& p : data.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
  // min/max must bound the stored floats exactly, so they are not rounded.
  model_.accessors[position].minValues = {lo.x, lo.y, lo.z};
  model_.accessors[position].maxValues = {hi.x, hi.y, hi.z};
  primitive.attributes["POSITION"] = position;
  primitive.attributes["NORMAL"] = addAccessor(data.normals.data(), n * sizeof(glm::vec3), n,
                                               TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3,
                                               TINYGLTF_TARGET_ARRAY_BUFFER);
  primitive.attributes["TEXCOORD_0"] = addAccessor(data.uvs.data(), n * sizeof(glm::vec2), n,
                                                   TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC2,
                                                   TINYGLTF_TARGET_ARRAY_BUFFER);
  if (n <= 65535) {
    std::vector<uint16_t> shortIndices(data.indices.begin(), data.indices.end());
    primitive.indices = addAccessor(shortIndices.data(), shortIndices.size() * 2, shortIndices.size(),
                                    TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, TINYGLTF_TYPE_SCALAR,
                                    TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
  } else {
    primitive.indices = addAccessor(data.indices.data(), data.indices.size() * 4, data.indices.size(),
                                    TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR,
                                    TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
  }
  tinygltf::Mesh mesh;
  mesh.name = name;
  mesh.primitives.push_back(primitive);
  model_.meshes.push_back(mesh);
  triangles_ += data.triangleCount();
  return int(model_.meshes.size()) - 1;
}

int SceneBuilder::addNode(const std::string& name, int mesh, const glm::vec3& t, const glm::quat& r,
                          const glm::vec3& s) {
  tinygltf::Node node;
  node.name = name;
  node.mesh = mesh;
  if (t != glm::vec3(0.0f)) node.translation = tidy({t.x, t.y, t.z});
  if (r != glm::quat(1, 0, 0, 0)) node.rotation = tidy({r.x, r.y, r.z, r.w});
  if (s != glm::vec3(1.0f)) node.scale = tidy({s.x, s.y, s.z});
  model_.nodes.push_back(node);
  model_.scenes[0].nodes.push_back(int(model_.nodes.size()) - 1);
  return int(model_.nodes.size()) - 1;
}

int SceneBuilder::addObject(const std::string& name, const MeshData& data, int material) {
  return addNode(name, addMesh(name, data, material));
}

// Rotation whose -Z axis points along `forward` and whose +Y is as close to world up as possible.
static glm::quat lookRotation(const glm::vec3& forward) {
  const glm::vec3 back = -glm::normalize(forward);
  const glm::vec3 worldUp = std::abs(back.y) > 0.999f ? glm::vec3(0, 0, -1) : glm::vec3(0, 1, 0);
  const glm::vec3 right = glm::normalize(glm::cross(worldUp, back));
  const glm::vec3 up = glm::cross(back, right);
  return glm::normalize(glm::quat_cast(glm::mat3(right, up, back)));
}

void SceneBuilder::setCamera(const glm::vec3& eye, const glm::vec3& target, float yfov, float aspectRatio) {
  tinygltf::Camera camera;
  camera.type = "perspective";
  camera.name = "camera";
  camera.perspective.yfov = tidy(yfov);
  camera.perspective.aspectRatio = tidy(aspectRatio);
  camera.perspective.znear = 0.01;
  camera.perspective.zfar = 1000.0;
  model_.cameras.push_back(camera);
  int node = addNode("camera", -1, eye, lookRotation(target - eye));
  model_.nodes[node].camera = int(model_.cameras.size()) - 1;
}

void SceneBuilder::addSun(const std::string& name, const glm::vec3& direction, const glm::vec3& color,
                          float intensity) {
  tinygltf::Light light;
  light.name = name;
  light.type = "directional";
  light.color = tidy({color.r, color.g, color.b});
  light.intensity = tidy(intensity);
  model_.lights.push_back(light);
  useExtension("KHR_lights_punctual");
  int node = addNode(name, -1, glm::vec3(0.0f), lookRotation(direction));
  model_.nodes[node].extensions["KHR_lights_punctual"] =
      tinygltf::Value(Object{{"light", tinygltf::Value(int(model_.lights.size()) - 1)}});
}

void SceneBuilder::setRenderDefaults(bool allHv, int width, int height) {
  Object pxf;
  if (allHv) pxf["all_hv"] = tinygltf::Value(true);
  if (width > 0) pxf["width"] = tinygltf::Value(width);
  if (height > 0) pxf["height"] = tinygltf::Value(height);
  model_.scenes[0].extras = tinygltf::Value(Object{{"pxf", tinygltf::Value(pxf)}});
}

bool SceneBuilder::write(const std::string& dir, std::string* error) const {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) {
    *error = dir + ": cannot create directory: " + ec.message();
    return false;
  }
  tinygltf::TinyGLTF writer;
  writer.SetImageWriter(&writePng, nullptr);
  const std::string path = (std::filesystem::path(dir) / (name_ + ".gltf")).string();
  if (!writer.WriteGltfSceneToFile(&model_, path, /*embedImages=*/false, /*embedBuffers=*/false,
                                   /*prettyPrint=*/true, /*writeBinary=*/false)) {
    *error = path + ": tinygltf could not write the scene";
    return false;
  }
  return true;
}

}  // namespace pxf::scenegen
