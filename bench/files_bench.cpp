#include "bench/files_bench.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <set>
#include <sstream>

#include "bench/bench_harness.h"
#include "bench/bench_runs.h"
#include "core/error.h"
#include "core/timing.h"
#include "image/input_file.h"
#include "image/metrics.h"

namespace pxf {

namespace {

namespace fs = std::filesystem;

constexpr uint64_t kMaxListBytes = 1 << 20;

bool is_plain_name(const std::string& name) {
  return !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-';
  });
}

// A built-in scene's name stays as it is; a file is taken from the list's folder.
std::string resolve(const std::string& path, const std::string& folder, bool may_be_builtin) {
  if (path.empty() || path == "-") return "";
  if (may_be_builtin && path.find('/') == std::string::npos && path.find('.') == std::string::npos) return path;
  const fs::path p(path);
  return p.is_absolute() || folder.empty() ? path : (fs::path(folder) / p).string();
}

// One file's figures at one budget, over the rounds.
struct FileRow {
  std::string name;
  double seconds = 0;
  std::vector<TimedRun> plain, filtered;  // one per round
};

// The median of the rounds' values; of two rounds, their mean (median_of takes the upper one).
double rounds_median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

double median_metric(const std::vector<TimedRun>& runs, double RowError::*metric) {
  std::vector<double> values;
  for (const TimedRun& r : runs) values.push_back(r.error.*metric);
  return rounds_median(values);
}

double median_spp(const std::vector<TimedRun>& runs) {
  std::vector<double> spp;
  for (const TimedRun& r : runs) spp.push_back(r.spp);
  return median_of(spp);
}

const char* kCsvHeader =
    "name,scene,env,time_s,rounds,unfiltered_spp,filtered_spp,unfiltered_hdr_nrmse_percent,"
    "filtered_hdr_nrmse_percent,hdr_ratio,unfiltered_display_nrmse_percent,filtered_display_nrmse_percent,"
    "display_ratio,unfiltered_flip,filtered_flip,flip_ratio,filtered_mean_bias_percent,"
    "reference_display_floor_percent,reference_hdr_floor_percent,reference_pair_flip,display_ratio_above_floor\n";

// The reference's own error (--reference-floor): a second reference of another seed differs from it
// by the noise of both (correct_for_reference_noise, image/metrics.h). FLIP is not a variance and
// is given as it is between the two. display_ratio_above_floor is the ratio of the arms' display
// errors with the reference's noise taken off each: what a noise-free reference would show.
struct ReferenceFloor {
  bool measured = false;
  RowError pair;  // the second reference against the first
  double display() const { return correct_for_reference_noise(0.0, pair.display_nrmse).reference_noise_percent; }
  double hdr() const { return correct_for_reference_noise(0.0, pair.hdr_nrmse).reference_noise_percent; }
};

// NaN where the floor is not measured or the unfiltered error does not stand above it.
double ratio_above_floor(double filtered, double unfiltered, const ReferenceFloor& floor) {
  const ReferenceNoiseCorrection u = correct_for_reference_noise(unfiltered, floor.pair.display_nrmse);
  if (!floor.measured || u.within_reference_noise) return std::nan("");
  return correct_for_reference_noise(filtered, floor.pair.display_nrmse).corrected_percent / u.corrected_percent;
}

// A row's medians over its rounds, unfiltered (u) and filtered (f).
struct RowMedians {
  double u_spp, f_spp, u_hdr, f_hdr, u_display, f_display, u_flip, f_flip;
  double f_bias;  // the filtered image's mean over its own samples' unfiltered mean, - 1, in %
};

// The preview's bias in one run: its image's mean against the unfiltered image of the same samples
// (paired, so the noise of the mean mostly cancels), in %.
double mean_bias_percent(const TimedRun& run) {
  const ImageMetrics m = compare_images(run.image, run.unfiltered);
  return m.reference_mean > 0.0 ? 100.0 * (m.test_mean / m.reference_mean - 1.0) : 0.0;
}

double median_bias_percent(const std::vector<TimedRun>& runs) {
  std::vector<double> values;
  for (const TimedRun& r : runs) values.push_back(mean_bias_percent(r));
  return rounds_median(values);
}

RowMedians medians(const FileRow& row) {
  return {median_spp(row.plain),
          median_spp(row.filtered),
          median_metric(row.plain, &RowError::hdr_nrmse),
          median_metric(row.filtered, &RowError::hdr_nrmse),
          median_metric(row.plain, &RowError::display_nrmse),
          median_metric(row.filtered, &RowError::display_nrmse),
          median_metric(row.plain, &RowError::flip),
          median_metric(row.filtered, &RowError::flip),
          median_bias_percent(row.filtered)};
}

std::string csv_row(const BenchFileEntry& e, const FileRow& row, const RowMedians& m, const ReferenceFloor& floor) {
  std::ostringstream s;
  s << e.name << "," << e.scene << "," << e.env << "," << row.seconds << "," << row.plain.size() << "," << m.u_spp
    << "," << m.f_spp << "," << m.u_hdr << "," << m.f_hdr << "," << m.f_hdr / m.u_hdr << "," << m.u_display << ","
    << m.f_display << "," << m.f_display / m.u_display << "," << m.u_flip << "," << m.f_flip << ","
    << m.f_flip / m.u_flip << "," << m.f_bias << ",";
  if (floor.measured)
    s << floor.display() << "," << floor.hdr() << "," << floor.pair.flip << ","
      << ratio_above_floor(m.f_display, m.u_display, floor);
  else
    s << ",,,";
  s << "\n";
  return s.str();
}

// The contact sheet: a row per file, a column per image (for each budget the unfiltered and the
// filtered image of the last round, then the reference), each tone-mapped with its reference's key
// and log-average as the display metrics see it; cells of another size are left black.
class ContactSheet {
 public:
  ContactSheet(int rows, int columns, int cell_width, int cell_height)
      : sheet_(Image::rgb(columns * (cell_width + kGap), rows * (cell_height + kGap))), cw_(cell_width), ch_(cell_height) {}
  void put(int row, int column, const Image& display) {
    if (display.width != cw_ || display.height != ch_) return;
    for (int y = 0; y < ch_; ++y)
      for (int x = 0; x < cw_; ++x)
        for (int c = 0; c < 3; ++c) sheet_.at(column * (cw_ + kGap) + x, row * (ch_ + kGap) + y, c) = display.at(x, y, c);
  }
  const Image& image() const { return sheet_; }

 private:
  static constexpr int kGap = 2;
  Image sheet_;
  int cw_, ch_;
};

std::vector<double> parse_seconds(const std::string& text) {
  std::vector<double> seconds;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    char* end = nullptr;
    const double v = std::strtod(item.c_str(), &end);
    if (item.empty() || *end || !(v > 0.0 && v <= 3600.0)) throw UsageError("--times: '" + item + "' is not a time in (0, 3600] s");
    seconds.push_back(v);
  }
  if (seconds.empty()) throw UsageError("--times: no time given");
  return seconds;
}

}  // namespace

std::vector<BenchFileEntry> parse_bench_file_list(const std::string& text, const std::string& source,
                                                  const std::string& folder) {
  std::vector<BenchFileEntry> entries;
  std::set<std::string> names;
  std::istringstream lines(text);
  int number = 0;
  for (std::string line; std::getline(lines, line);) {
    ++number;
    line = line.substr(0, line.find('#'));
    std::istringstream words(line);
    std::vector<std::string> w;
    for (std::string word; words >> word;) w.push_back(word);
    if (w.empty()) continue;
    const std::string where = source + ":" + std::to_string(number) + ": ";
    if (w.size() < 2 || w.size() > 3) throw Error(where + "expected NAME SCENE [ENV]");
    if (!is_plain_name(w[0])) throw Error(where + "the name '" + w[0] + "' must be letters, digits, '.', '_' or '-'");
    if (!names.insert(w[0]).second) throw Error(where + "the name '" + w[0] + "' is used twice");
    entries.push_back({w[0], resolve(w[1], folder, true), w.size() == 3 ? resolve(w[2], folder, false) : ""});
  }
  if (entries.empty()) throw Error(source + ": no file listed");
  return entries;
}

int files_bench_mode(const std::vector<std::string>& args, const std::string& summary) {
  BenchHarness h("files", summary);
  std::string list_path, times_text = "1,4";
  int rounds = 2;
  bool measure_floor = false;
  h.add_reference_options(1024);
  h.cli().option("--list", &list_path, "FILE", "the files: one 'NAME SCENE [ENV]' a line (required)");
  h.cli().option("--times", &times_text, "LIST", "wall-time budgets of the whole job in seconds (default 1,4)");
  h.cli().option("--rounds", &rounds, "rounds, unfiltered and filtered in turn, alternating which goes first (default 2)",
                 1, 64);
  h.cli().flag("--reference-floor", &measure_floor,
               "also render a second reference of another seed and report the reference's own error (the\n"
               "floor under every figure) and the display ratio above it");
  if (!h.parse(args)) return 0;
  if (list_path.empty()) throw UsageError("--list FILE is required");
  if (h.cli().given("--reference")) throw UsageError("--reference: each file gets its own (--reference-spp)");
  const std::vector<double> times = parse_seconds(times_text);
  const std::vector<unsigned char> bytes = read_input_file(list_path, kMaxListBytes);
  const std::vector<BenchFileEntry> entries = parse_bench_file_list(
      std::string(bytes.begin(), bytes.end()), list_path, fs::path(list_path).parent_path().string());

  auto context = h.gl_context();
  std::printf("bench files: %zu files, times %s s, %d rounds, t=%g, filter %s, GL %s (%s)\n", entries.size(),
              times_text.c_str(), rounds, h.settings().threshold, filter_kind_name(h.settings().filter.kind),
              context->backend_name(), context->gl_renderer().c_str());
  std::printf("display NRMSE, HDR NRMSE and LDR-FLIP: median over rounds, filtered / unfiltered; bias: the\n"
              "filtered image's mean against the unfiltered mean of its own samples\n");
  std::printf("%-16s %6s | %9s %9s | %8s %8s %6s | %8s %8s %6s | %7s %7s %6s | %6s\n", "file", "time s", "unf spp",
              "filt spp", "disp unf", "filt", "ratio", "HDR unf", "filt", "ratio", "FLIP unf", "filt", "ratio", "bias");
  std::ostringstream csv;
  csv << kCsvHeader;
  std::unique_ptr<ContactSheet> sheet;
  const int columns = 2 * static_cast<int>(times.size()) + 1;
  for (size_t i = 0; i < entries.size(); ++i) {
    const BenchFileEntry& e = entries[i];
    const auto load_start = BenchClock::now();
    const BenchSetup b = h.setup_scene(e.scene, e.env, e.name, /*needs_filter=*/true);
    const double load_ms = elapsed_ms(load_start);
    const Image reference = h.reference(b);
    ReferenceFloor floor;
    if (measure_floor) {
      floor = {true, row_error(h.second_reference(b), reference)};
      std::printf("%-16s reference floor (its own error): display %.2f%%, HDR %.2f%%; FLIP between two references %.4f\n",
                  e.name.c_str(), floor.display(), floor.hdr(), floor.pair.flip);
    }
    if (!sheet) sheet = std::make_unique<ContactSheet>(static_cast<int>(entries.size()), columns, b.width, b.height);
    for (size_t k = 0; k < times.size(); ++k) {
      FileRow row{e.name, times[k], {}, {}};
      // Equal wall time of the whole job: the file's load, measured once, is taken off both alike.
      const double budget_ms = std::max(1.0, times[k] * 1000.0 - load_ms);
      for (int r = 0; r < rounds; ++r) {
        const bool plain_first = r % 2 == 0;
        for (int arm = 0; arm < 2; ++arm) {
          const bool plain = (arm == 0) == plain_first;
          TimedRun run = run_timed(b.scene, plain ? b.plain : b.filtered, b.width, b.height, budget_ms, reference);
          (plain ? row.plain : row.filtered).push_back(std::move(run));
        }
      }
      const RowMedians m = medians(row);
      csv << csv_row(e, row, m, floor);
      std::printf("%-16s %6g | %9.0f %9.0f | %7.2f%% %7.2f%% %5.2fx | %7.2f%% %7.2f%% %5.2fx | %7.4f %7.4f %5.2fx | "
                  "%+5.2f%%\n",
                  e.name.c_str(), times[k], m.u_spp, m.f_spp, m.u_display, m.f_display, m.f_display / m.u_display,
                  m.u_hdr, m.f_hdr, m.f_hdr / m.u_hdr, m.u_flip, m.f_flip, m.f_flip / m.u_flip, m.f_bias);
      if (floor.measured)
        std::printf("%-16s %6g | display ratio above the reference's floor %.2fx\n", e.name.c_str(), times[k],
                    ratio_above_floor(m.f_display, m.u_display, floor));
      std::fflush(stdout);
      sheet->put(static_cast<int>(i), 2 * static_cast<int>(k), tonemap_like_reference(row.plain.back().image, reference).test);
      sheet->put(static_cast<int>(i), 2 * static_cast<int>(k) + 1,
                 tonemap_like_reference(row.filtered.back().image, reference).test);
    }
    sheet->put(static_cast<int>(i), columns - 1, tonemap_like_reference(reference, reference).reference);
  }
  const std::string csv_path = h.out() + "/files.csv", sheet_path = h.out() + "/files_sheet.png";
  write_bench_text(csv_path, csv.str());
  write_png(sheet_path, sheet->image());
  std::printf("wrote %s and %s (a row per file: for each time the unfiltered and the filtered image, then the "
              "reference)\n", csv_path.c_str(), sheet_path.c_str());
  return 0;
}

}  // namespace pxf
