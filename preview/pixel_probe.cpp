#include "preview/pixel_probe.h"

namespace pxf {

PixelProbe probe_pixel(const Preview& preview, const std::vector<uint32_t>& samples, int x, int y) {
  PixelProbe p;
  p.x = x;
  p.y = y;
  const size_t i = static_cast<size_t>(y) * preview.width() + x;
  p.n = i < samples.size() ? samples[i] : 0;
  p.final_s = preview.blend().output().texel(x, y);
  p.guide = preview.range().guide().texel(x, y);
  p.blended = preview.blend().has_run();
  if (p.blended) p.blend = preview.blend().inspect(x, y);
  p.surface = preview.renderer().surface_material(x, y);
  return p;
}

}  // namespace pxf
