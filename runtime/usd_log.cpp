#include "runtime/usd_log.hpp"

#include <cmath>
#include <cstring>
#include <limits>
#include <set>
#include <string_view>

#include "runtime/log_bytes.hpp"
#include "runtime/log_file.hpp"

namespace quadgen::runtime {

std::uint32_t crc32(const std::string& bytes, std::size_t size) {
  std::uint32_t crc = 0xFFFFFFFFu;
  for (std::size_t i = 0; i < size; ++i) {
    crc ^= static_cast<unsigned char>(bytes[i]);
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

namespace {

// The type codes of the variable definitions (Python struct codes).
struct TypeCode {
  char code;
  unsigned size;
};
constexpr TypeCode kTypeCodes[] = {{'B', 1}, {'b', 1}, {'H', 2}, {'h', 2}, {'I', 4}, {'i', 4}, {'f', 4}, {'e', 2}};

const TypeCode* type_code(char c) {
  for (const auto& t : kTypeCodes)
    if (t.code == c) return &t;
  return nullptr;
}


// IEEE 754 half precision: 1 sign, 5 exponent (bias 15), 10 mantissa bits.
double half_to_double(std::uint16_t h) {
  const int sign = (h >> 15) ? -1 : 1, exponent = (h >> 10) & 0x1F, mantissa = h & 0x3FF;
  if (exponent == 0x1F) return mantissa ? std::numeric_limits<double>::quiet_NaN() : sign * HUGE_VAL;
  if (exponent == 0) return sign * std::ldexp(mantissa, -24);  // subnormal: 2^-14 * m / 2^10
  return sign * std::ldexp(1024 + mantissa, exponent - 25);    // 2^(e-15) * (1 + m / 2^10)
}

double decode(char code, const char* p) {
  switch (code) {
    case 'B':
      return static_cast<double>(little_endian(p, 1));
    case 'b':
      return static_cast<std::int8_t>(little_endian(p, 1));
    case 'H':
      return static_cast<double>(little_endian(p, 2));
    case 'h':
      return static_cast<std::int16_t>(little_endian(p, 2));
    case 'I':
      return static_cast<double>(little_endian(p, 4));
    case 'i':
      return static_cast<std::int32_t>(little_endian(p, 4));
    case 'e':
      return half_to_double(static_cast<std::uint16_t>(little_endian(p, 2)));
    default: {  // 'f'
      const auto bits = static_cast<std::uint32_t>(little_endian(p, 4));
      float v;
      std::memcpy(&v, &bits, sizeof v);
      return v;
    }
  }
}


// Event and log-variable names: a-zA-Z0-9_ and '.' between group and name (plain ASCII tests:
// std::isalnum on a negative char is undefined).
bool is_log_name(std::string_view s) {
  if (s.empty() || s.size() > kUsdMaxName || s.front() == '.' || s.back() == '.') return false;
  for (char c : s)
    if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '.'))
      return false;
  return true;
}

struct EventType {
  unsigned id;
  std::size_t topic;        // index in UsdLog::topics
  std::string codes;        // one type code per variable
  std::size_t record_bytes;  // id + timestamp + values
};

class Parser {
 public:
  Parser(const std::string& bytes, const std::string& name) : b_(bytes) { out_.path = name; }
  UsdLog run();

 private:
  [[noreturn]] void fail(std::size_t at, const std::string& what) const {
    throw LogError(out_.path + ": byte " + std::to_string(at) + ": " + what);
  }
  std::uint64_t take(unsigned n, const char* what);
  std::string take_text(const char* what);
  void read_event_type();
  void read_records(std::size_t end);

  const std::string& b_;
  std::size_t pos_ = 0;
  unsigned timestamp_bytes_ = 8;
  std::vector<EventType> types_;
  UsdLog out_;
};

std::uint64_t Parser::take(unsigned n, const char* what) {
  if (b_.size() - pos_ < n) fail(pos_, std::string("the header ends inside ") + what);
  const std::uint64_t v = little_endian(b_.data() + pos_, n);
  pos_ += n;
  return v;
}

std::string Parser::take_text(const char* what) {
  const std::size_t nul = b_.find('\0', pos_);
  if (nul == std::string::npos) fail(pos_, std::string("the header ends inside ") + what + " (no terminating NUL)");
  std::string s = b_.substr(pos_, nul - pos_);
  pos_ = nul + 1;
  return s;
}

void Parser::read_event_type() {
  const std::size_t at = pos_;
  EventType e{static_cast<unsigned>(take(2, "an event id")), out_.topics.size(), "", 2 + timestamp_bytes_};
  LogTopic topic;
  topic.name = take_text("an event name");
  if (!is_log_name(topic.name)) fail(at + 2, "event name " + quoted_from_log(topic.name) + " is no log name (a-zA-Z0-9_.)");
  for (const auto& t : types_)
    if (t.id == e.id || out_.topics[t.topic].name == topic.name)
      fail(at, "event type " + std::to_string(e.id) + " " + quoted_from_log(topic.name) + " is defined twice");
  const auto count = static_cast<unsigned>(take(2, "a variable count"));
  if (count > kUsdMaxVariables)
    fail(pos_ - 2, std::to_string(count) + " variables in event " + quoted_from_log(topic.name) + " (at most " +
                       std::to_string(kUsdMaxVariables) + ")");
  topic.fields.push_back("timestamp");
  std::set<std::string> seen;
  for (unsigned k = 0; k < count; ++k) {
    const std::size_t var_at = pos_;
    const std::string def = take_text("a variable definition");
    // "name(T)": the name, an opening parenthesis, one type code, a closing one.
    const TypeCode* type = def.size() >= 4 && def[def.size() - 3] == '(' && def.back() == ')'
                               ? type_code(def[def.size() - 2])
                               : nullptr;
    if (!type) fail(var_at, "variable " + quoted_from_log(def) + " is not name(T) with T one of B b H h I i f e");
    const std::string name = def.substr(0, def.size() - 3);
    if (!is_log_name(name)) fail(var_at, "variable name " + quoted_from_log(name) + " is no log name (a-zA-Z0-9_.)");
    if (!seen.insert(name).second) fail(var_at, "variable " + quoted_from_log(name) + " appears twice in one event");
    topic.fields.push_back(name);
    e.codes += type->code;
    e.record_bytes += type->size;
  }
  types_.push_back(e);
  out_.topics.push_back(std::move(topic));
}

// Records from pos_ to `end`. Without a valid CRC, a tail shorter than its record is a
// record cut off by the end of logging: dropped. With one, the records must fill the file.
void Parser::read_records(std::size_t end) {
  while (pos_ < end) {
    const std::size_t at = pos_;
    if (end - pos_ < 2 + timestamp_bytes_) {
      if (out_.crc_valid) fail(at, "the last record is cut off before the CRC");
      out_.truncated = true, out_.truncated_at = at;
      return;
    }
    const auto id = static_cast<unsigned>(little_endian(b_.data() + pos_, 2));
    const EventType* e = nullptr;
    for (const auto& t : types_)
      if (t.id == id) e = &t;
    if (!e) fail(at, "record of event id " + std::to_string(id) + ", which the header does not define");
    if (end - pos_ < e->record_bytes) {
      if (out_.crc_valid) fail(at, "the last record is cut off before the CRC");
      out_.truncated = true, out_.truncated_at = at;
      return;
    }
    const char* p = b_.data() + pos_ + 2;
    const std::uint64_t stamp = little_endian(p, timestamp_bytes_);
    std::vector<double> row;
    row.reserve(1 + e->codes.size());
    // Microseconds on both versions: version 1 counts milliseconds (the 1 kHz system tick).
    row.push_back(timestamp_bytes_ == 8 ? static_cast<double>(stamp) : 1000.0 * static_cast<double>(stamp));
    p += timestamp_bytes_;
    for (char code : e->codes) {
      row.push_back(decode(code, p));
      p += type_code(code)->size;
    }
    out_.topics[e->topic].rows.push_back(std::move(row));
    pos_ += e->record_bytes;
  }
}

UsdLog Parser::run() {
  if (b_.size() < 5 || static_cast<unsigned char>(b_[0]) != 0xBC)
    fail(0, "not a Crazyflie uSD log (it starts with the byte 0xBC, a version and an event count)");
  pos_ = 1;
  out_.version = static_cast<int>(take(2, "the version"));
  if (out_.version != 1 && out_.version != 2)
    fail(1, "file version " + std::to_string(out_.version) + " (this reader knows 1 and 2)");
  timestamp_bytes_ = out_.version == 2 ? 8 : 4;
  const auto types = static_cast<unsigned>(take(2, "the event type count"));
  if (types == 0) fail(3, "the header defines no event type");
  for (unsigned k = 0; k < types; ++k) read_event_type();
  // The CRC, when logging stopped cleanly: the last four bytes, over everything before them.
  out_.crc_valid = b_.size() >= pos_ + 4 && little_endian(b_.data() + b_.size() - 4, 4) == crc32(b_, b_.size() - 4);
  read_records(out_.crc_valid ? b_.size() - 4 : b_.size());
  return std::move(out_);
}

}  // namespace

bool is_usd_log(const std::string& path) {
  const std::string head = read_head(path, 3);
  return head.size() == 3 && head[0] == '\xBC' && (head[1] == 1 || head[1] == 2) && head[2] == 0;
}

UsdLog parse_usd_log(const std::string& bytes, const std::string& name) { return Parser(bytes, name).run(); }

UsdLog read_usd_log(const std::string& path) {
  const LogFile file(path, "a Crazyflie uSD log");
  return parse_usd_log(file.read_all(), path);
}

}  // namespace quadgen::runtime
