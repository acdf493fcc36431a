#include <gtest/gtest.h>

#include <functional>

#include <cstdlib>

#include "gl/context.h"
#include "gl/gl.h"
#include "gl/resources.h"
#include "gl/shader_library.h"
#include "gl/test_util.h"

namespace pxf {
namespace {

// Draws a known pattern (per-pixel values written by a fragment shader from gl_FragCoord) into a
// float FBO and reads it back exactly.
void draw_and_check_pattern() {
  const int w = 13, h = 7;
  const std::string frag = R"(#version 450 core
layout(location = 0) out vec4 color;
void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  color = vec4(float(p.x), float(p.y), float(p.x * 100 + p.y), 0.25);
}
)";
  Shader vs(ShaderStage::Vertex, "fullscreen.vert", embedded_shader("fullscreen.vert"));
  Shader fs(ShaderStage::Fragment, "pattern.frag", frag);
  Program program({&vs, &fs});
  Texture2D target(w, h, TextureFormat::RGBA32F);
  Framebuffer fbo;
  fbo.attach(0, target);
  fbo.check("pattern");
  FullscreenPass quad;
  program.use();
  quad.draw(program, fbo, w, h);
  Image image = target.download({"R", "G", "B", "A"});
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      ASSERT_EQ(image.at(x, y, 0), float(x));
      ASSERT_EQ(image.at(x, y, 1), float(y));
      ASSERT_EQ(image.at(x, y, 2), float(x * 100 + y));
      ASSERT_EQ(image.at(x, y, 3), 0.25f);
    }
  check_gl_error("pattern");
}

TEST(GlContext, BackendNamesRoundTrip) {
  for (GlBackend b : {GlBackend::Auto, GlBackend::OSMesa, GlBackend::Egl, GlBackend::Window})
    EXPECT_EQ(parse_gl_backend(gl_backend_name(b)), b);
  EXPECT_THROW(parse_gl_backend("vulkan"), Error);
}

TEST(GlContext, OSMesaDrawsKnownPattern) {
  GlContext& ctx = test::osmesa_context();
  EXPECT_EQ(ctx.backend(), GlBackend::OSMesa);
  EXPECT_NE(ctx.gl_version().find("4.5"), std::string::npos) << ctx.gl_version();
  draw_and_check_pattern();
}

TEST(GlContext, EglSurfacelessDrawsKnownPattern) {
  std::unique_ptr<GlContext> egl;
  try {
    egl = create_gl_context(GlBackend::Egl);
  } catch (const Error& e) {
    GTEST_SKIP() << e.what();
  }
  EXPECT_EQ(egl->backend(), GlBackend::Egl);
  EXPECT_FALSE(egl->gl_version().empty());
  draw_and_check_pattern();
  egl.reset();
  // Back to OSMesa: the entry points are reloaded for it.
  test::osmesa_context();
  draw_and_check_pattern();
}

TEST(GlContext, AutoWithoutWindowIsHeadless) {
  GlContextOptions options;
  options.want_window = false;
  auto ctx = create_gl_context(GlBackend::Auto, options);
  EXPECT_NE(ctx->backend(), GlBackend::Window);
  draw_and_check_pattern();
  ctx.reset();
  test::osmesa_context();
}

TEST(GlContext, WindowWithoutDisplayIsAOneLineError) {
  if (std::getenv("DISPLAY") || std::getenv("WAYLAND_DISPLAY")) GTEST_SKIP() << "a display exists";
  try {
    create_gl_context(GlBackend::Window);
    FAIL() << "created a window without a display";
  } catch (const Error& e) {
    std::string m = e.what();
    EXPECT_EQ(m.rfind("window: ", 0), 0u) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  }
  test::osmesa_context();
}

TEST(Shader, CompileErrorNamesFileAndLine) {
  test::osmesa_context();
  const std::string src = "#version 450 core\nout vec4 c;\nvoid main() {\n  c = vec4(undefined_name);\n}\n";
  try {
    Shader s(ShaderStage::Fragment, "broken.frag", src);
    FAIL() << "compiled";
  } catch (const Error& e) {
    std::string m = e.what();
    EXPECT_NE(m.find("broken.frag:4"), std::string::npos) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  }
}

TEST(Shader, CompileErrorInIncludeNamesIncludedFile) {
  test::osmesa_context();
  const std::string src = "#version 450 core\n#include \"helpers.glsl\"\nout vec4 c;\nvoid main() {\n  c = vec4(f(), bad_main);\n}\n";
  auto resolve = [](const std::string& name) -> std::string {
    if (name == "helpers.glsl") return "float f() {\n  return 1.0;\n}\nfloat g() { return missing_thing; }\n";
    throw Error("no " + name);
  };
  try {
    Shader s(ShaderStage::Fragment, "main.frag", src, resolve);
    FAIL() << "compiled";
  } catch (const Error& e) {
    std::string m = e.what();
    EXPECT_NE(m.find("helpers.glsl:4"), std::string::npos) << m;
  }
  const std::string src2 = "#version 450 core\n#include \"ok.glsl\"\nout vec4 c;\nvoid main() {\n  c = vec4(bad_main);\n}\n";
  auto resolve2 = [](const std::string&) -> std::string { return "float f() {\n  return 1.0;\n}\n"; };
  try {
    Shader s(ShaderStage::Fragment, "main.frag", src2, resolve2);
    FAIL() << "compiled";
  } catch (const Error& e) {
    std::string m = e.what();
    EXPECT_NE(m.find("main.frag:5"), std::string::npos) << m;
  }
}

// Every fragment and compute shader in shaders/ (most include the shared shaders/pass_formulas.h),
// each fragment shader with its vertex shader: the one of the same name, else the full-screen one.
// A uniform the program does not have is an error naming both, not a silent no-op (a
// misspelt name used to leave the pass running with the uniform's default).
TEST(Shader, SettingAnUndeclaredUniformFails) {
  test::osmesa_context();
  const std::string frag = R"(#version 450 core
uniform float gain;
layout(location = 0) out vec4 color;
void main() { color = vec4(gain); }
)";
  Shader vs(ShaderStage::Vertex, "fullscreen.vert", embedded_shader("fullscreen.vert"));
  Shader fs(ShaderStage::Fragment, "gain.frag", frag);
  Program program({&vs, &fs});
  EXPECT_NO_THROW(program.set("gain", 2.0f));
  try {
    program.set("gian", 2.0f);
    FAIL() << "a misspelt uniform was accepted";
  } catch (const Error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("gain.frag"), std::string::npos) << message;
    EXPECT_NE(message.find("'gian'"), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
}

// Texture inputs, as Falcor checks shader variables: binding a texture at a unit where the program
// has no sampler fails, and so does drawing before every sampler was bound by the pass itself
// (since its use()); a binding left by an earlier draw of the same program does not count.
TEST(Shader, TextureInputsAreBoundByThePassThatReadsThem) {
  test::osmesa_context();
  const std::string frag = R"(#version 450 core
layout(binding = 3) uniform sampler2D light_tex;
layout(binding = 5) uniform sampler2D albedo_tex;
layout(location = 0) out vec4 color;
void main() { color = texelFetch(light_tex, ivec2(gl_FragCoord.xy), 0) * texelFetch(albedo_tex, ivec2(gl_FragCoord.xy), 0); }
)";
  Shader vs(ShaderStage::Vertex, "fullscreen.vert", embedded_shader("fullscreen.vert"));
  Shader fs(ShaderStage::Fragment, "product.frag", frag);
  Program program({&vs, &fs});
  const int w = 4, h = 2;
  Texture2D light(w, h, TextureFormat::RGBA32F), albedo(w, h, TextureFormat::RGBA32F), target(w, h, TextureFormat::RGBA32F);
  light.upload(Image::rgba(w, h, 2.0f));
  albedo.upload(Image::rgba(w, h, 0.25f));
  Framebuffer fbo;
  fbo.attach(0, target);
  fbo.check("product");
  FullscreenPass quad;
  auto expect_one_line_error = [](const std::function<void()>& f, const std::string& needle) {
    try {
      f();
      ADD_FAILURE() << "no error; expected one naming " << needle;
    } catch (const Error& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find("product.frag"), std::string::npos) << message;
      EXPECT_NE(message.find(needle), std::string::npos) << message;
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
  };
  program.use();
  expect_one_line_error([&] { program.bind(4, light); }, "texture unit 4");  // no sampler there
  program.bind(3, light);
  expect_one_line_error([&] { quad.draw(program, fbo, w, h); }, "'albedo_tex' (texture unit 5)");
  albedo.bind(5);  // bound behind the program's back: not the pass's own binding
  expect_one_line_error([&] { quad.draw(program, fbo, w, h); }, "'albedo_tex'");
  program.bind(5, albedo);
  EXPECT_NO_THROW(quad.draw(program, fbo, w, h));
  EXPECT_FLOAT_EQ(target.download({"R", "G", "B", "A"}).at(1, 1, 0), 0.5f);
  program.use();  // a new set of inputs: the last draw's bindings do not carry over
  expect_one_line_error([&] { quad.draw(program, fbo, w, h); }, "'light_tex' (texture unit 3)");
}

TEST(Shader, EveryEmbeddedPassCompiles) {
  test::osmesa_context();
  auto ends_with = [](const std::string& s, const std::string& end) {
    return s.size() >= end.size() && s.compare(s.size() - end.size(), end.size(), end) == 0;
  };
  int programs = 0;
  for (const EmbeddedShader* s = kEmbeddedShaders; s->name; ++s) {
    const std::string name = s->name;
    SCOPED_TRACE(name);
    if (ends_with(name, ".frag")) {
      std::string vert = name.substr(0, name.size() - 5) + ".vert";
      bool own_vert = false;
      for (const EmbeddedShader* v = kEmbeddedShaders; v->name; ++v) own_vert = own_vert || vert == v->name;
      EXPECT_NO_THROW(Program::from_embedded(own_vert ? vert : "fullscreen.vert", name));
      ++programs;
    } else if (ends_with(name, ".comp")) {
      EXPECT_NO_THROW(Program::from_embedded_compute(name));
      ++programs;
    }
  }
  EXPECT_GE(programs, 20);
  EXPECT_THROW(embedded_shader("nope.frag"), Error);
}

}  // namespace
}  // namespace pxf
