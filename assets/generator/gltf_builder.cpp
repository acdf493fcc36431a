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
bool write_png_file(const std::string* base_path, const std::string* file_name, const tinygltf::Image* image,
                    bool /*embed*/, std::string* out_uri, void* /*user*/) {
  const std::string path = (std::filesystem::path(*base_path) / *file_name).string();
  *out_uri = *file_name;
  return stbi_write_png(path.c_str(), image->width, image->height, image->component,
                        image->image.data(), image->width * image->component) != 0;
}

}  // namespace

MaterialDesc plain_material(const std::string& name, const glm::vec3& color, float roughness) {
  MaterialDesc desc;
  desc.name = name;
  desc.base_color = glm::vec4(color, 1.0f);
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

void SceneBuilder::use_extension(const std::string& extension) {
  auto& used = model_.extensionsUsed;
  if (std::find(used.begin(), used.end(), extension) == used.end()) used.push_back(extension);
}

int SceneBuilder::add_texture(ByteImage image, const std::string& file_stem) {
  if (model_.samplers.empty()) {  // one repeating, trilinear sampler shared by every texture
    tinygltf::Sampler sampler;
    sampler.magFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
    sampler.minFilter = TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_LINEAR;
    model_.samplers.push_back(sampler);
  }
  tinygltf::Image gltf_image;
  gltf_image.name = file_stem;
  gltf_image.uri = file_stem + ".png";
  gltf_image.width = image.width;
  gltf_image.height = image.height;
  gltf_image.component = image.channels;
  gltf_image.bits = 8;
  gltf_image.pixel_type = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
  gltf_image.image = std::move(image.data);
  model_.images.push_back(std::move(gltf_image));
  tinygltf::Texture texture;
  texture.sampler = 0;
  texture.source = int(model_.images.size()) - 1;
  model_.textures.push_back(texture);
  return int(model_.textures.size()) - 1;
}

tinygltf::TextureInfo SceneBuilder::texture_info(int texture, const MaterialDesc& desc) {
  tinygltf::TextureInfo info;
  info.index = texture;
  if (desc.uv_scale != glm::vec2(1.0f)) {
    use_extension("KHR_texture_transform");
    Object transform;
    transform["scale"] = tinygltf::Value(tinygltf::Value::Array{number(desc.uv_scale.x), number(desc.uv_scale.y)});
    info.extensions["KHR_texture_transform"] = tinygltf::Value(transform);
  }
  return info;
}

int SceneBuilder::add_material(const MaterialDesc& d) {
  tinygltf::Material m;
  m.name = d.name;
  auto& pbr = m.pbrMetallicRoughness;
  pbr.baseColorFactor = tidy({d.base_color.r, d.base_color.g, d.base_color.b, d.base_color.a});
  pbr.metallicFactor = tidy(d.metallic);
  pbr.roughnessFactor = tidy(d.roughness);
  if (d.base_color_texture >= 0) pbr.baseColorTexture = texture_info(d.base_color_texture, d);
  if (d.metallic_roughness_texture >= 0) pbr.metallicRoughnessTexture = texture_info(d.metallic_roughness_texture, d);
  if (d.normal_texture >= 0) {
    tinygltf::TextureInfo info = texture_info(d.normal_texture, d);
    m.normalTexture.index = info.index;
    m.normalTexture.scale = tidy(d.normal_scale);
    m.normalTexture.extensions = info.extensions;
  }
  m.emissiveFactor = tidy({d.emissive.r, d.emissive.g, d.emissive.b});
  if (d.emissive_strength != 1.0f) {
    use_extension("KHR_materials_emissive_strength");
    m.extensions["KHR_materials_emissive_strength"] =
        tinygltf::Value(Object{{"emissiveStrength", number(d.emissive_strength)}});
  }
  if (d.transmission > 0.0f) {
    use_extension("KHR_materials_transmission");
    m.extensions["KHR_materials_transmission"] =
        tinygltf::Value(Object{{"transmissionFactor", number(d.transmission)}});
  }
  if (d.transmission > 0.0f || d.ior != 1.5f) {
    use_extension("KHR_materials_ior");
    m.extensions["KHR_materials_ior"] = tinygltf::Value(Object{{"ior", number(d.ior)}});
  }
  if (d.use_specular) {
    use_extension("KHR_materials_specular");
    Object specular{{"specularFactor", number(d.specular)},
                    {"specularColorFactor", tinygltf::Value(tinygltf::Value::Array{
                        number(d.specular_color.r), number(d.specular_color.g), number(d.specular_color.b)})}};
    if (d.specular_texture >= 0) {
      Object info{{"index", tinygltf::Value(d.specular_texture)}};
      tinygltf::TextureInfo transformed = texture_info(d.specular_texture, d);
      if (!transformed.extensions.empty())
        info["extensions"] = tinygltf::Value(Object(transformed.extensions.begin(), transformed.extensions.end()));
      specular["specularTexture"] = tinygltf::Value(info);
    }
    m.extensions["KHR_materials_specular"] = tinygltf::Value(specular);
  }
  if (d.clearcoat > 0.0f) {
    use_extension("KHR_materials_clearcoat");
    m.extensions["KHR_materials_clearcoat"] = tinygltf::Value(Object{
        {"clearcoatFactor", number(d.clearcoat)}, {"clearcoatRoughnessFactor", number(d.clearcoat_roughness)}});
  }
  m.doubleSided = d.doubleSided;
  if (d.alpha_mask) {
    m.alphaMode = "MASK";
    m.alphaCutoff = tidy(d.alpha_cutoff);
  }
  model_.materials.push_back(m);
  return int(model_.materials.size()) - 1;
}

int SceneBuilder::add_accessor(const void* bytes, size_t byte_count, size_t count, int component_type,
                               int type, int target) {
  auto& buffer = model_.buffers[0].data;
  while (buffer.size() % 4 != 0) buffer.push_back(0);  // every accessor starts 4-byte aligned
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = buffer.size();
  view.byteLength = byte_count;
  view.target = target;
  const auto* begin = static_cast<const unsigned char*>(bytes);
  buffer.insert(buffer.end(), begin, begin + byte_count);
  model_.bufferViews.push_back(view);
  tinygltf::Accessor accessor;
  accessor.bufferView = int(model_.bufferViews.size()) - 1;
  accessor.componentType = component_type;
  accessor.type = type;
  accessor.count = count;
  model_.accessors.push_back(accessor);
  return int(model_.accessors.size()) - 1;
}

int SceneBuilder::add_mesh(const std::string& name, const MeshData& data, int material) {
  tinygltf::Primitive primitive;
  primitive.mode = TINYGLTF_MODE_TRIANGLES;
  primitive.material = material;
  const size_t n = data.positions.size();
  int position = add_accessor(data.positions.data(), n * sizeof(glm::vec3), n, TINYGLTF_COMPONENT_TYPE_FLOAT,
                              TINYGLTF_TYPE_VEC3, TINYGLTF_TARGET_ARRAY_BUFFER);
  glm::vec3 lo(INFINITY), hi(-INFINITY);
  for (const glm::vec3& p : data.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
  // min/max must bound the stored floats exactly, so they are not rounded.
  model_.accessors[position].minValues = {lo.x, lo.y, lo.z};
  model_.accessors[position].maxValues = {hi.x, hi.y, hi.z};
  primitive.attributes["POSITION"] = position;
  primitive.attributes["NORMAL"] = add_accessor(data.normals.data(), n * sizeof(glm::vec3), n,
                                                TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3,
                                                TINYGLTF_TARGET_ARRAY_BUFFER);
  primitive.attributes["TEXCOORD_0"] = add_accessor(data.uvs.data(), n * sizeof(glm::vec2), n,
                                                    TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC2,
                                                    TINYGLTF_TARGET_ARRAY_BUFFER);
  if (n <= 65535) {
    std::vector<uint16_t> short_indices(data.indices.begin(), data.indices.end());
    primitive.indices = add_accessor(short_indices.data(), short_indices.size() * 2, short_indices.size(),
                                     TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, TINYGLTF_TYPE_SCALAR,
                                     TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
  } else {
    primitive.indices = add_accessor(data.indices.data(), data.indices.size() * 4, data.indices.size(),
                                     TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR,
                                     TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
  }
  tinygltf::Mesh mesh;
  mesh.name = name;
  mesh.primitives.push_back(primitive);
  model_.meshes.push_back(mesh);
  triangles_ += data.triangle_count();
  return int(model_.meshes.size()) - 1;
}

int SceneBuilder::add_node(const std::string& name, int mesh, const glm::vec3& t, const glm::quat& r,
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

int SceneBuilder::add_object(const std::string& name, const MeshData& data, int material) {
  return add_node(name, add_mesh(name, data, material));
}

// Rotation whose -Z axis points along `forward` and whose +Y is as close to world up as possible.
static glm::quat look_rotation(const glm::vec3& forward) {
  const glm::vec3 back = -glm::normalize(forward);
  const glm::vec3 world_up = std::abs(back.y) > 0.999f ? glm::vec3(0, 0, -1) : glm::vec3(0, 1, 0);
  const glm::vec3 right = glm::normalize(glm::cross(world_up, back));
  const glm::vec3 up = glm::cross(back, right);
  return glm::normalize(glm::quat_cast(glm::mat3(right, up, back)));
}

void SceneBuilder::set_camera(const glm::vec3& eye, const glm::vec3& target, float yfov, float aspect_ratio) {
  tinygltf::Camera camera;
  camera.type = "perspective";
  camera.name = "camera";
  camera.perspective.yfov = tidy(yfov);
  camera.perspective.aspectRatio = tidy(aspect_ratio);
  camera.perspective.znear = 0.01;
  camera.perspective.zfar = 1000.0;
  model_.cameras.push_back(camera);
  int node = add_node("camera", -1, eye, look_rotation(target - eye));
  model_.nodes[node].camera = int(model_.cameras.size()) - 1;
}

void SceneBuilder::add_sun(const std::string& name, const glm::vec3& direction, const glm::vec3& color,
                           float intensity) {
  tinygltf::Light light;
  light.name = name;
  light.type = "directional";
  light.color = tidy({color.r, color.g, color.b});
  light.intensity = tidy(intensity);
  model_.lights.push_back(light);
  use_extension("KHR_lights_punctual");
  int node = add_node(name, -1, glm::vec3(0.0f), look_rotation(direction));
  model_.nodes[node].extensions["KHR_lights_punctual"] =
      tinygltf::Value(Object{{"light", tinygltf::Value(int(model_.lights.size()) - 1)}});
}

void SceneBuilder::set_render_defaults(bool all_hv, int width, int height) {
  Object pxf;
  if (all_hv) pxf["all_hv"] = tinygltf::Value(true);
  if (width > 0) pxf["width"] = tinygltf::Value(width);
  if (height > 0) pxf["height"] = tinygltf::Value(height);
  model_.scenes[0].extras = tinygltf::Value(Object{{"pxf", tinygltf::Value(pxf)}});
}

void SceneBuilder::write(const std::string& dir) const {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw Error(dir + ": cannot create directory: " + ec.message());
  tinygltf::TinyGLTF writer;
  writer.SetImageWriter(&write_png_file, nullptr);
  const std::string path = (std::filesystem::path(dir) / (name_ + ".gltf")).string();
  if (!writer.WriteGltfSceneToFile(&model_, path, /*embedImages=*/false, /*embedBuffers=*/false,
                                   /*prettyPrint=*/true, /*writeBinary=*/false))
    throw Error(path + ": tinygltf could not write the scene");
}

}  // namespace pxf::scenegen
