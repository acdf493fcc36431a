// The setting table (preview/setting_table.h) is the one declaration of every preview setting: each
// entry reaches the command line, stats.json and its read-back, the state file exactly when it
// changes the samples, and the preview's change detection; explorer ranges stay inside the
// command line's. A setting missing from any of them fails here.
#include "preview/setting_table.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <set>
#include <string>

#include "app/checkpoint.h"
#include "app/cli.h"
#include "app/options.h"

namespace pxf {
namespace {

// A value other than the default, in range, and how the command line writes it.
std::string other_value(const SettingDescriptor& d, PreviewSettings& s) {
  const double now = d.value(s);
  char text[64];
  switch (d.type) {
    case SettingType::Float: {
      const float v = static_cast<float>(now == d.max ? d.min : std::min(d.max, 2.0 * now + 1.0));
      d.set_value(s, v);
      std::snprintf(text, sizeof text, "%.9g", v);
      return text;
    }
    case SettingType::Int:
    case SettingType::Seed: {
      const double v = now == d.max ? now - 1 : now + 1;
      d.set_value(s, v);
      std::snprintf(text, sizeof text, "%.0f", v);
      return text;
    }
    case SettingType::Switch:
      d.set_value(s, now == 0.0 ? 1.0 : 0.0);
      return d.bare_flag ? "" : (*d.names)[now == 0.0 ? 1 : 0];
    case SettingType::Choice: {
      const size_t i = (static_cast<size_t>(now) + 1) % d.names->size();
      d.set_value(s, static_cast<double>(i));
      return (*d.names)[i];
    }
  }
  return "";
}

// The descriptors whose value differs between a and b.
std::set<std::string> differing(const PreviewSettings& a, const PreviewSettings& b) {
  std::set<std::string> keys;
  for (const SettingDescriptor& d : setting_table())
    if (d.value(a) != d.value(b)) keys.insert(d.key);
  return keys;
}

TEST(SettingTable, KeysFlagsAndRangesAreConsistent) {
  std::set<std::string> keys, flags;
  const PreviewSettings defaults;
  for (const SettingDescriptor& d : setting_table()) {
    SCOPED_TRACE(d.key);
    EXPECT_TRUE(keys.insert(d.key).second);
    EXPECT_TRUE(flags.insert(d.flag).second);
    EXPECT_EQ(std::string(d.flag).rfind("--", 0), 0u);
    EXPECT_FALSE(d.help.empty());
    const double v = d.value(defaults);
    if (d.type == SettingType::Float || d.type == SettingType::Int || d.type == SettingType::Seed) {
      EXPECT_LT(d.min, d.max);
      EXPECT_GE(v, d.min);
      EXPECT_LE(v, d.max);
    }
    if (d.type == SettingType::Switch || d.type == SettingType::Choice) {
      ASSERT_NE(d.names, nullptr);
    }
    if (d.bare_flag) {
      EXPECT_EQ(v, 0.0) << "a bare flag can only turn a setting on";
    }
    // The explorer's slider stays within what the command line accepts and shows the default.
    if (*d.widget.label && (d.type == SettingType::Float || d.type == SettingType::Int)) {
      EXPECT_GE(d.widget.min, d.min);
      EXPECT_LE(d.widget.max, d.max);
      EXPECT_GE(v, d.widget.min);
      EXPECT_LE(v, d.widget.max);
    }
  }
}

TEST(SettingTable, EveryFlagSetsItsOwnSettingAndNoOther) {
  for (const SettingDescriptor& d : setting_table()) {
    SCOPED_TRACE(d.key);
    PreviewSettings expected;
    const std::string text = other_value(d, expected);
    PreviewSettings parsed;
    CommandLine cli("test", "", "");
    add_preview_options(cli, parsed);
    std::vector<std::string> args{d.flag};
    if (!d.bare_flag) args.push_back(text);
    ASSERT_TRUE(cli.parse(args));
    EXPECT_EQ(differing(parsed, expected), std::set<std::string>{});
    EXPECT_EQ(differing(parsed, PreviewSettings{}), std::set<std::string>{d.key});
  }
}

TEST(SettingTable, StatsJsonHoldsEverySettingAndReadsItBack) {
  for (const SettingDescriptor& d : setting_table()) {
    SCOPED_TRACE(d.key);
    PreviewSettings changed;
    other_value(d, changed);
    const nlohmann::json j = settings_json(changed);
    ASSERT_TRUE(j.contains(d.key));
    PreviewSettings read;
    read_settings_json(nlohmann::json::parse(j.dump()), read);  // through text, as pxf diff reads it
    EXPECT_EQ(differing(read, changed), std::set<std::string>{});
  }
  // A stats.json of an older build lacks newer settings: they keep their values.
  PreviewSettings read;
  read_settings_json(nlohmann::json{{"threshold", 0.5}}, read);
  EXPECT_EQ(differing(read, PreviewSettings{}), std::set<std::string>{"threshold"});
  EXPECT_THROW(read_settings_json(nlohmann::json{{"filter", "blur"}}, read), Error);
  EXPECT_THROW(read_settings_json(nlohmann::json{{"guiding", 1}}, read), Error);
}

// The state file (SampleSettings) records a setting exactly when a change of it retraces: a resume
// or merge that ignored one would mix two renders, one that checked another would refuse a merge
// that is exact. pxf merge takes every such setting back from the states.
TEST(SettingTable, TheStateRecordsExactlyTheSettingsThatChangeTheSamples) {
  SceneOptions scene;
  scene.width = 32;
  scene.height = 24;
  const SampleSettings plain = render_sample_settings(scene, PreviewSettings{});
  for (const SettingDescriptor& d : setting_table()) {
    SCOPED_TRACE(d.key);
    PreviewSettings changed;
    other_value(d, changed);
    const SampleSettings state = render_sample_settings(scene, changed);
    EXPECT_EQ(!(state == plain), d.effect == SettingEffect::Retrace) << state.difference(plain);
    if (d.effect != SettingEffect::Retrace) continue;
    PreviewSettings merged;
    SceneOptions merged_scene;
    apply_sample_settings(state, merged_scene, merged);
    EXPECT_EQ(d.value(merged), d.value(changed));
    EXPECT_EQ(merged_scene.width, 32);
  }
}

TEST(SettingTable, AChangeInvalidatesWhatItsDescriptorSays) {
  for (const SettingDescriptor& d : setting_table()) {
    SCOPED_TRACE(d.key);
    PreviewSettings changed;
    other_value(d, changed);
    SettingEffect effect;
    EXPECT_EQ(strongest_change(PreviewSettings{}, changed, &effect), &d);
    EXPECT_EQ(effect, d.effect);
    EXPECT_TRUE(changes(PreviewSettings{}, changed, d.effect));
  }
  EXPECT_EQ(strongest_change(PreviewSettings{}, PreviewSettings{}, nullptr), nullptr);
  // Under full specular sampling the near-only switch changes nothing.
  PreviewSettings a, b;
  a.trace.specular_sampling = b.trace.specular_sampling = true;
  b.trace.specular_chains = !a.trace.specular_chains;
  EXPECT_FALSE(changes(a, b, SettingEffect::Retrace));
  // A threshold and a seed together: the seed's retrace is what the preview must do.
  b = PreviewSettings{};
  b.threshold *= 2.0f;
  b.trace.seed += 1;
  SettingEffect effect;
  EXPECT_STREQ(strongest_change(PreviewSettings{}, b, &effect)->key, "seed");
  EXPECT_EQ(effect, SettingEffect::Retrace);
}

}  // namespace
}  // namespace pxf
