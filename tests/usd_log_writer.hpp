// Writes Crazyflie uSD logs for tests, from the layout in runtime/usd_log.hpp, byte by byte.
// The checksum is this file's own bitwise CRC-32 (not the reader's), so that a reader and a
// writer sharing one mistake cannot agree; the golden example in test_usd_log.cpp checks it
// against bytes made with zlib.
#pragma once
#include <cstdint>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

namespace quadgen::test {

class UsdWriter {
 public:
  explicit UsdWriter(int version = 2) : version_(version) {}

  // An event type: its id, name and variables as ("group.name", type code).
  void event(unsigned id, const std::string& name, const std::vector<std::pair<std::string, char>>& vars) {
    header_ += u(id, 2) + name + '\0' + u(vars.size(), 2);
    for (const auto& [v, code] : vars) header_ += v + "(" + code + ")" + '\0';
    ++events_;
    codes_.push_back({id, ""});
    for (const auto& var : vars) codes_.back().second += var.second;
  }

  // A record: the event's values in its variables' order; `stamp` in the version's unit.
  void record(unsigned id, std::uint64_t stamp, const std::vector<double>& values) {
    std::string r = u(id, 2) + u(stamp, version_ == 2 ? 8 : 4);
    const std::string* codes = nullptr;
    for (const auto& c : codes_)
      if (c.first == id) codes = &c.second;
    for (std::size_t k = 0; codes && k < codes->size(); ++k) r += value((*codes)[k], values.at(k));
    records_ += r;
  }
  // Raw bytes after the records (a corrupt or foreign tail).
  void raw(const std::string& bytes) { records_ += bytes; }

  std::string header() const { return std::string(1, '\xBC') + u(version_, 2) + u(events_, 2) + header_; }
  // The file as a clean stop leaves it (with the CRC) or as a power cut does (without).
  std::string bytes(bool with_crc = true) const {
    const std::string b = header() + records_;
    return with_crc ? b + u(crc(b), 4) : b;
  }

  static std::string u(std::uint64_t v, int n) {
    std::string s;
    for (int i = 0; i < n; ++i) s += static_cast<char>((v >> (8 * i)) & 0xFF);
    return s;
  }

 private:
  static std::string value(char code, double v) {
    switch (code) {
      case 'B': case 'b': return u(static_cast<std::uint64_t>(static_cast<std::int64_t>(v)), 1);
      case 'H': case 'h': return u(static_cast<std::uint64_t>(static_cast<std::int64_t>(v)), 2);
      case 'I': case 'i': return u(static_cast<std::uint64_t>(static_cast<std::int64_t>(v)), 4);
      default: {  // 'f'
        const float f = static_cast<float>(v);
        std::uint32_t bits;
        std::memcpy(&bits, &f, 4);
        return u(bits, 4);
      }
    }
  }
  static std::uint32_t crc(const std::string& b) {  // table-driven CRC-32, reflected 0xEDB88320
    std::uint32_t table[256];
    for (std::uint32_t n = 0; n < 256; ++n) {
      std::uint32_t c = n;
      for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      table[n] = c;
    }
    std::uint32_t c = 0xFFFFFFFFu;
    for (unsigned char ch : b) c = table[(c ^ ch) & 0xFF] ^ (c >> 8);
    return c ^ 0xFFFFFFFFu;
  }

  int version_;
  unsigned events_ = 0;
  std::string header_, records_;
  std::vector<std::pair<unsigned, std::string>> codes_;
};

}  // namespace quadgen::test
