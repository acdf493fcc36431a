#include "gl/resources.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <glm/gtc/type_ptr.hpp>
#include "gl/dispatch.h"
#include "gl/gl.h"

namespace pxf {
namespace {

GLenum gl_stage(ShaderStage stage) {
  switch (stage) {
    case ShaderStage::Vertex: return GL_VERTEX_SHADER;
    case ShaderStage::Fragment: return GL_FRAGMENT_SHADER;
    case ShaderStage::Compute: return GL_COMPUTE_SHADER;
  }
  return GL_FRAGMENT_SHADER;
}

ShaderStage stage_of(const std::string& file) {
  auto ends = [&](const char* ext) {
    std::string e(ext);
    return file.size() >= e.size() && file.compare(file.size() - e.size(), e.size(), e) == 0;
  };
  if (ends(".vert")) return ShaderStage::Vertex;
  if (ends(".frag")) return ShaderStage::Fragment;
  if (ends(".comp")) return ShaderStage::Compute;
  throw Error("shader " + file + ": unknown stage (expected .vert, .frag or .comp)");
}

struct FormatInfo {
  GLenum internal, format, type;
  int channels;
};
FormatInfo info(TextureFormat f) {
  switch (f) {
    case TextureFormat::R32F: return {GL_R32F, GL_RED, GL_FLOAT, 1};
    case TextureFormat::RG32F: return {GL_RG32F, GL_RG, GL_FLOAT, 2};
    case TextureFormat::RGBA32F: return {GL_RGBA32F, GL_RGBA, GL_FLOAT, 4};
    case TextureFormat::RGBA8: return {GL_RGBA8, GL_RGBA, GL_FLOAT, 4};
    case TextureFormat::SRGB8_ALPHA8: return {GL_SRGB8_ALPHA8, GL_RGBA, GL_FLOAT, 4};
    case TextureFormat::Depth32F: return {GL_DEPTH_COMPONENT32F, GL_DEPTH_COMPONENT, GL_FLOAT, 1};
  }
  return {GL_RGBA32F, GL_RGBA, GL_FLOAT, 4};
}
GLenum components_format(int c) {
  static const GLenum f[] = {GL_RED, GL_RED, GL_RG, GL_RGB, GL_RGBA};
  return f[c < 1 ? 1 : (c > 4 ? 4 : c)];
}

GlTiming g_timing = GlTiming::Finish;
double now_ms() {
  using namespace std::chrono;
  return duration<double, std::milli>(steady_clock::now().time_since_epoch()).count();
}

}  // namespace

// ---- Shader / Program ----

Shader::Shader(ShaderStage stage, const std::string& file_name, const std::string& source,
               const IncludeResolver& resolve)
    : file_(file_name) {
  ExpandedShader expanded = expand_includes(file_name, source, resolve);
  name_.id = glCreateShader(gl_stage(stage));
  const char* text = expanded.text.c_str();
  glShaderSource(name_.id, 1, &text, nullptr);
  glCompileShader(name_.id);
  GLint ok = 0;
  glGetShaderiv(name_.id, GL_COMPILE_STATUS, &ok);
  if (ok) return;
  GLint length = 0;
  glGetShaderiv(name_.id, GL_INFO_LOG_LENGTH, &length);
  std::string log(static_cast<size_t>(length > 1 ? length : 1), '\0');
  glGetShaderInfoLog(name_.id, length, nullptr, log.data());
  std::string first = first_error_line(log, expanded.files);
  glDeleteShader(name_.id);
  name_.id = 0;
  throw Error("shader " + (first.empty() ? file_name + ": compilation failed" : first));
}

Shader::~Shader() {
  if (name_.id) glDeleteShader(name_.id);
}

Program::Program(const std::vector<const Shader*>& shaders) {
  name_.id = glCreateProgram();
  for (const Shader* s : shaders) {
    glAttachShader(name_.id, s->id());
    files_ += (files_.empty() ? "" : " + ") + s->file_name();
  }
  glLinkProgram(name_.id);
  for (const Shader* s : shaders) glDetachShader(name_.id, s->id());
  GLint ok = 0;
  glGetProgramiv(name_.id, GL_LINK_STATUS, &ok);
  if (ok) {
    find_samplers();
    return;
  }
  GLint length = 0;
  glGetProgramiv(name_.id, GL_INFO_LOG_LENGTH, &length);
  std::string log(static_cast<size_t>(length > 1 ? length : 1), '\0');
  glGetProgramInfoLog(name_.id, length, nullptr, log.data());
  std::string first = first_error_line(log, {});
  glDeleteProgram(name_.id);
  name_.id = 0;
  throw Error("shader program " + files_ + ": link failed: " + first);
}

Program::~Program() {
  if (name_.id) glDeleteProgram(name_.id);
}

Program Program::from_embedded(const std::string& vertex_file, const std::string& fragment_file) {
  Shader vs(stage_of(vertex_file), vertex_file, embedded_shader(vertex_file));
  Shader fs(stage_of(fragment_file), fragment_file, embedded_shader(fragment_file));
  return Program({&vs, &fs});
}

Program Program::from_embedded_compute(const std::string& compute_file) {
  Shader cs(ShaderStage::Compute, compute_file, embedded_shader(compute_file));
  return Program({&cs});
}

void Program::find_samplers() {
  GLint count = 0;
  glGetProgramiv(name_.id, GL_ACTIVE_UNIFORMS, &count);
  for (GLint i = 0; i < count; ++i) {
    char name[256];
    GLint size = 0;
    GLenum type = 0;
    glGetActiveUniform(name_.id, static_cast<GLuint>(i), sizeof name, nullptr, &size, &type, name);
    const bool sampler = type == GL_SAMPLER_2D || type == GL_SAMPLER_3D || type == GL_SAMPLER_CUBE ||
                         type == GL_SAMPLER_2D_ARRAY || type == GL_INT_SAMPLER_2D || type == GL_UNSIGNED_INT_SAMPLER_2D;
    if (!sampler) continue;
    GLint unit = 0;
    glGetUniformiv(name_.id, glGetUniformLocation(name_.id, name), &unit);
    if (unit < 0 || unit >= 64) throw Error("shader program " + files_ + ": sampler '" + name + "' at texture unit " + std::to_string(unit) + " (0 to 63 are checked)");
    samplers_.push_back({unit, name});
  }
}

void Program::use() const {
  glUseProgram(name_.id);
  bound_units_ = 0;
}

void Program::bind(int unit, const Texture2D& texture) const {
  const bool declared = std::any_of(samplers_.begin(), samplers_.end(), [unit](const Sampler& s) { return s.unit == unit; });
  if (!declared) throw Error("shader program " + files_ + " has no active sampler at texture unit " + std::to_string(unit));
  texture.bind(unit);
  bound_units_ |= uint64_t{1} << unit;
}

void Program::require_inputs() const {
  for (const Sampler& s : samplers_)
    if (!(bound_units_ >> s.unit & 1u))
      throw Error("shader program " + files_ + ": sampler '" + s.name + "' (texture unit " + std::to_string(s.unit) +
                  ") was not bound by its pass");
}
int Program::location(const char* uniform) const { return glGetUniformLocation(name_.id, uniform); }
// A pass that sets a uniform the program does not have (misspelt, or one the shader no longer
// reads and the linker dropped) fails loudly, as Falcor's shader variables do: GL would ignore
// location -1 and the pass would run with the uniform's default.
int Program::declared_location(const char* uniform) const {
  const int at = location(uniform);
  if (at < 0) throw Error("shader program " + files_ + " has no active uniform '" + uniform + "'");
  return at;
}
void Program::set(const char* u, int v) const { glProgramUniform1i(name_.id, declared_location(u), v); }
void Program::set(const char* u, float v) const { glProgramUniform1f(name_.id, declared_location(u), v); }
void Program::set(const char* u, glm::vec2 v) const { glProgramUniform2fv(name_.id, declared_location(u), 1, glm::value_ptr(v)); }
void Program::set(const char* u, glm::vec3 v) const { glProgramUniform3fv(name_.id, declared_location(u), 1, glm::value_ptr(v)); }
void Program::set(const char* u, glm::vec4 v) const { glProgramUniform4fv(name_.id, declared_location(u), 1, glm::value_ptr(v)); }
void Program::set(const char* u, glm::ivec2 v) const { glProgramUniform2iv(name_.id, declared_location(u), 1, glm::value_ptr(v)); }
void Program::set(const char* u, const glm::mat3& v) const {
  glProgramUniformMatrix3fv(name_.id, declared_location(u), 1, GL_FALSE, glm::value_ptr(v));
}
void Program::set(const char* u, const glm::mat4& v) const {
  glProgramUniformMatrix4fv(name_.id, declared_location(u), 1, GL_FALSE, glm::value_ptr(v));
}

// ---- Texture2D ----

int texture_format_channels(TextureFormat format) { return info(format).channels; }

Texture2D::Texture2D(int width, int height, TextureFormat format, int levels)
    : width_(width), height_(height), format_(format) {
  if (width <= 0 || height <= 0) throw Error("texture: invalid size " + std::to_string(width) + "x" + std::to_string(height));
  check_texture_size("texture", width, height, query_gl_limits());  // a one-line error, not a GL error later
  glCreateTextures(GL_TEXTURE_2D, 1, &name_.id);
  glTextureStorage2D(name_.id, levels, info(format).internal, width, height);
  set_filter(false);
  set_wrap(GL_CLAMP_TO_EDGE, GL_CLAMP_TO_EDGE);
}

Texture2D::~Texture2D() {
  if (name_.id) glDeleteTextures(1, &name_.id);
}

void Texture2D::upload(const float* data, int components) {
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTextureSubImage2D(name_.id, 0, 0, 0, width_, height_, components_format(components), GL_FLOAT, data);
}

void Texture2D::upload_rgba8(const unsigned char* data) {
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTextureSubImage2D(name_.id, 0, 0, 0, width_, height_, GL_RGBA, GL_UNSIGNED_BYTE, data);
}

void Texture2D::upload(const Image& image) {
  if (image.width != width_ || image.height != height_)
    throw Error("texture upload: image is " + std::to_string(image.width) + "x" + std::to_string(image.height) +
                ", texture " + std::to_string(width_) + "x" + std::to_string(height_));
  int c = image.num_channels();
  if (c < 1 || c > 4) throw Error("texture upload: images need 1 to 4 channels, got " + std::to_string(c));
  upload(image.pixels.data(), c);
}

Image variance_from_alpha(const Texture2D& texture) {
  const Image rgba = texture.download({"R", "G", "B", "A"});
  Image out = Image::gray(rgba.width, rgba.height);
  for (size_t i = 0; i < out.pixel_count(); ++i) {
    const float v = rgba.pixels[4 * i + 3];
    out.pixels[i] = v > 0 ? v : 0.0f;
  }
  return out;
}

Image Texture2D::download(const std::vector<std::string>& channels) const {
  Image image(width_, height_, channels);
  int c = image.num_channels();
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  GLenum format = format_ == TextureFormat::Depth32F ? GL_DEPTH_COMPONENT : components_format(c);
  glGetTextureImage(name_.id, 0, format, GL_FLOAT, static_cast<GLsizei>(image.pixels.size() * sizeof(float)),
                    image.pixels.data());
  return image;
}

glm::vec4 Texture2D::texel(int x, int y) const {
  glm::vec4 v(0.0f);
  glGetTextureSubImage(name_.id, 0, x, y, 0, 1, 1, 1, GL_RGBA, GL_FLOAT, sizeof(v), &v.x);
  return v;
}

void Texture2D::set_filter(bool linear, bool mipmaps) {
  GLenum min = linear ? (mipmaps ? GL_LINEAR_MIPMAP_LINEAR : GL_LINEAR) : (mipmaps ? GL_NEAREST_MIPMAP_NEAREST : GL_NEAREST);
  glTextureParameteri(name_.id, GL_TEXTURE_MIN_FILTER, min);
  glTextureParameteri(name_.id, GL_TEXTURE_MAG_FILTER, linear ? GL_LINEAR : GL_NEAREST);
}

void Texture2D::set_wrap(int s, int t) {
  glTextureParameteri(name_.id, GL_TEXTURE_WRAP_S, s);
  glTextureParameteri(name_.id, GL_TEXTURE_WRAP_T, t);
}

void Texture2D::bind(int unit) const { glBindTextureUnit(unit, name_.id); }

// ---- Framebuffer ----

Framebuffer::Framebuffer() { glCreateFramebuffers(1, &name_.id); }
Framebuffer::~Framebuffer() {
  if (name_.id) glDeleteFramebuffers(1, &name_.id);
}

void Framebuffer::attach(int color_index, const Texture2D& texture) {
  glNamedFramebufferTexture(name_.id, GL_COLOR_ATTACHMENT0 + color_index, texture.id(), 0);
  if (color_index + 1 > draw_buffers_) draw_buffers_ = color_index + 1;
  GLenum buffers[8];
  for (int i = 0; i < draw_buffers_; ++i) buffers[i] = GL_COLOR_ATTACHMENT0 + i;
  glNamedFramebufferDrawBuffers(name_.id, draw_buffers_, buffers);
}

void Framebuffer::attach_depth(const Texture2D& texture) {
  glNamedFramebufferTexture(name_.id, GL_DEPTH_ATTACHMENT, texture.id(), 0);
}

void Framebuffer::check(const char* what) const {
  GLenum status = glCheckNamedFramebufferStatus(name_.id, GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "0x%04x", status);
    throw Error(std::string(what) + ": framebuffer incomplete (" + buf + ")");
  }
}

void Framebuffer::bind(int width, int height) const {
  glBindFramebuffer(GL_FRAMEBUFFER, name_.id);
  glViewport(0, 0, width, height);
}

// ---- Buffer / VertexArray ----

Buffer::Buffer(size_t bytes, const void* data) : size_(bytes) {
  glCreateBuffers(1, &name_.id);
  glNamedBufferData(name_.id, static_cast<GLsizeiptr>(bytes), data, GL_DYNAMIC_DRAW);
}
Buffer::~Buffer() {
  if (name_.id) glDeleteBuffers(1, &name_.id);
}
void Buffer::upload(const void* data, size_t bytes, size_t offset) {
  if (!name_.id) glCreateBuffers(1, &name_.id);
  if (offset + bytes > size_) {
    size_ = offset + bytes;
    glNamedBufferData(name_.id, static_cast<GLsizeiptr>(size_), nullptr, GL_DYNAMIC_DRAW);
  }
  if (bytes) glNamedBufferSubData(name_.id, static_cast<GLintptr>(offset), static_cast<GLsizeiptr>(bytes), data);
}
void Buffer::download(void* data, size_t bytes, size_t offset) const {
  glGetNamedBufferSubData(name_.id, static_cast<GLintptr>(offset), static_cast<GLsizeiptr>(bytes), data);
}
void Buffer::bind_storage(int binding) const { glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding, name_.id); }

VertexArray::VertexArray() { glCreateVertexArrays(1, &name_.id); }
VertexArray::~VertexArray() {
  if (name_.id) glDeleteVertexArrays(1, &name_.id);
}
void VertexArray::bind() const { glBindVertexArray(name_.id); }
void VertexArray::attribute(int index, const Buffer& buffer, int components, size_t stride, size_t offset) {
  glVertexArrayVertexBuffer(name_.id, index, buffer.id(), static_cast<GLintptr>(offset), static_cast<GLsizei>(stride));
  glVertexArrayAttribFormat(name_.id, index, components, GL_FLOAT, GL_FALSE, 0);
  glVertexArrayAttribBinding(name_.id, index, index);
  glEnableVertexArrayAttrib(name_.id, index);
}
void VertexArray::element_buffer(const Buffer& buffer) { glVertexArrayElementBuffer(name_.id, buffer.id()); }

// ---- Full-screen pass ----

void FullscreenPass::draw(const Program& program, const Framebuffer& target, int width, int height) const {
  program.require_inputs();
  target.bind(width, height);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_BLEND);
  vao_.bind();
  glDrawArrays(GL_TRIANGLES, 0, 3);
}

// ---- Timing / errors ----

const std::vector<std::string>& gl_timing_names() {
  static const std::vector<std::string> names = {"finish", "submit"};
  return names;
}
void set_gl_timing(GlTiming timing) { g_timing = timing; }
GlTiming gl_timing() { return g_timing; }

void StageTimer::begin() {
  if (g_timing == GlTiming::Finish) glFinish();
  start_ = now_ms();
}

double StageTimer::end() {
  if (g_timing == GlTiming::Finish) glFinish();
  return last_ms_ = now_ms() - start_;
}

void check_gl_error(const char* what) {
  GLenum e = glGetError();
  if (e == GL_NO_ERROR) return;
  while (glGetError() != GL_NO_ERROR) {
  }
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%04x", e);
  throw Error(std::string(what) + ": GL error " + buf);
}

}  // namespace pxf
