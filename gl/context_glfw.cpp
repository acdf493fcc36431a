// GLFW window back end (GL 4.5 core), for the ImGui explorer. native_window() is the GLFWwindow*.
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <string>
#include "gl/context.h"

namespace pxf {
namespace {

std::string g_glfw_error;
void on_glfw_error(int, const char* description) { g_glfw_error = description ? description : "unknown"; }

class GlfwGlContext final : public GlContext {
 public:
  explicit GlfwGlContext(const GlContextOptions& options) {
    glfwSetErrorCallback(on_glfw_error);
    if (!glfwInit()) throw Error("window: glfwInit failed: " + g_glfw_error);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfwWindowHint(GLFW_VISIBLE, options.visible ? GLFW_TRUE : GLFW_FALSE);
    window_ = glfwCreateWindow(options.width, options.height, options.title.c_str(), nullptr, nullptr);
    if (!window_) {
      glfwTerminate();
      throw Error("window: no GL 4.5 core window: " + g_glfw_error);
    }
    make_current();
    glfwSwapInterval(options.vsync ? 1 : 0);
  }
  ~GlfwGlContext() override {
    glfwDestroyWindow(window_);
    glfwTerminate();
  }
  void present() override { glfwSwapBuffers(window_); }
  GlBackend backend() const override { return GlBackend::Window; }
  GlProc get_proc_address(const char* name) const override { return glfwGetProcAddress(name); }
  void* native_window() const override { return window_; }
  bool should_close() const override { return glfwWindowShouldClose(window_); }

 protected:
  void do_make_current() override { glfwMakeContextCurrent(window_); }

 private:
  GLFWwindow* window_ = nullptr;
};

}  // namespace

std::unique_ptr<GlContext> create_window_context(const GlContextOptions& options) {
  return std::make_unique<GlfwGlContext>(options);
}

}  // namespace pxf
