#include "gl/context.h"

#include <cstdlib>
#include "gl/gl.h"

namespace pxf {
namespace {

const char* const kBackendNames[] = {"auto", "osmesa", "egl", "window"};

// glad keeps one global set of entry points; remember whose they are.
const GlContext* g_loaded_for = nullptr;
const GlContext* g_loader_ctx = nullptr;  // used by the C callback below

GLADapiproc glad_loader(const char* name) {
  return reinterpret_cast<GLADapiproc>(g_loader_ctx->get_proc_address(name));
}

bool has_display() {
  const char* x = std::getenv("DISPLAY");
  const char* w = std::getenv("WAYLAND_DISPLAY");
  return (x && *x) || (w && *w);
}

}  // namespace

const char* gl_backend_name(GlBackend backend) { return kBackendNames[static_cast<int>(backend)]; }

GlBackend parse_gl_backend(const std::string& name) {
  for (int i = 0; i < 4; ++i)
    if (name == kBackendNames[i]) return static_cast<GlBackend>(i);
  throw Error("unknown GL back end '" + name + "' (expected auto, osmesa, egl or window)");
}

GlContext::~GlContext() {
  if (g_loaded_for == this) g_loaded_for = nullptr;
}

void GlContext::make_current() {
  do_make_current();
  if (g_loaded_for != this) load_gl();
}

void GlContext::load_gl() {
  g_loader_ctx = this;
  int version = gladLoadGL(glad_loader);
  g_loader_ctx = nullptr;
  if (version == 0) throw Error(std::string(backend_name()) + ": could not load the GL entry points");
  if (GLAD_VERSION_MAJOR(version) * 10 + GLAD_VERSION_MINOR(version) < 45)
    throw Error(std::string(backend_name()) + ": GL 4.5 core needed, context has " +
                std::to_string(GLAD_VERSION_MAJOR(version)) + "." + std::to_string(GLAD_VERSION_MINOR(version)));
  g_loaded_for = this;
}

std::string GlContext::gl_version() const {
  const GLubyte* s = glGetString ? glGetString(GL_VERSION) : nullptr;
  return s ? reinterpret_cast<const char*>(s) : "";
}

std::string GlContext::gl_renderer() const {
  const GLubyte* s = glGetString ? glGetString(GL_RENDERER) : nullptr;
  return s ? reinterpret_cast<const char*>(s) : "";
}

std::unique_ptr<GlContext> create_gl_context(GlBackend backend, const GlContextOptions& options) {
  switch (backend) {
    case GlBackend::OSMesa: return create_osmesa_context(options);
    case GlBackend::Egl: return create_egl_context(options);
    case GlBackend::Window: return create_window_context(options);
    case GlBackend::Auto: break;
  }
  if (options.want_window && has_display()) return create_window_context(options);
  try {
    return create_osmesa_context(options);
  } catch (const Error& osmesa_error) {
    try {
      return create_egl_context(options);
    } catch (const Error& egl_error) {
      throw Error(std::string("auto: no GL context (") + osmesa_error.what() + "; " + egl_error.what() + ")");
    }
  }
}

}  // namespace pxf
