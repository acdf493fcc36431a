#include <gtest/gtest.h>

#include "app/options.h"

using namespace pxf;

TEST(PreviewOptions, CommandLineSetsThePreviewSettingsThemselves) {
  PreviewSettings s;
  CommandLine cli{"render", "[options]", "test"};
  add_preview_options(cli, s);
  ASSERT_TRUE(cli.parse({"--threshold", "0.02", "--filter", "none", "--schedule", "pow2", "--sampler", "independent",
                         "--demodulate", "off", "--bias-guard", "off", "--sigma-shrink", "off", "--seed", "7",
                         "--all-hv", "--guiding", "on"}));
  EXPECT_EQ(s.threshold, 0.02f);
  EXPECT_EQ(s.filter.kind, FilterKind::None);
  EXPECT_FALSE(s.filtering());
  EXPECT_EQ(s.schedule, FilterSchedule::PowersOfTwo);
  EXPECT_EQ(s.trace.sampler, SamplerType::Independent);
  EXPECT_FALSE(s.demodulate);
  EXPECT_FALSE(s.bias_guard);
  EXPECT_FALSE(s.shrink_sigma);
  EXPECT_EQ(s.trace.guiding, GuidingMode::On);
  EXPECT_EQ(s.trace.seed, 7u);
  EXPECT_TRUE(s.trace.all_hv);
}

TEST(PreviewOptions, DefaultsAreThoseOfPreviewSettings) {
  PreviewSettings s;
  CommandLine cli{"render", "[options]", "test"};
  add_preview_options(cli, s);
  ASSERT_TRUE(cli.parse({}));
  const PreviewSettings d;
  EXPECT_EQ(s.threshold, d.threshold);
  EXPECT_EQ(s.filter.kind, FilterKind::Grid);
  EXPECT_TRUE(s.filtering());
  EXPECT_EQ(s.schedule, FilterSchedule::Final);  // headless; the explorer sets Budget
  EXPECT_EQ(s.trace.sampler, SamplerType::Sobol);
  EXPECT_TRUE(s.demodulate);
  EXPECT_TRUE(s.bias_guard);
  EXPECT_TRUE(s.shrink_sigma);
  EXPECT_EQ(s.trace.guiding, GuidingMode::Auto);
}

TEST(PreviewOptions, FilterNameTableIndexesFilterKind) {
  const std::vector<std::string>& names = filter_option_names();
  ASSERT_EQ(names.size(), filter_kind_names().size() + 1);
  for (size_t i = 0; i < names.size(); ++i) EXPECT_EQ(names[i], filter_kind_name(static_cast<FilterKind>(i))) << i;
  EXPECT_EQ(names.back(), "none");
  EXPECT_EQ(static_cast<size_t>(FilterKind::None), names.size() - 1);
  for (size_t i = 0; i < filter_schedule_names().size(); ++i)
    EXPECT_EQ(parse_filter_schedule(filter_schedule_names()[i]), static_cast<FilterSchedule>(i));
  for (size_t i = 0; i < sampler_type_names().size(); ++i) {
    PreviewSettings s;
    CommandLine cli{"render", "[options]", "test"};
    add_preview_options(cli, s);
    ASSERT_TRUE(cli.parse({"--sampler", sampler_type_names()[i]}));
    EXPECT_EQ(s.trace.sampler, static_cast<SamplerType>(i));
  }
}

TEST(SceneOptions, StageTimingIsBoundThroughItsNameTable) {
  for (bool headless : {true, false}) {
    SceneOptions o;
    EXPECT_EQ(o.stage_timing, GlTiming::Submit);  // rendering: no stall per stage
    CommandLine cli{"render", "[options]", "test"};
    add_scene_options(cli, o, headless);
    ASSERT_TRUE(cli.parse({"--stage-timing", "finish"}));
    EXPECT_EQ(o.stage_timing, GlTiming::Finish);
    CommandLine bad{"render", "[options]", "test"};
    add_scene_options(bad, o, headless);
    EXPECT_THROW(bad.parse({"--stage-timing", "query"}), UsageError);
  }
  ASSERT_EQ(gl_timing_names().size(), 2u);
  EXPECT_EQ(gl_timing_names()[static_cast<int>(GlTiming::Finish)], "finish");
  EXPECT_EQ(gl_timing_names()[static_cast<int>(GlTiming::Submit)], "submit");
}
