// OSMesa back end: GL 4.5 core on llvmpipe, headless. Rendering goes into FBOs; the context's
// own color buffer (OSMesa needs one to make a context current) is a small unused RGBA8 array.
// This file includes Mesa's GL headers, so it must not include glad.
#include <GL/osmesa.h>

#include <vector>
#include "gl/context.h"

namespace pxf {
namespace {

class OSMesaGlContext final : public GlContext {
 public:
  explicit OSMesaGlContext(const GlContextOptions& options)
      : width_(options.width > 0 ? options.width : 1), height_(options.height > 0 ? options.height : 1),
        buffer_(static_cast<size_t>(width_) * height_) {
    const int attribs[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 24, OSMESA_STENCIL_BITS, 0,
                           OSMESA_ACCUM_BITS, 0, OSMESA_PROFILE, OSMESA_CORE_PROFILE,
                           OSMESA_CONTEXT_MAJOR_VERSION, 4, OSMESA_CONTEXT_MINOR_VERSION, 5, 0};
    context_ = OSMesaCreateContextAttribs(attribs, nullptr);
    if (!context_) throw Error("osmesa: OSMesaCreateContextAttribs failed for a GL 4.5 core context");
    make_current();
  }
  ~OSMesaGlContext() override {
    if (context_) OSMesaDestroyContext(context_);
  }
  GlBackend backend() const override { return GlBackend::OSMesa; }
  GlProc get_proc_address(const char* name) const override {
    return reinterpret_cast<GlProc>(OSMesaGetProcAddress(name));
  }

 protected:
  void do_make_current() override {
    if (!OSMesaMakeCurrent(context_, buffer_.data(), GL_UNSIGNED_BYTE, width_, height_))
      throw Error("osmesa: OSMesaMakeCurrent failed");
  }

 private:
  int width_, height_;
  std::vector<uint32_t> buffer_;
  OSMesaContext context_ = nullptr;
};

}  // namespace

std::unique_ptr<GlContext> create_osmesa_context(const GlContextOptions& options) {
  // Headless: the default framebuffer is never shown, keep it tiny.
  GlContextOptions headless = options;
  headless.width = headless.height = 16;
  return std::make_unique<OSMesaGlContext>(headless);
}

}  // namespace pxf
