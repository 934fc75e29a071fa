#include "runtime/topic_log.hpp"

#include "runtime/dynamic_model.hpp"  // index_in

namespace quadgen::runtime {

int LogTopic::column(const std::string& field) const { return index_in(fields, field); }

const LogTopic* TopicLog::find(const std::string& name, int multi_id) const {
  for (const auto& t : topics)
    if (t.name == name && t.multi_id == multi_id) return &t;
  return nullptr;
}

}  // namespace quadgen::runtime
