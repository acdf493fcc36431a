#include "gl/history_reference.h"

#include "gl/history_pass.h"

namespace pxf {
namespace {

// An "R,G,B,A" image as the shared code reads a sampler (shaders/cpu_gpu.h).
struct RgbaTexels {
  const Image* image;
};
glm::vec4 texelFetch(const RgbaTexels& t, glm::ivec2 p, int) {
  const Image& im = *t.image;
  return {im.at(p.x, p.y, 0), im.at(p.x, p.y, 1), im.at(p.x, p.y, 2), im.at(p.x, p.y, 3)};
}
glm::ivec2 textureSize(const RgbaTexels& t, int) { return {t.image->width, t.image->height}; }

void check_rgba(const Image& image, int width, int height, const char* what) {
  if (image.width != width || image.height != height || image.num_channels() != 4)
    throw Error(std::string("history reference: ") + what + " is not an RGBA image of the guide's size");
}

void put(Image& image, int x, int y, glm::vec4 v) {
  for (int c = 0; c < 4; ++c) image.at(x, y, c) = v[c];
}

// shared::history_normal per pixel ("R,G,B,A"), as history_normals.frag computes it.
Image guide_normals(const Image& guide, const Image* specular, const shared::ViewCamera& camera) {
  Image normals = Image::rgba(guide.width, guide.height);
  for (int y = 0; y < guide.height; ++y)
    for (int x = 0; x < guide.width; ++x) {
      const float flag = specular ? specular->at(x, y, 0) : 0.0f;
      put(normals, x, y, shared::history_normal(RgbaTexels{&guide}, flag, {x, y}, camera));
    }
  return normals;
}

}  // namespace

HistoryReprojection cpu_reproject_history(const Image& previous_lv, const Image& previous_hv,
                                          const Image& previous_guide, const Camera& previous_camera,
                                          const Image& guide, const Camera& camera, const Image* previous_specular,
                                          const Image* specular) {
  const int w = guide.width, h = guide.height;
  check_rgba(guide, w, h, "the guide");
  check_rgba(previous_lv, w, h, "the previous L_lv");
  check_rgba(previous_hv, w, h, "the previous L_u");
  check_rgba(previous_guide, w, h, "the previous guide");
  const shared::ViewCamera now = view_camera(camera, w, h), before = view_camera(previous_camera, w, h);
  HistoryReprojection out{Image(w, h, {"R", "G", "B", "A"}), Image(w, h, {"R", "G", "B", "A"}), Image::gray(w, h)};
  const Image previous_normals = guide_normals(previous_guide, previous_specular, before),
              normals = guide_normals(guide, specular, now);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const glm::ivec2 p(x, y);
      const shared::HistorySample s =
          shared::reproject_history(RgbaTexels{&previous_lv}, RgbaTexels{&previous_hv}, RgbaTexels{&previous_guide},
                                    RgbaTexels{&previous_normals}, RgbaTexels{&guide}, RgbaTexels{&normals}, p, now,
                                    before);
      put(out.lv, x, y, glm::vec4(s.lv, s.count));
      put(out.hv, x, y, glm::vec4(s.hv, s.var));
      out.outcome.at(x, y, 0) = static_cast<float>(s.outcome);
    }
  return out;
}

HistoryCombination cpu_combine_history(const Image& lv, const Image& hv, float samples,
                                       const HistoryReprojection* history) {
  const int w = lv.width, h = lv.height;
  check_rgba(lv, w, h, "the fresh L_lv");
  check_rgba(hv, w, h, "the fresh L_u");
  if (history) {
    check_rgba(history->lv, w, h, "the history's L_lv");
    check_rgba(history->hv, w, h, "the history's L_u");
  }
  HistoryCombination out{Image(w, h, {"R", "G", "B", "A"}), Image(w, h, {"R", "G", "B", "A"}),
                         Image(w, h, {"R", "G", "B", "A"}), Image::gray(w, h)};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const glm::ivec2 p(x, y);
      const glm::vec4 l = texelFetch(RgbaTexels{&lv}, p, 0), u = texelFetch(RgbaTexels{&hv}, p, 0);
      shared::HistorySample s = shared::history_none(shared::kHistoryNone);
      if (history) {
        const glm::vec4 hl = texelFetch(RgbaTexels{&history->lv}, p, 0), hu = texelFetch(RgbaTexels{&history->hv}, p, 0);
        s.lv = glm::vec3(hl);
        s.count = hl.a;
        s.hv = glm::vec3(hu);
        s.var = hu.a;
      }
      const shared::HistoryBlend b = shared::combine_history(glm::vec3(l), glm::vec3(u), u.a, samples, s);
      put(out.lv, x, y, glm::vec4(b.lv, l.a));
      put(out.hv, x, y, glm::vec4(b.hv, b.var));
      put(out.state, x, y, glm::vec4(b.lv, b.count));
      out.weight.at(x, y, 0) = b.weight;
    }
  return out;
}

}  // namespace pxf
