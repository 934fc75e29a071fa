// The ULog reader (runtime/ulog.hpp) against logs written here from the specification
// (docs.px4.io, "ULog File Format"): every value read back; every cut and every corrupted
// byte of the fixture ends in a parse or a LogError; size fields that would demand
// gigabytes, recursive and too deep formats are refused with file, byte offset and cause.
#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "fit/log_reader.hpp"  // ulog_notes
#include "runtime/ulog.hpp"
#include "tests/ulog_writer.hpp"

using namespace quadgen::runtime;
using namespace quadgen::test;

namespace {

// A format with a nested type (itself with padding), an array, every kind of number and a
// trailing padding field that data messages may leave out.
const char* const kProbe =
    "probe:uint64_t timestamp;float[4] q;wheel[2] wheels;double alt;int32_t count;bool armed;uint8_t[3] _padding0;";
const char* const kWheel = "wheel:int16_t speed;uint8_t flags;uint8_t _padding0;";
const std::vector<std::string> kProbeFields{
    "timestamp",       "q[0]", "q[1]",  "q[2]", "q[3]", "wheels[0].speed", "wheels[0].flags", "wheels[1].speed",
    "wheels[1].flags", "alt",  "count", "armed"};

struct Probe {
  std::uint64_t t;
  std::array<float, 4> q;
  std::array<std::int16_t, 2> speed;
  std::array<std::uint8_t, 2> flags;
  double alt;
  std::int32_t count;
  bool armed;
};

const float kNaN = std::numeric_limits<float>::quiet_NaN();
const Probe p0{1000, {1, 0.5f, -0.25f, 0.125f}, {-1234, 32767}, {255, 0}, 123.456789, -7, true};
const Probe p1{2000, {kNaN, 2, 3e-8f, -4e30f}, {-32768, 1}, {1, 2}, -1e300, 2147483647, false};
const Probe p2{3000, {0, -0.0f, 1e-3f, 7}, {0, -1}, {17, 128}, 0.1, -2147483647 - 1, true};
const Probe p3{1500, {9, 8, 7, 6}, {5, 4}, {3, 2}, 1.0, 0, false};

std::string probe_bytes(const Probe& p, bool trailing_padding) {
  std::string s = le(p.t, 8);
  for (float v : p.q) s += f32(v);
  for (int w = 0; w < 2; ++w)  // the nested padding byte is junk the reader must skip
    s += le(static_cast<std::uint16_t>(p.speed[w]), 2) + static_cast<char>(p.flags[w]) + "\xAA";
  s += f64(p.alt) + le(static_cast<std::uint32_t>(p.count), 4) + static_cast<char>(p.armed);
  return trailing_padding ? s + "\xEE\xEE\xEE" : s;
}

std::vector<double> probe_row(const Probe& p) {
  return {static_cast<double>(p.t),
          p.q[0],
          p.q[1],
          p.q[2],
          p.q[3],
          static_cast<double>(p.speed[0]),
          static_cast<double>(p.flags[0]),
          static_cast<double>(p.speed[1]),
          static_cast<double>(p.flags[1]),
          p.alt,
          static_cast<double>(p.count),
          p.armed ? 1.0 : 0.0};
}

const std::string kSyncMagic("\x2F\x73\x13\x20\x25\x0C\xBB\x12", 8);

Writer fixture() {
  Writer w;
  w.flag_bits()
      .format(kProbe)  // used before its nested type is defined: the spec allows it
      .format(kWheel)
      .format("late:float v;uint64_t timestamp;")  // timestamp not first
      .format("unused:no_such_type x;")            // never subscribed, so never resolved
      .key_value('I', "char[3] sys_name", "PX4")
      .key_value('I', "uint32_t ver_sw_release", le(0x010402FF, 4))
      .key_value('I', "int32_t time_ref_utc", le(static_cast<std::uint32_t>(-3600), 4))
      .msg('M', std::string(1, '\0') + static_cast<char>(12) + "char[3] perf" + "abc")
      .key_value('P', "float MC_ROLL_P", f32(6.5f))
      .key_value('P', "int32_t SYS_AUTOSTART", le(4001, 4))
      .msg('Q', std::string(1, '\1') + static_cast<char>(15) + "float MC_ROLL_P" + f32(6.0f))
      .msg('Z', "\x01\x02\x03\x04\x05")  // a type of some later version: skipped by its size
      .add(0, 0, "probe")
      .add(1, 1, "probe")
      .add(0, 2, "late")
      .data(0, probe_bytes(p0, true))
      .data(1, probe_bytes(p3, true))
      .msg('L', "6" + le(1100, 8) + "hello")
      .data(0, probe_bytes(p1, false))
      .msg('S', kSyncMagic)
      .msg('O', le(25, 2))
      .data(2, f32(-2.5f) + le(1800, 8))
      .key_value('P', "float MC_ROLL_P", f32(7.0f))  // changed while logging
      .msg('Y', "")
      .msg('R', le(1, 2))
      .data(0, probe_bytes(p2, true));
  return w;
}

bool same(double a, double b) { return a == b ? std::signbit(a) == std::signbit(b) : std::isnan(a) && std::isnan(b); }

void expect_rows(const LogTopic& t, const std::vector<std::vector<double>>& rows) {
  ASSERT_EQ(t.rows.size(), rows.size()) << t.name;
  for (std::size_t r = 0; r < rows.size(); ++r) {
    ASSERT_EQ(t.rows[r].size(), rows[r].size()) << t.name << " row " << r;
    for (std::size_t c = 0; c < rows[r].size(); ++c)
      EXPECT_TRUE(same(t.rows[r][c], rows[r][c]))
          << t.name << " row " << r << " " << t.fields[c] << ": " << t.rows[r][c] << " != " << rows[r][c];
  }
}

// What a LogError says, or "" if the bytes parse.
std::string error_of(const std::string& bytes, const std::string& name = "x.ulg") {
  try {
    parse_ulog(bytes, name);
  } catch (const LogError& e) {
    return e.what();
  }
  return "";
}

void expect_error(const std::string& bytes, const std::string& part) {
  const std::string what = error_of(bytes);
  EXPECT_NE(what.find(part), std::string::npos) << "expected '" << part << "' in: " << what;
  EXPECT_EQ(what.rfind("x.ulg: byte ", 0), 0u) << what;
}

// Definitions and one subscription of probe as msg_id 0.
Writer probe_log() {
  Writer w;
  w.flag_bits().format(kProbe).format(kWheel).add(0, 0, "probe");
  return w;
}

}  // namespace

TEST(Ulog, ReadsEveryValueOfTheFixture) {
  const Ulog log = parse_ulog(fixture().bytes(), "fixture.ulg");
  EXPECT_EQ(log.path, "fixture.ulg");
  EXPECT_EQ(log.version, 1);
  EXPECT_EQ(log.start_time, 123456789u);
  EXPECT_FALSE(log.truncated);
  ASSERT_EQ(log.topics.size(), 3u);

  const LogTopic& a = log.topics[0];
  EXPECT_EQ(a.name, "probe");
  EXPECT_EQ(a.multi_id, 0);
  EXPECT_EQ(a.fields, kProbeFields);
  expect_rows(a, {probe_row(p0), probe_row(p1), probe_row(p2)});

  const LogTopic& b = log.topics[1];
  EXPECT_EQ(b.name, "probe");
  EXPECT_EQ(b.multi_id, 1);
  EXPECT_EQ(b.fields, kProbeFields);
  expect_rows(b, {probe_row(p3)});

  const LogTopic& c = log.topics[2];
  EXPECT_EQ(c.name, "late");
  EXPECT_EQ(c.fields, (std::vector<std::string>{"timestamp", "v"}));
  expect_rows(c, {{1800, -2.5}});

  EXPECT_EQ(log.parameters, (std::map<std::string, double>{{"MC_ROLL_P", 6.5}, {"SYS_AUTOSTART", 4001}}));
  ASSERT_EQ(log.parameter_changes.size(), 1u);
  EXPECT_EQ(log.parameter_changes[0].name, "MC_ROLL_P");
  EXPECT_EQ(log.parameter_changes[0].value, 7.0);
  EXPECT_EQ(log.parameter_changes[0].timestamp, 2000.0);  // latest data before it
  EXPECT_EQ(log.info, (std::vector<std::string>{"sys_name=PX4", "ver_sw_release=" + std::to_string(0x010402FF),
                                                "time_ref_utc=-3600"}));
  EXPECT_EQ(log.dropouts, 1);
  EXPECT_EQ(log.dropout_ms, 25.0);
}

TEST(Ulog, TopicsAreFoundByNameAndInstance) {
  const Ulog log = parse_ulog(fixture().bytes(), "fixture.ulg");
  ASSERT_NE(log.find("probe", 1), nullptr);
  EXPECT_EQ(log.find("probe", 1)->rows.size(), 1u);
  EXPECT_EQ(log.find("probe", 2), nullptr);
  EXPECT_EQ(log.find("unused"), nullptr);
  EXPECT_EQ(log.find("probe")->column("alt"), 9);
  EXPECT_EQ(log.find("probe")->column("_padding0"), -1);
}

TEST(Ulog, FutureVersionsAndFilesWithoutFlagBitsAreRead) {
  Writer w('\x07');  // version 1 files have no 'B' message; later versions must be read too
  w.format("t:uint64_t timestamp;uint16_t v;").add(0, 0, "t").data(0, le(5, 8) + le(65535, 2));
  const Ulog log = parse_ulog(w.bytes(), "v7.ulg");
  EXPECT_EQ(log.version, 7);
  ASSERT_EQ(log.topics.size(), 1u);
  expect_rows(log.topics[0], {{5, 65535}});
}

// Logging stops mid-message on power loss: the cut message is dropped, the rest kept.
TEST(Ulog, EveryCutParsesAPrefixOrThrowsLogError) {
  Writer w = fixture();
  const std::string& all = w.bytes();
  const Ulog full = parse_ulog(all, "full.ulg");
  for (std::size_t n = 0; n <= all.size(); ++n) {
    SCOPED_TRACE("cut at " + std::to_string(n));
    if (n < 16) {
      EXPECT_NE(error_of(all.substr(0, n)), "");
      continue;
    }
    const Ulog cut = parse_ulog(all.substr(0, n), "cut.ulg");
    const bool on_boundary = n == 16 || w.ends().count(n);
    EXPECT_EQ(cut.truncated, !on_boundary);
    if (cut.truncated) {
      EXPECT_LT(cut.truncated_at, n);
    }
    ASSERT_LE(cut.topics.size(), full.topics.size());
    for (std::size_t t = 0; t < cut.topics.size(); ++t) {
      const auto& want = full.topics[t].rows;
      ASSERT_LE(cut.topics[t].rows.size(), want.size());
      expect_rows(cut.topics[t], std::vector<std::vector<double>>(
                                     want.begin(), want.begin() + static_cast<long>(cut.topics[t].rows.size())));
    }
  }
}

TEST(Ulog, EveryCorruptedByteParsesOrThrowsLogError) {
  const std::string all = fixture().bytes();
  for (std::size_t i = 0; i < all.size(); ++i)
    for (const int v : {0x00, 0xff, all[i] ^ 0x01, all[i] ^ 0x80}) {
      std::string bad = all;
      bad[i] = static_cast<char>(v);
      try {
        parse_ulog(bad, "bad.ulg");
      } catch (const LogError& e) {
        EXPECT_EQ(std::string(e.what()).rfind("bad.ulg: byte ", 0), 0u) << e.what();
      }
    }
  std::mt19937 rng(7);  // and random message streams after a valid header
  for (int k = 0; k < 3000; ++k) {
    std::string junk = all.substr(0, 16);
    for (int j = 0; j < 300; ++j) junk += static_cast<char>(rng() % 4 ? rng() % 16 : rng());
    try {
      parse_ulog(junk, "junk.ulg");
    } catch (const LogError&) {
    }
  }
}

TEST(Ulog, ErrorsNameFileOffsetAndCause) {
  Writer w = probe_log();
  const std::size_t at = w.bytes().size();
  w.data(7, probe_bytes(p0, true));
  EXPECT_EQ(error_of(w.bytes()), "x.ulg: byte " + std::to_string(at) + ": data message for unknown msg_id 7");

  Writer s = probe_log();
  const std::size_t short_at = s.bytes().size();
  s.data(0, std::string(10, '\0'));
  EXPECT_EQ(error_of(s.bytes()),
            "x.ulg: byte " + std::to_string(short_at) + ": data message for 'probe' has 10 bytes, expected 45..48");
}

TEST(Ulog, SizeFieldsClaimingGigabytesAreRefused) {
  expect_error(Writer().format("big:uint64_t timestamp;float[4000000000] x;").bytes(), "array length 4000000000");
  expect_error(Writer().format("big:uint64_t timestamp;float[99999999999999999999999999] x;").bytes(), "array length");
  expect_error(Writer().format("big:uint64_t timestamp;float[0] x;").bytes(), "array length 0");

  // 60000 x 60000 floats: each array is allowed, the product (14.4 GB) is not.
  expect_error(Writer()
                   .format("big:uint64_t timestamp;block[60000] b;")
                   .format("block:float[60000] v;")
                   .add(0, 0, "big")
                   .bytes(),
               "larger than 65535 bytes");

  Writer appended;
  appended.flag_bits(1, 1ULL << 40);
  expect_error(appended.bytes(), "appended_offsets[0] = 1099511627776");

  // Each subscription is small; together their 65026 columns each would need gigabytes.
  Writer many;
  many.format("row:uint8_t[255] v;").format("big:uint64_t timestamp;row[255] r;");
  for (int k = 0; k < 256; ++k) many.add(k, k, "big");
  expect_error(many.bytes(), "MiB (corrupt or hostile log)");
}

TEST(Ulog, RecursiveAndDeepFormatsAreRefused) {
  expect_error(Writer().format("a:uint64_t timestamp;a inner;").add(0, 0, "a").bytes(), "contains itself");
  expect_error(Writer().format("a:uint64_t timestamp;b x;").format("b:uint8_t y;a back;").add(0, 0, "a").bytes(),
               "format 'a' contains itself");
  Writer deep;
  deep.format("n0:uint64_t timestamp;n1 x;");
  for (int i = 1; i < 20; ++i) deep.format("n" + std::to_string(i) + ":n" + std::to_string(i + 1) + " x;");
  deep.format("n20:uint8_t v;").add(0, 0, "n0");
  expect_error(deep.bytes(), "nested deeper than 16 levels");
}

TEST(Ulog, MalformedLogsAreRefused) {
  expect_error(std::string("ULog\x01\x12\x36", 7) + std::string(9, '\0'), "not a ULog file");
  expect_error("PK\x03\x04", "not a ULog file");
  expect_error(std::string("ULog\x01\x12\x35\x01", 8), "ends inside the 16-byte ULog header");
  expect_error(Writer().flag_bits(2).bytes(), "unknown incompatible flag bits");
  expect_error(Writer().format(kWheel).flag_bits().bytes(), "flag bits message ('B')");
  expect_error(Writer().format("t:uint32_t time;").add(0, 0, "t").bytes(), "no field 'uint64_t timestamp'");
  expect_error(Writer().format("t:uint32_t timestamp;").add(0, 0, "t").bytes(), "no field 'uint64_t timestamp'");
  expect_error(Writer().add(0, 0, "nope").bytes(), "undefined format 'nope'");
  expect_error(Writer().format("t:uint64_t timestamp;").add(0, 0, "t").add(1, 0, "t").bytes(),
               "msg_id 0 subscribed twice");
  expect_error(Writer().format("t:uint64_t timestamp;x y;").add(0, 0, "t").bytes(), "unknown type 'x'");
  expect_error(Writer().format("t:uint64_t;").bytes(), "is not \"type name\"");
  expect_error(Writer().format("t uint64_t timestamp;").bytes(), "has no ':'");
  expect_error(Writer().format("float:uint8_t v;").bytes(), "not a valid message name");
  expect_error(Writer().format("t:uint8_t v;uint8_t v;").bytes(), "field 'v' twice");
  expect_error(Writer().format("t:").bytes(), "has no fields");
  expect_error(Writer().format("t:uint8_t a b;").bytes(), "is not \"type name\"");
  expect_error(Writer().format("t:uint8_t v;").format("t:uint16_t v;").bytes(), "defined again");
  expect_error(Writer().key_value('P', "char[4] NAME", "abcd").bytes(), "parameter 'NAME'");
  expect_error(Writer().key_value('P', "float NAME", "ab").bytes(), "parameter 'NAME'");
  expect_error(Writer().key_value('I', "sys_name", "PX4").bytes(), "is not \"type name\"");
  expect_error(Writer().key_value('I', "uint32_t v", "PX4").bytes(), "value of 3 bytes, expected 4");
  expect_error(Writer()
                   .msg('I',
                        "\x09"
                        "abc")
                   .bytes(),
               "expected at least 10 (the key)");
  expect_error(Writer().msg('A', std::string("\x00\x01", 2)).bytes(), "expected at least 4");
  expect_error(Writer().msg('D', std::string(1, '\0')).bytes(), "expected at least 2 (msg_id)");
  expect_error(Writer().msg('B', std::string(39, '\0')).bytes(), "expected at least 40");
  // Padding may be left out only at the end of a message.
  Writer longer = probe_log();
  longer.data(0, probe_bytes(p0, true) + "x");
  expect_error(longer.bytes(), "has 49 bytes, expected 45..48");
}

// Data appended after a log that stopped mid-message (e.g. a crash dump): the cut message is
// dropped and the appended messages read as part of the Data section.
TEST(Ulog, AppendedDataIsReadAfterACutOffMessage) {
  Writer w;
  w.flag_bits(1).format(kProbe).format(kWheel).add(0, 0, "probe").data(0, probe_bytes(p0, true));
  const std::size_t cut_at = w.bytes().size();
  w.raw(le(50, 2) + "D" + le(0, 2) + "abc");  // the cut-off message
  const std::size_t appended = w.bytes().size();
  w.bytes().replace(16 + 3 + 16, 8, le(appended, 8));
  w.data(0, probe_bytes(p1, false));
  const Ulog log = parse_ulog(w.bytes(), "appended.ulg");
  ASSERT_EQ(log.topics.size(), 1u);
  expect_rows(log.topics[0], {probe_row(p0), probe_row(p1)});
  EXPECT_TRUE(log.truncated);
  EXPECT_EQ(log.truncated_at, cut_at);
}

TEST(Ulog, ReadUlogReadsRegularFilesOnly) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("quadgen_ulog_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string path = (dir / "fixture.ulg").string();
  const std::string bytes = fixture().bytes();
  std::ofstream(path, std::ios::binary) << bytes;
  const Ulog log = read_ulog(path);
  EXPECT_EQ(log.path, path);
  ASSERT_EQ(log.topics.size(), 3u);
  expect_rows(log.topics[0], {probe_row(p0), probe_row(p1), probe_row(p2)});

  auto error = [](const std::string& p) {
    try {
      read_ulog(p);
    } catch (const LogError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(error(dir.string()), dir.string() + ": a directory, not a regular file (expected a ULog file)");
  EXPECT_EQ(error((dir / "missing.ulg").string()).rfind((dir / "missing.ulg").string() + ": cannot open a ULog file", 0), 0u);
  std::ofstream((dir / "cut.ulg").string(), std::ios::binary) << bytes.substr(0, bytes.size() - 5);
  EXPECT_TRUE(read_ulog((dir / "cut.ulg").string()).truncated);
  fs::remove_all(dir);
}

// A corrupt message in the Data section is skipped to the next sync message, as the spec
// intends them for (real PX4 logs have such stretches: PX4/pyulog#31, #51): the rows before
// and after it are kept, what lay between is lost, and the skip is said with its bytes and
// cause. Three corruptions: a data message for no subscription, a size running past the end,
// a type the spec does not name. Without a sync message after it the log is refused, as
// before (ErrorsNameFileOffsetAndCause); a later type with none after it is skipped by its
// size (the fixture's 'Y').
TEST(Ulog, ACorruptMessageIsSkippedToTheNextSyncMessage) {
  const auto corrupt_then_sync = [](const std::string& corruption, std::size_t* from, std::size_t* to) {
    Writer w = probe_log();
    w.data(0, probe_bytes(p0, true));
    *from = w.bytes().size();
    w.bytes() += corruption;
    w.data(0, probe_bytes(p1, true));  // after the corruption, before the sync: lost
    *to = w.bytes().size();
    w.msg('S', kSyncMagic).data(0, probe_bytes(p2, true));
    return w.bytes();
  };
  const std::string unknown_id = le(2 + 45, 2) + "D" + le(7, 2) + probe_bytes(p1, false);
  const std::string huge = le(65535, 2) + "D" + le(0, 2);
  const std::string unnamed = le(1, 2) + "Z" + "abc";  // its size ends it inside its own bytes: no message follows
  const std::string causes[3] = {"data message for unknown msg_id 7", "a message whose size runs past the end",
                                 "unknown message type 90"};
  const std::string corruptions[3] = {unknown_id, huge, unnamed};
  for (int k = 0; k < 3; ++k) {
    SCOPED_TRACE(causes[k]);
    std::size_t from = 0, to = 0;
    const Ulog log = parse_ulog(corrupt_then_sync(corruptions[k], &from, &to), "c.ulg");
    ASSERT_EQ(log.topics.size(), 1u);
    expect_rows(log.topics[0], {probe_row(p0), probe_row(p2)});
    ASSERT_EQ(log.skipped.size(), 1u);
    EXPECT_EQ(log.skipped[0].from, from);
    EXPECT_EQ(log.skipped[0].to, to);
    EXPECT_EQ(log.skipped[0].cause, "byte " + std::to_string(from) + ": " + causes[k]);
    EXPECT_FALSE(log.truncated);
    const auto notes = quadgen::fit::ulog_notes(log);
    ASSERT_EQ(notes.size(), 1u);
    EXPECT_EQ(notes[0], "c.ulg: reading found the log corrupt at byte " + std::to_string(from) + " (byte " + std::to_string(from) +
                            ": " + causes[k] + "): reading resumed at its next sync message, byte " + std::to_string(to) +
                            " (" + std::to_string(to - from) +
                            " bytes skipped: what they held is lost, a gap in the signals where it lasts longer than "
                            "their gap threshold)");
  }
  // A type the spec does not name, followed by a sensible message, is a later version's:
  // skipped by its size, nothing lost.
  std::size_t from = 0, to = 0;
  const Ulog later = parse_ulog(corrupt_then_sync(le(3, 2) + "Z" + "abc", &from, &to), "l.ulg");
  expect_rows(later.topics[0], {probe_row(p0), probe_row(p1), probe_row(p2)});
  EXPECT_TRUE(later.skipped.empty());
  // After a skip, data of a subscription lost in it is skipped and counted, not a new skip:
  // here msg_id 1's 'A' lay in the skipped stretch.
  Writer lost = probe_log();
  lost.data(0, probe_bytes(p0, true)).data(9, "garbage").add(0, 1, "late");
  lost.msg('S', kSyncMagic).data(1, f32(1.0f) + le(5000, 8)).data(1, f32(2.0f) + le(6000, 8)).data(0, probe_bytes(p2, true));
  const Ulog orphan = parse_ulog(lost.bytes(), "o.ulg");
  EXPECT_EQ(orphan.skipped.size(), 1u);
  EXPECT_EQ(orphan.data_without_subscription, 2);
  expect_rows(orphan.topics[0], {probe_row(p0), probe_row(p2)});
  EXPECT_NE(quadgen::fit::ulog_notes(orphan).front().find("; 2 data messages after it of subscriptions lost with it skipped too)"),
            std::string::npos)
      << quadgen::fit::ulog_notes(orphan).front();
  // The Definitions section has no such recovery: a broken format is refused though a sync follows.
  Writer d;
  d.flag_bits().format("t uint64_t timestamp").format("u:uint64_t timestamp;").add(0, 0, "u").msg('S', kSyncMagic);
  EXPECT_NE(error_of(d.bytes()).find("has no ':'"), std::string::npos) << error_of(d.bytes());
}

// A subscription refused (here: the subscribed topics' columns past their budget) leaves
// nothing behind. Before reading resumed at sync messages a refusal ended the log; after, the
// same topic subscribed again found a half-made entry and was written through it, out of
// bounds (a review, helper-155). Every subscription is made again after a sync message, and
// each one's data follow: those refused again are skipped, none is written out of place.
TEST(Ulog, ARefusedSubscriptionLeavesNothingForAResumedReading) {
  Writer w;
  w.flag_bits().format("big:uint64_t timestamp;float[16000] v;");
  for (int k = 0; k < 200; ++k) w.add(k, k, "big");  // more than the budget holds
  const std::string row = le(1000, 8) + std::string(4 * 16000, '\0');
  for (int k = 0; k < 200; ++k) w.msg('S', kSyncMagic).add(k, 200 + k, "big").data(200 + k, row);
  w.msg('S', kSyncMagic);  // the last refusal resumes here too
  const Ulog log = parse_ulog(w.bytes(), "b.ulg");
  ASSERT_GT(log.topics.size(), 10u);
  ASSERT_LT(log.topics.size(), 200u);
  EXPECT_GE(log.skipped.size(), 200u - log.topics.size());
  for (const auto& t : log.topics) {
    ASSERT_LE(t.rows.size(), 1u) << t.multi_id;
    for (const auto& r : t.rows) EXPECT_EQ(r.size(), t.fields.size()) << t.multi_id;
  }
}
