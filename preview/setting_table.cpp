#include "preview/setting_table.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <type_traits>

#include "core/error.h"

namespace pxf {

namespace {

const std::vector<std::string>& off_on() {
  static const std::vector<std::string> names{"off", "on"};
  return names;
}

// Builders: one line per setting in the table below.
SettingDescriptor number(const char* key, const char* flag, std::string help, double min, double max,
                         float& (*field)(PreviewSettings&), SettingEffect effect, SettingWidget widget = {}) {
  SettingDescriptor d;
  d.type = SettingType::Float;
  d.key = key;
  d.flag = flag;
  d.help = std::move(help);
  d.min = min;
  d.max = max;
  d.float_field = field;
  d.effect = effect;
  d.widget = widget;
  return d;
}

SettingDescriptor integer(const char* key, const char* flag, std::string help, int min, int max,
                          int& (*field)(PreviewSettings&), SettingEffect effect, SettingWidget widget = {}) {
  SettingDescriptor d;
  d.type = SettingType::Int;
  d.key = key;
  d.flag = flag;
  d.help = std::move(help);
  d.min = min;
  d.max = max;
  d.int_field = field;
  d.effect = effect;
  d.widget = widget;
  return d;
}

SettingDescriptor on_off(const char* key, const char* flag, std::string help, bool& (*field)(PreviewSettings&),
                         SettingEffect effect, const char* label = "", bool bare_flag = false) {
  SettingDescriptor d;
  d.type = SettingType::Switch;
  d.key = key;
  d.flag = flag;
  d.help = std::move(help);
  d.names = &off_on();
  d.bare_flag = bare_flag;
  d.switch_field = field;
  d.effect = effect;
  d.widget.label = label;
  return d;
}

template <auto Field>
SettingDescriptor choice(const char* key, const char* flag, std::string help, const std::vector<std::string>& names,
                         SettingEffect effect, const char* label = "") {
  SettingDescriptor d;
  d.type = SettingType::Choice;
  d.key = key;
  d.flag = flag;
  d.help = std::move(help);
  d.names = &names;
  d.choice_index = [](const PreviewSettings& s) {
    return static_cast<size_t>(Field(const_cast<PreviewSettings&>(s)));
  };
  d.set_choice_index = [](PreviewSettings& s, size_t i) {
    using E = std::remove_reference_t<decltype(Field(s))>;
    Field(s) = static_cast<E>(i);
  };
  d.effect = effect;
  d.widget.label = label;
  return d;
}

FilterKind& filter_kind(PreviewSettings& s) { return s.filter.kind; }
FilterSchedule& schedule(PreviewSettings& s) { return s.schedule; }
SamplerType& sampler(PreviewSettings& s) { return s.trace.sampler; }
GuidingMode& guiding(PreviewSettings& s) { return s.trace.guiding; }

// The blend's and the filter's settings.
void add_filter_settings(std::vector<SettingDescriptor>& t) {
  using E = SettingEffect;
  t.push_back(number("threshold", "--threshold", "blend threshold t on perceived variance", 0.0, 1e6,
                     [](PreviewSettings& s) -> float& { return s.threshold; }, E::Refilter,
                     {"threshold t", 1e-5, 1.0, true, "%.2e"}));
  t.push_back(number("sigma_s", "--sigma-s", "spatial sigma in pixels", 0.1, kMaxFilterRadius / 3.0,
                     [](PreviewSettings& s) -> float& { return s.filter.sigma_s; }, E::Refilter,
                     {"sigma s (px)", 0.1, kMaxFilterRadius / 3.0, false, "%.2f"}));
  t.push_back(on_off("sigma_shrink", "--sigma-shrink",
                     "shrink the filter's sigma_s to the noise: the kernel the noisiest tenth of the pixels\n"
                     "above t needs to reach it, between 2 px and --sigma-s (--sigma-s up to 4 spp; off:\n"
                     "--sigma-s for every filter run, docs/method.md 2.5)",
                     [](PreviewSettings& s) -> bool& { return s.shrink_sigma; }, E::Refilter, "shrink sigma s to the noise"));
  t.push_back(number("sigma_c", "--sigma-c", "range color sigma, linear RGB", 1e-6, 1e6,
                     [](PreviewSettings& s) -> float& { return s.filter.sigma_c; }, E::Refilter,
                     {"sigma c", 1e-4, 10.0, true, "%.3g"}));
  t.push_back(number("sigma_d", "--sigma-d", "range depth sigma, scene units", 1e-6, 1e6,
                     [](PreviewSettings& s) -> float& { return s.filter.sigma_d; }, E::Refilter,
                     {"sigma d", 1e-3, 1e3, true, "%.3g"}));
  t.push_back(number("sigma_n", "--sigma-n",
                     "range normal sigma, radians between shading normals (normal maps applied); 0: off",
                     0.0, 4.0, [](PreviewSettings& s) -> float& { return s.filter.sigma_n; }, E::Refilter,
                     {"sigma n (rad)", 0.0, 3.2, false, "%.3g"}));
  t.push_back(number("sigma_r", "--sigma-r", "range roughness sigma (glTF roughness, 0..1); 0: off", 0.0, 1e3,
                     [](PreviewSettings& s) -> float& { return s.filter.sigma_r; }, E::Refilter,
                     {"sigma r", 0.0, 1.0, false, "%.3g"}));
  t.push_back(number("sigma_l", "--sigma-l",
                     "atrous: luminance edge stop, in standard deviations of the filtered light (SVGF); 0: off",
                     0.0, 1e3, [](PreviewSettings& s) -> float& { return s.filter.sigma_l; }, E::Refilter,
                     {"sigma l", 0.0, 64.0, false, "%.3g"}));
  t.push_back(choice<&filter_kind>("filter", "--filter", "filter variant (grid: the bilateral grid on the range luminance)",
                                  filter_option_names(), E::Refilter, "filter"));
  t.push_back(on_off("demodulate", "--demodulate",
                     "albedo demodulation: filter HV divided by the directional albedo of the first non-delta\n"
                     "surface (its coverage of the pixel included), so textures and thin strands stay sharp",
                     [](PreviewSettings& s) -> bool& { return s.demodulate; }, E::Refilter, "albedo demodulation"));
  t.push_back(on_off("bias_guard", "--bias-guard",
                     "the blend's bias guard: where the filtered light measurably differs from the unfiltered\n"
                     "(5x5 neighbours, 2 standard deviations), s is raised to the least-error blend factor (off: the\n"
                     "published blend, noise held at t everywhere; docs/method.md section 3.7)",
                     [](PreviewSettings& s) -> bool& { return s.bias_guard; }, E::Redisplay, "bias guard"));
  t.push_back(on_off("split_decision", "--split-decision",
                     "blend each half of a pixel's samples (even and odd sample index) by the weight the other\n"
                     "half's variance decides: the image keeps its mean (one decision from all the pixel's\n"
                     "samples darkens it), and keeps half of each outlier (docs/method.md section 3.8). The\n"
                     "render keeps the halves from its first sample, so a change restarts it",
                     [](PreviewSettings& s) -> bool& { return s.trace.split_halves; }, E::Retrace, "split decision"));
  t.push_back(choice<&schedule>("schedule", "--schedule",
                               "when the filter runs: final = once to measure its cost, then on the last frame (a headless\n"
                               "job shows only that); budget = at power-of-two sample counts while filter + range stay\n"
                               "within 10 % of the tracing time (the explorer's default); pow2 = at every power of two;\n"
                               "every = each frame; all also the last frame",
                               filter_schedule_names(), E::Redisplay, "schedule"));
  t.push_back(on_off("motion_history", "--motion-history",
                     "after a camera move, reproject what the view showed into the new view beside the fresh samples,\n"
                     "its weight falling to 0 over 16 samples (off: a move restarts from nothing; docs/method.md 4.1)",
                     [](PreviewSettings& s) -> bool& { return s.motion_history; }, E::Redisplay, "reproject history"));
}

// The tracer's settings, then the display's.
void add_trace_and_display_settings(std::vector<SettingDescriptor>& t) {
  using E = SettingEffect;
  // Sampling: these change the samples (the state file records them).
  t.push_back(on_off("adaptive", "--adaptive",
                     "adaptive sampling: after 16 uniform frames each frame's paths (as many as a uniform frame's)\n"
                     "go where the neighbourhood's noise is furthest above the threshold, up to 32 a pixel, every\n"
                     "pixel at least every 16 frames; with --until-clean, to the pixels short of the count their\n"
                     "neighbours predict (docs/sampling.md)",
                     [](PreviewSettings& s) -> bool& { return s.adaptive; }, E::Retrace, "adaptive sampling"));
  SettingDescriptor seed;
  seed.type = SettingType::Seed;
  seed.key = "seed";
  seed.flag = "--seed";
  seed.help = "random seed";
  seed.min = 0;
  seed.max = 2147483647;
  seed.seed_field = [](PreviewSettings& s) -> uint64_t& { return s.trace.seed; };
  seed.effect = E::Retrace;
  t.push_back(seed);
  t.push_back(choice<&sampler>("sampler", "--sampler",
                              "random numbers of the path tracer: Owen-scrambled Sobol or independent PCG32",
                              sampler_type_names(), E::Retrace));
  t.push_back(integer("replicates", "--replicates",
                      "independently scrambled Sobol replicates for the variance estimate (1 = none)", 1, 64,
                      [](PreviewSettings& s) -> int& { return s.trace.replicates; }, E::Retrace));
  // Not a property of the samples (the same image whatever the count), but the tracer restarts to use it.
  t.push_back(integer("threads", "--threads", "path-tracing threads (0 = all cores)", 0, 1024,
                      [](PreviewSettings& s) -> int& { return s.trace.threads; }, E::Restart));
  t.push_back(integer("max_vertices", "--max-vertices", "maximum path length in vertices, camera and light included", 2,
                      1024, [](PreviewSettings& s) -> int& { return s.trace.max_vertices; }, E::Retrace,
                      {"path length", 2, 1024, true, "%d"}));
  t.push_back(integer("rr_start_vertex", "--rr-start", "Russian roulette from this vertex on", 2, 1024,
                      [](PreviewSettings& s) -> int& { return s.trace.rr_start_vertex; }, E::Retrace));
  t.push_back(on_off("specular_sampling", "--specular-sampling",
                     "also trace chains toward mirror and glass objects at diffuse vertices (toward a sphere solved\n"
                     "for the light's path), MIS-combined with BSDF sampling: unbiased, fewer caustic fireflies, more\n"
                     "rays (docs/sampling.md#fireflies)",
                     [](PreviewSettings& s) -> bool& { return s.trace.specular_sampling; }, E::Retrace,
                     "specular sampling", /*bare_flag=*/true));
  SettingDescriptor chains = on_off(
      "specular_chains", "--specular-chains",
      "the same only where it pays: from the first diffuse vertex toward mirror and glass objects that\n"
      "fill at least pi sr of its view (the focus a glass object throws on the floor it stands on), and from\n"
      "the other diffuse vertices toward a mirror sphere in 1 of 20 (its caustic on every wall;\n"
      "docs/sampling.md#specular-chains)",
      [](PreviewSettings& s) -> bool& { return s.trace.specular_chains; }, E::Retrace, "specular chains");
  chains.same = [](const PreviewSettings& a, const PreviewSettings& b) {
    return specular_sampling_mode(a.trace) == specular_sampling_mode(b.trace);
  };
  t.push_back(chains);
  t.push_back(choice<&guiding>("guiding", "--guiding",
                               "path guiding: learn from photons where indirect light comes from (parallax-aware lobes in\n"
                               "an SD-tree's regions) and send a learned share of every diffuse bounce there,\n"
                               "MIS-combined with BSDF sampling: unbiased; auto: from the 5th frame on where the scene\n"
                               "sees at most half of its sky (a room lit through windows), else off (docs/guiding.md)",
                               guiding_mode_names(), E::Retrace, "path guiding"));
  t.push_back(on_off("environment_visibility", "--env-visibility",
                     "light through openings: learn per region which parts of the environment its shadow rays\n"
                     "find unblocked (a window) and draw up to half of the environment's light samples there,\n"
                     "MIS-combined with sampling by radiance: unbiased; dormant under an open sky\n"
                     "(docs/sampling.md, Light through openings)",
                     [](PreviewSettings& s) -> bool& { return s.trace.environment_visibility; }, E::Retrace,
                     "light through openings"));
  t.push_back(on_off("all_hv", "--all-hv",
                     "put the emitters' light at the first surface into the HV buffer too (the environment's always\n"
                     "goes there): only what the camera sees directly or through mirrors and glass, and the exact\n"
                     "light of up to 4 punctual lights, stays unfiltered",
                     [](PreviewSettings& s) -> bool& { return s.trace.all_hv; }, E::Retrace, "all HV", /*bare_flag=*/true));
  // The display.
  t.push_back(number("key", "--key", "Reinhard key a", 1e-4, 100.0, [](PreviewSettings& s) -> float& { return s.tonemap.key; },
                     E::Redisplay, {"exposure key", 0.01, 2.0, true, "%.3f"}));
  t.push_back(number("white", "--white", "Reinhard white point (0 = none)", 0.0, 1e9,
                     [](PreviewSettings& s) -> float& { return s.tonemap.white; }, E::Redisplay,
                     {"white point", 0.0, 100.0, false, "%.2f"}));
}

std::vector<SettingDescriptor> make_table() {
  std::vector<SettingDescriptor> t;
  add_filter_settings(t);
  add_trace_and_display_settings(t);
  return t;
}

}  // namespace

double SettingDescriptor::value(const PreviewSettings& s) const {
  PreviewSettings& m = const_cast<PreviewSettings&>(s);  // the accessors only read here
  switch (type) {
    case SettingType::Float: return float_field(m);
    case SettingType::Int: return int_field(m);
    case SettingType::Seed: return static_cast<double>(seed_field(m));
    case SettingType::Switch: return switch_field(m) ? 1.0 : 0.0;
    case SettingType::Choice: return static_cast<double>(choice_index(s));
  }
  return 0.0;
}

void SettingDescriptor::set_value(PreviewSettings& s, double v) const {
  switch (type) {
    case SettingType::Float: float_field(s) = static_cast<float>(v); break;
    case SettingType::Int: int_field(s) = static_cast<int>(v); break;
    case SettingType::Seed: seed_field(s) = static_cast<uint64_t>(v); break;
    case SettingType::Switch: switch_field(s) = v != 0.0; break;
    case SettingType::Choice: set_choice_index(s, static_cast<size_t>(v)); break;
  }
}

bool SettingDescriptor::equal(const PreviewSettings& a, const PreviewSettings& b) const {
  return same ? same(a, b) : value(a) == value(b);
}

nlohmann::json SettingDescriptor::to_json(const PreviewSettings& s) const {
  PreviewSettings& m = const_cast<PreviewSettings&>(s);
  switch (type) {
    case SettingType::Float: return float_field(m);
    case SettingType::Int: return int_field(m);
    case SettingType::Seed: return seed_field(m);
    case SettingType::Switch: return switch_field(m);
    case SettingType::Choice: return (*names)[choice_index(s)];
  }
  return nullptr;
}

void SettingDescriptor::from_json(PreviewSettings& s, const nlohmann::json& j) const {
  const auto wrong = [&] { return Error(std::string("stats.json setting '") + key + "' has the wrong kind of value"); };
  switch (type) {
    case SettingType::Float:
    case SettingType::Int:
    case SettingType::Seed:
    {
      if (!j.is_number()) throw wrong();
      const double v = j.get<double>();
      // The command line's range: a value outside it (a threshold of -1, a seed of 1e300) would be
      // cast without a defined result or give settings no render can have.
      if (!(v >= min && v <= max) || (type != SettingType::Float && v != std::floor(v))) {
        char text[160];
        std::snprintf(text, sizeof text, "stats.json setting '%s' is %.17g, not %s in [%g, %g]", key, v,
                      type == SettingType::Float ? "a number" : "an integer", min, max);
        throw Error(text);
      }
      set_value(s, v);
      return;
    }
    case SettingType::Switch:
      if (!j.is_boolean()) throw wrong();
      switch_field(s) = j.get<bool>();
      return;
    case SettingType::Choice: {
      if (!j.is_string()) throw wrong();
      const auto it = std::find(names->begin(), names->end(), j.get<std::string>());
      if (it == names->end()) throw Error(std::string("stats.json setting '") + key + "' has an unknown value");
      set_choice_index(s, static_cast<size_t>(it - names->begin()));
      return;
    }
  }
}

const std::vector<SettingDescriptor>& setting_table() {
  static const std::vector<SettingDescriptor> table = make_table();
  return table;
}

const SettingDescriptor& setting(const std::string& key) {
  for (const SettingDescriptor& d : setting_table())
    if (key == d.key) return d;
  throw Error("no setting named '" + key + "'");
}

const SettingDescriptor* strongest_change(const PreviewSettings& before, const PreviewSettings& after,
                                          SettingEffect* effect) {
  const SettingDescriptor* strongest = nullptr;
  for (const SettingDescriptor& d : setting_table())
    if (!d.equal(before, after) && (!strongest || d.effect < strongest->effect)) strongest = &d;
  if (strongest && effect) *effect = strongest->effect;
  return strongest;
}

bool changes(const PreviewSettings& before, const PreviewSettings& after, SettingEffect effect) {
  for (const SettingDescriptor& d : setting_table())
    if (d.effect == effect && !d.equal(before, after)) return true;
  return false;
}

nlohmann::json settings_json(const PreviewSettings& s) {
  nlohmann::json j = nlohmann::json::object();
  for (const SettingDescriptor& d : setting_table()) j[d.key] = d.to_json(s);
  return j;
}

void read_settings_json(const nlohmann::json& settings, PreviewSettings& s) {
  for (const SettingDescriptor& d : setting_table())
    if (settings.contains(d.key)) d.from_json(s, settings[d.key]);
}

}  // namespace pxf
