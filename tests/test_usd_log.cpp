// Crazyflie uSD card logs (runtime/usd_log.hpp): a golden file made outside this project, the
// versions, fp16 payloads, power cuts, hostile headers, and a real flight (the ARPL Crazyflie
// log, published as the CSV Bitcraze's decoder makes of such a file) carried through the
// binary format and read back through a mapping.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "fit/least_squares.hpp"  // FitError
#include "fit/log_reader.hpp"
#include "runtime/usd_log.hpp"
#include "tests/usd_log_writer.hpp"
#include "tests/shared_data.hpp"

using namespace quadgen;
using namespace quadgen::runtime;
using quadgen::test::UsdWriter;
namespace fs = std::filesystem;

namespace {

std::string from_hex(const std::string& hex) {
  std::string out;
  for (std::size_t i = 0; i + 1 < hex.size(); i += 2) out += static_cast<char>(std::stoi(hex.substr(i, 2), nullptr, 16));
  return out;
}

// 117 bytes written from the published layout by a separate script (Python, zlib.crc32), not
// by this project's writer: fixed-frequency acc.x (f) and pm.state (b), and an event "myEvent"
// (id 5) with a payload var1 (B) and stabilizer.yaw (f); one record each; the CRC at the end.
const std::string kGolden = from_hex(
    "bc02000200ffff66697865644672657175656e63790002006163632e78286629"
    "00706d2e73746174652862290005006d794576656e7400020076617231284229"
    "0073746162696c697a65722e79617728662900ffff40420f0000000000000080"
    "3f0305003a430f0000000000070000b5c27ab8f17e");

std::string write_file(const std::string& name, const std::string& bytes) {
  const fs::path p = fs::temp_directory_path() / name;
  std::ofstream(p, std::ios::binary) << bytes;
  return p.string();
}

// Two event types and n records of the fixed-frequency one, 10 ms apart.
UsdWriter two_event_log(int n) {
  UsdWriter w;
  w.event(kUsdFixedFrequencyId, "fixedFrequency", {{"gyro.x", 'f'}, {"motor.m1", 'H'}, {"pm.state", 'b'}});
  w.event(3, "takeoff", {{"height", 'f'}});
  for (int k = 0; k < n; ++k) w.record(kUsdFixedFrequencyId, 1000000 + 10000 * k, {0.5 * k, 1000.0 * k, -1.0});
  w.record(3, 1000000 + 5000, {0.25});
  return w;
}

}  // namespace

TEST(UsdLog, ChecksumIsZlibsCrc32) {
  EXPECT_EQ(crc32("123456789", 9), 0xCBF43926u);  // the CRC-32 check value
  EXPECT_EQ(crc32(kGolden, kGolden.size() - 4), 0x7EF1B87Au);
}

TEST(UsdLog, ReadsTheGoldenFile) {
  ASSERT_EQ(kGolden.size(), 117u);
  const UsdLog log = parse_usd_log(kGolden, "golden.bin");
  EXPECT_EQ(log.version, 2);
  EXPECT_TRUE(log.crc_valid);
  EXPECT_FALSE(log.truncated);
  ASSERT_EQ(log.topics.size(), 2u);
  const LogTopic* ff = log.find("fixedFrequency");
  ASSERT_NE(ff, nullptr);
  EXPECT_EQ(ff->fields, (std::vector<std::string>{"timestamp", "acc.x", "pm.state"}));
  ASSERT_EQ(ff->rows.size(), 1u);
  EXPECT_EQ(ff->rows[0], (std::vector<double>{1000000, 1.0, 3}));
  const LogTopic* ev = log.find("myEvent");
  ASSERT_NE(ev, nullptr);
  EXPECT_EQ(ev->fields, (std::vector<std::string>{"timestamp", "var1", "stabilizer.yaw"}));
  ASSERT_EQ(ev->rows.size(), 1u);
  EXPECT_EQ(ev->rows[0], (std::vector<double>{1000250, 7, -90.5}));
}

TEST(UsdLog, WriterAgreesWithTheGoldenFile) {  // the test writer, checked before it is trusted
  UsdWriter w;
  w.event(kUsdFixedFrequencyId, "fixedFrequency", {{"acc.x", 'f'}, {"pm.state", 'b'}});
  w.event(5, "myEvent", {{"var1", 'B'}, {"stabilizer.yaw", 'f'}});
  w.record(kUsdFixedFrequencyId, 1000000, {1.0, 3});
  w.record(5, 1000250, {7, -90.5});
  EXPECT_EQ(w.bytes(), kGolden);
}

TEST(UsdLog, VersionOneCountsMilliseconds) {
  UsdWriter w(1);
  w.event(kUsdFixedFrequencyId, "fixedFrequency", {{"acc.z", 'f'}, {"pm.vbat", 'f'}, {"stateEstimate.z", 'i'}});
  w.record(kUsdFixedFrequencyId, 4000000000u, {1.5, 3.7, -12});
  w.record(kUsdFixedFrequencyId, 4000000001u, {1.25, 3.6, 40000});
  const UsdLog log = parse_usd_log(w.bytes(), "v1.bin");
  EXPECT_EQ(log.version, 1);
  ASSERT_EQ(log.topics[0].rows.size(), 2u);
  EXPECT_EQ(log.topics[0].rows[0], (std::vector<double>{4e12, 1.5, 3.700000047683716, -12}));
  EXPECT_EQ(log.topics[0].rows[1][0], 4000000001e3);
  EXPECT_EQ(log.topics[0].rows[1][3], 40000);
}

TEST(UsdLog, IntegerAndHalfPrecisionValues) {
  UsdWriter w;
  w.event(7, "ev", {{"a", 'B'}, {"b", 'b'}, {"c", 'H'}, {"d", 'h'}, {"e", 'I'}, {"f", 'i'}, {"g", 'e'}, {"h", 'e'},
                    {"i", 'e'}, {"j", 'e'}});
  // IEEE half precision, by hand: 0x3C00 = 1, 0xC000 = -2, 0x7BFF = 65504 (the largest),
  // 0x0001 = 2^-24 (the smallest subnormal).
  w.raw(UsdWriter::u(7, 2) + UsdWriter::u(42, 8) + UsdWriter::u(255, 1) + UsdWriter::u(0x80, 1) +
        UsdWriter::u(65535, 2) + UsdWriter::u(0x8000, 2) + UsdWriter::u(0xFFFFFFFFu, 4) + UsdWriter::u(0x80000000u, 4) +
        UsdWriter::u(0x3C00, 2) + UsdWriter::u(0xC000, 2) + UsdWriter::u(0x7BFF, 2) + UsdWriter::u(0x0001, 2));
  const UsdLog log = parse_usd_log(w.bytes(), "types.bin");
  ASSERT_EQ(log.topics[0].rows.size(), 1u);
  EXPECT_EQ(log.topics[0].rows[0], (std::vector<double>{42, 255, -128, 65535, -32768, 4294967295.0, -2147483648.0, 1,
                                                        -2, 65504, std::ldexp(1.0, -24)}));
}

TEST(UsdLog, APowerCutKeepsEveryWholeRecord) {
  const UsdWriter w = two_event_log(20);
  const std::string full = w.bytes(false);  // no CRC: logging did not stop cleanly
  const UsdLog all = parse_usd_log(full, "cut.bin");
  EXPECT_FALSE(all.crc_valid);
  EXPECT_FALSE(all.truncated);
  EXPECT_EQ(all.topics[0].rows.size(), 20u);
  EXPECT_EQ(all.topics[1].rows.size(), 1u);
  // Cut inside the last record (the takeoff event, 14 bytes): everything before it is kept.
  for (std::size_t cut = 1; cut < 14; ++cut) {
    const UsdLog log = parse_usd_log(full.substr(0, full.size() - cut), "cut.bin");
    EXPECT_TRUE(log.truncated);
    EXPECT_EQ(log.truncated_at, full.size() - 14);
    EXPECT_EQ(log.topics[0].rows.size(), 20u);
    EXPECT_TRUE(log.topics[1].rows.empty());
  }
  const UsdLog clean = parse_usd_log(w.bytes(true), "clean.bin");
  EXPECT_TRUE(clean.crc_valid);
  EXPECT_EQ(clean.topics[0].rows, all.topics[0].rows);
}

// A cut log that parses holds a prefix of the whole log's rows, value for value (a review of
// the tests, helper-126: only the count was checked).
TEST(UsdLog, EveryCutParsesAPrefixOrThrowsLogError) {
  const std::string full = two_event_log(5).bytes();
  const UsdLog whole = parse_usd_log(full, "whole.bin");
  ASSERT_EQ(whole.topics[0].rows.size(), 5u);
  for (std::size_t n = 0; n <= full.size(); ++n) {
    try {
      const UsdLog log = parse_usd_log(full.substr(0, n), "cut.bin");
      ASSERT_LE(log.topics.size(), whole.topics.size()) << n;
      for (std::size_t t = 0; t < log.topics.size(); ++t) {
        const auto& rows = log.topics[t].rows;
        ASSERT_LE(rows.size(), whole.topics[t].rows.size()) << n;
        for (std::size_t r = 0; r < rows.size(); ++r) EXPECT_EQ(rows[r], whole.topics[t].rows[r]) << "cut at " << n;
      }
    } catch (const LogError& e) {
      EXPECT_NE(std::string(e.what()).find("cut.bin: byte "), std::string::npos) << e.what();
    }
  }
}

// A byte changed anywhere: the log is refused with a LogError, or it parses, its checksum is
// found wrong (CRC-32 sees every change of one byte), and every record that lies wholly before
// the changed byte is read as it was (the rows a cut there keeps lead each topic's rows).
// A review of the tests (helper-126) found the first version checked only that nothing crashed.
TEST(UsdLog, EveryCorruptedByteParsesOrThrowsLogError) {
  const std::string full = two_event_log(5).bytes();
  int parsed = 0, refused = 0;
  for (std::size_t i = 0; i < full.size(); ++i)
    for (unsigned char v : {0x00, 0x01, 0x28, 0x7F, 0xBC, 0xFF}) {
      if (static_cast<unsigned char>(full[i]) == v) continue;
      std::string b = full;
      b[i] = static_cast<char>(v);
      UsdLog log;
      try {
        log = parse_usd_log(b, "bad.bin");
      } catch (const LogError& e) {
        EXPECT_NE(std::string(e.what()).find("bad.bin: byte "), std::string::npos) << e.what();
        ++refused;
        continue;
      }
      ++parsed;
      EXPECT_FALSE(log.crc_valid) << "byte " << i << " set to " << int(v);
      UsdLog kept;
      try {
        kept = parse_usd_log(full.substr(0, i), "cut.bin");
      } catch (const LogError&) {
        continue;  // changed inside the header: no record lies before it
      }
      ASSERT_LE(kept.topics.size(), log.topics.size()) << i;
      for (std::size_t t = 0; t < kept.topics.size(); ++t) {
        const auto& before = kept.topics[t].rows;
        const auto& rows = log.topics[t].rows;
        ASSERT_LE(before.size(), rows.size()) << "byte " << i << " set to " << int(v);
        for (std::size_t r = 0; r < before.size(); ++r) EXPECT_EQ(rows[r], before[r]) << "byte " << i;
      }
    }
  // Both outcomes occur (the loop is not vacuous either way).
  EXPECT_GT(parsed, 0);
  EXPECT_GT(refused, 0);
}

TEST(UsdLog, MalformedLogsAreRefusedWithByteAndCause) {
  const auto refused = [](const std::string& bytes, const std::string& cause) {
    try {
      parse_usd_log(bytes, "bad.bin");
      ADD_FAILURE() << "accepted; expected: " << cause;
    } catch (const LogError& e) {
      const std::string m = e.what();
      EXPECT_EQ(m.rfind("bad.bin: byte ", 0), 0u) << m;
      EXPECT_NE(m.find(cause), std::string::npos) << m;
      EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    }
  };
  const auto one_event = [](const std::vector<std::pair<std::string, char>>& vars, const std::string& name = "ev") {
    UsdWriter w;
    w.event(1, name, vars);
    return w.bytes();
  };
  refused("ULog\x01\x12\x35", "not a Crazyflie uSD log");
  refused(std::string("\xBC\x03\x00\x01\x00", 5), "file version 3");
  refused(std::string("\xBC\x02\x00\x00\x00", 5), "defines no event type");
  refused(one_event({{"acc.x", 'd'}}), "is not name(T)");
  refused(one_event({{"acc.x", 'f'}, {"acc.x", 'f'}}), "appears twice");
  refused(one_event({{"acc\nx", 'f'}}), "'acc?x' is no log name");
  refused(one_event({{"", 'f'}}), "is not name(T)");
  refused(one_event({}, "my event"), "event name 'my event' is no log name");
  {
    UsdWriter w;  // a variable count larger than the header
    std::string b = w.header();
    b[3] = 1;
    b += UsdWriter::u(1, 2) + std::string("ev") + '\0' + UsdWriter::u(60000, 2);
    refused(b, "60000 variables");
  }
  {
    UsdWriter w;  // a header that ends inside a name
    std::string b = w.header();
    b[3] = 1;
    refused(b + UsdWriter::u(1, 2) + "fixedFreq", "no terminating NUL");
  }
  {
    UsdWriter w;
    w.event(1, "a", {});
    w.event(1, "b", {});
    refused(w.bytes(), "defined twice");
  }
  {
    UsdWriter w;
    w.event(1, "a", {{"x", 'f'}});
    w.record(1, 10, {1.0});
    w.record(9, 20, {});
    refused(w.bytes(false) + std::string(20, '\0'), "record of event id 9, which the header does not define");
  }
  {
    UsdWriter w;  // a clean stop after half a record: the CRC says the file is whole
    w.event(1, "a", {{"x", 'f'}});
    w.record(1, 10, {1.0});
    w.raw(UsdWriter::u(1, 2) + UsdWriter::u(20, 8));
    refused(w.bytes(true), "cut off before the CRC");
  }
}

TEST(UsdLog, FilesAreRecognisedByTheirFirstBytes) {
  const std::string usd = write_file("quadgen_usd_detect.bin", kGolden);
  const std::string csv = write_file("quadgen_usd_detect.csv", "t,p\n0,1\n");
  EXPECT_TRUE(is_usd_log(usd));
  EXPECT_TRUE(fit::is_topic_log(usd));
  EXPECT_FALSE(fit::is_ulog(usd));
  EXPECT_FALSE(is_usd_log(csv));
  EXPECT_FALSE(is_usd_log("/nonexistent/quadgen.bin"));
  EXPECT_EQ(read_usd_log(usd).topics.size(), 2u);
  try {
    fit::read_log(usd, "", 0);
    ADD_FAILURE() << "a uSD log without a mapping was read";
  } catch (const fit::FitError& e) {
    EXPECT_NE(std::string(e.what()).find("Crazyflie uSD log needs --mapping"), std::string::npos) << e.what();
  }
}

// The ARPL log (../shared/data/crazyflie/arpl/log10.csv, MIT) is what Bitcraze's decoder
// prints of a uSD card log: fixed-frequency acc and gyro (float) and motor commands. Its first
// 3000 records written back into the binary format (v2, microseconds, motor.mN as uint16) and
// read through data/mappings/crazyflie_usd.yaml must give the flight that the CSV gives through
// data/mappings/arpl.yaml, to float precision.
TEST(UsdLog, ARealFlightReadsAsItsDecodedCsvDoes) {
  const fs::path source = quadgen::test::shared_data("crazyflie/arpl/log10.csv");
  QUADGEN_NEEDS_SHARED_DATA(source);
  std::ifstream in(source);
  std::string line, csv;
  std::getline(in, line);
  ASSERT_EQ(line, "timestamp_ms,acc.x,acc.y,acc.z,gyro.x,gyro.y,gyro.z,motor.m1,motor.m2,motor.m3,motor.m4");
  csv = line + "\n";
  UsdWriter w;
  w.event(kUsdFixedFrequencyId, "fixedFrequency",
          {{"acc.x", 'f'}, {"acc.y", 'f'}, {"acc.z", 'f'}, {"gyro.x", 'f'}, {"gyro.y", 'f'}, {"gyro.z", 'f'},
           {"motor.m1", 'H'}, {"motor.m2", 'H'}, {"motor.m3", 'H'}, {"motor.m4", 'H'}});
  for (int k = 0; k < 3000 && std::getline(in, line); ++k) {
    csv += line + "\n";
    std::stringstream row(line);
    std::string cell;
    std::vector<double> v;
    while (std::getline(row, cell, ',')) v.push_back(std::stod(cell));
    ASSERT_EQ(v.size(), 11u);
    w.record(kUsdFixedFrequencyId, static_cast<std::uint64_t>(std::llround(v[0] * 1000)),
             std::vector<double>(v.begin() + 1, v.end()));
  }
  const std::string bin = write_file("quadgen_arpl_head.bin", w.bytes());
  const std::string text = write_file("quadgen_arpl_head.csv", csv);
  const std::string mappings = std::string(QUADGEN_SOURCE_DIR) + "/data/mappings/";
  const CsvTable a = fit::read_log(text, mappings + "arpl.yaml", 500.0);
  const CsvTable b = fit::read_log(bin, mappings + "crazyflie_usd.yaml", 500.0);
  ASSERT_GT(b.rows.size(), 1000u);
  // The CSV's clock starts at its first sample, the binary's at 0 at the same instant.
  std::size_t compared = 0;
  for (const char* c : {"p", "q", "r", "ax", "ay", "az", "u_M1", "u_M2", "u_M3", "u_M4"}) {
    ASSERT_GE(b.column(c), 0) << c;
    for (std::size_t k = 0; k < std::min(a.rows.size(), b.rows.size()); k += 7) {
      EXPECT_NEAR(b.rows[k][b.column("t")] + a.rows[0][a.column("t")], a.rows[k][a.column("t")], 1e-9);
      const double want = a.rows[k][a.column(c)];
      EXPECT_NEAR(b.rows[k][b.column(c)], want, 1e-6 * (1 + std::fabs(want))) << c << " row " << k;
      ++compared;
    }
  }
  EXPECT_GT(compared, 1000u);
}
