// GL contexts behind one small interface, three back ends:
//   osmesa — headless software GL 4.5 core (llvmpipe), the default for `pxf render` and tests;
//   egl    — EGL surfaceless (EGL_MESA_platform_surfaceless), headless GPU or llvmpipe;
//   window — a GLFW window, used by the ImGui explorer.
// Usage:
//   auto ctx = pxf::create_gl_context(pxf::GlBackend::Auto);   // made current, GL loaded
//   ... render into FBOs (headless back ends have no useful default framebuffer) ...
//   ctx->present();                                            // swaps for a window, no-op else
// Every failure is a pxf::Error with a one-line message naming the back end and the reason.
#pragma once
#include <memory>
#include <string>
#include "core/error.h"

namespace pxf {

enum class GlBackend { Auto, OSMesa, Egl, Window };

// "auto", "osmesa", "egl", "window".
const char* gl_backend_name(GlBackend backend);
// Parses a name of the table above; throws pxf::Error listing the valid names.
GlBackend parse_gl_backend(const std::string& name);

using GlProc = void (*)();

class GlContext {
 public:
  virtual ~GlContext();
  GlContext(const GlContext&) = delete;
  GlContext& operator=(const GlContext&) = delete;

  // Makes this context current on the calling thread and (re)loads the GL entry points when
  // another context was loaded last (OSMesa and EGL both live in this process).
  void make_current();
  virtual void present() {}  // swap buffers for a window; no-op headless
  virtual GlBackend backend() const = 0;
  const char* backend_name() const { return gl_backend_name(backend()); }
  // GL_VERSION / GL_RENDERER of the current context (call after make_current()).
  std::string gl_version() const;
  std::string gl_renderer() const;
  virtual GlProc get_proc_address(const char* name) const = 0;
  virtual void* native_window() const { return nullptr; }  // GLFWwindow* for the window back end
  virtual bool should_close() const { return false; }

 protected:
  GlContext() = default;
  virtual void do_make_current() = 0;
  void load_gl();  // gladLoadGL with get_proc_address; throws on failure
};

struct GlContextOptions {
  bool want_window = false;  // Auto picks the window back end only when asked and a display exists
  int width = 1280;          // window size (headless: size of the unused default framebuffer)
  int height = 720;
  std::string title = "pxf";
  bool visible = true;
  bool vsync = true;
};

// Creates the context, makes it current and loads GL 4.5 core. Auto: window if requested and
// DISPLAY/WAYLAND_DISPLAY is set, else OSMesa, falling back to EGL.
std::unique_ptr<GlContext> create_gl_context(GlBackend backend, const GlContextOptions& options = {});

// Back-end constructors (each throws pxf::Error "<backend>: <reason>").
std::unique_ptr<GlContext> create_osmesa_context(const GlContextOptions& options);
std::unique_ptr<GlContext> create_egl_context(const GlContextOptions& options);
std::unique_ptr<GlContext> create_window_context(const GlContextOptions& options);

}  // namespace pxf
