#include "runtime/ulog.hpp"

#include "runtime/log_bytes.hpp"
#include "runtime/log_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <optional>
#include <set>
#include <sstream>
#include <string_view>
#include <utility>

namespace quadgen::runtime {

namespace {

constexpr std::size_t kHeaderBytes = 16, kMsgHeaderBytes = 3;
constexpr std::uint64_t kColumnCost = 32, kTopicCost = 256;  // rough bytes of bookkeeping

enum class Base { i8, u8, i16, u16, i32, u32, i64, u64, f32, f64, boolean, chr };

struct BaseType {
  const char* name;
  Base base;
  unsigned size;
};

constexpr BaseType kBaseTypes[] = {{"int8_t", Base::i8, 1},    {"uint8_t", Base::u8, 1},   {"int16_t", Base::i16, 2},
                                   {"uint16_t", Base::u16, 2}, {"int32_t", Base::i32, 4},  {"uint32_t", Base::u32, 4},
                                   {"int64_t", Base::i64, 8},  {"uint64_t", Base::u64, 8}, {"float", Base::f32, 4},
                                   {"double", Base::f64, 8},   {"bool", Base::boolean, 1}, {"char", Base::chr, 1}};

const BaseType* base_type(std::string_view name) {
  for (const auto& b : kBaseTypes)
    if (name == b.name) return &b;
  return nullptr;
}


double decode(Base b, const char* p) {
  switch (b) {
    case Base::i8:
      return static_cast<std::int8_t>(little_endian(p, 1));
    case Base::i16:
      return static_cast<std::int16_t>(little_endian(p, 2));
    case Base::i32:
      return static_cast<std::int32_t>(little_endian(p, 4));
    case Base::i64:
      return static_cast<double>(static_cast<std::int64_t>(little_endian(p, 8)));
    case Base::u8:
    case Base::boolean:
    case Base::chr:
      return static_cast<double>(little_endian(p, 1));
    case Base::u16:
      return static_cast<double>(little_endian(p, 2));
    case Base::u32:
      return static_cast<double>(little_endian(p, 4));
    case Base::u64:
      return static_cast<double>(little_endian(p, 8));
    case Base::f32: {
      const auto bits = static_cast<std::uint32_t>(little_endian(p, 4));
      float f;
      std::memcpy(&f, &bits, sizeof f);
      return f;
    }
    case Base::f64: {
      const std::uint64_t bits = little_endian(p, 8);
      double d;
      std::memcpy(&d, &bits, sizeof d);
      return d;
    }
  }
  return 0;
}

std::string number_text(Base b, const char* p) {
  // Through double, 64-bit integers would lose digits.
  if (b == Base::u64) return std::to_string(little_endian(p, 8));
  if (b == Base::i64) return std::to_string(static_cast<std::int64_t>(little_endian(p, 8)));
  std::ostringstream os;
  os.precision(b == Base::f32 ? 9 : 17);
  os << decode(b, p);
  return os.str();
}


// Plain ASCII tests: std::isalnum on a negative char is undefined.
bool name_char(char c, bool message_name) {
  if ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_') return true;
  return message_name && (c == '-' || c == '/');
}

// Message names allow a-zA-Z0-9_-/, field names a-zA-Z0-9_.
bool is_name(std::string_view s, bool message_name) {
  if (s.empty() || s.size() > kUlogMaxName) return false;
  return std::all_of(s.begin(), s.end(), [&](char c) { return name_char(c, message_name); });
}

struct TypeRef {
  std::string name;
  std::uint64_t count = 1;
  bool array = false;
};

// "type" or "type[n]"; the reason if malformed, else "".
std::string parse_type(std::string_view s, TypeRef& t) {
  const auto open = s.find('[');
  t.name = std::string(s.substr(0, open));
  if (!is_name(t.name, true)) return "type " + quoted_from_log(t.name) + " is not a valid type name";
  if (open == std::string_view::npos) return "";
  const std::string_view digits = s.substr(open + 1, s.size() - open - 2);
  if (s.back() != ']' || digits.empty() ||
      !std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; }))
    return "type " + quoted_from_log(s) + " is not type[length]";
  t.array = true;
  t.count = digits.size() > 6 ? kUlogMaxArray + 1 : std::stoull(std::string(digits));
  if (t.count == 0 || t.count > kUlogMaxArray)
    return "array length " + text_from_log(digits, 20) + " in " + quoted_from_log(s) + " (expected 1.." +
           std::to_string(kUlogMaxArray) + ")";
  return "";
}

struct FieldDef {
  TypeRef type;
  std::string name;
  bool padding = false;  // written for alignment; its bytes are skipped
};

struct FormatDef {
  std::vector<FieldDef> fields;
  std::string text;
  std::uint64_t at = 0;
};

struct Leaf {
  std::uint32_t offset;
  Base type;
};

// Where each column of a format is in a data message.
struct Layout {
  std::vector<std::string> names;
  std::vector<Leaf> leaves;
  std::uint64_t size = 0, min_size = 0;  // min_size: a trailing padding field may be left out
  std::uint64_t cost = 0;                // charged against kUlogMaxLayoutBytes per copy
};

struct Msg {
  char type;
  std::uint64_t at;  // offset of the message header
  std::string_view body;
};

struct KeyValue {
  TypeRef type;
  std::string name;
  std::string_view value;
};

// The spec's message types; in the Data section another is taken for corruption where no
// sensible message follows it and a sync message does (Parser::run), else skipped by its size
// as the spec asks of later types.
bool known_type(char type) { return std::strchr("BFIMPQARDLCSO", type) != nullptr && type != '\0'; }

// A sync message whole, header included: size 8, 'S', the spec's magic.
constexpr char kSyncMessage[] = {0x08, 0x00, 'S', 0x2F, 0x73, 0x13, 0x20, 0x25, 0x0C, static_cast<char>(0xBB), 0x12};

class Parser {
 public:
  Parser(const std::string& bytes, const std::string& path) : b_(bytes) { out_.path = path; }
  Ulog run();

 private:
  struct Sub {
    std::size_t topic;
    const Layout* layout;
  };

  [[noreturn]] void fail(std::uint64_t at, const std::string& what) const {
    throw LogError(out_.path + ": byte " + std::to_string(at) + ": " + what);
  }
  void require(const Msg& m, std::size_t n, const char* what) const;
  void charge(std::uint64_t cost, std::uint64_t at);

  void read_header();
  std::optional<Msg> message_at(std::size_t pos, std::size_t end) const;
  bool resync(std::size_t& pos, std::size_t end, const std::string& cause);
  std::size_t next_sync(std::size_t from, std::size_t end);
  // Whether the message after m ends the stretch or is whole and of a type the spec names.
  bool followed_by_a_message(const Msg& m, std::size_t end) const {
    const std::size_t next = m.at + kMsgHeaderBytes + m.body.size();
    const auto after = message_at(next, end);
    return next == end || (after && known_type(after->type));
  }
  struct SyncSearch {
    std::size_t from = std::string::npos, end = 0, found = std::string::npos;
  } sync_search_;
  std::vector<std::size_t> flag_bits(const Msg& m) const;
  void handle(const Msg& m);

  void format(const Msg& m);
  FieldDef parse_field(std::string_view item, std::uint64_t at, const std::string& fmt) const;
  KeyValue key_value(const Msg& m) const;
  void info(const Msg& m);
  void parameter(const Msg& m);
  void subscribe(const Msg& m);
  void data(const Msg& m);

  const Layout& layout(const std::string& fmt, std::uint64_t at);
  std::uint64_t format_size(const std::string& fmt, int depth, std::set<std::string>& open, std::uint64_t at);
  std::uint64_t element_size(const TypeRef& t, const std::string& fmt, int depth, std::set<std::string>& open,
                             std::uint64_t at);
  void flatten(const std::string& fmt, const std::string& prefix, std::uint64_t base, Layout& l, std::uint64_t at);
  void timestamp_first(Layout& l, const std::string& fmt, std::uint64_t at) const;

  const std::string& b_;
  Ulog out_;
  std::map<std::string, FormatDef> formats_;
  std::map<std::string, std::uint64_t> sizes_;
  std::map<std::string, Layout> layouts_;  // node-based: Sub::layout stays valid
  std::map<std::uint16_t, Sub> subs_;
  std::map<std::pair<std::string, int>, std::size_t> topic_of_;
  std::uint64_t layout_left_ = kUlogMaxLayoutBytes;
  bool in_data_ = false;  // the Definitions section ends at the first 'A', 'D', 'L' or 'C'
  double last_timestamp_ = 0;
};

void Parser::require(const Msg& m, std::size_t n, const char* what) const {
  if (m.body.size() < n)
    fail(m.at, std::string("'") + m.type + "' message of " + std::to_string(m.body.size()) +
                   " bytes, expected at least " + std::to_string(n) + " (" + what + ")");
}

void Parser::charge(std::uint64_t cost, std::uint64_t at) {
  if (cost > layout_left_)
    fail(at, "the subscribed topics' columns would take more than " + std::to_string(kUlogMaxLayoutBytes >> 20) +
                 " MiB (corrupt or hostile log)");
  layout_left_ -= cost;
}

void Parser::read_header() {
  static const char kMagic[] = {'U', 'L', 'o', 'g', 0x01, 0x12, 0x35};
  if (std::memcmp(b_.data(), kMagic, std::min(b_.size(), sizeof kMagic)) != 0)
    fail(0, "not a ULog file (expected the magic \"ULog\" 01 12 35)");
  if (b_.size() < kHeaderBytes) fail(b_.size(), "the file ends inside the 16-byte ULog header");
  out_.version = static_cast<unsigned char>(b_[7]);
  out_.start_time = little_endian(b_.data() + 8, 8);
}

// The message at pos if it ends by `end`, else nothing (a cut-off or absent message).
std::optional<Msg> Parser::message_at(std::size_t pos, std::size_t end) const {
  if (end - pos < kMsgHeaderBytes) return std::nullopt;
  const std::size_t size = little_endian(b_.data() + pos, 2);
  if (end - pos - kMsgHeaderBytes < size) return std::nullopt;
  return Msg{b_[pos + 2], pos, std::string_view(b_).substr(pos + kMsgHeaderBytes, size)};
}

// The ends of the stretches of messages: before each appended part, and the end of the file.
std::vector<std::size_t> Parser::flag_bits(const Msg& m) const {
  require(m, 40, "compat_flags, incompat_flags, appended_offsets");
  const char* p = m.body.data();
  for (int i = 8; i < 16; ++i) {
    const unsigned known = i == 8 ? 1u : 0u;  // DATA_APPENDED
    if (static_cast<unsigned char>(p[i]) & ~known)
      fail(m.at, "unknown incompatible flag bits (incompat_flags[" + std::to_string(i - 8) +
                     "] = " + std::to_string(static_cast<unsigned char>(p[i])) + "): the log needs a newer reader");
  }
  std::vector<std::size_t> ends;
  const std::uint64_t start = m.at + kMsgHeaderBytes + m.body.size();
  for (int i = 0; i < 3 && (p[8] & 1); ++i) {
    const std::uint64_t offset = little_endian(p + 16 + 8 * i, 8), from = ends.empty() ? start : ends.back();
    if (offset == 0) continue;
    if (offset < from || offset > b_.size())
      fail(m.at, "appended_offsets[" + std::to_string(i) + "] = " + std::to_string(offset) +
                     ", expected an offset in " + std::to_string(from) + ".." + std::to_string(b_.size()) +
                     " (the file size)");
    ends.push_back(static_cast<std::size_t>(offset));
  }
  ends.push_back(b_.size());
  return ends;
}


// The first sync message at or after `from` and before `end`, or npos. The last search is kept:
// many corrupt messages before one sync message (or none) cost one scan, not one each.
std::size_t Parser::next_sync(std::size_t from, std::size_t end) {
  if (!(sync_search_.from <= from && sync_search_.end == end && (sync_search_.found == std::string::npos || sync_search_.found >= from))) {
    const std::string_view rest = std::string_view(b_).substr(0, end);
    sync_search_ = {from, end, rest.find(std::string_view(kSyncMessage, sizeof kSyncMessage), from)};
  }
  return sync_search_.found;
}

// In the Data section, after a corrupt message at `pos`: the next sync message before `end`
// becomes the reading position, the skip kept for the notes; false where none follows.
bool Parser::resync(std::size_t& pos, std::size_t end, const std::string& cause) {
  if (!in_data_) return false;
  const std::size_t sync = next_sync(pos + 1, end);
  if (sync == std::string::npos) return false;
  const std::string prefix = out_.path + ": ";
  out_.skipped.push_back({pos, sync, cause.compare(0, prefix.size(), prefix) == 0 ? cause.substr(prefix.size()) : cause});
  pos = sync;
  return true;
}

Ulog Parser::run() {
  read_header();
  std::size_t pos = kHeaderBytes;
  std::vector<std::size_t> ends{b_.size()};
  if (const auto m = message_at(pos, b_.size()); m && m->type == 'B') {
    ends = flag_bits(*m);
    pos += kMsgHeaderBytes + m->body.size();
  }
  for (const std::size_t end : ends) {
    while (pos < end) {
      const auto m = message_at(pos, end);
      if (!m) {  // runs past the end: cut off, unless a sync message follows (a corrupt size)
        if (resync(pos, end, "byte " + std::to_string(pos) + ": a message whose size runs past the end")) continue;
        break;
      }
      // A type the spec does not name is a later version's when a sensible message follows it
      // (skipped by its size, as the spec asks), corruption when none does.
      if (in_data_ && !known_type(m->type) && !followed_by_a_message(*m, end) &&
          resync(pos, end, "byte " + std::to_string(pos) + ": unknown message type " + std::to_string(static_cast<unsigned char>(m->type))))
        continue;
      try {
        handle(*m);
      } catch (const LogError& e) {
        if (!resync(pos, end, e.what())) throw;
        continue;
      }
      pos += kMsgHeaderBytes + m->body.size();
    }
    if (pos < end && !out_.truncated) {
      out_.truncated = true;
      out_.truncated_at = pos;
    }
    pos = end;
  }
  return std::move(out_);
}

void Parser::handle(const Msg& m) {
  switch (m.type) {
    case 'F':
      return format(m);
    case 'I':
      return info(m);
    case 'P':
      return parameter(m);
    case 'A':
      in_data_ = true;
      return subscribe(m);
    case 'D':
      in_data_ = true;
      return data(m);
    case 'R':
      require(m, 2, "msg_id");
      subs_.erase(static_cast<std::uint16_t>(little_endian(m.body.data(), 2)));
      return;
    case 'O':
      require(m, 2, "duration");
      ++out_.dropouts;
      out_.dropout_ms += static_cast<double>(little_endian(m.body.data(), 2));
      return;
    case 'L':
    case 'C':
      in_data_ = true;
      return;  // printf output: not needed for fitting
    case 'B':
      fail(m.at, "flag bits message ('B') other than right after the header");
    default:
      return;  // 'M', 'Q', 'S' and types of later versions: skipped by size, as the spec asks
  }
}

void Parser::format(const Msg& m) {
  const std::string_view text = m.body;
  const auto colon = text.find(':');
  if (colon == std::string_view::npos)
    fail(m.at, "format " + quoted_from_log(text) + " has no ':' (expected \"name:type field;...\")");
  const std::string name(text.substr(0, colon));
  if (!is_name(name, true) || base_type(name))
    fail(m.at, "format name " + quoted_from_log(name) + " is not a valid message name");
  FormatDef def{{}, std::string(text), m.at};
  std::set<std::string> seen;
  for (std::string_view list = text.substr(colon + 1); !list.empty();) {
    const auto semi = list.find(';');
    const std::string_view item = list.substr(0, semi);
    list = semi == std::string_view::npos ? std::string_view{} : list.substr(semi + 1);
    if (item.empty()) continue;  // after the trailing ';'
    def.fields.push_back(parse_field(item, m.at, name));
    const FieldDef& f = def.fields.back();
    if (!f.padding && !seen.insert(f.name).second)
      fail(m.at, "format " + quoted_from_log(name) + " has field " + quoted_from_log(f.name) + " twice");
  }
  if (def.fields.empty()) fail(m.at, "format " + quoted_from_log(name) + " has no fields");
  const auto [it, added] = formats_.emplace(name, std::move(def));
  // Formats cannot change once data may have been read with them.
  if (!added && it->second.text != text)
    fail(m.at,
         "format " + quoted_from_log(name) + " defined again, differently (first at byte " + std::to_string(it->second.at) + ")");
}

FieldDef Parser::parse_field(std::string_view item, std::uint64_t at, const std::string& fmt) const {
  const auto space = item.find(' ');
  if (space == std::string_view::npos || item.find(' ', space + 1) != std::string_view::npos)
    fail(at, "format " + quoted_from_log(fmt) + ": field " + quoted_from_log(item) + " is not \"type name\"");
  FieldDef f;
  if (const std::string why = parse_type(item.substr(0, space), f.type); !why.empty())
    fail(at, "format " + quoted_from_log(fmt) + ": " + why);
  f.name = std::string(item.substr(space + 1));
  if (!is_name(f.name, false)) fail(at, "format " + quoted_from_log(fmt) + ": " + quoted_from_log(f.name) + " is not a valid field name");
  f.padding = f.name.rfind("_padding", 0) == 0;
  return f;
}

// 'I' and 'P': uint8_t key_len, key "type name", value.
KeyValue Parser::key_value(const Msg& m) const {
  require(m, 1, "key_len");
  const std::size_t key_len = static_cast<unsigned char>(m.body[0]);
  require(m, 1 + key_len, "the key");
  const std::string_view key = m.body.substr(1, key_len);
  KeyValue kv;
  const auto space = key.find(' ');
  std::string why = space == std::string_view::npos ? "no space" : parse_type(key.substr(0, space), kv.type);
  if (why.empty()) {
    kv.name = std::string(key.substr(space + 1));
    if (!is_name(kv.name, true)) why = quoted_from_log(kv.name) + " is not a valid name";
  }
  if (!why.empty()) fail(m.at, std::string("'") + m.type + "' key " + quoted_from_log(key) + " is not \"type name\": " + why);
  kv.value = m.body.substr(1 + key_len);
  return kv;
}

void Parser::info(const Msg& m) {
  const KeyValue kv = key_value(m);
  const BaseType* t = base_type(kv.type.name);
  std::string text;
  if (!t) {
    text = "<" + std::to_string(kv.value.size()) + " bytes of " + kv.type.name + ">";
  } else if (t->base == Base::chr) {
    const auto used = kv.value.find_last_not_of('\0');  // some writers keep C terminators
    const std::string_view value = kv.value.substr(0, used == std::string_view::npos ? 0 : used + 1);
    text = text_from_log(value, value.size());
  } else {
    if (kv.value.size() != t->size * kv.type.count)
      fail(m.at, "info " + quoted_from_log(kv.name) + ": value of " + std::to_string(kv.value.size()) + " bytes, expected " +
                     std::to_string(t->size * kv.type.count));
    for (std::size_t i = 0; i < kv.type.count; ++i)
      text += (i ? "," : "") + number_text(t->base, kv.value.data() + i * t->size);
  }
  out_.info.push_back(kv.name + "=" + text);
}

void Parser::parameter(const Msg& m) {
  const KeyValue kv = key_value(m);
  const BaseType* t = base_type(kv.type.name);
  if (!t || kv.type.array || t->base == Base::chr || kv.value.size() != t->size)
    fail(m.at, "parameter " + quoted_from_log(kv.name) + ": expected a number (int32_t or float), got " + quoted_from_log(kv.type.name) +
                   (kv.type.array ? "[]" : "") + " with " + std::to_string(kv.value.size()) + " bytes");
  const double v = decode(t->base, kv.value.data());
  if (in_data_)
    out_.parameter_changes.push_back({last_timestamp_, kv.name, v});
  else
    out_.parameters[kv.name] = v;
}

void Parser::subscribe(const Msg& m) {
  require(m, 4, "multi_id, msg_id, message name");
  const int multi_id = static_cast<unsigned char>(m.body[0]);
  const auto msg_id = static_cast<std::uint16_t>(little_endian(m.body.data() + 1, 2));
  const std::string name(m.body.substr(3));
  if (!is_name(name, true)) fail(m.at, "subscription to " + quoted_from_log(name) + ", not a valid message name");
  if (!formats_.count(name)) fail(m.at, "subscription to undefined format " + quoted_from_log(name));
  if (subs_.count(msg_id)) fail(m.at, "msg_id " + std::to_string(msg_id) + " subscribed twice");
  const Layout& l = layout(name, m.at);
  // Charged before anything is kept: a throw leaves no half-made topic behind for a reading
  // resumed at a sync message to write into (a review, helper-155).
  const auto key = std::make_pair(name, multi_id);
  auto it = topic_of_.find(key);
  if (it == topic_of_.end()) {
    charge(kTopicCost + l.cost, m.at);
    out_.topics.push_back({name, multi_id, l.names, {}});
    it = topic_of_.emplace(key, out_.topics.size() - 1).first;
  }
  subs_[msg_id] = {it->second, &l};
}

void Parser::data(const Msg& m) {
  require(m, 2, "msg_id");
  const auto msg_id = static_cast<std::uint16_t>(little_endian(m.body.data(), 2));
  const auto s = subs_.find(msg_id);
  if (s == subs_.end() && !out_.skipped.empty()) {  // its subscription may have been in a skipped stretch
    ++out_.data_without_subscription;
    return;
  }
  if (s == subs_.end()) fail(m.at, "data message for unknown msg_id " + std::to_string(msg_id));
  const Layout& l = *s->second.layout;
  LogTopic& topic = out_.topics[s->second.topic];
  const std::string_view d = m.body.substr(2);
  if (d.size() < l.min_size || d.size() > l.size)
    fail(m.at, "data message for " + quoted_from_log(topic.name) + " has " + std::to_string(d.size()) + " bytes, expected " +
                   (l.min_size == l.size ? "" : std::to_string(l.min_size) + "..") + std::to_string(l.size));
  std::vector<double> row(l.leaves.size());
  for (std::size_t i = 0; i < row.size(); ++i) row[i] = decode(l.leaves[i].type, d.data() + l.leaves[i].offset);
  last_timestamp_ = std::max(last_timestamp_, row[0]);
  topic.rows.push_back(std::move(row));
}

// Formats are checked only here, when subscribed: they may be defined in any order.
const Layout& Parser::layout(const std::string& fmt, std::uint64_t at) {
  if (const auto it = layouts_.find(fmt); it != layouts_.end()) return it->second;
  Layout l;
  std::set<std::string> open;
  l.size = format_size(fmt, 0, open, at);
  flatten(fmt, "", 0, l, at);
  timestamp_first(l, fmt, at);
  const FieldDef& last = formats_.at(fmt).fields.back();
  l.min_size = l.size - (last.padding ? element_size(last.type, fmt, 0, open, at) * last.type.count : 0);
  return layouts_.emplace(fmt, std::move(l)).first->second;
}

std::uint64_t Parser::format_size(const std::string& fmt, int depth, std::set<std::string>& open, std::uint64_t at) {
  if (const auto it = sizes_.find(fmt); it != sizes_.end()) return it->second;
  if (!open.insert(fmt).second) fail(at, "format " + quoted_from_log(fmt) + " contains itself (recursive formats are refused)");
  if (depth > kUlogMaxNesting)
    fail(at, "format " + quoted_from_log(fmt) + " is nested deeper than " + std::to_string(kUlogMaxNesting) + " levels");
  std::uint64_t total = 0;
  for (const auto& f : formats_.at(fmt).fields) {
    total += element_size(f.type, fmt, depth, open, at) * f.type.count;  // both <= 65535: no overflow
    if (total > kUlogMaxFormatBytes)
      fail(at, "format " + quoted_from_log(fmt) + " is larger than " + std::to_string(kUlogMaxFormatBytes) +
                   " bytes (no data message can hold it)");
  }
  open.erase(fmt);
  return sizes_[fmt] = total;
}

std::uint64_t Parser::element_size(const TypeRef& t, const std::string& fmt, int depth, std::set<std::string>& open,
                                   std::uint64_t at) {
  if (const BaseType* b = base_type(t.name)) return b->size;
  if (!formats_.count(t.name)) fail(at, "format " + quoted_from_log(fmt) + ": unknown type " + quoted_from_log(t.name));
  return format_size(t.name, depth + 1, open, at);
}

// Sizes are known (format_size) and at most 65535 bytes, so offsets fit and the loops end;
// each element visited is charged, padding too, so the work is bounded as well.
void Parser::flatten(const std::string& fmt, const std::string& prefix, std::uint64_t base, Layout& l,
                     std::uint64_t at) {
  for (const auto& f : formats_.at(fmt).fields) {
    const BaseType* b = base_type(f.type.name);
    const std::uint64_t each = b ? b->size : sizes_.at(f.type.name);
    for (std::uint64_t i = 0; !f.padding && i < f.type.count; ++i) {
      std::string name = prefix + f.name + (f.type.array ? "[" + std::to_string(i) + "]" : "");
      const std::uint64_t cost = kColumnCost + name.size();
      charge(cost, at);
      if (!b) {
        flatten(f.type.name, name + ".", base + i * each, l, at);
        continue;
      }
      l.cost += cost;
      l.leaves.push_back({static_cast<std::uint32_t>(base + i * each), b->base});
      l.names.push_back(std::move(name));
    }
    base += each * f.type.count;
  }
}

void Parser::timestamp_first(Layout& l, const std::string& fmt, std::uint64_t at) const {
  const auto it = std::find(l.names.begin(), l.names.end(), "timestamp");
  const auto i = it - l.names.begin();
  if (it == l.names.end() || l.leaves[i].type != Base::u64)
    fail(at, "format " + quoted_from_log(fmt) + " has no field 'uint64_t timestamp' (every subscribed format needs one)");
  std::rotate(l.names.begin(), it, it + 1);
  std::rotate(l.leaves.begin(), l.leaves.begin() + i, l.leaves.begin() + i + 1);
}

}  // namespace

Ulog parse_ulog(const std::string& bytes, const std::string& name) { return Parser(bytes, name).run(); }

Ulog read_ulog(const std::string& path) {
  const LogFile file(path, "a ULog file");
  return parse_ulog(file.read_all(), path);
}

}  // namespace quadgen::runtime
