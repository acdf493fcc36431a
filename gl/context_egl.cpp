// EGL surfaceless back end: EGL_MESA_platform_surfaceless display, EGL_KHR_surfaceless_context,
// GL 4.5 core. Renders only into FBOs.
#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <cstring>
#include <string>
#include "gl/context.h"

namespace pxf {
namespace {

std::string egl_error_name(EGLint code) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "EGL error 0x%04x", code);
  return buf;
}

bool has_extension(const char* list, const char* name) {
  if (!list) return false;
  size_t n = std::strlen(name);
  for (const char* p = list; (p = std::strstr(p, name)); p += n)
    if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return true;
  return false;
}

class EglGlContext final : public GlContext {
 public:
  EglGlContext() {
    const char* client_ext = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (!has_extension(client_ext, "EGL_MESA_platform_surfaceless"))
      fail("EGL_MESA_platform_surfaceless is not supported");
    auto get_platform_display =
        reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
    if (!get_platform_display) fail("eglGetPlatformDisplayEXT is missing");
    display_ = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    if (display_ == EGL_NO_DISPLAY) fail("no surfaceless display");
    if (!eglInitialize(display_, nullptr, nullptr)) fail("eglInitialize: " + egl_error_name(eglGetError()));
    initialized_ = true;
    if (!has_extension(eglQueryString(display_, EGL_EXTENSIONS), "EGL_KHR_surfaceless_context"))
      fail("EGL_KHR_surfaceless_context is not supported");
    if (!eglBindAPI(EGL_OPENGL_API)) fail("eglBindAPI(EGL_OPENGL_API): " + egl_error_name(eglGetError()));
    const EGLint config_attribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_SURFACE_TYPE, 0, EGL_NONE};
    EGLConfig config = nullptr;
    EGLint count = 0;
    if (!eglChooseConfig(display_, config_attribs, &config, 1, &count) || count < 1)
      fail("no EGL config for desktop OpenGL");
    const EGLint context_attribs[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5,
                                      EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                      EGL_NONE};
    context_ = eglCreateContext(display_, config, EGL_NO_CONTEXT, context_attribs);
    if (context_ == EGL_NO_CONTEXT) fail("no GL 4.5 core context: " + egl_error_name(eglGetError()));
    make_current();
  }
  ~EglGlContext() override { release(); }
  GlBackend backend() const override { return GlBackend::Egl; }
  GlProc get_proc_address(const char* name) const override {
    return reinterpret_cast<GlProc>(eglGetProcAddress(name));
  }

 protected:
  void do_make_current() override {
    if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_))
      throw Error("egl: eglMakeCurrent failed: " + egl_error_name(eglGetError()));
  }

 private:
  [[noreturn]] void fail(const std::string& reason) {
    release();
    throw Error("egl: " + reason);
  }
  void release() {
    if (context_ != EGL_NO_CONTEXT) {
      if (eglGetCurrentContext() == context_) eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
      eglDestroyContext(display_, context_);
      context_ = EGL_NO_CONTEXT;
    }
    // The surfaceless display is shared per process; terminating it would invalidate other
    // EGL contexts, so it is left initialized.
  }
  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLContext context_ = EGL_NO_CONTEXT;
  bool initialized_ = false;
};

}  // namespace

std::unique_ptr<GlContext> create_egl_context(const GlContextOptions&) { return std::make_unique<EglGlContext>(); }

}  // namespace pxf
