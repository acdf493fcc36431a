// pxf_helmet_like: writes a GLB the size of Khronos' DamagedHelmet, for measuring load time and
// peak memory (scripts/measure_load.sh): one mesh of about 70k triangles (POSITION, NORMAL,
// TEXCOORD_0, 32-bit indices) and five 2048x2048 textures stored in the binary chunk, four JPEG
// (base color, metallic-roughness, normal, emissive) and one PNG (occlusion, which pxf does not
// read), about 6 MB in all. Deterministic: integer hashing, no clocks.
//
// Usage: pxf_helmet_like OUT.glb [texture-size]
#include <stb_image_write.h>
#include <tiny_gltf.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "texture.h"

namespace {

using pxf::scenegen::tileable_fbm;

void append(std::vector<unsigned char>& buffer, const void* data, size_t size) {
  const auto* bytes = static_cast<const unsigned char*>(data);
  buffer.insert(buffer.end(), bytes, bytes + size);
  while (buffer.size() % 4) buffer.push_back(0);
}

void write_to_vector(void* context, void* data, int size) {
  auto* out = static_cast<std::vector<unsigned char>*>(context);
  const auto* bytes = static_cast<const unsigned char*>(data);
  out->insert(out->end(), bytes, bytes + size);
}

// An RGB image from three noise fields (detail at several scales, as photographed textures have).
std::vector<unsigned char> noise_image(int size, uint32_t seed, float base, float amplitude) {
  std::vector<unsigned char> rgb(static_cast<size_t>(size) * size * 3);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x)
      for (int c = 0; c < 3; ++c) {
        float u = (x + 0.5f) / size, v = (y + 0.5f) / size;
        float n = tileable_fbm(u, v, 8, 6, 0.6f, seed + 17 * c);
        float value = std::fmin(std::fmax(base + amplitude * (n - 0.5f), 0.0f), 1.0f);
        rgb[(static_cast<size_t>(y) * size + x) * 3 + c] = static_cast<unsigned char>(value * 255.0f + 0.5f);
      }
  return rgb;
}

struct SphereMesh {
  std::vector<float> positions, normals, uvs;
  std::vector<uint32_t> indices;
};

SphereMesh helmet_sphere() {
  // A sphere of 256 x 138 quads: 70,656 triangles, 35,717 vertices (seam and poles duplicated).
  const int segments = 256, rings = 138;
  SphereMesh m;
  for (int r = 0; r <= rings; ++r)
    for (int s = 0; s <= segments; ++s) {
      float theta = 3.14159265f * r / rings, phi = 2.0f * 3.14159265f * s / segments;
      float nx = std::sin(theta) * std::cos(phi), ny = std::cos(theta), nz = std::sin(theta) * std::sin(phi);
      m.positions.insert(m.positions.end(), {nx, ny, nz});
      m.normals.insert(m.normals.end(), {nx, ny, nz});
      m.uvs.insert(m.uvs.end(), {static_cast<float>(s) / segments, static_cast<float>(r) / rings});
    }
  for (int r = 0; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      uint32_t a = r * (segments + 1) + s, b = a + segments + 1;
      m.indices.insert(m.indices.end(), {a, b, a + 1, a + 1, b, b + 1});
    }
  return m;
}

// The material (textures 0-4), the mesh of `primitive`, its node and the scene.
void add_helmet(tinygltf::Model& model, const tinygltf::Primitive& primitive) {
  tinygltf::Material material;
  material.name = "helmet";
  material.pbrMetallicRoughness.baseColorTexture.index = 0;
  material.pbrMetallicRoughness.metallicRoughnessTexture.index = 1;
  material.normalTexture.index = 2;
  material.emissiveTexture.index = 3;
  material.emissiveFactor = {1, 1, 1};
  material.occlusionTexture.index = 4;
  model.materials.push_back(material);

  tinygltf::Mesh mesh;
  mesh.name = "helmet";
  mesh.primitives.push_back(primitive);
  model.meshes.push_back(mesh);
  tinygltf::Node node;
  node.mesh = 0;
  model.nodes.push_back(node);
  tinygltf::Scene scene;
  scene.nodes = {0};
  model.scenes.push_back(scene);
  model.defaultScene = 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s OUT.glb [texture-size]\n", argv[0]);
    return 2;
  }
  const int tex_size = argc > 2 ? std::atoi(argv[2]) : 2048;
  if (tex_size < 1 || tex_size > 16384) {
    std::fprintf(stderr, "pxf_helmet_like: texture size must be in [1, 16384]\n");
    return 2;
  }

  const SphereMesh sphere = helmet_sphere();
  const std::vector<float>&positions = sphere.positions, &normals = sphere.normals, &uvs = sphere.uvs;
  const std::vector<uint32_t>& indices = sphere.indices;

  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "pxf_helmet_like";
  std::vector<unsigned char> bin;
  auto add_view = [&](const void* data, size_t size, int target) {
    tinygltf::BufferView view;
    view.buffer = 0;
    view.byteOffset = bin.size();
    view.byteLength = size;
    view.target = target;
    append(bin, data, size);
    model.bufferViews.push_back(view);
    return static_cast<int>(model.bufferViews.size()) - 1;
  };
  auto add_accessor = [&](const void* data, size_t size, size_t count, int component, int type, int target) {
    tinygltf::Accessor accessor;
    accessor.bufferView = add_view(data, size, target);
    accessor.componentType = component;
    accessor.count = count;
    accessor.type = type;
    if (type == TINYGLTF_TYPE_VEC3 && target == TINYGLTF_TARGET_ARRAY_BUFFER && data == positions.data()) {
      accessor.minValues = {-1, -1, -1};
      accessor.maxValues = {1, 1, 1};
    }
    model.accessors.push_back(accessor);
    return static_cast<int>(model.accessors.size()) - 1;
  };
  const size_t vertex_count = positions.size() / 3;
  tinygltf::Primitive primitive;
  primitive.attributes["POSITION"] = add_accessor(positions.data(), positions.size() * 4, vertex_count,
                                                  TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, TINYGLTF_TARGET_ARRAY_BUFFER);
  primitive.attributes["NORMAL"] = add_accessor(normals.data(), normals.size() * 4, vertex_count,
                                                TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, TINYGLTF_TARGET_ARRAY_BUFFER);
  primitive.attributes["TEXCOORD_0"] = add_accessor(uvs.data(), uvs.size() * 4, vertex_count,
                                                    TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC2, TINYGLTF_TARGET_ARRAY_BUFFER);
  primitive.indices = add_accessor(indices.data(), indices.size() * 4, indices.size(),
                                   TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR,
                                   TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
  primitive.material = 0;
  primitive.mode = TINYGLTF_MODE_TRIANGLES;

  // Textures: base color, metallic-roughness, normal, emissive as JPEG, occlusion as PNG.
  struct Spec {
    const char* name;
    float base, amplitude;
    bool png;
  };
  const Spec specs[] = {{"albedo", 0.5f, 0.9f, false},
                        {"metal_roughness", 0.5f, 1.0f, false},
                        {"normal", 0.6f, 0.5f, false},
                        {"emissive", 0.05f, 0.3f, false},
                        {"occlusion", 0.8f, 0.15f, true}};
  uint32_t seed = 1;
  for (const Spec& spec : specs) {
    std::vector<unsigned char> pixels = noise_image(tex_size, seed++, spec.base, spec.amplitude), encoded;
    bool ok = spec.png ? stbi_write_png_to_func(write_to_vector, &encoded, tex_size, tex_size, 3, pixels.data(), tex_size * 3)
                       : stbi_write_jpg_to_func(write_to_vector, &encoded, tex_size, tex_size, 3, pixels.data(), 90);
    if (!ok) {
      std::fprintf(stderr, "pxf_helmet_like: cannot encode %s\n", spec.name);
      return 1;
    }
    tinygltf::Image image;
    image.name = spec.name;
    image.mimeType = spec.png ? "image/png" : "image/jpeg";
    image.bufferView = add_view(encoded.data(), encoded.size(), 0);
    model.images.push_back(image);
    tinygltf::Texture texture;
    texture.source = static_cast<int>(model.images.size()) - 1;
    texture.sampler = 0;
    model.textures.push_back(texture);
  }
  tinygltf::Sampler sampler;
  sampler.magFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
  sampler.minFilter = TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_LINEAR;
  model.samplers.push_back(sampler);

  add_helmet(model, primitive);

  tinygltf::Buffer buffer;
  buffer.data = std::move(bin);
  model.buffers.push_back(std::move(buffer));
  tinygltf::TinyGLTF writer;
  if (!writer.WriteGltfSceneToFile(&model, argv[1], /*embedImages=*/false, /*embedBuffers=*/true,
                                   /*prettyPrint=*/false, /*writeBinary=*/true)) {
    std::fprintf(stderr, "pxf_helmet_like: cannot write %s\n", argv[1]);
    return 1;
  }
  std::printf("wrote %s: %zu triangles, 5 textures of %dx%d\n", argv[1], indices.size() / 3, tex_size, tex_size);
  return 0;
}
