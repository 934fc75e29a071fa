// PX4 ULog flight logs (the "ULog File Format" specification of docs.px4.io): every logged
// topic as a table of doubles, the parameters and the information messages.
//
// Logs come from users, so the reader trusts no length or offset in them. Policies:
// - A message cut off by the end of the file is dropped and everything before it kept
//   (logging stops mid-message on power loss; the spec asks for exactly this). The same
//   holds at the start of appended data ('B' message, DATA_APPENDED). Ulog::truncated says
//   that this happened and where.
// - In the Data section, a message that does not fit the spec (or of a type the spec does not
//   name, where no sensible message follows it) is skipped to the next sync ('S') message, as
//   the spec intends them for (PX4 writes one every 500 ms), when one follows. Ulog::skipped
//   says where and why, and the readers say it as a note of the flight (a corrupt log is
//   reported, not silently shortened); the offset kept is where the corruption was found,
//   which may lie after where it began (messages the spec tolerates, such as 'O' and 'P', may
//   have been read from its bytes). A message running past the end is such a corruption too
//   when a sync message follows it; after a skip, a data message of a msg_id never subscribed
//   is skipped by its size and counted (its 'A' may have been skipped). Without a sync after it,
//   and anywhere in the Definitions section, anything that does not fit the spec throws
//   LogError "path: byte N: cause", N the offset of the message at fault; a type the spec does
//   not name is then skipped by its size (forward compatibility).
// - Message types this reader does not use ('M', 'Q', 'L', 'C', 'S') are skipped by their
//   size; unknown incompatible flag bits are refused.
// - Formats are checked when they are subscribed: an unused format naming an unknown type
//   is no error. A subscribed format must not be recursive, nest deeper than
//   kUlogMaxNesting, have arrays longer than kUlogMaxArray (or of length 0) or exceed
//   kUlogMaxFormatBytes (no data message can be larger), and needs a `uint64_t timestamp`.
// - Names longer than kUlogMaxName are refused, and the column layouts of all subscribed
//   topics together may take at most about kUlogMaxLayoutBytes, so a few bytes of formats
//   and subscriptions cannot demand gigabytes. Otherwise memory grows with the file: rows
//   take at most about 8 times the bytes of their data messages.
#pragma once
#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "runtime/flight_log.hpp"  // LogError
#include "runtime/topic_log.hpp"

namespace quadgen::runtime {

constexpr int kUlogMaxNesting = 16;
constexpr std::uint64_t kUlogMaxArray = 65535;
constexpr std::uint64_t kUlogMaxFormatBytes = 65535;
constexpr std::size_t kUlogMaxName = 255;
constexpr std::uint64_t kUlogMaxLayoutBytes = 64ULL << 20;

// Each topic instance (a format name and its multi_id) is a LogTopic: its columns are the
// flattened fields, `timestamp` (microseconds) first wherever the format has it, the others in
// message order: arrays as `q[0]`.., nested types as `sub.field` and `sub[1].field`;
// `_padding*` fields are left out. Every value is converted to double (char and bool as their
// byte value, 64-bit integers rounded beyond 2^53). Values are as logged: PX4 logs NaN for
// unset floats and nothing is range-checked here.

// A parameter set while logging ('P' message in the Data section).
struct UlogParameterChange {
  double timestamp = 0;  // latest data timestamp before it (microseconds), 0 if none yet
  std::string name;
  double value = 0;
};

struct Ulog : TopicLog {  // path, topics (in order of first subscription), find()
  int version = 0;                // file format version (header byte 7)
  std::uint64_t start_time = 0;   // header timestamp, microseconds
  // Values when logging started ('P' messages of the Definitions section), int32_t and float.
  std::map<std::string, double> parameters;
  std::vector<UlogParameterChange> parameter_changes;
  // 'I' messages as "name=value" in file order: char arrays as text (control characters as
  // '?'), numbers in decimal, arrays comma-separated, other types as "<N bytes of TYPE>".
  std::vector<std::string> info;
  int dropouts = 0;  // 'O' messages and their total duration
  double dropout_ms = 0;
  // Stretches skipped after a corrupt message in the Data section (see above): the corrupt
  // message's offset, the sync message's where reading resumed, and what was wrong.
  struct Skip {
    std::uint64_t from = 0, to = 0;
    std::string cause;
  };
  std::vector<Skip> skipped;
  // Data messages after a skipped stretch for a msg_id never subscribed (its 'A' may have been
  // in the stretch): skipped by their size and counted.
  int data_without_subscription = 0;
  bool truncated = false;                                                  // a cut-off message was dropped (see above)
  std::uint64_t truncated_at = 0;                                          // the byte offset of the first one
};

// A regular file of at most max_input_bytes(), read into memory as a whole.
Ulog read_ulog(const std::string& path);
// `name` is the file name used in error messages.
Ulog parse_ulog(const std::string& bytes, const std::string& name);

}  // namespace quadgen::runtime
