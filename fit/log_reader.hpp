// One entry point for the flight logs quadgen reads, in the canonical layout (docs/formats.md):
//  - CSV, canonical or through a column mapping;
//  - PX4 ULog (runtime/ulog.hpp) and Crazyflie uSD card logs (runtime/usd_log.hpp), both logs
//    of several topics. The mapping names a signal as "topic.field" (ULog array elements
//    "topic.field[i]", instance 0 of a topic; uSD "fixedFrequency.acc.x", the event type's
//    name and the log variable). Every topic keeps its own rate: the
//    signals the mapping uses are put onto one uniform time base (column "t", seconds) over
//    the span all of them cover, each grid value a signal's mean over the grid interval around
//    it (fit/grid_mean.hpp), an Euler angle averaged unwrapped. Samples a topic logs as NaN (not set yet)
//    are left out; where any signal has a gap (a dropout, a paused topic: longer than three
//    of its median intervals and 0.1 s) the table has a gap too, rather than a line drawn
//    across it. Quaternion components are sign-aligned sample to sample first.
// A mapping's `frame: ned_frd` then turns PX4's north-east-down world and forward-right-down
// body axes into the model's east-north-up world and forward-left-up body axes.
#pragma once
#include <optional>
#include <string>

#include "fit/flight_data.hpp"
#include "output/accepted_range.hpp"
#include "runtime/flight_log.hpp"
#include "runtime/ulog.hpp"
#include "runtime/usd_log.hpp"

namespace quadgen::fit {

// Whether the file starts with the ULog magic bytes.
bool is_ulog(const std::string& path);
// Whether it is a log of several topics (ULog or uSD), which needs a mapping.
bool is_topic_log(const std::string& path);

// The signals a mapping uses, from a log of topics, on a uniform grid at `rate_hz`: "t" and one
// column per source. Throws FitError naming a missing topic or field and what the log has.
// A topic logged more than once is named by its instance, `topic[k].field` (instance 0 without
// the brackets). Its notes (CsvTable::notes) name the signals logged more slowly than the grid
// (followed by `how_to_log_faster` where there are any) and the estimator's resets (gaps).
runtime::CsvTable topic_table(const runtime::TopicLog& log, const ColumnMapping& m, double rate_hz,
                              const std::string& how_to_log_faster = "");
// What a person should know of a ULog before trusting it: the logger's dropouts, a cut-off end.
std::vector<std::string> ulog_notes(const runtime::Ulog& log);
// The part of a logged field's or parameter's name before `suffix` ("accelerometer" of
// "accelerometer_timestamp_relative", "PWM_MAIN" of "PWM_MAIN_FUNC1"), or nothing where the
// name does not end in it after at least one character.
std::optional<std::string> stem_before(const std::string& name, const std::string& suffix);

// Reads a log (CSV, ULog or uSD) and returns it in the canonical layout. `mapping_path` may be
// empty (`mapping` null) for a canonical CSV; a log of topics needs one. `resample_hz` > 0
// resamples the result (a log of topics is always sampled at that rate, kTopicLogRate when 0).
runtime::CsvTable read_log(const std::string& path, const std::string& mapping_path, double resample_hz);
// The resample rates options accept: 0 (as logged) or kResampleRange [Hz].
inline constexpr output::AcceptedRange kResampleRange{0.1, 1e5};
// A log of topics (ULog, uSD) is sampled onto one grid at this rate unless told another [Hz].
inline constexpr double kTopicLogRate = 100;
// The default in words, for --help.
inline std::string resample_default_text() {
  return "none for a CSV, " + output::short_number(kTopicLogRate) + " Hz for a ULog or uSD log";
}
inline bool valid_resample_rate(double hz) { return hz == 0 || kResampleRange.contains(hz); }
runtime::CsvTable read_log(const std::string& path, const ColumnMapping* mapping, double resample_hz);

}  // namespace quadgen::fit
