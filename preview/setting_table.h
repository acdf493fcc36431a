// One descriptor per preview setting (yocto-gl's trace_params and name tables
// are the model): the field of PreviewSettings, its command-line flag and help, default (the
// struct's), range, stats.json key, explorer widget and what a change of it invalidates. The
// command line (add_preview_options), the explorer's parameter panel, stats.json, pxf diff's
// read-back of a render's settings and the preview's change detection all loop over this table,
// so a setting is declared once. Settings that change the samples are also in the state file's
// SampleSettings (render_sample_settings, apply_sample_settings); app/setting_table_test.cpp checks
// that every such setting is, and that every other one is not.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "preview/preview.h"

namespace pxf {

// What a change of the setting makes the preview redo (Preview::set_settings), cheapest last.
enum class SettingEffect {
  Retrace,    // the samples are another render's: the accumulation restarts (and the state file records it)
  Restart,    // the tracer restarts to apply it, the samples do not change (the thread count)
  Refilter,   // the samples stay; the filter runs again on them
  Redisplay,  // the samples and L_f stay; blend and tone map run again
};

enum class SettingType {
  Float,
  Int,
  Seed,    // uint64_t
  Switch,  // bool: "--x on|off", or a bare flag (SettingDescriptor::bare_flag)
  Choice,  // an enum bound to its name table (names[i] names static_cast<E>(i))
};

// The explorer's widget for a setting; an empty label: none (set on the command line only).
struct SettingWidget {
  const char* label = "";
  double min = 0.0, max = 0.0;  // slider range (Float, Int); the command line's where that is finite enough
  bool logarithmic = false;
  const char* format = "%.3g";
};

struct SettingDescriptor {
  SettingType type = SettingType::Float;
  const char* key = "";   // stats.json "settings" key
  const char* flag = "";  // command-line option
  std::string help;       // command-line help
  double min = 0.0, max = 0.0;                       // command-line range (Float, Int, Seed)
  const std::vector<std::string>* names = nullptr;  // Choice: the name table
  bool bare_flag = false;                            // Switch: "--x" sets it, there is no "off"
  SettingEffect effect = SettingEffect::Redisplay;
  SettingWidget widget;
  // The field: one of these, by type.
  float& (*float_field)(PreviewSettings&) = nullptr;
  int& (*int_field)(PreviewSettings&) = nullptr;
  uint64_t& (*seed_field)(PreviewSettings&) = nullptr;
  bool& (*switch_field)(PreviewSettings&) = nullptr;
  size_t (*choice_index)(const PreviewSettings&) = nullptr;
  void (*set_choice_index)(PreviewSettings&, size_t) = nullptr;
  // Optional: whether two settings objects count as equal for this setting where their values
  // differ (the specular chains do nothing under full specular sampling).
  bool (*same)(const PreviewSettings&, const PreviewSettings&) = nullptr;

  // The value as a number (a Switch 0 or 1, a Choice its index).
  double value(const PreviewSettings& s) const;
  void set_value(PreviewSettings& s, double v) const;
  bool equal(const PreviewSettings& a, const PreviewSettings& b) const;
  // stats.json: numbers, true/false for a Switch, the name for a Choice.
  nlohmann::json to_json(const PreviewSettings& s) const;
  // Sets the setting from a stats.json value; throws pxf::Error on a value of the wrong kind.
  void from_json(PreviewSettings& s, const nlohmann::json& j) const;
};

// Every preview setting, in the order the command line's help and the explorer show them.
const std::vector<SettingDescriptor>& setting_table();
// The descriptor with this stats.json key; throws pxf::Error for an unknown key.
const SettingDescriptor& setting(const std::string& key);

// The most a change from `before` to `after` makes the preview redo (nullptr: nothing changed).
const SettingDescriptor* strongest_change(const PreviewSettings& before, const PreviewSettings& after,
                                          SettingEffect* effect);
bool changes(const PreviewSettings& before, const PreviewSettings& after, SettingEffect effect);

// stats.json's settings, every entry of the table.
nlohmann::json settings_json(const PreviewSettings& s);
// Sets every setting that `settings` (a stats.json "settings" object) holds; the others keep their
// value (a stats.json of an older build lacks the newer settings).
void read_settings_json(const nlohmann::json& settings, PreviewSettings& s);

}  // namespace pxf
