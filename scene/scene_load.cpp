// glTF 2.0 scene loading (tinygltf) into the flattened world-space pxf::Scene, built-in scene
// lookup and environment maps. Bad input throws pxf::Error("<file>: <problem>"); anything we can
// render around (missing textures, bad triangles, unknown optional extensions) becomes one warning
// line in Scene::warnings.
#include <tiny_gltf.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <cstdio>
#include <cstring>
#include <functional>
#include <map>
#include <set>
#include <sstream>

#include <unistd.h>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "core/json_depth.h"
#include "core/parallel.h"
#include "image/image.h"
#include "image/input_file.h"
#include "scene/auto_camera.h"
#include "scene/default_light.h"
#include "scene/gltf_accessor.h"
#include "scene/gltf_draco.h"
#include "scene/gltf_geometry.h"
#include "scene/gltf_images.h"
#include "scene/gltf_instancing.h"
#include "scene/gltf_meshopt.h"
#include "scene/gltf_prepass.h"
#include "scene/load.h"
#include "scene/spec_gloss.h"
#include "scene/texture.h"

#ifndef PXF_ASSETS_FROM_BINDIR
#define PXF_ASSETS_FROM_BINDIR "../share/pxf/assets"
#endif
#ifndef PXF_ASSETS_DIR
#define PXF_ASSETS_DIR ""
#endif

namespace pxf {

size_t Scene::triangle_count() const {
  size_t count = 0;
  for (const Mesh& mesh : meshes) count += mesh.triangles.size();
  return count;
}

namespace {

namespace fs = std::filesystem;

const std::set<std::string>& supported_extensions() {
  static const std::set<std::string> names = {
      "KHR_lights_punctual",      "KHR_texture_transform", "KHR_materials_emissive_strength",
      "KHR_materials_transmission", "KHR_materials_ior",   "KHR_materials_specular",
      "KHR_materials_volume",     "KHR_materials_pbrSpecularGlossiness", "KHR_materials_clearcoat",
      "KHR_materials_sheen",
      "KHR_mesh_quantization",    "KHR_draco_mesh_compression", "EXT_meshopt_compression",
      "EXT_texture_webp",         "EXT_mesh_gpu_instancing"};
  return names;
}

struct BuiltinInfo {
  const char* name;
  const char* description;
};
const BuiltinInfo kBuiltins[] = {
    {"cornell", "Cornell box lit by its ceiling light (the source's test scene)"},
    {"atrium", "Atrium with columns, mostly indirect light from a skylight"},
    {"kitchen", "Kitchen interior with glossy, textured and glass materials"},
    {"envmap", "Objects lit only by an environment map (renders with all_hv)"},
    {"product", "Textured, normal-mapped glossy helmet under a sky with a bright sun"},
    {"window", "Furnished room lit only by the sky and sun through one window"},
};

std::string builtin_path(const std::string& name) {
  return builtin_assets_dir() + "/" + name + "/" + name + ".gltf";
}

// ---------------------------------------------------------------------------------------------
// Small conversions

constexpr float kMaxCoordinate = 1e12f;
// The brightest emission a material may have (emissiveFactor times emissiveStrength, per channel):
// its paths' sums and squared sums stay far inside float over 2^24 frames, and inside the 1e30
// that the blend and tone map clamp to.
constexpr double kMaxEmission = 1e12;

// Texture coordinates beyond 2^24 have no fraction left in float, so a repeating, mirrored or
// clamped texture reads the same texel there as at 2^24. UVs and KHR_texture_transform's offset
// and scale are clamped to it, which keeps every transformed coordinate (at most about 2^49)
// finite: a scale of 3e38 made them infinite, and the range buffer with them.
constexpr float kMaxTextureCoordinate = 16777216.0f;

// "1e+12", "3.4e+38", "0.5": short and exact enough for an error message.
std::string format_number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", v);
  return text;
}

std::string count_text(uint64_t n) { return n == UINT64_MAX ? "more than 1.8e19" : std::to_string(n); }

std::string mib_text(uint64_t bytes) {
  return bytes == UINT64_MAX ? "more than 16 EiB" : format_number(static_cast<double>(bytes) / (1024.0 * 1024.0)) + " MiB";
}

// Refuses, before anything large is allocated, an estimate over the available memory: one line
// naming `file`, the estimate and what makes it large.
void check_estimate(const LoadEstimate& estimate, const LoadLimits& limits, const std::string& file) {
  const uint64_t available = limits.available_memory > 0 ? limits.available_memory : available_memory_bytes();
  if (available == 0) return;  // unknown: nothing to check against
  const uint64_t needed = estimate.bytes();
  if (needed <= available) return;
  std::string parts = count_text(estimate.triangles) + " triangles";
  if (estimate.lights > 0) parts += ", " + count_text(estimate.lights) + " lights";
  parts += ", " + mib_text(estimate.texture_bytes) + " of textures";
  if (estimate.environment_texels > 0)
    parts += ", an environment map of " + count_text(estimate.environment_texels) + " texels";
  if (estimate.decoded_buffer_bytes > 0) parts += ", " + mib_text(estimate.decoded_buffer_bytes) + " of decoded meshopt data";
  throw Error(file + ": loading needs an estimated " + mib_text(needed) + " (" + parts + "), more than the " +
              mib_text(available) + " of memory available");
}

float finite_or(double value, float fallback) {
  return std::isfinite(value) ? static_cast<float>(value) : fallback;
}

float clamp01(double value, float fallback) { return std::clamp(finite_or(value, fallback), 0.0f, 1.0f); }

glm::vec3 vec3_or(const std::vector<double>& v, glm::vec3 fallback) {
  if (v.size() < 3) return fallback;
  return {finite_or(v[0], fallback.x), finite_or(v[1], fallback.y), finite_or(v[2], fallback.z)};
}

// value[key], or a null value when `value` is not an object (tinygltf asserts on that).
const tinygltf::Value& member(const tinygltf::Value& value, const std::string& key) {
  static const tinygltf::Value null_value;
  return value.IsObject() ? value.Get(key) : null_value;
}

double number_or(const tinygltf::Value& value, double fallback) {
  return value.IsNumber() ? value.GetNumberAsDouble() : fallback;
}

// An integer-valued property; `fallback` when absent, not a number or outside int range.
int int_or(const tinygltf::Value& value, int fallback) {
  double v = number_or(value, fallback);
  return std::isfinite(v) && v >= -2147483648.0 && v <= 2147483647.0 ? static_cast<int>(v) : fallback;
}

glm::vec3 value_vec3_or(const tinygltf::Value& value, glm::vec3 fallback) {
  if (!value.IsArray() || value.ArrayLen() < 3) return fallback;
  glm::vec3 out;
  for (int i = 0; i < 3; ++i) out[i] = finite_or(number_or(value.Get(i), fallback[i]), fallback[i]);
  return out;
}

glm::vec4 value_vec4_or(const tinygltf::Value& value, glm::vec4 fallback) {
  if (!value.IsArray() || value.ArrayLen() < 4) return fallback;
  glm::vec4 out;
  for (int i = 0; i < 4; ++i) out[i] = finite_or(number_or(value.Get(i), fallback[i]), fallback[i]);
  return out;
}

const tinygltf::Value* find_extension(const tinygltf::ExtensionMap& extensions, const std::string& name) {
  auto it = extensions.find(name);
  return it != extensions.end() && it->second.IsObject() ? &it->second : nullptr;
}

// First non-empty line of a (possibly multi-line) tinygltf message, cut short: tinygltf quotes
// whole data URIs in some messages.
std::string first_line(const std::string& text) {
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line))
    if (line.find_first_not_of(" \t\r") != std::string::npos) {
      if (!line.empty() && line.back() == '\r') line.pop_back();
      return line.size() > 160 ? line.substr(0, 160) + "..." : line;
    }
  return "unknown error";
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line))
    if (line.find_first_not_of(" \t\r") != std::string::npos) lines.push_back(line);
  return lines;
}

glm::mat4 node_local_transform(const tinygltf::Node& node) {
  if (node.matrix.size() == 16) {
    glm::mat4 m;
    for (int i = 0; i < 16; ++i) glm::value_ptr(m)[i] = static_cast<float>(node.matrix[i]);  // column-major
    return m;
  }
  glm::mat4 m(1.0f);
  if (node.translation.size() == 3)
    m = glm::translate(m, glm::vec3(node.translation[0], node.translation[1], node.translation[2]));
  if (node.rotation.size() == 4) {
    glm::quat q(static_cast<float>(node.rotation[3]), static_cast<float>(node.rotation[0]),
                static_cast<float>(node.rotation[1]), static_cast<float>(node.rotation[2]));  // w, x, y, z
    float len = glm::length(q);
    if (len > 0.0f && std::isfinite(len)) m *= glm::mat4_cast(q / len);
  }
  if (node.scale.size() == 3) m = glm::scale(m, glm::vec3(node.scale[0], node.scale[1], node.scale[2]));
  return m;
}

// v / |v|, scaled by its largest component first: the length of a column scaled by 2e19 overflows
// float, and normalizing by it gave a zero camera basis (NaN rays, an Embree abort). `fallback` for
// a zero or non-finite v.
glm::vec3 unit_or(glm::vec3 v, glm::vec3 fallback) {
  if (!gltf::is_finite(v)) return fallback;
  const float largest = std::max({std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)});
  return largest > 0.0f ? glm::normalize(v / largest) : fallback;
}

// The rigid part of a node transform: camera frames must not carry scale or shear.
glm::mat4 rigid_frame(const glm::mat4& m) {
  const glm::vec3 z = unit_or(glm::vec3(m[2]), glm::vec3(0, 0, 1));
  glm::vec3 x = unit_or(glm::vec3(m[0]), gltf::any_orthogonal(z));
  x -= z * glm::dot(x, z);
  x = glm::length(x) < 1e-6f ? gltf::any_orthogonal(z) : glm::normalize(x);
  glm::vec3 y = glm::cross(z, x);
  glm::vec3 origin = gltf::is_finite(glm::vec3(m[3])) ? glm::vec3(m[3]) : glm::vec3(0.0f);
  return glm::mat4(glm::vec4(x, 0), glm::vec4(y, 0), glm::vec4(z, 0), glm::vec4(origin, 1));
}

// ---------------------------------------------------------------------------------------------
// The loader

class GltfLoader {
 public:
  // `environment_texels`: the environment map's, loaded beside the scene, in the same estimate.
  GltfLoader(std::string file, const LoadLimits& limits, uint64_t environment_texels = 0)
      : file_(std::move(file)), limits_(limits) {
    estimate_.environment_texels = environment_texels;
  }

  Scene load() {
    read_model();
    return build();
  }

  Scene load_from_memory(const unsigned char* data, size_t size, const std::string& base_dir) {
    parse_model(data, size, base_dir);
    return build();
  }

 private:
  Scene build() {
    check_extensions();
    // Compressed views: all checked and counted first; the images' decoded before their headers
    // are probed, the accessors' only once the whole estimate holds.
    const gltf::MeshoptPlan meshopt = gltf::plan_meshopt_views(model_, file_);
    estimate_.decoded_buffer_bytes = meshopt.decoded_bytes;
    check_estimate(estimate_, limits_, file_);
    gltf::decode_meshopt_views(model_, file_, meshopt.image_views);
    load_materials();    // registers the used textures; nothing is decoded yet
    count_instances();   // the triangle cap, before any geometry is read
    probe_textures();    // the texture size cap, from the image headers
    check_memory();      // the estimate against the available memory
    gltf::decode_meshopt_views(model_, file_, meshopt.accessor_views);
    gltf::decode_draco_primitives(model_, file_);  // to the accessor counts just checked
    decode_textures();
    convert_spec_gloss();  // after decoding: textures are baked from their texels
    build_mips();
    traverse_scene();
    read_scene_defaults();  // before the camera: the default image aspect frames the model
    finish_camera();
    report_dropped_triangles();
    return std::move(scene_);
  }

  [[noreturn]] void fail(const std::string& problem) const { throw Error(file_ + ": " + problem); }

  // The mip chains of the textures the path tracer reads with footprints (scene/texture.h).
  void build_mips() {
    const std::vector<bool> wanted = textures_read_with_footprints(scene_);
    build_texture_mips(scene_.textures, &wanted);
  }

  // Ray origins come from the camera and from surface points; Embree asserts on origins beyond
  // about 1.8e18, and float precision is long gone well before that.
  void check_magnitude(glm::vec3 p, const std::string& what) const {
    const float m = std::max({std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)});
    if (m > kMaxCoordinate)
      fail(what + " has a world-space coordinate of " + format_number(m) + ", beyond the supported " +
           format_number(kMaxCoordinate) + " (check the node transforms and units)");
  }
  // An orthographic camera's rays start up to its half-extent times the image aspect (at most
  // 16384, the --size cap) from its position: bounded like a coordinate, every ray origin stays
  // far inside the 1.8e18 Embree accepts.
  void check_extent(float extent, const std::string& what) const {
    if (std::fabs(extent) > kMaxCoordinate)
      fail(what + " is " + format_number(extent) + ", beyond the supported " + format_number(kMaxCoordinate) +
           " (check the camera's units)");
  }
  void warn(const std::string& message) { scene_.warnings.push_back(file_ + ": " + message); }

  void read_model() {
    const std::vector<unsigned char> bytes = read_input_file(file_, kMaxGltfFileBytes);
    parse_model(bytes.data(), bytes.size(), fs::path(file_).parent_path().string());
  }

  // tinygltf joins its base folder with every uri, which breaks absolute uris ("dir//abs/x.bin").
  // So it gets no base folder, and this callback resolves relative uris against the glTF's folder.
  // It also replaces tinygltf's default, which runs wordexp() on uris from the file.
  static std::string resolve_uri(const std::string& uri, void* base_dir) {
    const fs::path path(uri);
    if (path.is_absolute()) return uri;
    return (fs::path(*static_cast<const std::string*>(base_dir)) / path).string();
  }

  // tinygltf's own callbacks open a uri's file to see whether it exists and then read it with a
  // stream: a FIFO blocks both, a directory reads as a huge length (std::bad_alloc). A uri that
  // names nothing stays tinygltf's "not found" (a missing texture is a warning); anything else
  // goes through read_input_file, whose error (a pxf::Error, through tinygltf) fails the load.
  static bool uri_exists(const std::string& path, void*) {
    std::error_code ec;
    return fs::exists(path, ec);
  }
  static bool read_uri(std::vector<unsigned char>* out, std::string*, const std::string& path, void*) {
    *out = read_input_file(path, kMaxGltfFileBytes);
    return true;
  }

  void parse_model(const unsigned char* data, size_t size, const std::string& base_dir) {
    base_dir_ = base_dir;
    if (size > std::numeric_limits<unsigned int>::max()) fail("file larger than 4 GiB");
    const bool binary = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
    check_json_nesting(data, size, binary);
    const gltf::PreparedJson prepared = gltf::prepare_json(data, size, binary, file_, supported_extensions());
    if (prepared.rewritten) {
      data = prepared.bytes.data();
      size = prepared.bytes.size();
      if (size > std::numeric_limits<unsigned int>::max()) fail("file larger than 4 GiB");
    }
    tinygltf::TinyGLTF loader;
    loader.SetFsCallbacks({&GltfLoader::uri_exists, &GltfLoader::resolve_uri, &GltfLoader::read_uri,
                           &tinygltf::WriteWholeFile, &base_dir_});
    images_.install(loader);
    std::string err, warn_text;
    bool ok = false;
    try {
      ok = binary ? loader.LoadBinaryFromMemory(&model_, &err, &warn_text, data, static_cast<unsigned int>(size), "")
                  : loader.LoadASCIIFromString(&model_, &err, &warn_text, reinterpret_cast<const char*>(data),
                                               static_cast<unsigned int>(size), "");
    } catch (const Error& e) {
      fail(e.what());  // a uri's file (read_uri)
    } catch (const std::exception& e) {
      fail(std::string("invalid glTF: ") + e.what());
    }
    if (!ok) fail(first_line(err.empty() ? warn_text : err));
    gltf::restore_draco_index_accessors(model_, prepared);
    // tinygltf's image warnings ("File not found", "Failed to load external 'uri' for image[0]") are
    // replaced by our single line per texture, which says which material loses what.
    for (const std::string& line : lines_of(warn_text))
      if (line.find("image[") == std::string::npos && line.find("File not found") == std::string::npos) warn(line);
  }

  // tinygltf converts JSON values by recursion: the nesting is bounded before it parses (the .gltf
  // text, or a GLB's JSON chunk: length at byte 12, text from byte 20).
  void check_json_nesting(const unsigned char* data, size_t size, bool binary) const {
    size_t begin = 0, length = size;
    if (binary) {
      if (size < 20) return;  // tinygltf names the truncation
      uint32_t chunk_length = 0;
      std::memcpy(&chunk_length, data + 12, sizeof chunk_length);
      begin = 20;
      length = std::min<size_t>(chunk_length, size - begin);
    }
    check_json_depth(reinterpret_cast<const char*>(data) + begin, length, file_);
  }

  // Required extensions were checked before tinygltf parsed the file (gltf::prepare_json).
  void check_extensions() {
    std::string unsupported;
    for (const std::string& name : model_.extensionsUsed) {
      if (name == "KHR_texture_basisu")
        warn("KHR_texture_basisu's KTX2 images cannot be decoded; its textures use their PNG/JPEG source where they have one");
      else if (!supported_extensions().count(name))
        unsupported += (unsupported.empty() ? "" : ", ") + name;
    }
    if (!unsupported.empty()) warn("ignoring unsupported extensions " + unsupported + " (rendered without them)");
  }

  // -- textures ---------------------------------------------------------------------------------

  // A glTF textureInfo in any of its three spellings (TextureInfo, NormalTextureInfo, JSON value).
  struct TextureInfoView {
    int index = -1;
    int texcoord = 0;
    const tinygltf::Value* transform = nullptr;  // KHR_texture_transform object
  };

  static TextureInfoView info_of(const tinygltf::TextureInfo& info) {
    return {info.index, info.texCoord, find_extension(info.extensions, "KHR_texture_transform")};
  }
  static TextureInfoView info_of(const tinygltf::NormalTextureInfo& info) {
    return {info.index, info.texCoord, find_extension(info.extensions, "KHR_texture_transform")};
  }
  static TextureInfoView info_of(const tinygltf::Value& value) {
    TextureInfoView view;
    if (!value.IsObject()) return view;
    view.index = int_or(value.Get("index"), -1);
    view.texcoord = int_or(value.Get("texCoord"), 0);
    const tinygltf::Value& ext = member(member(value, "extensions"), "KHR_texture_transform");
    if (ext.IsObject()) view.transform = &ext;
    return view;
  }

  TextureRef texture_ref(const TextureInfoView& info, bool srgb, const std::string& material, const char* slot) {
    TextureRef ref;
    if (info.index < 0) return ref;
    ref.texture = scene_texture(info.index, srgb, material, slot);
    if (ref.texture < 0) return ref;
    ref.texcoord = info.texcoord;
    if (info.transform) {
      const tinygltf::Value& t = *info.transform;
      glm::vec2 offset(0.0f), scale(1.0f);
      const tinygltf::Value& o = t.Get("offset");
      const tinygltf::Value& s = t.Get("scale");
      if (o.IsArray() && o.ArrayLen() >= 2)
        offset = {finite_or(number_or(o.Get(0), 0), 0), finite_or(number_or(o.Get(1), 0), 0)};
      if (s.IsArray() && s.ArrayLen() >= 2)
        scale = {finite_or(number_or(s.Get(0), 1), 1), finite_or(number_or(s.Get(1), 1), 1)};
      float rotation = finite_or(number_or(t.Get("rotation"), 0), 0);
      const glm::vec2 limit(kMaxTextureCoordinate);
      if (glm::any(glm::greaterThan(glm::abs(offset), limit)) || glm::any(glm::greaterThan(glm::abs(scale), limit))) {
        warn("material '" + material + "' " + slot + " texture transform has an offset or scale beyond +-" +
             format_number(kMaxTextureCoordinate) + "; clamped to it");
        offset = glm::clamp(offset, -limit, limit);
        scale = glm::clamp(scale, -limit, limit);
      }
      ref.transform = texture_transform_matrix(offset, rotation, scale);
      if (t.Get("texCoord").IsNumber()) ref.texcoord = int_or(t.Get("texCoord"), -1);
    }
    if (ref.texcoord != 0 && ref.texcoord != 1) {
      warn("material '" + material + "' " + slot + " uses TEXCOORD_" + std::to_string(ref.texcoord) +
           ", only sets 0 and 1 are supported; using TEXCOORD_0");
      ref.texcoord = 0;
    }
    return ref;
  }

  // Index into scene_.textures of glTF texture `index` decoded as sRGB or linear; -1 (with a
  // warning naming the image) when its image is unavailable.
  int scene_texture(int index, bool srgb, const std::string& material, const char* slot) {
    auto key = std::make_pair(index, srgb);
    auto cached = texture_cache_.find(key);
    if (cached != texture_cache_.end()) return cached->second;
    if (index >= static_cast<int>(model_.textures.size())) fail("texture " + std::to_string(index) + " out of range");
    const tinygltf::Texture& texture = model_.textures[index];
    int& slot_index = texture_cache_[key];
    slot_index = -1;
    const int source = image_source(texture);
    if (source < 0) {
      const bool ktx2_only = find_extension(texture.extensions, "KHR_texture_basisu") != nullptr;
      warn("texture " + std::to_string(index) +
           (ktx2_only ? " has only a KTX2 image (KHR_texture_basisu), which pxf cannot decode"
                      : " has no supported image source") +
           "; material '" + material + "' renders without its " + slot + " texture");
      return -1;
    }
    if (source >= static_cast<int>(model_.images.size()))
      fail("texture " + std::to_string(index) + " references image " + std::to_string(source) + " out of range");
    scene_.textures.push_back(texture_settings(texture, model_.images[source]));
    pending_.push_back({source, srgb, material, slot});
    slot_index = static_cast<int>(scene_.textures.size()) - 1;
    return slot_index;
  }

  // EXT_texture_webp's image when the texture has one (also when it has a PNG/JPEG source beside
  // it); else the texture's own source. KHR_texture_basisu's KTX2 image cannot be decoded, so such a
  // texture falls back to its source, the PNG/JPEG the extension asks exporters to keep.
  static int image_source(const tinygltf::Texture& texture) {
    if (const tinygltf::Value* webp = find_extension(texture.extensions, "EXT_texture_webp")) {
      const int source = int_or(webp->Get("source"), -1);
      if (source >= 0) return source;
    }
    return texture.source;
  }

  static Wrap wrap_mode(int gl_wrap) {
    switch (gl_wrap) {
      case TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE: return Wrap::ClampToEdge;
      case TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT: return Wrap::MirroredRepeat;
      default: return Wrap::Repeat;
    }
  }

  // A texture's name and sampler; its texels come from decode_textures.
  Texture texture_settings(const tinygltf::Texture& texture, const tinygltf::Image& image) {
    Texture out;
    out.name = !image.uri.empty() && image.uri.rfind("data:", 0) != 0 ? image.uri : image.name;
    if (texture.sampler >= 0) {
      if (texture.sampler >= static_cast<int>(model_.samplers.size()))
        fail("sampler " + std::to_string(texture.sampler) + " out of range");
      const tinygltf::Sampler& sampler = model_.samplers[texture.sampler];
      out.wrap_s = wrap_mode(sampler.wrapS);
      out.wrap_t = wrap_mode(sampler.wrapT);
      out.nearest = sampler.magFilter == TINYGLTF_TEXTURE_FILTER_NEAREST;
    }
    return out;
  }

  // 8-bit images keep their codes (RGBA8, sRGB decoded at lookup), shared by the textures that use
  // the image (`codes`, made on first use); 16-bit and HDR images become linear floats.
  static void fill_texels(Texture& out, gltf::DecodedImage& decoded, bool srgb,
                          std::shared_ptr<const std::vector<unsigned char>>& codes) {
    out.width = decoded.width;
    out.height = decoded.height;
    size_t texel_count = static_cast<size_t>(decoded.width) * decoded.height;
    if (decoded.bits == 8) {
      out.srgb = srgb;
      if (!codes) codes = std::make_shared<const std::vector<unsigned char>>(std::move(decoded.bytes));
      out.texels8 = codes;
      return;
    }
    out.texels.resize(texel_count);
    int c = decoded.channels;
    auto color = [&](float v) {
      float x = std::isfinite(v) ? std::max(v, 0.0f) : 0.0f;
      return srgb ? linear_from_srgb(x) : x;
    };
    for (size_t i = 0; i < texel_count; ++i) {
      const float* p = &decoded.values[i * c];
      glm::vec4 t;
      if (c <= 2) {
        float g = color(p[0]);
        t = glm::vec4(g, g, g, c == 2 ? p[1] : 1.0f);
      } else {
        t = glm::vec4(color(p[0]), color(p[1]), color(p[2]), c == 4 ? p[3] : 1.0f);
      }
      if (!std::isfinite(t.w)) t.w = 1.0f;
      out.texels[i] = t;
    }
  }

  // The used images' headers: size cap, and the texel bytes for the memory estimate.
  void probe_textures() {
    std::map<int, gltf::ImageHeader> headers;
    for (const PendingTexture& p : pending_) {
      auto [it, inserted] = headers.try_emplace(p.image);
      if (inserted) {
        gltf::ByteRange bytes = images_.bytes(model_, p.image, file_);
        it->second = gltf::probe_image(bytes.data, bytes.size);
        const gltf::ImageHeader& h = it->second;
        if (h.ok && (h.width > limits_.max_texture_size || h.height > limits_.max_texture_size))
          fail(image_label(p.image) + " is " + std::to_string(h.width) + "x" + std::to_string(h.height) +
               ", over the texture size limit of " + std::to_string(limits_.max_texture_size) +
               " (raise it with --max-texture-size)");
      }
      const gltf::ImageHeader& h = it->second;
      if (!h.ok) continue;
      const uint64_t texels = static_cast<uint64_t>(h.width) * static_cast<uint64_t>(h.height);
      estimate_.texture_bytes += texels * (h.bits == 8 ? 4 : 16);
      // stb's buffer and our copy for 8-bit images; stb's buffer and the float values otherwise.
      const uint64_t decode = h.bits == 8 ? 8 * texels : texels * h.channels * (h.bits / 8 + 4);
      estimate_.largest_decode_bytes = std::max(estimate_.largest_decode_bytes, decode);
    }
    // Specular-glossiness materials get two baked 8-bit textures at the larger of their two sizes.
    for (const SpecGlossMaterial& sg : spec_gloss_) {
      uint64_t width = 0, height = 0;
      for (const TextureRef* ref : {&scene_.materials[sg.material].base_color_texture,
                                    &scene_.materials[sg.material].metallic_roughness_texture}) {
        if (!ref->valid()) continue;
        const gltf::ImageHeader& h = headers[pending_[ref->texture].image];
        if (!h.ok) continue;
        width = std::max<uint64_t>(width, h.width);
        height = std::max<uint64_t>(height, h.height);
      }
      estimate_.texture_bytes += 8 * width * height;
    }
  }

  std::string image_label(int index) const {
    const tinygltf::Image& image = model_.images[index];
    if (!image.uri.empty() && image.uri.rfind("data:", 0) != 0) return "image " + std::to_string(index) + " '" + image.uri + "'";
    if (!image.name.empty()) return "image " + std::to_string(index) + " '" + image.name + "'";
    return "image " + std::to_string(index);
  }

  // Decodes every used image once, in parallel, fills the textures, then drops those whose image
  // could not be decoded (a warning each, naming the material that loses it) and renumbers the
  // materials' references.
  void decode_textures() {
    std::vector<int> images;
    for (const PendingTexture& p : pending_) images.push_back(p.image);
    std::sort(images.begin(), images.end());
    images.erase(std::unique(images.begin(), images.end()), images.end());
    std::vector<gltf::ByteRange> bytes(images.size());
    for (size_t k = 0; k < images.size(); ++k) bytes[k] = images_.bytes(model_, images[k], file_);
    std::vector<gltf::DecodedImage> decoded(images.size());
    parallel_for(images.size(), [&](size_t k) {
      if (bytes[k].size > 0) gltf::decode_image(bytes[k].data, bytes[k].size, decoded[k]);
    });
    auto slot_of = [&](int image) {
      return static_cast<size_t>(std::lower_bound(images.begin(), images.end(), image) - images.begin());
    };
    // Per image: its textures in order (one image's textures share its storage).
    std::vector<std::vector<size_t>> users(images.size());
    for (size_t t = 0; t < pending_.size(); ++t) users[slot_of(pending_[t].image)].push_back(t);
    parallel_for(images.size(), [&](size_t k) {
      if (!decoded[k].decoded) return;
      std::shared_ptr<const std::vector<unsigned char>> codes;
      for (size_t t : users[k]) fill_texels(scene_.textures[t], decoded[k], pending_[t].srgb, codes);
      std::vector<unsigned char>().swap(decoded[k].bytes);  // moved from, or no longer needed
      std::vector<float>().swap(decoded[k].values);
    });
    std::vector<int> renumber(pending_.size(), -1);
    std::vector<Texture> kept;
    for (size_t t = 0; t < pending_.size(); ++t) {
      const PendingTexture& p = pending_[t];
      const gltf::DecodedImage& d = decoded[slot_of(p.image)];
      if (!d.decoded) {
        const tinygltf::Image& image = model_.images[p.image];
        std::string what = !image.uri.empty() ? "'" + image.uri + "'" : "image " + std::to_string(p.image);
        std::string why = !d.failure.empty() ? " (" + d.failure + ")" : " (missing or unreadable)";
        warn("texture image " + what + " could not be loaded" + why + "; material '" + p.material +
             "' renders without its " + p.slot + " texture");
        continue;
      }
      renumber[t] = static_cast<int>(kept.size());
      kept.push_back(std::move(scene_.textures[t]));
    }
    scene_.textures = std::move(kept);
    pending_.clear();
    for (Material& m : scene_.materials)
      for (TextureRef* ref : {&m.base_color_texture, &m.metallic_roughness_texture, &m.normal_texture, &m.emissive_texture,
                              &m.transmission_texture, &m.specular_texture, &m.specular_color_texture,
                              &m.clearcoat_texture, &m.clearcoat_roughness_texture, &m.clearcoat_normal_texture,
                              &m.sheen_color_texture, &m.sheen_roughness_texture})
        if (ref->texture >= 0) {
          ref->texture = renumber[ref->texture];
          if (ref->texture < 0) *ref = TextureRef{};
        }
  }

  // -- materials --------------------------------------------------------------------------------

  void load_materials() {
    for (size_t i = 0; i < model_.materials.size(); ++i) scene_.materials.push_back(load_material(model_.materials[i], i));
    // Primitives without a material use this one (glTF's default material is white; we make it
    // a plain diffuse rather than glTF's metallic default, which renders black without an environment).
    Material fallback;
    fallback.name = "pxf_default";
    fallback.metallic = 0.0f;
    fallback.roughness = 1.0f;
    scene_.materials.push_back(fallback);
  }

  Material load_material(const tinygltf::Material& gm, size_t index) {
    Material m;
    m.name = gm.name.empty() ? "material " + std::to_string(index) : gm.name;
    const auto& pbr = gm.pbrMetallicRoughness;
    if (const tinygltf::Value* ext = find_extension(gm.extensions, "KHR_materials_pbrSpecularGlossiness")) {
      read_spec_gloss(*ext, m, index);  // replaces pbrMetallicRoughness (the file's fallback for other viewers)
    } else {
      if (pbr.baseColorFactor.size() == 4)
        for (int c = 0; c < 4; ++c) m.base_color[c] = clamp01(pbr.baseColorFactor[c], 1.0f);
      m.base_color_texture = texture_ref(info_of(pbr.baseColorTexture), true, m.name, "base color");
      m.metallic = clamp01(pbr.metallicFactor, 1.0f);
      m.roughness = clamp01(pbr.roughnessFactor, 1.0f);
      m.metallic_roughness_texture = texture_ref(info_of(pbr.metallicRoughnessTexture), false, m.name, "metallic-roughness");
    }
    m.normal_texture = texture_ref(info_of(gm.normalTexture), false, m.name, "normal");
    m.normal_scale = finite_or(gm.normalTexture.scale, 1.0f);
    m.emissive = glm::max(vec3_or(gm.emissiveFactor, glm::vec3(0.0f)), glm::vec3(0.0f));
    m.emissive_texture = texture_ref(info_of(gm.emissiveTexture), true, m.name, "emissive");
    double strength = 1.0;  // in double: 1e300 is finite here and is clamped below, not dropped
    if (const tinygltf::Value* ext = find_extension(gm.extensions, "KHR_materials_emissive_strength")) {
      const double s = number_or(ext->Get("emissiveStrength"), 1.0);
      strength = std::isfinite(s) ? std::max(s, 0.0) : 1.0;
    }
    const glm::dvec3 emission = glm::dvec3(m.emissive) * strength;
    const double brightest = std::max({emission.x, emission.y, emission.z});
    if (brightest > kMaxEmission) {
      // Radiance this bright overflows the accumulated sums and variances (the blend and tone map
      // clamp at 1e30): scaled down, hue kept, with a warning rather than a black image.
      m.emissive = glm::vec3(emission * (kMaxEmission / brightest));
      warn("material '" + m.name + "' emits " + format_number(brightest) +
           ", more than the " + format_number(kMaxEmission) +
           " pxf can represent; clamped to it (check emissiveStrength and the scene's units)");
    } else {
      m.emissive = glm::vec3(emission);
    }
    if (const tinygltf::Value* ext = find_extension(gm.extensions, "KHR_materials_transmission")) {
      m.transmission = clamp01(number_or(ext->Get("transmissionFactor"), 0.0), 0.0f);
      m.transmission_texture = texture_ref(info_of(ext->Get("transmissionTexture")), false, m.name, "transmission");
    }
    if (const tinygltf::Value* ext = find_extension(gm.extensions, "KHR_materials_ior")) {
      float ior = finite_or(number_or(ext->Get("ior"), 1.5), 1.5f);
      // ior 0 is not meaningful for a path tracer; keep it physical.
      if (ior < 1.0f) {
        warn("material '" + m.name + "' has ior " + std::to_string(ior) + " < 1; using 1.5");
        ior = 1.5f;
      }
      m.ior = std::min(ior, 10.0f);
    }
    if (const tinygltf::Value* ext = find_extension(gm.extensions, "KHR_materials_specular")) {
      m.specular = clamp01(number_or(ext->Get("specularFactor"), 1.0), 1.0f);
      m.specular_texture = texture_ref(info_of(ext->Get("specularTexture")), false, m.name, "specular");
      m.specular_color = glm::max(value_vec3_or(ext->Get("specularColorFactor"), glm::vec3(1.0f)), glm::vec3(0.0f));
      m.specular_color_texture = texture_ref(info_of(ext->Get("specularColorTexture")), true, m.name, "specular color");
    }
    if (const tinygltf::Value* ext = find_extension(gm.extensions, "KHR_materials_volume")) read_volume(*ext, m);
    if (const tinygltf::Value* ext = find_extension(gm.extensions, "KHR_materials_clearcoat")) read_clearcoat(*ext, m);
    if (const tinygltf::Value* ext = find_extension(gm.extensions, "KHR_materials_sheen")) {
      m.sheen_color = glm::clamp(value_vec3_or(ext->Get("sheenColorFactor"), glm::vec3(0.0f)), glm::vec3(0.0f), glm::vec3(1.0f));
      m.sheen_color_texture = texture_ref(info_of(ext->Get("sheenColorTexture")), true, m.name, "sheen color");
      m.sheen_roughness = clamp01(number_or(ext->Get("sheenRoughnessFactor"), 0.0), 0.0f);
      m.sheen_roughness_texture = texture_ref(info_of(ext->Get("sheenRoughnessTexture")), false, m.name, "sheen roughness");
    }
    if (gm.alphaMode == "MASK") m.alpha_mode = AlphaMode::Mask;
    else if (gm.alphaMode == "BLEND") m.alpha_mode = AlphaMode::Blend;
    m.alpha_cutoff = std::max(finite_or(gm.alphaCutoff, 0.5f), 0.0f);
    m.double_sided = gm.doubleSided;
    return m;
  }

  void read_clearcoat(const tinygltf::Value& ext, Material& m) {
    m.clearcoat = clamp01(number_or(ext.Get("clearcoatFactor"), 0.0), 0.0f);
    m.clearcoat_texture = texture_ref(info_of(ext.Get("clearcoatTexture")), false, m.name, "clearcoat");
    m.clearcoat_roughness = clamp01(number_or(ext.Get("clearcoatRoughnessFactor"), 0.0), 0.0f);
    m.clearcoat_roughness_texture =
        texture_ref(info_of(ext.Get("clearcoatRoughnessTexture")), false, m.name, "clearcoat roughness");
    const tinygltf::Value& normal = ext.Get("clearcoatNormalTexture");
    m.clearcoat_normal_texture = texture_ref(info_of(normal), false, m.name, "clearcoat normal");
    m.clearcoat_normal_scale = finite_or(number_or(member(normal, "scale"), 1.0), 1.0f);
  }

  // KHR_materials_pbrSpecularGlossiness: the factors are converted here; the diffuse and
  // specular-glossiness textures are registered in the base color and metallic-roughness slots
  // (so decoding and renumbering handle them) and replaced by baked textures in convert_spec_gloss.
  void read_spec_gloss(const tinygltf::Value& ext, Material& m, size_t index) {
    SpecGlossMaterial sg;
    sg.material = index;
    sg.factors.diffuse = glm::clamp(value_vec4_or(ext.Get("diffuseFactor"), glm::vec4(1.0f)), glm::vec4(0.0f), glm::vec4(1.0f));
    sg.factors.specular = glm::clamp(value_vec3_or(ext.Get("specularFactor"), glm::vec3(1.0f)), glm::vec3(0.0f), glm::vec3(1.0f));
    sg.factors.glossiness = clamp01(number_or(ext.Get("glossinessFactor"), 1.0), 1.0f);
    const MetalRough c = metal_rough_from_spec_gloss(sg.factors.diffuse, sg.factors.specular, sg.factors.glossiness);
    m.base_color = c.base_color;
    m.metallic = c.metallic;
    m.roughness = c.roughness;
    m.base_color_texture = texture_ref(info_of(ext.Get("diffuseTexture")), true, m.name, "diffuse");
    m.metallic_roughness_texture =
        texture_ref(info_of(ext.Get("specularGlossinessTexture")), true, m.name, "specular-glossiness");
    spec_gloss_.push_back(sg);
  }

  static bool same_mapping(const TextureRef& a, const TextureRef& b) {
    return a.texcoord == b.texcoord && a.transform == b.transform;
  }

  // Replaces each specular-glossiness material's textures by metallic-roughness ones baked per
  // texel (at the larger of the two sizes, through their common UV mapping), then warns once. When
  // the diffuse and specular-glossiness textures use different UV mappings they cannot be baked
  // together: metallic and roughness come from the specular-glossiness texture and the diffuse
  // factor, and the base color stays the diffuse color (exact only for dielectrics).
  void convert_spec_gloss() {
    if (spec_gloss_.empty()) return;
    size_t baked = 0;
    std::string approximated;
    for (const SpecGlossMaterial& sg : spec_gloss_) {
      Material& m = scene_.materials[sg.material];
      const TextureRef diffuse_ref = m.base_color_texture, sg_ref = m.metallic_roughness_texture;
      const Texture* diffuse = diffuse_ref.valid() ? &scene_.textures[diffuse_ref.texture] : nullptr;
      const Texture* spec = sg_ref.valid() ? &scene_.textures[sg_ref.texture] : nullptr;
      if (!diffuse && !spec) continue;  // factors only: converted in read_spec_gloss
      ++baked;
      if (diffuse && spec && !same_mapping(diffuse_ref, sg_ref)) {
        BakedSpecGloss out = bake_spec_gloss(nullptr, spec, sg.factors, spec->width, spec->height, *spec);
        scene_.textures.push_back(std::move(out.metallic_roughness));
        m.metallic_roughness_texture.texture = static_cast<int>(scene_.textures.size()) - 1;
        m.base_color = sg.factors.diffuse;
        m.metallic = m.roughness = 1.0f;
        approximated += (approximated.empty() ? "'" : ", '") + m.name + "'";
        continue;
      }
      const Texture& sampler = diffuse ? *diffuse : *spec;
      const int width = std::max(diffuse ? diffuse->width : 0, spec ? spec->width : 0);
      const int height = std::max(diffuse ? diffuse->height : 0, spec ? spec->height : 0);
      BakedSpecGloss out = bake_spec_gloss(diffuse, spec, sg.factors, width, height, sampler);
      TextureRef mapping = diffuse ? diffuse_ref : sg_ref;
      scene_.textures.push_back(std::move(out.base_color));
      mapping.texture = static_cast<int>(scene_.textures.size()) - 1;
      m.base_color_texture = mapping;
      scene_.textures.push_back(std::move(out.metallic_roughness));
      mapping.texture = static_cast<int>(scene_.textures.size()) - 1;
      m.metallic_roughness_texture = mapping;
      m.base_color = glm::vec4(1.0f);
      m.metallic = m.roughness = 1.0f;
    }
    std::string message = "converted " + std::to_string(spec_gloss_.size()) +
                          " KHR_materials_pbrSpecularGlossiness material(s) to metallic-roughness (metallic solved "
                          "from specular and diffuse brightness, roughness = 1 - glossiness";
    if (baked) message += "; textures baked per texel";
    message += ")";
    if (!approximated.empty())
      message += "; approximated for " + approximated +
                 ": diffuse and specular-glossiness textures use different UV mappings, so the base color is the "
                 "diffuse color (exact only for dielectrics)";
    warn(message);
  }

  // Beer-Lambert coefficient from attenuationColor (the color left after attenuationDistance).
  // thicknessFactor 0 means thin-walled: no medium. A thickness texture only matters for
  // rasterizers that do not trace the real path length, so it is not read.
  void read_volume(const tinygltf::Value& ext, Material& m) {
    double thickness = number_or(ext.Get("thicknessFactor"), 0.0);
    const tinygltf::Value& distance_value = ext.Get("attenuationDistance");
    double distance = distance_value.IsNumber() ? distance_value.GetNumberAsDouble() : 0.0;
    if (!(thickness > 0.0) || !(distance > 0.0) || !std::isfinite(distance)) return;  // thin or clear
    if (m.transmission <= 0.0f)
      warn("material '" + m.name + "' has KHR_materials_volume without transmission; its volume is never entered");
    glm::vec3 color = glm::clamp(value_vec3_or(ext.Get("attenuationColor"), glm::vec3(1.0f)), glm::vec3(1e-6f), glm::vec3(1.0f));
    m.attenuation = -glm::log(color) / static_cast<float>(distance);
  }

  // -- limits -----------------------------------------------------------------------------------

  // Triangles and vertices primitive `p` will instance once, from its accessors' counts (0 where
  // the accessors are invalid: reading them fails later with the precise error).
  void primitive_counts(const tinygltf::Primitive& p, uint64_t& vertices, uint64_t& triangles) const {
    vertices = triangles = 0;
    auto count_of = [&](int accessor) -> uint64_t {
      return accessor >= 0 && accessor < static_cast<int>(model_.accessors.size()) ? model_.accessors[accessor].count : 0;
    };
    const int mode = p.mode < 0 ? TINYGLTF_MODE_TRIANGLES : p.mode;
    vertices = count_of(attribute(p, "POSITION"));
    const uint64_t n = p.indices >= 0 ? count_of(p.indices) : vertices;
    if (mode == TINYGLTF_MODE_TRIANGLES) triangles = n / 3;
    else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP || mode == TINYGLTF_MODE_TRIANGLE_FAN) triangles = n >= 3 ? n - 2 : 0;
  }

  static uint64_t saturating_add(uint64_t a, uint64_t b) { return a > UINT64_MAX - b ? UINT64_MAX : a + b; }
  static uint64_t saturating_multiply(uint64_t a, uint64_t b) { return b != 0 && a > UINT64_MAX / b ? UINT64_MAX : a * b; }

  // The instanced totals of the scene, each node's subtree counted once (a node referenced from
  // many parents is not walked again, so a hierarchy that instances exponentially is cheap to
  // count), checked against the triangle cap before any geometry is read.
  void count_instances() {
    struct Counts {
      uint64_t vertices = 0, triangles = 0, nodes = 0, primitives = 0, lights = 0;
      Counts times(uint64_t n) const {
        Counts c;
        c.vertices = saturating_multiply(vertices, n);
        c.triangles = saturating_multiply(triangles, n);
        c.primitives = saturating_multiply(primitives, n);
        return c;
      }
      void add(const Counts& o) {
        vertices = saturating_add(vertices, o.vertices);
        triangles = saturating_add(triangles, o.triangles);
        nodes = saturating_add(nodes, o.nodes);
        primitives = saturating_add(primitives, o.primitives);
        lights = saturating_add(lights, o.lights);
      }
    };
    std::vector<Counts> mesh_counts(model_.meshes.size());
    for (size_t m = 0; m < model_.meshes.size(); ++m) {
      mesh_counts[m].primitives = model_.meshes[m].primitives.size();
      for (const tinygltf::Primitive& p : model_.meshes[m].primitives) {
        uint64_t v, t;
        primitive_counts(p, v, t);
        mesh_counts[m].vertices = saturating_add(mesh_counts[m].vertices, v);
        mesh_counts[m].triangles = saturating_add(mesh_counts[m].triangles, t);
      }
    }
    const size_t node_count = model_.nodes.size();
    std::vector<Counts> subtree(node_count);
    std::vector<char> state(node_count, 0);  // 0 new, 1 on the current path, 2 done
    Counts total;
    for (int root : scene_roots()) {
      if (root < 0 || root >= static_cast<int>(node_count)) continue;  // traverse_scene names it
      std::vector<std::pair<int, size_t>> stack;  // node, next child
      if (state[root] == 0) {
        state[root] = 1;
        stack.push_back({root, 0});
      }
      while (!stack.empty()) {
        auto& [index, next] = stack.back();
        const std::vector<int>& children = model_.nodes[index].children;
        if (next < children.size()) {
          const int child = children[next++];
          if (child < 0 || child >= static_cast<int>(node_count)) continue;
          if (state[child] == 1) continue;  // a cycle: traverse_scene reports it
          if (state[child] == 0) {
            state[child] = 1;
            stack.push_back({child, 0});
          }
          continue;
        }
        const tinygltf::Node& node = model_.nodes[index];
        Counts c;
        // EXT_mesh_gpu_instancing: the mesh once per instance, each instance a visit like a node's.
        const uint64_t instances = gltf::instance_count(model_, node);
        if (node.mesh >= 0 && node.mesh < static_cast<int>(mesh_counts.size())) c = mesh_counts[node.mesh].times(instances);
        c.nodes = saturating_add(1, instances > 1 ? instances : 0);
        c.lights = find_extension(node.extensions, "KHR_lights_punctual") ? 1 : 0;
        for (int child : children)
          if (child >= 0 && child < static_cast<int>(node_count) && state[child] == 2) c.add(subtree[child]);
        subtree[index] = c;
        state[index] = 2;
        stack.pop_back();
      }
      total.add(subtree[root]);
    }
    estimate_.vertices = total.vertices;
    estimate_.triangles = total.triangles;
    estimate_.meshes = total.primitives;
    estimate_.lights = total.lights;
    if (total.triangles > limits_.max_triangles)
      fail("the scene instances " + count_text(total.triangles) + " triangles, over the limit of " +
           count_text(limits_.max_triangles) + " (raise it with --max-triangles)");
    // Node visits cost time even without meshes; a hierarchy that revisits shared subtrees this
    // often is an attack, not a scene.
    if (total.nodes > limits_.max_triangles)
      fail("the node hierarchy instances " + count_text(total.nodes) + " nodes, over the limit of " +
           count_text(limits_.max_triangles) + " (raise it with --max-triangles)");
  }

  void check_memory() {
    check_estimate(estimate_, limits_, file_);
    scene_.estimated_load_bytes = estimate_.bytes();
  }

  // -- node hierarchy ---------------------------------------------------------------------------

  // The default scene's root nodes; without scenes, every node that is nobody's child.
  std::vector<int> scene_roots() const {
    std::vector<int> roots;
    if (!model_.scenes.empty()) {
      const int index = model_.defaultScene >= 0 ? model_.defaultScene : 0;
      if (index < static_cast<int>(model_.scenes.size())) roots = model_.scenes[index].nodes;
      return roots;
    }
    std::vector<bool> is_child(model_.nodes.size(), false);
    for (const tinygltf::Node& node : model_.nodes)
      for (int child : node.children)
        if (child >= 0 && child < static_cast<int>(is_child.size())) is_child[child] = true;
    for (size_t i = 0; i < model_.nodes.size(); ++i)
      if (!is_child[i]) roots.push_back(static_cast<int>(i));
    return roots;
  }

  void traverse_scene() {
    if (!model_.scenes.empty()) {
      scene_index_ = model_.defaultScene >= 0 ? model_.defaultScene : 0;
      if (scene_index_ >= static_cast<int>(model_.scenes.size()))
        fail("default scene " + std::to_string(scene_index_) + " out of range");
    }
    const std::vector<int> roots = scene_roots();
    std::vector<bool> on_path(model_.nodes.size(), false);
    for (int root : roots) visit_node(root, glm::mat4(1.0f), on_path);
  }

  // Depth-first with an explicit stack: a hierarchy thousands of levels deep must not overflow the
  // call stack. A node reached again while still on the current path is a cycle.
  void visit_node(int root, const glm::mat4& parent, std::vector<bool>& on_path) {
    struct Frame {
      int index;
      glm::mat4 world;
      size_t next_child = 0;
    };
    std::vector<Frame> stack;
    auto enter = [&](int index, const glm::mat4& parent_world) {
      if (index < 0 || index >= static_cast<int>(model_.nodes.size())) fail("node " + std::to_string(index) + " out of range");
      if (on_path[index]) fail("node " + std::to_string(index) + " is its own ancestor (cycle in the node hierarchy)");
      on_path[index] = true;
      const tinygltf::Node& node = model_.nodes[index];
      glm::mat4 world = parent_world * node_local_transform(node);
      if (node.mesh >= 0) add_mesh_instances(index, world);
      else if (node.mesh < -1) fail("node " + std::to_string(index) + " mesh index out of range");
      if (node.camera >= 0) add_camera(node.camera, world);
      if (const tinygltf::Value* ext = find_extension(node.extensions, "KHR_lights_punctual"))
        add_light(int_or(ext->Get("light"), -1), world);
      stack.push_back({index, world});
    };
    enter(root, parent);
    while (!stack.empty()) {
      Frame& top = stack.back();
      const std::vector<int>& children = model_.nodes[top.index].children;
      if (top.next_child < children.size()) {
        const int child = children[top.next_child++];
        const glm::mat4 world = top.world;  // `top` may dangle once enter() grows the stack
        enter(child, world);
      } else {
        on_path[top.index] = false;
        stack.pop_back();
      }
    }
  }

  void add_camera(int index, const glm::mat4& world) {
    if (index >= static_cast<int>(model_.cameras.size())) fail("camera " + std::to_string(index) + " out of range");
    if (have_camera_) return;  // the first camera in the hierarchy wins
    const tinygltf::Camera& camera = model_.cameras[index];
    if (camera.type == "orthographic") return add_orthographic_camera(index, camera.orthographic, world);
    if (camera.type != "perspective") {
      warn("camera " + std::to_string(index) + " is of type '" + camera.type + "' (perspective or orthographic); ignoring it");
      return;
    }
    const auto& p = camera.perspective;
    Camera& out = scene_.camera;
    out.camera_to_world = rigid_frame(world);
    check_magnitude(glm::vec3(out.camera_to_world[3]), "camera " + std::to_string(index));
    const double yfov = p.yfov;
    out.yfov = (yfov > 1e-4 && yfov < 3.1) ? static_cast<float>(yfov) : Camera{}.yfov;
    if (out.yfov != static_cast<float>(yfov)) {
      char text[160];
      std::snprintf(text, sizeof text, "camera %d has a yfov of %.6g, outside (0.0001, 3.1) radians; using %.4g", index,
                    yfov, static_cast<double>(out.yfov));
      warn(text);
    }
    float znear = finite_or(p.znear, 0.0f);
    out.znear = znear > 0.0f ? znear : Camera{}.znear;
    float zfar = finite_or(p.zfar, 0.0f);
    infinite_far_ = !(zfar > out.znear);
    out.zfar = infinite_far_ ? Camera{}.zfar : zfar;
    float aspect = finite_or(p.aspectRatio, 0.0f);
    out.aspect = aspect > 0.0f ? aspect : 0.0f;
    have_camera_ = true;
  }

  // glTF's xmag/ymag are half-extents; the image aspect wins over xmag as it does over aspectRatio.
  void add_orthographic_camera(int index, const tinygltf::OrthographicCamera& o, const glm::mat4& world) {
    float ymag = std::fabs(finite_or(o.ymag, 0.0f));
    if (!(ymag > 0.0f)) {
      warn("orthographic camera " + std::to_string(index) + " has ymag " + std::to_string(o.ymag) + "; ignoring it");
      return;
    }
    Camera& out = scene_.camera;
    out = Camera{};
    out.camera_to_world = rigid_frame(world);
    check_magnitude(glm::vec3(out.camera_to_world[3]), "camera " + std::to_string(index));
    out.orthographic = true;
    out.ymag = ymag;
    float xmag = std::fabs(finite_or(o.xmag, 0.0f));
    check_extent(ymag, "orthographic camera " + std::to_string(index) + " ymag");
    check_extent(xmag, "orthographic camera " + std::to_string(index) + " xmag");
    out.aspect = xmag > 0.0f ? xmag / ymag : 0.0f;
    float znear = finite_or(o.znear, 0.0f);
    out.znear = znear >= 0.0f ? znear : 0.0f;
    float zfar = finite_or(o.zfar, 0.0f);
    infinite_far_ = !(zfar > out.znear);  // zfar is required for orthographic; bad values are widened
    out.zfar = infinite_far_ ? Camera{}.zfar : zfar;
    have_camera_ = true;
  }

  void add_light(int index, const glm::mat4& world) {
    if (index < 0 || index >= static_cast<int>(model_.lights.size())) fail("light " + std::to_string(index) + " out of range");
    const tinygltf::Light& light = model_.lights[index];
    PunctualLight out;
    if (light.type == "point") out.type = PunctualLight::Type::Point;
    else if (light.type == "spot") out.type = PunctualLight::Type::Spot;
    else if (light.type == "directional") out.type = PunctualLight::Type::Directional;
    else {
      warn("light " + std::to_string(index) + " has unknown type '" + light.type + "'; ignoring it");
      return;
    }
    out.name = light.name;
    out.color = glm::max(vec3_or(light.color, glm::vec3(1.0f)), glm::vec3(0.0f));
    out.intensity = std::max(finite_or(light.intensity, 1.0f), 0.0f);
    out.range = std::max(finite_or(light.range, 0.0f), 0.0f);
    out.position = glm::vec3(world[3]);
    glm::vec3 direction = glm::mat3(world) * glm::vec3(0.0f, 0.0f, -1.0f);  // lights shine down -Z
    float len = glm::length(direction);
    out.direction = (len > 0.0f && std::isfinite(len)) ? direction / len : glm::vec3(0.0f, 0.0f, -1.0f);
    out.outer_cone = std::clamp(finite_or(light.spot.outerConeAngle, 0.785398f), 0.0f, 1.5707963f);
    out.inner_cone = std::clamp(finite_or(light.spot.innerConeAngle, 0.0f), 0.0f, out.outer_cone);
    if (!gltf::is_finite(out.position)) {
      warn("light " + std::to_string(index) + " has a non-finite position; ignoring it");
      return;
    }
    check_magnitude(out.position, "light " + std::to_string(index));
    scene_.lights.push_back(out);
  }

  // -- meshes -----------------------------------------------------------------------------------

  // The node's mesh, once per EXT_mesh_gpu_instancing instance (its transform after the node's).
  void add_mesh_instances(int node_index, const glm::mat4& world) {
    const tinygltf::Node& node = model_.nodes[node_index];
    const auto instances = gltf::instance_transforms(model_, node, file_, "node " + std::to_string(node_index));
    if (!instances) return add_mesh(node.mesh, world);
    for (const glm::mat4& instance : *instances) add_mesh(node.mesh, world * instance);
  }

  void add_mesh(int index, const glm::mat4& world) {
    if (index >= static_cast<int>(model_.meshes.size())) fail("mesh " + std::to_string(index) + " out of range");
    const tinygltf::Mesh& mesh = model_.meshes[index];
    for (size_t p = 0; p < mesh.primitives.size(); ++p) add_primitive(mesh, index, p, world);
  }

  int attribute(const tinygltf::Primitive& primitive, const char* name) const {
    auto it = primitive.attributes.find(name);
    return it == primitive.attributes.end() ? -1 : it->second;
  }

  static std::vector<glm::uvec3> assemble_triangles(const std::vector<uint32_t>& idx, int mode) {
    std::vector<glm::uvec3> tris;
    if (mode == TINYGLTF_MODE_TRIANGLES) {
      for (size_t i = 0; i + 2 < idx.size(); i += 3) tris.emplace_back(idx[i], idx[i + 1], idx[i + 2]);
    } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
      for (size_t i = 0; i + 2 < idx.size(); ++i)
        tris.push_back(i % 2 == 0 ? glm::uvec3(idx[i], idx[i + 1], idx[i + 2]) : glm::uvec3(idx[i + 1], idx[i], idx[i + 2]));
    } else if (mode == TINYGLTF_MODE_TRIANGLE_FAN) {
      for (size_t i = 1; i + 1 < idx.size(); ++i) tris.emplace_back(idx[0], idx[i], idx[i + 1]);
    }
    return tris;
  }

  void add_primitive(const tinygltf::Mesh& gmesh, int mesh_index, size_t prim_index, const glm::mat4& world) {
    const tinygltf::Primitive& prim = gmesh.primitives[prim_index];
    std::string what = "mesh " + std::to_string(mesh_index) + " primitive " + std::to_string(prim_index);
    int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
    if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP && mode != TINYGLTF_MODE_TRIANGLE_FAN) {
      warn(what + " uses mode " + std::to_string(mode) + " (points or lines); skipped");
      return;
    }
    int position_accessor = attribute(prim, "POSITION");
    if (position_accessor < 0) {
      warn(what + " has no POSITION; skipped");
      return;
    }
    Mesh mesh;
    mesh.name = gmesh.name.empty() ? what : gmesh.name;
    mesh.positions = gltf::read_vec3(model_, position_accessor, file_, what + " POSITION");
    size_t n = mesh.positions.size();
    auto check_count = [&](size_t count, const char* name) {
      if (count != n) fail(what + " " + name + " has " + std::to_string(count) + " elements, POSITION has " + std::to_string(n));
    };
    if (int a = attribute(prim, "NORMAL"); a >= 0) {
      mesh.normals = gltf::read_vec3(model_, a, file_, what + " NORMAL");
      check_count(mesh.normals.size(), "NORMAL");
    }
    if (int a = attribute(prim, "TANGENT"); a >= 0) {
      mesh.tangents = gltf::read_vec4(model_, a, file_, what + " TANGENT");
      check_count(mesh.tangents.size(), "TANGENT");
    }
    if (int a = attribute(prim, "TEXCOORD_0"); a >= 0) {
      mesh.uv0 = gltf::read_vec2(model_, a, file_, what + " TEXCOORD_0");
      check_count(mesh.uv0.size(), "TEXCOORD_0");
    }
    if (int a = attribute(prim, "TEXCOORD_1"); a >= 0) {
      mesh.uv1 = gltf::read_vec2(model_, a, file_, what + " TEXCOORD_1");
      check_count(mesh.uv1.size(), "TEXCOORD_1");
    }
    if (int a = attribute(prim, "COLOR_0"); a >= 0) {
      mesh.colors = gltf::read_color(model_, a, file_, what + " COLOR_0");
      check_count(mesh.colors.size(), "COLOR_0");
    }
    std::vector<uint32_t> indices;
    if (prim.indices >= 0) {
      indices = gltf::read_indices(model_, prim.indices, file_, what + " indices");
      for (uint32_t i : indices)
        if (i >= n) fail(what + " index " + std::to_string(i) + " out of range (" + std::to_string(n) + " vertices)");
    } else {
      indices.resize(n);
      for (size_t i = 0; i < n; ++i) indices[i] = static_cast<uint32_t>(i);
    }
    mesh.triangles = assemble_triangles(indices, mode);
    if (prim.material >= static_cast<int>(model_.materials.size()) || prim.material < -1)
      fail(what + " material " + std::to_string(prim.material) + " out of range");
    mesh.material = prim.material >= 0 ? prim.material : static_cast<int>(model_.materials.size());

    transform_to_world(mesh, world);
    gltf::drop_invalid_triangles(mesh, dropped_);
    if (mesh.triangles.empty()) return;
    for (const glm::uvec3& t : mesh.triangles)
      for (uint32_t v : {t.x, t.y, t.z}) check_magnitude(mesh.positions[v], what + " vertex");
    finish_attributes(mesh, what);
    scene_.meshes.push_back(std::move(mesh));
  }

  static void transform_to_world(Mesh& mesh, const glm::mat4& world) {
    glm::mat3 linear(world);
    float det = glm::determinant(linear);
    glm::mat3 normal_matrix = glm::transpose(glm::inverse(linear));
    for (glm::vec3& p : mesh.positions) p = glm::vec3(world * glm::vec4(p, 1.0f));
    for (glm::vec3& nrm : mesh.normals) nrm = normal_matrix * nrm;
    // A mirroring transform flips the handedness of the tangent frame and, per glTF, the winding.
    float handedness = det < 0.0f ? -1.0f : 1.0f;
    for (glm::vec4& t : mesh.tangents) t = glm::vec4(linear * glm::vec3(t), t.w * handedness);
    if (det < 0.0f)
      for (glm::uvec3& tri : mesh.triangles) std::swap(tri.y, tri.z);
  }

  // Normals always, tangents when the material has a normal map, bounded UVs and colors.
  void finish_attributes(Mesh& mesh, const std::string& what) {
    std::vector<glm::vec3> geometric = gltf::area_weighted_normals(mesh);
    if (mesh.normals.empty()) mesh.normals = geometric;
    else gltf::sanitize_normals(mesh, geometric);
    const glm::vec2 uv_limit(kMaxTextureCoordinate);
    for (std::vector<glm::vec2>* uvs : {&mesh.uv0, &mesh.uv1})
      for (glm::vec2& uv : *uvs) uv = gltf::is_finite(uv) ? glm::clamp(uv, -uv_limit, uv_limit) : glm::vec2(0.0f);
    // A linear multiplier of the base color, which is in [0, 1] too: a color of 3e38 times an HDR
    // texel was an infinite albedo.
    for (glm::vec4& c : mesh.colors) c = gltf::is_finite(c) ? glm::clamp(c, glm::vec4(0.0f), glm::vec4(1.0f)) : glm::vec4(1.0f);

    const Material& material = scene_.materials[mesh.material];
    // Tangents for the normal map, else for the clearcoat's (from its UV set when there is only that).
    const TextureRef& normal_map = material.normal_texture.valid() ? material.normal_texture : material.clearcoat_normal_texture;
    if (!normal_map.valid()) {
      if (!mesh.tangents.empty()) gltf::sanitize_tangents(mesh);
      return;
    }
    if (mesh.tangents.empty()) {
      const std::vector<glm::vec2>& uvs = normal_map.texcoord == 1 ? mesh.uv1 : mesh.uv0;
      if (uvs.empty()) warn(what + " has a normal map but no texture coordinates; its tangents are arbitrary");
      mesh.tangents = gltf::compute_tangents(mesh, uvs);
    }
    gltf::sanitize_tangents(mesh);
  }

  // -- camera, defaults, warnings ---------------------------------------------------------------

  void scene_bounds(glm::vec3& lo, glm::vec3& hi) const {
    lo = glm::vec3(std::numeric_limits<float>::max());
    hi = -lo;
    for (const Mesh& mesh : scene_.meshes)
      for (const glm::uvec3& t : mesh.triangles)
        for (uint32_t v : {t.x, t.y, t.z}) {
          lo = glm::min(lo, mesh.positions[v]);
          hi = glm::max(hi, mesh.positions[v]);
        }
    if (!(lo.x <= hi.x)) lo = hi = glm::vec3(0.0f);
  }

  void finish_camera() {
    glm::vec3 lo, hi;
    scene_bounds(lo, hi);
    glm::vec3 center = 0.5f * (lo + hi);
    float radius = std::max(0.5f * glm::length(hi - lo), 1e-3f);
    if (!have_camera_) {
      const SceneDefaults& d = scene_.defaults;
      float aspect = d.width > 0 && d.height > 0 ? static_cast<float>(d.width) / d.height : 1.0f;
      scene_.camera = frame_bounds(lo, hi, aspect);
      scene_.automatic_camera = true;
      return;
    }
    if (infinite_far_) {
      glm::vec3 eye(scene_.camera.camera_to_world[3]);
      scene_.camera.zfar = std::max(scene_.camera.zfar, 2.0f * (glm::length(eye - center) + radius));
    }
  }

  void read_scene_defaults() {
    if (scene_index_ < 0) return;
    const tinygltf::Value& pxf = member(model_.scenes[scene_index_].extras, "pxf");
    if (!pxf.IsObject()) return;
    const tinygltf::Value& all_hv = pxf.Get("all_hv");
    if (all_hv.IsBool()) scene_.defaults.all_hv = all_hv.Get<bool>();
    auto size = [&](const char* key) {
      double v = number_or(pxf.Get(key), 0.0);
      return std::isfinite(v) && v > 0 && v <= 16384 ? static_cast<int>(v) : 0;
    };
    scene_.defaults.width = size("width");
    scene_.defaults.height = size("height");
  }

  void report_dropped_triangles() {
    if (dropped_.nonfinite)
      warn("dropped " + std::to_string(dropped_.nonfinite) + " triangles with NaN/Inf vertex positions");
    if (dropped_.degenerate)
      warn("dropped " + std::to_string(dropped_.degenerate) + " degenerate (zero-area) triangles");
  }

  // A registered texture waiting for its image (scene_.textures has one entry per pending one).
  struct PendingTexture {
    int image;
    bool srgb;
    std::string material;
    const char* slot;
  };

  std::string file_;
  LoadLimits limits_;
  LoadEstimate estimate_;
  std::vector<PendingTexture> pending_;
  // A material read from KHR_materials_pbrSpecularGlossiness, converted after decoding.
  struct SpecGlossMaterial {
    size_t material;
    SpecGlossFactors factors;
  };
  std::vector<SpecGlossMaterial> spec_gloss_;
  std::string base_dir_;  // what relative uris are resolved against
  tinygltf::Model model_;
  gltf::ImageStore images_;
  Scene scene_;
  std::map<std::pair<int, bool>, int> texture_cache_;
  gltf::DroppedTriangles dropped_;
  int scene_index_ = -1;
  bool have_camera_ = false;
  bool infinite_far_ = false;
};

// ---------------------------------------------------------------------------------------------
// Environment

enum class FileKind { Exr, RadianceHdr, Gltf, Glb, Other };

// The format by its first bytes, not its name: a renamed or mislabelled file still gets the
// right reader or a clear error.
// `max_bytes`: the bound of the readers the file may go to.
FileKind sniff_file(const std::string& path, uint64_t max_bytes) {
  const std::vector<unsigned char> head = read_input_file_head(path, max_bytes, 10);
  const std::string bytes(head.begin(), head.end());
  if (bytes.compare(0, 4, "\x76\x2f\x31\x01") == 0) return FileKind::Exr;
  if (bytes.compare(0, 2, "#?") == 0) return FileKind::RadianceHdr;
  if (bytes.compare(0, 4, "glTF") == 0) return FileKind::Glb;
  size_t first = bytes.find_first_not_of(" \t\r\n\xef\xbb\xbf");
  if (first != std::string::npos && bytes[first] == '{') return FileKind::Gltf;
  return FileKind::Other;
}

// The environment image as linear float RGB(A)/Y channels, by format.
Image read_environment_image(const std::string& path) {
  switch (sniff_file(path, std::max(kMaxExrFileBytes, kMaxStbImageFileBytes))) {
    case FileKind::Exr: return read_exr(path);
    case FileKind::RadianceHdr: return read_ldr_or_hdr(path);
    default: throw Error(path + ": not a supported environment map (supported: OpenEXR .exr, Radiance .hdr)");
  }
}

// An image's size as its header states it (0 x 0: unknown).
struct ImageSize {
  uint64_t width = 0, height = 0;
};

// An OpenEXR header's dataWindow: after the magic and version, attributes "name\0type\0", an
// int32 size and the value, up to an empty name.
ImageSize exr_data_window(const std::vector<unsigned char>& head) {
  size_t at = 8;
  auto next_string = [&](std::string& out) {
    if (at >= head.size()) return false;
    const auto end = std::find(head.begin() + at, head.end(), 0);
    if (end == head.end()) return false;
    out.assign(head.begin() + at, end);
    at = static_cast<size_t>(end - head.begin()) + 1;
    return true;
  };
  std::string name, type;
  while (next_string(name) && !name.empty() && next_string(type) && at + 4 <= head.size()) {
    int32_t size = 0;
    std::memcpy(&size, &head[at], 4);
    at += 4;
    if (size < 0 || static_cast<size_t>(size) > head.size() - at) break;
    if (name == "dataWindow" && type == "box2i" && size == 16) {
      int32_t box[4];
      std::memcpy(box, &head[at], sizeof box);
      const int64_t width = int64_t{box[2]} - box[0] + 1, height = int64_t{box[3]} - box[1] + 1;
      if (width <= 0 || height <= 0) break;
      return {static_cast<uint64_t>(width), static_cast<uint64_t>(height)};
    }
    at += static_cast<size_t>(size);
  }
  return {};
}

// The environment image's size from its header, before a pixel is decoded: OpenEXR's dataWindow,
// Radiance's resolution line (stb). Unknown (0 x 0) when the header does not say, or the path is
// not a regular file: the reader then names the problem.
ImageSize environment_size(const std::string& path) {
  constexpr size_t kHeaderBytes = 1 << 16;
  // Through the shared reader: a file swapped for a FIFO after the sniff is refused, not waited on.
  const std::vector<unsigned char> head =
      read_input_file_head(path, std::max(kMaxExrFileBytes, kMaxStbImageFileBytes), kHeaderBytes);
  if (head.size() >= 8 && std::memcmp(head.data(), "\x76\x2f\x31\x01", 4) == 0) return exr_data_window(head);
  const gltf::ImageHeader header = gltf::probe_image(head.data(), head.size());
  if (!header.ok) return {};
  return {static_cast<uint64_t>(header.width), static_cast<uint64_t>(header.height)};
}

// The environment map is a texture like the scene's: under --max-texture-size and, with the
// scene, in the memory estimate. Checked from its header, before it is decoded.
void check_environment_size(const std::string& path, const LoadLimits& limits) {
  const ImageSize size = environment_size(path);
  const uint64_t cap = static_cast<uint64_t>(std::max(limits.max_texture_size, 0));
  if (size.width > cap || size.height > cap)
    throw Error(path + ": environment map is " + std::to_string(size.width) + "x" + std::to_string(size.height) +
                ", over the texture size limit of " + std::to_string(cap) + " (raise it with --max-texture-size)");
  LoadEstimate estimate;
  estimate.environment_texels = size.width * size.height;  // both at most the cap (an int)
  check_estimate(estimate, limits, path);
}

Environment load_environment(const std::string& path, float strength, std::vector<std::string>& warnings) {
  if (!std::isfinite(strength) || strength < 0.0f)
    throw Error(path + ": environment strength " + std::to_string(strength) + " must be finite and >= 0");
  Image image = read_environment_image(path);
  int r = image.channel_index("R"), g = image.channel_index("G"), b = image.channel_index("B");
  int y = image.channel_index("Y");
  if ((r < 0 || g < 0 || b < 0) && y < 0) throw Error(path + ": environment map needs R, G, B (or Y) channels");
  if (image.empty()) throw Error(path + ": environment map is empty");
  if (image.width != 2 * image.height)
    warnings.push_back(path + ": environment map is " + std::to_string(image.width) + "x" + std::to_string(image.height) +
                       ", not 2:1; read as equirectangular (latitude-longitude) anyway");
  Environment env;
  env.strength = strength;
  env.source = path;
  Texture& tex = env.image;
  tex.name = path;
  tex.width = image.width;
  tex.height = image.height;
  tex.wrap_s = Wrap::Repeat;       // longitude wraps around
  tex.wrap_t = Wrap::ClampToEdge;  // latitude stops at the poles
  tex.texels.resize(image.pixel_count());
  size_t replaced = 0;
  auto clean = [&](float v) {
    if (std::isfinite(v) && v >= 0.0f) return v;
    ++replaced;
    return 0.0f;
  };
  for (int py = 0; py < image.height; ++py)
    for (int px = 0; px < image.width; ++px) {
      glm::vec3 c = r >= 0 && g >= 0 && b >= 0
                        ? glm::vec3(image.at(px, py, r), image.at(px, py, g), image.at(px, py, b))
                        : glm::vec3(image.at(px, py, y));
      tex.texels[static_cast<size_t>(py) * image.width + px] = glm::vec4(clean(c.x), clean(c.y), clean(c.z), 1.0f);
    }
  bool any_light = std::any_of(tex.texels.begin(), tex.texels.end(),
                               [](const glm::vec4& t) { return t.x > 0.0f || t.y > 0.0f || t.z > 0.0f; });
  if (!any_light) throw Error(path + ": environment map has no positive radiance (it would light nothing)");
  if (replaced)
    warnings.push_back(path + ": replaced " + std::to_string(replaced) + " NaN/Inf/negative environment values by 0");
  return env;
}

// An image passed as the scene gets told so, rather than reaching the JSON parser.
void check_scene_file(const std::string& path) {
  FileKind kind = sniff_file(path, kMaxGltfFileBytes);
  if (kind == FileKind::Exr || kind == FileKind::RadianceHdr)
    throw Error(path + ": is an environment image, not a scene (--scene takes a .gltf/.glb file or a built-in name; "
                "pass environment maps with --env)");
}

}  // namespace


// Per instanced vertex: the loader's attributes (position, normal, tangent, two uv sets, color:
// 72 B) and the raster pass's vertex, in its staging copy and its GL buffer (2 x 64 B). Per
// instanced triangle: the indices as read and as triangles, the raster pass's index buffer
// (3 x 12 B) and the BVH (Embree's build, about 100 B). Per instanced primitive, whatever its size:
// a Mesh with its vectors, an Embree geometry and the raster pass's draw (measured on many
// instances of a quad above the vertices' and triangles' share, with a margin).
// The raster pass's draws through llvmpipe, the software GL that renders headless: it bins every
// triangle it draws (about 700 B each with the range pass's varyings) into scenes of bounded size
// that queue for its rasterizer threads, so this grows with the triangles up to a ceiling and
// then stays (docs/robustness.md, "Memory", has the measurements).
// Per instanced punctual light: the PunctualLight in a growing vector (up to 3 copies while it
// doubles) and the light sampler's pointer (measured on many lights). Textures: their
// storage, the raster pass's copy (at most as large), and the largest image's decoding buffers.
// Per environment texel: while loading, the decoded image (up to 4 float channels) and the linear
// RGBA texture (16 + 16 B); after, the texture, the raster pass's RGBA32F copy and the importance
// map (16 + 16 + 8 B; a measured peak agrees).
uint64_t LoadEstimate::bytes() const {
  constexpr uint64_t kBytesPerVertex = 72 + 2 * 64, kBytesPerTriangle = 3 * 12 + 100, kBytesPerMesh = 8192,
                     kBytesPerLight = 320, kBytesPerEnvironmentTexel = 40;
  constexpr uint64_t kRasterBinBytesPerTriangle = 768, kRasterBinBytesMax = uint64_t{160} << 20;
  auto add = [](uint64_t a, uint64_t b) { return a > UINT64_MAX - b ? UINT64_MAX : a + b; };
  auto mul = [](uint64_t a, uint64_t b) { return b != 0 && a > UINT64_MAX / b ? UINT64_MAX : a * b; };
  const uint64_t raster_bins = std::min(mul(triangles, kRasterBinBytesPerTriangle), kRasterBinBytesMax);
  const uint64_t geometry = add(add(add(mul(vertices, kBytesPerVertex), mul(triangles, kBytesPerTriangle)), raster_bins),
                                add(mul(meshes, kBytesPerMesh), mul(lights, kBytesPerLight)));
  // Level 0 stored and copied by the raster pass, and the path tracer's mip chains (a third of
  // level 0 at most).
  const uint64_t images = add(add(add(mul(texture_bytes, 2), texture_bytes / 3), largest_decode_bytes),
                              mul(environment_texels, kBytesPerEnvironmentTexel));
  return add(add(geometry, images), decoded_buffer_bytes);
}

std::string builtin_assets_dir() {
  static const std::string dir = [] {
    std::error_code ec;
    const fs::path executable = fs::read_symlink("/proc/self/exe", ec);
    if (!ec) {
      const fs::path installed = (executable.parent_path() / PXF_ASSETS_FROM_BINDIR).lexically_normal();
      if (fs::is_directory(installed, ec)) return installed.string();
    }
    return std::string(PXF_ASSETS_DIR);
  }();
  return dir;
}

std::vector<BuiltinScene> builtin_scenes() {
  std::vector<BuiltinScene> scenes;
  for (const BuiltinInfo& info : kBuiltins) {
    std::string path = builtin_path(info.name);
    std::error_code ec;
    if (fs::is_regular_file(path, ec)) scenes.push_back({info.name, info.description, path});
  }
  return scenes;
}

Scene load_scene_from_memory(const std::vector<unsigned char>& bytes, const std::string& name,
                             const std::string& base_dir, const LoadLimits& limits) {
  Scene scene = GltfLoader(name, limits).load_from_memory(bytes.data(), bytes.size(), base_dir);
  scene.source = name;
  return scene;
}

Scene load_scene(const std::string& name_or_path, const std::string& env_path, float env_strength,
                 DefaultLight default_light, const LoadLimits& limits) {
  std::string path = name_or_path;
  std::string builtin_env;
  for (const BuiltinScene& builtin : builtin_scenes())
    if (builtin.name == name_or_path) {
      path = builtin.path;
      std::string env = (fs::path(path).parent_path() / "environment.exr").string();
      std::error_code ec;
      if (fs::is_regular_file(env, ec)) builtin_env = env;
    }
  // Every input is checked before the (possibly long) scene load, so a bad --env fails at once.
  std::vector<std::string> env_warnings;
  std::string env = env_path.empty() ? builtin_env : env_path;
  std::optional<Environment> environment;
  uint64_t environment_texels = 0;
  if (!env.empty()) {
    check_environment_size(env, limits);
    environment = load_environment(env, env_strength, env_warnings);
    environment_texels = environment->image.texel_count();
  }
  check_scene_file(path);
  Scene scene = GltfLoader(path, limits, environment_texels).load();
  scene.source = name_or_path;
  scene.warnings.insert(scene.warnings.end(), env_warnings.begin(), env_warnings.end());
  if (environment) scene.environment = std::move(environment);
  std::string note = apply_default_light(scene, default_light);
  if (!note.empty()) (default_light == DefaultLight::None ? scene.warnings : scene.notes).push_back(note);
  return scene;
}

}  // namespace pxf
