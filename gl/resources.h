// RAII wrappers of the GL objects the passes use (move-only, GL 4.5 direct state access), a
// full-screen pass helper and a per-stage timer. A GL context must be current (gl/context.h).
// Usage:
//   Program p = Program::from_embedded("fullscreen.vert", "blend.frag");   // shaders/ files
//   Texture2D t(w, h, TextureFormat::RGBA32F); t.upload(image);            // pxf::Image, top row first
//   Framebuffer fb; fb.attach(0, t); fb.check("blend");
//   FullscreenPass quad; quad.draw(fb, w, h);                                 // after p.use() + binds
// Convention of every texture here: GL row y holds image row y (row 0 = top row), so uploads and
// read-backs of pxf::Image need no flip; full-screen passes address texels by gl_FragCoord.
#pragma once
#include <cstdint>
#include <string>
#include <utility>
#include <vector>
#include <glm/glm.hpp>
#include "gl/shader_library.h"
#include "image/image.h"

namespace pxf {

using GlHandle = unsigned int;  // GLuint, without including GL here

// Moves the handle, leaves 0 behind.
struct GlName {
  GlHandle id = 0;
  GlName() = default;
  explicit GlName(GlHandle h) : id(h) {}
  GlName(GlName&& o) noexcept : id(std::exchange(o.id, 0)) {}
  GlName& operator=(GlName&& o) noexcept {
    std::swap(id, o.id);
    return *this;
  }
};

enum class ShaderStage { Vertex, Fragment, Compute };

class Shader {
 public:
  // Compiles `source` (after #include expansion); a failure is a pxf::Error "shader <file>:<line>: ...".
  Shader(ShaderStage stage, const std::string& file_name, const std::string& source,
         const IncludeResolver& resolve = embedded_shader);
  ~Shader();
  Shader(Shader&&) = default;
  Shader& operator=(Shader&&) = default;
  GlHandle id() const { return name_.id; }
  const std::string& file_name() const { return file_; }

 private:
  GlName name_;
  std::string file_;
};

class Program {
 public:
  Program() = default;
  // Links the given shaders; a failure is a pxf::Error naming the files.
  explicit Program(const std::vector<const Shader*>& shaders);
  ~Program();
  Program(Program&&) = default;
  Program& operator=(Program&&) = default;
  // Stage from the extension (.vert/.frag/.comp), source from the embedded shaders/.
  static Program from_embedded(const std::string& vertex_file, const std::string& fragment_file);
  static Program from_embedded_compute(const std::string& compute_file);

  GlHandle id() const { return name_.id; }
  // Makes the program current and starts a new set of inputs (bind, require_inputs).
  void use() const;
  int location(const char* uniform) const;  // -1 when absent (optimized out)
  // set(): throws pxf::Error naming the program and the uniform when the program has no active
  // uniform of that name.
  void set(const char* uniform, int v) const;
  void set(const char* uniform, float v) const;
  void set(const char* uniform, glm::vec2 v) const;
  void set(const char* uniform, glm::vec3 v) const;
  void set(const char* uniform, glm::vec4 v) const;
  void set(const char* uniform, glm::ivec2 v) const;
  void set(const char* uniform, const glm::mat3& v) const;
  void set(const char* uniform, const glm::mat4& v) const;

  // Texture inputs, checked as Falcor checks shader variables. bind() binds `texture` to a texture
  // unit where the program has an active sampler, and throws pxf::Error naming the program and the
  // unit where it has none. require_inputs() (FullscreenPass::draw calls it, compute passes before
  // their dispatch) throws where one of the program's samplers was not bound through bind() since
  // use(): a pass binds what it reads itself, never relying on a binding another pass left behind.
  void bind(int unit, const class Texture2D& texture) const;
  void require_inputs() const;

 private:
  int declared_location(const char* uniform) const;
  void find_samplers();

  struct Sampler {
    int unit = 0;
    std::string name;
  };
  GlName name_;
  std::string files_;
  std::vector<Sampler> samplers_;  // the active sampler uniforms and their units
  mutable uint64_t bound_units_ = 0;  // bit u: unit u bound through bind() since use()
};

enum class TextureFormat { R32F, RG32F, RGBA32F, RGBA8, SRGB8_ALPHA8, Depth32F };
int texture_format_channels(TextureFormat format);

class Texture2D {
 public:
  Texture2D() = default;
  Texture2D(int width, int height, TextureFormat format, int levels = 1);
  ~Texture2D();
  Texture2D(Texture2D&&) = default;
  Texture2D& operator=(Texture2D&&) = default;

  GlHandle id() const { return name_.id; }
  int width() const { return width_; }
  int height() const { return height_; }
  TextureFormat format() const { return format_; }
  bool valid() const { return name_.id != 0; }

  // Uploads `components` floats per texel (1..4), top row first, into the whole level 0
  // (one glTextureSubImage2D). Missing components read as 0 (alpha 1).
  void upload(const float* data, int components);
  // 4 bytes a texel, RGBA (RGBA8 and SRGB8_ALPHA8 textures).
  void upload_rgba8(const unsigned char* data);
  // Upload of an image of the same size; its channel count picks the components.
  void upload(const Image& image);
  // Read-back of level 0 as floats with the given channel names (1..4 of them).
  Image download(const std::vector<std::string>& channels) const;
  // One texel of level 0 as RGBA floats (a 16-byte read-back; missing channels read 0, alpha 1).
  glm::vec4 texel(int x, int y) const;
  void set_filter(bool linear, bool mipmaps = false);
  void set_wrap(int gl_wrap_s, int gl_wrap_t);  // GL_REPEAT, GL_CLAMP_TO_EDGE, ...
  void bind(int unit) const;

 private:
  GlName name_;
  int width_ = 0, height_ = 0;
  TextureFormat format_ = TextureFormat::RGBA32F;
};

// "Y": the alpha channel of an RGBA texture that holds a variance there, 0 where it is a sentinel
// (unknown, skipped: negative).
Image variance_from_alpha(const Texture2D& texture);

class Framebuffer {
 public:
  Framebuffer();
  ~Framebuffer();
  Framebuffer(Framebuffer&&) = default;
  Framebuffer& operator=(Framebuffer&&) = default;
  GlHandle id() const { return name_.id; }
  void attach(int color_index, const Texture2D& texture);  // also enables the draw buffers 0..index
  void attach_depth(const Texture2D& texture);
  void check(const char* what) const;  // throws pxf::Error when incomplete
  void bind(int width, int height) const;  // binds for drawing and sets the viewport

 private:
  GlName name_;
  int draw_buffers_ = 0;
};

class Buffer {
 public:
  Buffer() = default;
  explicit Buffer(size_t bytes, const void* data = nullptr);  // dynamic storage
  ~Buffer();
  Buffer(Buffer&&) = default;
  Buffer& operator=(Buffer&&) = default;
  GlHandle id() const { return name_.id; }
  size_t size() const { return size_; }
  void upload(const void* data, size_t bytes, size_t offset = 0);  // grows (reallocates) when needed
  void download(void* data, size_t bytes, size_t offset = 0) const;
  void bind_storage(int binding) const;  // GL_SHADER_STORAGE_BUFFER

 private:
  GlName name_;
  size_t size_ = 0;
};

class VertexArray {
 public:
  VertexArray();
  ~VertexArray();
  VertexArray(VertexArray&&) = default;
  VertexArray& operator=(VertexArray&&) = default;
  GlHandle id() const { return name_.id; }
  void bind() const;
  // Float attribute `index` with `components` at byte `offset` of a vertex of `stride` bytes.
  void attribute(int index, const Buffer& buffer, int components, size_t stride, size_t offset);
  void element_buffer(const Buffer& buffer);

 private:
  GlName name_;
};

// One big triangle covering the viewport; the vertex shader is shaders/fullscreen.vert. Owns the
// attribute-less VAO that a core profile needs (VAOs are per context, so one per pass object).
class FullscreenPass {
 public:
  // Draws with `program`, which must be current (Program::use) and have all its inputs bound
  // (Program::require_inputs).
  void draw(const Program& program, const Framebuffer& target, int width, int height) const;

 private:
  VertexArray vao_;
};

// How a StageTimer measures a stage: its wall time on the calling thread, from begin() to end().
//   Finish (the default): glFinish on both sides, so all the stage's GL work is inside and nothing
//     of an earlier stage is: exact per-stage times, at the cost of a pipeline stall per stage. For
//     pxf bench and the timing tests.
//   Submit: no glFinish: the time to issue the stage plus the GL work the driver does before
//     returning. On llvmpipe that is nearly all of it: a pass runs when it is issued (its memory
//     barriers and read-backs wait for it), so little is left to a following glFinish. On a GPU it
//     would be the submission only. For production frames (pxf render, merge, explore): their
//     per-stage figures (stats.json, the filter schedule's budget) stay those of llvmpipe's work
//     without a stall per stage.
// GL timer queries (GL_TIME_ELAPSED, GL_TIMESTAMP) are not used: llvmpipe answers them, but with
// a fraction of the work (docs/timebudget.md, "Stage times").
enum class GlTiming { Finish, Submit };
const std::vector<std::string>& gl_timing_names();  // "finish", "submit" (index = value)
void set_gl_timing(GlTiming timing);
GlTiming gl_timing();
class StageTimer {
 public:
  void begin();
  double end();  // ms of this stage; also kept as last_ms()
  double last_ms() const { return last_ms_; }

 private:
  double start_ = 0;
  double last_ms_ = 0;
};

// Throws pxf::Error "<what>: GL error 0x..." when the GL reported one (cheap; used after passes).
void check_gl_error(const char* what);

}  // namespace pxf
