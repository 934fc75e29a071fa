// One entry point for the flight logs quadgen reads, in the canonical layout (docs/formats.md):
//  - CSV, canonical or through a column mapping;
//  - PX4 ULog (runtime/ulog.hpp). The mapping names a ULog signal as "topic.field" (array
//    elements "topic.field[i]"; instance 0 of a topic). Every topic keeps its own rate: the
//    signals the mapping uses are interpolated linearly onto one uniform time base (column
//    "t", seconds) over the span all of them cover. Samples a topic logs as NaN (not set yet)
//    are left out; where any signal has a gap (a dropout, a paused topic: longer than three
//    of its median intervals and 0.1 s) the table has a gap too, rather than a line drawn
//    across it. Quaternion components are sign-aligned sample to sample first.
// A mapping's `frame: ned_frd` then turns PX4's north-east-down world and forward-right-down
// body axes into the model's east-north-up world and forward-left-up body axes.
#pragma once
#include <string>

#include "flight_data.hpp"
#include "flight_log.hpp"
#include "ulog.hpp"

namespace quadgen::fit {

// Whether the file starts with the ULog magic bytes.
bool is_ulog(const std::string& path);

// The signals a mapping uses, from a ULog, on a uniform grid at `rate_hz`: "t" and one column
// per source. Throws FitError naming a missing topic or field and what the log has.
runtime::CsvTable ulog_table(const runtime::Ulog& log, const ColumnMapping& m, double rate_hz);

// Reads a log (CSV or ULog) and returns it in the canonical layout. `mapping_path` may be
// empty (`mapping` null) for a canonical CSV; a ULog needs one. `resample_hz` > 0 resamples
// the result (a ULog is always sampled at that rate, 100 Hz when 0).
runtime::CsvTable read_log(const std::string& path, const std::string& mapping_path, double resample_hz);
runtime::CsvTable read_log(const std::string& path, const ColumnMapping* mapping, double resample_hz);

}  // namespace quadgen::fit
