// A log of several topics, each a table on its own clock: what the binary log formats quadgen
// reads (PX4 ULog, runtime/ulog.hpp; Crazyflie uSD, runtime/usd_log.hpp) have in common, and
// all that fit/log_reader needs to merge the signals a mapping names onto one time base.
#pragma once
#include <string>
#include <vector>

namespace quadgen::runtime {

// The records of one topic (a ULog topic instance, a uSD event type), one row each. Column 0
// is `timestamp` in microseconds; the others are the logged fields as doubles.
struct LogTopic {
  std::string name;
  int multi_id = 0;  // the instance of a topic logged more than once (ULog); 0 otherwise
  std::vector<std::string> fields;
  std::vector<std::vector<double>> rows;
  int column(const std::string& field) const;  // -1 if absent
};

struct TopicLog {
  std::string path;
  std::vector<LogTopic> topics;                                             // in order of first appearance
  const LogTopic* find(const std::string& name, int multi_id = 0) const;  // nullptr if absent
};

}  // namespace quadgen::runtime
