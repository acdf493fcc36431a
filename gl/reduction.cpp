#include "gl/reduction.h"

#include "gl/dispatch.h"
#include "gl/gl.h"

namespace pxf {

GpuReduction::GpuReduction()
    : program_(Program::from_embedded_compute("reduce.comp")), partials_(sizeof(float)), result_(2 * sizeof(float)) {}

void GpuReduction::run(const Texture2D& source, int mode, float delta) {
  const int gx = (source.width() + 15) / 16, gy = (source.height() + 15) / 16;
  const size_t bytes = static_cast<size_t>(gx) * gy * sizeof(float);
  if (partials_.size() < bytes) partials_ = Buffer(bytes);
  program_.set("mode", mode);
  program_.set("delta", delta);
  program_.set("partial_count", gx * gy);
  program_.use();
  program_.bind(0, source);
  program_.require_inputs();
  partials_.bind_storage(1);
  result_.bind_storage(2);
  program_.set("stage", 0);
  dispatch_compute("reduction", gx, gy);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
  program_.set("stage", 1);
  glDispatchCompute(1, 1, 1);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
}

float GpuReduction::read_sum() const {
  float r[2] = {0, 0};
  result_.download(r, sizeof r);
  return r[0];
}

}  // namespace pxf
