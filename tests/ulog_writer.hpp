// A ULog writer for tests, message by message as the published specification lays them
// out: fixtures for the reader (test_ulog.cpp) and for logs read through a mapping
// (test_log_reader.cpp).
#pragma once
#include <cstdint>
#include <cstring>
#include <set>
#include <string>

namespace quadgen::test {

inline std::string le(std::uint64_t v, int n) {
  std::string s;
  for (int i = 0; i < n; ++i, v >>= 8) s += static_cast<char>(v & 0xff);
  return s;
}

inline std::string f32(float f) {
  std::uint32_t u;
  std::memcpy(&u, &f, sizeof u);
  return le(u, 4);
}

inline std::string f64(double d) {
  std::uint64_t u;
  std::memcpy(&u, &d, sizeof u);
  return le(u, 8);
}

// A ULog writer, message by message as the spec lays them out. ends() are the offsets where
// a message ends: a file cut there holds no partial message.
class Writer {
 public:
  explicit Writer(char version = 1) { bytes_ = std::string("ULog\x01\x12\x35", 7) + version + le(123456789, 8); }
  Writer& raw(const std::string& s) {
    bytes_ += s;
    return *this;
  }
  Writer& msg(char type, const std::string& body) {
    bytes_ += le(body.size(), 2) + type + body;
    ends_.insert(bytes_.size());
    return *this;
  }
  Writer& flag_bits(int incompat0 = 0, std::uint64_t appended0 = 0) {
    return msg('B', std::string(8, '\0') + static_cast<char>(incompat0) + std::string(7, '\0') + le(appended0, 8) +
                        std::string(16, '\0'));
  }
  Writer& format(const std::string& f) { return msg('F', f); }
  Writer& key_value(char type, const std::string& key, const std::string& value) {
    return msg(type, static_cast<char>(key.size()) + key + value);
  }
  Writer& add(int multi_id, int msg_id, const std::string& name) {
    return msg('A', static_cast<char>(multi_id) + le(msg_id, 2) + name);
  }
  Writer& data(int msg_id, const std::string& payload) { return msg('D', le(msg_id, 2) + payload); }
  std::string& bytes() { return bytes_; }
  const std::set<std::size_t>& ends() const { return ends_; }

 private:
  std::string bytes_;
  std::set<std::size_t> ends_;
};

}  // namespace quadgen::test
