// Crazyflie micro-SD card deck logs (the "usdlog" binary format the Crazyflie firmware's
// usddeck driver writes; Bitcraze documents it with the deck and decodes it with
// tools/usdlog/cfusdlog.py in crazyflie-firmware). Layout, little-endian, no padding:
//
//   0xBC, uint16 version (1 or 2), uint16 number of event types,
//   per event type: uint16 id (0xFFFF: fixed-frequency logging), name '\0',
//                   uint16 number of variables, each "name(T)\0" with T a type code
//                   (B b H h I i f e: uint8 int8 uint16 int16 uint32 int32 float fp16),
//   records: uint16 event id, timestamp (version 2: uint64 microseconds; version 1: uint32
//            milliseconds), the variables' values packed in header order,
//   uint32 CRC-32 (zlib's) of every byte before it, written when logging stops cleanly.
//
// Each event type becomes a LogTopic named after the event ("fixedFrequency" for the fixed-
// frequency data), with `timestamp` in microseconds first and the variables as logged
// ("acc.x", "motor.m1"): a mapping names a signal "fixedFrequency.acc.x".
//
// Logs come from users and from cards pulled mid-flight, so the reader trusts no count in them.
// Policies:
// - A file whose last four bytes are the CRC of the rest is complete: its records must fill
//   it exactly. Without a matching CRC (power cut, card pulled) the records run to the end of
//   the file; a record cut off there is dropped, everything before it kept, and
//   UsdLog::crc_valid / truncated say so.
// - A record of an event type the header does not define, a header that breaks the layout
//   (unknown type code, a name that is no log name, more than kUsdMaxVariables variables,
//   two event types with one id or name) throws LogError "path: byte N: cause".
// - Memory grows with the file: a record of k variables takes k + 1 doubles, at most about
//   ten times the bytes it had in the file.
#pragma once
#include <cstdint>
#include <string>

#include "runtime/flight_log.hpp"  // LogError
#include "runtime/topic_log.hpp"

namespace quadgen::runtime {

constexpr unsigned kUsdMaxVariables = 256;  // the firmware writes at most 20 per event
constexpr std::size_t kUsdMaxName = 255;
constexpr unsigned kUsdFixedFrequencyId = 0xFFFF;

struct UsdLog : TopicLog {  // path, topics (one per event type, in header order), find()
  int version = 0;
  bool crc_valid = false;          // the file ends in the CRC of its contents
  bool truncated = false;          // a record cut off by the end of the file was dropped
  std::uint64_t truncated_at = 0;  // its byte offset
};

// Whether the file starts like a uSD log: 0xBC and a version this reader knows.
bool is_usd_log(const std::string& path);
// A regular file of at most max_input_bytes(), read into memory as a whole.
UsdLog read_usd_log(const std::string& path);
// `name` is the file name used in error messages.
UsdLog parse_usd_log(const std::string& bytes, const std::string& name);
// zlib's CRC-32 (reflected polynomial 0xEDB88320), the checksum at the end of a uSD log.
std::uint32_t crc32(const std::string& bytes, std::size_t size);

}  // namespace quadgen::runtime
