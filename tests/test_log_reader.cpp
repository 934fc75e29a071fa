// Logs read through a mapping into the canonical layout: a PX4 ULog in north-east-down /
// forward-right-down axes, topics at different rates, becomes the model's east-north-up /
// forward-left-up flight. The axes are checked against rotation matrices built here, not
// against the converter's own formula.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <filesystem>
#include <fstream>

#include "runtime/attitude.hpp"
#include "fit/least_squares.hpp"
#include "fit/log_reader.hpp"
#include "fit/read_flight.hpp"
#include "output/joined.hpp"
#include "tests/ulog_writer.hpp"

using namespace quadgen;
using namespace quadgen::test;
namespace fs = std::filesystem;

namespace {

// What fit::FitError `read` throws, or "accepted" where it throws none.
template <class F>
std::string refusal_of(F&& read) {
  try {
    read();
  } catch (const fit::FitError& e) {
    return e.what();
  }
  return "accepted";
}

std::string write_file(const std::string& name, const std::string& bytes) {
  const fs::path p = fs::temp_directory_path() / name;
  std::ofstream(p, std::ios::binary) << bytes;
  return p.string();
}

// A PX4-like log: position and velocity at 50 Hz, attitude at 100 Hz, IMU at 200 Hz,
// motor outputs at 100 Hz, over 2 s. Position and velocity are linear in time (exact under
// linear interpolation); attitude and IMU constant.
const double kQned[4] = {0.8031189202104505, 0.2, -0.3, 0.4743416490252569};  // |q| = 1
const double kGyroFrd[3] = {0.1, 0.2, 0.3}, kAccFrd[3] = {0.5, -0.4, -9.7};

// `parameters`: PX4 parameters logged when logging started ("float NAME" or "int32_t NAME").
std::string px4_log(const std::vector<std::pair<std::string, double>>& parameters = {}) {
  Writer w;
  w.flag_bits();
  for (const auto& [key, value] : parameters)
    w.key_value('P', key, key.rfind("float ", 0) == 0 ? f32(static_cast<float>(value)) : le(static_cast<std::uint32_t>(value), 4));
  w.format("vehicle_local_position:uint64_t timestamp;float x;float y;float z;float vx;float vy;float vz;")
      .format("vehicle_attitude:uint64_t timestamp;float[4] q;")
      .format("sensor_combined:uint64_t timestamp;float[3] gyro_rad;float[3] accelerometer_m_s2;")
      .format("actuator_outputs:uint64_t timestamp;float[4] output;")
      .add(0, 0, "vehicle_local_position")
      .add(0, 1, "vehicle_attitude")
      .add(0, 2, "sensor_combined")
      .add(0, 3, "actuator_outputs");
  const std::uint64_t t0 = 5000000;  // 5 s after boot
  for (int k = 0; k <= 400; ++k) {
    const std::uint64_t t = t0 + 5000 * k;  // 200 Hz
    const double s = (t - t0) * 1e-6;
    std::string imu = le(t, 8);
    for (double g : kGyroFrd) imu += f32(static_cast<float>(g));
    for (double a : kAccFrd) imu += f32(static_cast<float>(a));
    w.data(2, imu);
    if (k % 2 == 0) {
      std::string att = le(t, 8), out = le(t, 8);
      for (double q : kQned) att += f32(static_cast<float>(q));
      for (int i = 0; i < 4; ++i) out += f32(static_cast<float>(1100 + 100 * i + 200 * s));
      w.data(1, att);
      w.data(3, out);
    }
    if (k % 4 == 0)  // north 1 + 2s, east 3 - s, down -1 - 0.5s (climbing)
      w.data(0, le(t, 8) + f32(static_cast<float>(1 + 2 * s)) + f32(static_cast<float>(3 - s)) +
                    f32(static_cast<float>(-1 - 0.5 * s)) + f32(2.0f) + f32(-1.0f) + f32(-0.5f));
  }
  return w.bytes();
}

const char* const kMapping = R"(name: px4_test
frame: ned_frd
columns:
  t:    {source: t, unit: s}
  x:    {source: vehicle_local_position.x, unit: m}
  y:    {source: vehicle_local_position.y, unit: m}
  z:    {source: vehicle_local_position.z, unit: m}
  vx:   {source: vehicle_local_position.vx, unit: m/s}
  vy:   {source: vehicle_local_position.vy, unit: m/s}
  vz:   {source: vehicle_local_position.vz, unit: m/s}
  qw:   {source: "vehicle_attitude.q[0]"}
  qx:   {source: "vehicle_attitude.q[1]"}
  qy:   {source: "vehicle_attitude.q[2]"}
  qz:   {source: "vehicle_attitude.q[3]"}
  p:    {source: "sensor_combined.gyro_rad[0]", unit: rad/s}
  q:    {source: "sensor_combined.gyro_rad[1]", unit: rad/s}
  r:    {source: "sensor_combined.gyro_rad[2]", unit: rad/s}
  ax:   {source: "sensor_combined.accelerometer_m_s2[0]", unit: m/s^2}
  ay:   {source: "sensor_combined.accelerometer_m_s2[1]", unit: m/s^2}
  az:   {source: "sensor_combined.accelerometer_m_s2[2]", unit: m/s^2}
  u_M1: {source: "actuator_outputs.output[0]", scale: 0.001, offset: -1}
)";

}  // namespace

TEST(LogReader, Px4UlogInNedFrdBecomesTheCanonicalFlight) {
  const std::string log = write_file("quadgen_px4.ulg", px4_log());
  const std::string mapping = write_file("quadgen_px4_mapping.yaml", kMapping);
  ASSERT_TRUE(fit::is_ulog(log));
  const runtime::CsvTable t = fit::read_log(log, mapping, 100.0);
  // the span all topics cover (the 50 Hz topic ends last at 2 s), on a 100 Hz grid from 0
  ASSERT_EQ(t.rows.size(), 201u);
  const auto at = [&](size_t row, const char* c) { return t.rows[row][t.column(c)]; };
  // NED world -> ENU: (east, north, up)
  for (size_t k : {0u, 37u, 200u}) {
    const double s = 0.01 * static_cast<double>(k);
    EXPECT_NEAR(at(k, "t"), s, 1e-9);
    EXPECT_NEAR(at(k, "x"), 3 - s, 1e-5);
    EXPECT_NEAR(at(k, "y"), 1 + 2 * s, 1e-5);
    EXPECT_NEAR(at(k, "z"), 1 + 0.5 * s, 1e-5);
    EXPECT_NEAR(at(k, "vx"), -1.0, 1e-6);
    EXPECT_NEAR(at(k, "vy"), 2.0, 1e-6);
    EXPECT_NEAR(at(k, "vz"), 0.5, 1e-6);
    EXPECT_NEAR(at(k, "u_M1"), 0.1 + 0.2 * s, 1e-5);
  }
  // FRD body -> FLU: (x, -y, -z)
  EXPECT_NEAR(at(50, "p"), 0.1, 1e-6);
  EXPECT_NEAR(at(50, "q"), -0.2, 1e-6);
  EXPECT_NEAR(at(50, "r"), -0.3, 1e-6);
  EXPECT_NEAR(at(50, "az"), 9.7, 1e-5);
  EXPECT_NEAR(at(50, "ay"), 0.4, 1e-6);
  EXPECT_NEAR(at(50, "ax"), 0.5, 1e-6);  // forward stays forward (helper-126: unchecked before)
  // attitude: R_enu<-flu = M R_ned<-frd F, M = [[0,1,0],[1,0,0],[0,0,-1]], F = diag(1,-1,-1)
  const double q[4] = {at(50, "qw"), at(50, "qx"), at(50, "qy"), at(50, "qz")};
  const runtime::Rotation got = runtime::rotation_matrix(q), ned = runtime::rotation_matrix(kQned);
  const double M[3][3] = {{0, 1, 0}, {1, 0, 0}, {0, 0, -1}}, F[3] = {1, -1, -1};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double want = 0;
      for (int k = 0; k < 3; ++k) want += M[i][k] * ned.m[k][j] * F[j];
      EXPECT_NEAR(got.m[i][j], want, 1e-6) << i << "," << j;
    }
  EXPECT_GT(q[0], 0.0);
}

// PX4 logs NaN for values not set yet, and topics pause (dropouts): unset samples are left
// out, and a pause stays a gap in the table instead of a line drawn across it. A quaternion
// logged with a sign flip is interpolated as one attitude.
TEST(LogReader, UnsetValuesAreSkippedGapsStayGapsQuaternionSignsAligned) {
  Writer w;
  w.flag_bits().format("a:uint64_t timestamp;float v;").format("q:uint64_t timestamp;float[4] q;");
  w.add(0, 0, "a").add(0, 1, "q");
  for (int k = 0; k <= 200; ++k) {
    const double s = 0.01 * k;
    if (s > 1.0 + 1e-9 && s < 1.5 - 1e-9) continue;  // a 0.5 s pause of both topics
    const std::uint64_t t = 1000000 + 10000 * static_cast<std::uint64_t>(k);
    const float v = (k >= 20 && k < 23) ? std::numeric_limits<float>::quiet_NaN() : static_cast<float>(s);
    w.data(0, le(t, 8) + f32(v));
    const float sign = k % 2 ? -1.0f : 1.0f;  // q and -q alternate
    w.data(1, le(t, 8) + f32(sign * 0.6f) + f32(sign * 0.8f) + f32(0) + f32(0));
  }
  const std::string log = write_file("quadgen_gaps.ulg", w.bytes());
  const std::string mapping = write_file("quadgen_gaps.yaml",
                                         "name: gaps\ncolumns:\n  t: {source: t}\n  x: {source: a.v}\n"
                                         "  qw: {source: \"q.q[0]\"}\n  qx: {source: \"q.q[1]\"}\n"
                                         "  qy: {source: \"q.q[2]\"}\n  qz: {source: \"q.q[3]\"}\n");
  const runtime::CsvTable t = fit::read_log(log, mapping, 200.0);
  bool gap = false;
  for (size_t k = 0; k < t.rows.size(); ++k) {
    const double s = t.rows[k][0], v = t.rows[k][t.column("x")];
    EXPECT_TRUE(std::isfinite(v)) << s;
    EXPECT_NEAR(v, s, 1e-5) << s;  // the NaN samples are bridged by their neighbours
    EXPECT_FALSE(s > 1.0 + 1e-9 && s < 1.5 - 1e-9) << "a row inside the pause at " << s;
    if (k > 0) gap = gap || s - t.rows[k - 1][0] > 0.4;
    // between a sample and its sign-flipped neighbour: still (0.6, 0.8) up to a common sign
    const double qw = t.rows[k][t.column("qw")], qx = t.rows[k][t.column("qx")];
    EXPECT_NEAR(std::hypot(qw, qx), 1.0, 1e-6) << s;
  }
  EXPECT_TRUE(gap);
}

// A roll logged in degrees and mapped as radians is refused at the sample, as logged: the
// table's roll is averaged unwrapped and wrapped into (-pi, pi] again, where 30 "rad" passed
// (hostile-input audit, helper-105). The same roll mapped with `unit: deg` is read.
TEST(LogReader, AMappedRollInDegreesIsRefusedBeforeItIsWrapped) {
  Writer w;
  w.flag_bits().format("att:uint64_t timestamp;float roll;float pitch;");
  w.add(0, 0, "att");
  for (int k = 0; k <= 100; ++k)
    w.data(0, le(1000000 + 10000 * static_cast<std::uint64_t>(k), 8) + f32(static_cast<float>(0.3 * k)) + f32(1.0f));
  const std::string log = write_file("quadgen_roll_degrees.ulg", w.bytes());
  const auto mapping = [](const char* unit) {
    return write_file("quadgen_roll_degrees.yaml", std::string("name: roll\ncolumns:\n  t: {source: t}\n") +
                                                       "  phi: {source: att.roll, unit: " + unit + "}\n" +
                                                       "  theta: {source: att.pitch, unit: " + unit + "}\n");
  };
  std::string said;
  try {
    fit::read_log(log, mapping("rad"), 100.0);
  } catch (const fit::FitError& e) {
    said = e.what();
  }
  EXPECT_EQ(said.rfind(log + " ('att.roll' at t = 1.11 s of the log's clock): phi = 3.3", 0), 0u) << said;
  EXPECT_NE(said.find("angles in degrees?"), std::string::npos) << said;
  const runtime::CsvTable t = fit::read_log(log, mapping("deg"), 100.0);
  EXPECT_NEAR(t.rows[50][t.column("phi")], 15.0 * M_PI / 180, 1e-6);
}

// A topic logged faster than the grid (a motor command at 1 kHz, read at 100 Hz) does not fold
// its fast content into the slow band: each grid value is the topic's mean over the grid
// interval around it (fit/grid_mean.hpp). Read at the grid points alone, the 403 Hz sine
// below came back as a 3 Hz one of its full size.
TEST(LogReader, ATopicFasterThanTheGridFoldsNothingIntoTheSlowBand) {
  Writer w;
  w.flag_bits().format("m:uint64_t timestamp;float u;");
  w.add(0, 0, "m");
  const auto slow = [](double s) { return 0.5 + 0.2 * std::sin(2 * M_PI * 0.3 * s); };
  for (int k = 0; k <= 3000; ++k) {
    const double s = 0.001 * k;
    w.data(0, le(1000000 + 1000 * static_cast<std::uint64_t>(k), 8) + f32(static_cast<float>(slow(s) + 0.2 * std::sin(2 * M_PI * 403 * s))));
  }
  const std::string log = write_file("quadgen_fast_topic.ulg", w.bytes());
  const std::string mapping = write_file("quadgen_fast_topic.yaml", "name: fast\ncolumns:\n  t: {source: t}\n  u_A: {source: m.u}\n");
  const runtime::CsvTable t = fit::read_log(log, mapping, 100.0);
  ASSERT_GT(t.rows.size(), 290u);
  double worst = 0;
  const int u = t.column("u_A"), time = t.column("t");
  for (size_t k = 5; k + 5 < t.rows.size(); ++k) worst = std::max(worst, std::abs(t.rows[k][u] - slow(t.rows[k][time])));
  EXPECT_LT(worst, 0.005);  // 0.2 folded back whole at the grid points alone
}

// A grid window never reaches across a gap: each stretch of a paused topic holds its own
// constant, and every grid value is its stretch's (a window averaged across the pause would
// mix two). The earlier gap test's signal was a line, which reads the same either way (a
// review, helper-92).
TEST(LogReader, AGridWindowStaysWithinItsStretch) {
  Writer w;
  w.flag_bits().format("a:uint64_t timestamp;float v;");
  w.add(0, 0, "a");
  const auto level = [](double s) { return s < 1.0 ? 1.0 : s < 2.0 ? 5.0 : 9.0; };
  for (int k = 0; k <= 3000; ++k) {
    const double s = 0.001 * k;
    if ((s > 0.8 + 1e-9 && s < 1.0 - 1e-9) || (s > 1.7 + 1e-9 && s < 2.0 - 1e-9)) continue;  // two pauses
    w.data(0, le(1000000 + 1000 * static_cast<std::uint64_t>(k), 8) + f32(static_cast<float>(level(s))));
  }
  const std::string log = write_file("quadgen_stretches.ulg", w.bytes());
  const std::string mapping = write_file("quadgen_stretches.yaml", "name: s\ncolumns:\n  t: {source: t}\n  vbat: {source: a.v}\n");
  const runtime::CsvTable t = fit::read_log(log, mapping, 100.0);
  ASSERT_GT(t.rows.size(), 200u);
  const int v = t.column("vbat"), time = t.column("t");
  for (const auto& row : t.rows) EXPECT_NEAR(row[v], level(row[time]), 1e-9) << row[time];
}

TEST(LogReader, MissingTopicsAndFieldsAreNamedWithWhatTheLogHas) {
  const std::string log = write_file("quadgen_px4_missing.ulg", px4_log());
  const auto error = [&](const std::string& mapping_text) {
    try {
      fit::read_log(log, write_file("quadgen_px4_bad.yaml", mapping_text), 100.0);
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  const std::string head = "name: bad\ncolumns:\n  t: {source: t, unit: s}\n";
  EXPECT_NE(error(head + "  x: {source: vehicle_gps_position.lat}\n").find("no topic 'vehicle_gps_position'"),
            std::string::npos);
  EXPECT_NE(error(head + "  x: {source: vehicle_gps_position.lat}\n").find("vehicle_attitude"), std::string::npos);
  EXPECT_NE(error(head + "  x: {source: vehicle_attitude.w}\n").find("fields: timestamp, q[0]"), std::string::npos);
  EXPECT_NE(error("name: bad\nframe: nwu\ncolumns:\n  t: {source: t}\n").find("frame: expected enu_flu"),
            std::string::npos);
  // the bundled PX4 mapping reads, converts axes, and names what this small log lacks
  const std::string px4 = std::string(QUADGEN_SOURCE_DIR) + "/data/mappings/px4.yaml";
  EXPECT_EQ(fit::load_mapping(px4).frame, "ned_frd");
  try {
    fit::read_log(log, px4, 100.0);
    ADD_FAILURE() << "a log without battery_status was accepted";
  } catch (const fit::FitError& e) {
    EXPECT_NE(std::string(e.what()).find("no topic 'battery_status'"), std::string::npos) << e.what();
  }
  // a ULog needs a mapping
  try {
    fit::read_log(log, "", 0);
    ADD_FAILURE() << "a ULog without a mapping was accepted";
  } catch (const fit::FitError& e) {
    EXPECT_NE(std::string(e.what()).find("needs --mapping"), std::string::npos);
  }
}

// What a real PX4 log does that the first fixtures did not (a review, helper-152): the motors
// on the second instance of actuator_outputs (DShot on a board with an IO), named
// topic[k].field; a topic logged at 10 Hz, slower than the grid, said; a battery voltage of
// exactly 0 (PX4's "not known") left out like a NaN; the logger's dropouts said.
TEST(LogReader, AnInstanceIsNamedASlowTopicSaidAnUnknownVoltageLeftOut) {
  Writer w;
  w.flag_bits()
      .format("actuator_outputs:uint64_t timestamp;float[2] output;")
      .format("battery_status:uint64_t timestamp;float voltage_v;");
  w.add(0, 0, "actuator_outputs").add(1, 1, "actuator_outputs").add(0, 2, "battery_status");
  for (int k = 0; k <= 200; ++k) {
    const std::uint64_t t = 1000000 + 10000 * static_cast<std::uint64_t>(k);
    w.data(0, le(t, 8) + f32(1500) + f32(1500));                                 // 100 Hz, not the motors
    if (k % 10 == 0) w.data(1, le(t, 8) + f32(1200 + k) + f32(1200));             // 10 Hz, the motors
    w.data(2, le(t, 8) + f32(k < 50 ? 0.0f : 4.0f));                              // unknown for 0.5 s
    if (k == 100) w.msg('O', le(20, 2));                                          // a 20 ms dropout
  }
  const std::string log = write_file("quadgen_instances.ulg", w.bytes());
  const auto mapped = [&](const std::string& motor_source) {
    return fit::read_log(log,
                         write_file("quadgen_instances.yaml", "name: inst\ncolumns:\n  t: {source: t}\n"
                                                              "  vbat: {source: battery_status.voltage_v}\n"
                                                              "  u_M1: {source: \"" + motor_source +
                                                                  "\", scale: 0.001, offset: -1}\n"),
                         100.0);
  };
  const runtime::CsvTable t = mapped("actuator_outputs[1].output[0]");
  ASSERT_GT(t.rows.size(), 100u);
  for (const auto& row : t.rows) {
    EXPECT_NEAR(row[t.column("vbat")], 4.0, 1e-6) << row[0];  // no 0 V averaged in
    EXPECT_GT(row[t.column("u_M1")], 0.2 - 1e-6) << row[0];   // instance 1's 1200.., not instance 0's 1500
    EXPECT_LT(row[t.column("u_M1")], 0.4 + 1e-6) << row[0];
  }
  const std::string notes = output::joined(t.notes, "\n");
  EXPECT_NE(notes.find("actuator_outputs[1].output[0] logged every 100 ms, slower than the 100 Hz grid"),
            std::string::npos)
      << notes;
  EXPECT_EQ(notes.find("battery_status"), std::string::npos) << notes;  // logged at the grid's rate
  EXPECT_NE(notes.find("etc/logging/logger_topics.txt"), std::string::npos) << notes;  // how PX4 logs it faster
  EXPECT_NE(notes.find("dropped data 1 time (20 ms in all)"), std::string::npos) << notes;
  // Instance 0 is the plain name; an instance the log lacks is named with those it has.
  const runtime::CsvTable first = mapped("actuator_outputs.output[0]");
  EXPECT_NEAR(first.rows.front()[first.column("u_M1")], 0.5, 1e-6);  // instance 0's 1500
  const auto error = [&](const std::string& source) { return refusal_of([&] { mapped(source); }); };
  EXPECT_NE(error("actuator_outputs[2].output[0]")
                .find("no instance 2 of topic 'actuator_outputs' for 'actuator_outputs[2].output[0]' (the log has "
                      "actuator_outputs, actuator_outputs[1]; name one as topic[k].field)"),
            std::string::npos)
      << error("actuator_outputs[2].output[0]");
  EXPECT_NE(error("actuator_outputs[one].output[0]").find("a topic's instance is written topic[k].field"),
            std::string::npos);
  EXPECT_NE(error("actuator_outputs[1.output[0]").find("a topic's instance is written topic[k].field"), std::string::npos)
      << error("actuator_outputs[1.output[0]");
  // "[01]" is not read as instance 1: a number is written without leading zeros.
  EXPECT_NE(error("actuator_outputs[01].output[0]").find("a topic's instance is written topic[k].field"),
            std::string::npos);
  // A battery voltage that is never known: the error says to leave vbat out.
  Writer none;
  none.flag_bits().format("battery_status:uint64_t timestamp;float voltage_v;").add(0, 0, "battery_status");
  for (int k = 0; k <= 20; ++k) none.data(0, le(1000000 + 10000 * static_cast<std::uint64_t>(k), 8) + f32(0.0f));
  const std::string unknown = refusal_of([&] {
    fit::read_log(write_file("quadgen_no_voltage.ulg", none.bytes()),
                  write_file("quadgen_no_voltage.yaml",
                             "name: v\ncolumns:\n  t: {source: t}\n  vbat: {source: battery_status.voltage_v}\n"),
                  100.0);
  });
  EXPECT_NE(unknown.find("(NaN or 0 V, PX4's \"not known\"): a log without a battery voltage is read without it, so "
                         "leave vbat out of the mapping"),
            std::string::npos)
      << unknown;
}

// PX4's actuator_outputs says in noutputs how many channels its driver set; the rest read 0
// (a PWM of 0 us, throttle -1 through the usual mapping), which a mapping must not take for a
// motor's command (a review, helper-152): such samples are left out, and a channel no message
// set is refused with what the log has.
TEST(LogReader, ChannelsBeyondNoutputsAreNotCommands) {
  Writer w;
  w.flag_bits().format("actuator_outputs:uint64_t timestamp;uint32_t noutputs;float[8] output;");
  w.add(0, 0, "actuator_outputs");
  for (int k = 0; k <= 200; ++k) {
    const std::uint64_t t = 1000000 + 10000 * static_cast<std::uint64_t>(k);
    const std::uint32_t channels = k < 50 ? 0 : 4;  // the driver starts after 0.5 s
    std::string m = le(t, 8) + le(channels, 4);
    for (std::uint32_t i = 0; i < 8; ++i) m += f32(i < channels ? 1500.0f : 0.0f);
    w.data(0, m);
  }
  const std::string log = write_file("quadgen_noutputs.ulg", w.bytes());
  const auto mapped = [&](const std::string& channel) {
    return fit::read_log(log,
                         write_file("quadgen_noutputs.yaml", "name: n\ncolumns:\n  t: {source: t}\n  u_M1: {source: "
                                                             "\"actuator_outputs.output[" + channel +
                                                                 "]\", scale: 0.001, offset: -1}\n"),
                         100.0);
  };
  const runtime::CsvTable t = mapped("3");
  ASSERT_GT(t.rows.size(), 100u);
  EXPECT_LT(t.rows.size(), 160u);  // from the driver's start on: 1.5 s of the 2 s
  for (const auto& row : t.rows) EXPECT_NEAR(row[t.column("u_M1")], 0.5, 1e-6) << row[0];  // never the 0 us
  const std::string never_set = refusal_of([&] { mapped("5"); });
  EXPECT_NE(never_set.find("'actuator_outputs.output[5]' is a channel its driver never set: every message of "
                           "'actuator_outputs' has noutputs 4 or fewer (channels 0..3)"),
            std::string::npos)
      << never_set;
}

namespace {

// PX4's quadrotor X as its airframe 4001 sets it (CA_ROTORn_PX/PY forward-right-down, m; KM
// > 0 counter-clockwise seen from above; PWM_MAIN_FUNCn = 100 + motor): motor 1 front-right
// ccw, 2 rear-left ccw, 3 front-left cw, 4 rear-right cw, written here from those rules.
std::map<std::string, double> px4_quad_x() {
  std::map<std::string, double> p{{"CA_ROTOR_COUNT", 4}};
  const double places[4][3] = {{0.15, 0.15, 0.05}, {-0.15, -0.15, 0.05}, {0.15, -0.15, -0.05}, {-0.15, 0.15, -0.05}};
  for (int n = 0; n < 4; ++n) {
    const std::string key = "CA_ROTOR" + std::to_string(n) + "_";
    p[key + "PX"] = places[n][0];
    p[key + "PY"] = places[n][1];
    p[key + "KM"] = places[n][2];
    p["PWM_MAIN_FUNC" + std::to_string(n + 1)] = 101 + n;
  }
  return p;
}

// A mapping of the vehicle's u_M1..u_M4 to these sources.
fit::ColumnMapping motors_from(const std::vector<std::string>& sources) {
  std::string text = "name: motors\ncolumns:\n  t: {source: t}\n";
  for (size_t i = 0; i < sources.size(); ++i)
    text += "  u_M" + std::to_string(i + 1) + ": {source: \"" + sources[i] + "\", scale: 0.001, offset: -1}\n";
  return fit::load_mapping(write_file("quadgen_motors.yaml", text));
}

}  // namespace

// The Crazyflie numbers its motors clockwise from front-right (vehicles/crazyflie21.yaml), PX4
// its quadrotor X otherwise: mapped channel for channel, three of the four u_ columns read a
// motor the log places elsewhere, and the notes say where and which rotor sits there. Mapped
// by place, nothing is said; a spin, a count, two output-function families that disagree and
// actuator_motors are checked as well.
TEST(LoggedRotors, TheLogsMotorPlacesAreComparedWithTheVehicleFile) {
  const Vehicle cf = load_vehicle(std::string(QUADGEN_SOURCE_DIR) + "/vehicles/crazyflie21.yaml");
  const auto notes = [&](const std::map<std::string, double>& p, const std::vector<std::string>& sources) {
    return fit::logged_rotor_notes("f.ulg", p, motors_from(sources), cf);
  };
  const std::vector<std::string> by_channel{"actuator_outputs.output[0]", "actuator_outputs.output[1]",
                                            "actuator_outputs.output[2]", "actuator_outputs.output[3]"};
  const auto wrong = notes(px4_quad_x(), by_channel);
  ASSERT_EQ(wrong.size(), 3u) << output::joined(wrong, "\n");
  EXPECT_EQ(wrong[0].rfind("f.ulg: u_M2 reads actuator_outputs.output[1], PX4's motor 2 (PWM_MAIN_FUNC2 = 102), which "
                           "the log's CA_ROTOR1_PX/PY place rear-left (x -0.15, y 0.15 m, forward-left-up); the vehicle "
                           "file's M2 (", 0), 0u) << wrong[0];
  EXPECT_NE(wrong[0].find(") sits rear-right, its M3 where that motor is"), std::string::npos) << wrong[0];
  EXPECT_NE(wrong[1].find("u_M3 reads actuator_outputs.output[2], PX4's motor 3"), std::string::npos) << wrong[1];
  EXPECT_NE(wrong[1].find("its M4 where that motor is"), std::string::npos) << wrong[1];
  EXPECT_NE(wrong[2].find("its M2 where that motor is"), std::string::npos) << wrong[2];
  // Each u_ column mapped to its own rotor's channel: M2 rear-right is PX4's motor 4, M3
  // rear-left motor 2, M4 front-left motor 3, with their spins.
  const std::vector<std::string> by_place{"actuator_outputs.output[0]", "actuator_outputs.output[3]",
                                          "actuator_outputs.output[1]", "actuator_outputs.output[2]"};
  EXPECT_TRUE(notes(px4_quad_x(), by_place).empty()) << output::joined(notes(px4_quad_x(), by_place), "\n");
  // A spin the other way is said; so is another rotor count.
  auto flipped = px4_quad_x();
  flipped["CA_ROTOR0_KM"] = -0.05;
  const auto spin = notes(flipped, by_place);
  ASSERT_EQ(spin.size(), 1u) << output::joined(spin, "\n");
  EXPECT_NE(spin[0].find("u_M1 reads actuator_outputs.output[0], PX4's motor 1 (PWM_MAIN_FUNC1 = 101), which the log's "
                         "CA_ROTOR0_KM (-0.05) spins clockwise seen from above; the vehicle file's M1 ("),
            std::string::npos)
      << spin[0];
  EXPECT_NE(spin[0].find(") spins counter-clockwise"), std::string::npos) << spin[0];
  auto six = px4_quad_x();
  six["CA_ROTOR_COUNT"] = 6;
  const auto counted = notes(six, by_place);
  ASSERT_EQ(counted.size(), 1u) << output::joined(counted, "\n");
  EXPECT_NE(counted[0].find("the log's CA_ROTOR_COUNT is 6"), std::string::npos) << counted[0];
  EXPECT_NE(counted[0].find("has 4 rotors"), std::string::npos) << counted[0];
  // Two families naming other motors for channel 1 (a board with an IO and UAVCAN ESCs): which
  // driver logged the instance the log does not say, so u_M2 is not judged.
  auto two_families = px4_quad_x();
  two_families["UAVCAN_EC_FUNC2"] = 103;
  EXPECT_EQ(notes(two_families, by_channel).size(), 2u);
  // actuator_motors.control[k] is motor k + 1, whatever the output functions.
  auto motors_topic = by_place;
  motors_topic[1] = "actuator_motors.control[3]";
  EXPECT_TRUE(notes(px4_quad_x(), motors_topic).empty());
  motors_topic[1] = "actuator_motors.control[1]";  // motor 2, rear-left: not M2's place
  EXPECT_EQ(notes(px4_quad_x(), motors_topic).size(), 1u);
  // A channel whose function is no motor, and a motor beyond the count, are said.
  auto servo = px4_quad_x();
  servo["PWM_MAIN_FUNC2"] = 0;  // disabled
  const auto no_motor = notes(servo, by_place);
  ASSERT_EQ(no_motor.size(), 1u) << output::joined(no_motor, "\n");
  EXPECT_EQ(no_motor[0], "f.ulg: u_M3 reads actuator_outputs.output[1], a channel whose output function is no motor "
                         "(PWM_MAIN_FUNC2 = 0; 101..112 are motors 1..12): the channel that drives this rotor is the one "
                         "whose function is its motor");
  auto fifth = px4_quad_x();
  fifth["PWM_MAIN_FUNC2"] = 105;
  const auto beyond = notes(fifth, by_place);
  ASSERT_EQ(beyond.size(), 1u) << output::joined(beyond, "\n");
  EXPECT_NE(beyond[0].find("u_M3 reads actuator_outputs.output[1], PX4's motor 5 (PWM_MAIN_FUNC2 = 105), but the log's "
                           "CA_ROTOR_COUNT is 4"),
            std::string::npos)
      << beyond[0];
  // A motor whose place is PX4's default (0, 0) is not judged, and moves no other's direction.
  auto unset = px4_quad_x();
  unset["CA_ROTOR1_PX"] = unset["CA_ROTOR1_PY"] = 0;
  const auto two = notes(unset, by_channel);
  ASSERT_EQ(two.size(), 2u) << output::joined(two, "\n");
  EXPECT_NE(two[0].find("u_M3 reads"), std::string::npos) << two[0];
  EXPECT_NE(two[1].find("u_M4 reads"), std::string::npos) << two[1];
  // Without the parameters (a CSV, a uSD log, PX4 before v1.14) nothing is judged.
  EXPECT_TRUE(notes({}, by_channel).empty());
}

// The parameters reach the check from a ULog through the reading of a flight.
TEST(LoggedRotors, AUlogsParametersReachTheFlightsNotes) {
  std::vector<std::pair<std::string, double>> logged;
  for (const auto& [name, value] : px4_quad_x())
    logged.push_back({(name == "CA_ROTOR_COUNT" || name.rfind("PWM", 0) == 0 ? "int32_t " : "float ") + name, value});
  const std::string log = write_file("quadgen_px4_params.ulg", px4_log(logged));
  std::string mapping = kMapping;
  mapping += "  u_M2: {source: \"actuator_outputs.output[1]\", scale: 0.001, offset: -1}\n"
             "  u_M3: {source: \"actuator_outputs.output[2]\", scale: 0.001, offset: -1}\n"
             "  u_M4: {source: \"actuator_outputs.output[3]\", scale: 0.001, offset: -1}\n";
  const Vehicle cf = load_vehicle(std::string(QUADGEN_SOURCE_DIR) + "/vehicles/crazyflie21.yaml");
  const fit::Flight f = fit::read_flight(log, write_file("quadgen_px4_params.yaml", mapping), 100.0, cf);
  int placed = 0;
  for (const auto& note : f.notes) placed += note.find("where that motor is") != std::string::npos ? 1 : 0;
  EXPECT_EQ(placed, 3) << output::joined(f.notes, "\n");
}

// A value is placed at the time it was measured, not published (a review, helper-152): PX4's
// estimates carry the sensor's `timestamp_sample` (here 4 ms before publication), and
// sensor_combined its accelerometer's offset from the gyro's time (`accelerometer_timestamp_
// relative`, here -2.5 ms; INT32_MAX where not valid). Each signal is 10/s times its true
// time, so on the grid all three agree; joined on publication times they were 0.04 and 0.025
// apart.
TEST(LogReader, ValuesArePlacedAtTheirSensorsTimeNotTheirPublication) {
  Writer w;
  w.flag_bits()
      .format("imu:uint64_t timestamp;float gyro;int32_t accelerometer_timestamp_relative;float accelerometer_m_s2;")
      .format("att:uint64_t timestamp;uint64_t timestamp_sample;float v;")
      .format("actuator_motors:uint64_t timestamp;uint64_t timestamp_sample;float control;")
      .add(0, 0, "imu")
      .add(0, 1, "att")
      .add(0, 2, "actuator_motors");
  const auto seconds = [](double us) { return (us - 1e6) * 1e-6; };
  for (int k = 0; k <= 400; ++k) {
    const std::uint64_t t = 1000000 + 5000 * static_cast<std::uint64_t>(k);
    const bool invalid = k == 200;  // an accelerometer time not valid: its sample is left out
    const std::int32_t relative = invalid ? 2147483647 : -2500;
    w.data(0, le(t, 8) + f32(static_cast<float>(10 * seconds(t))) + le(static_cast<std::uint32_t>(relative), 4) +
                  f32(invalid ? 999.0f : static_cast<float>(10 * seconds(t - 2500.0))));
    w.data(1, le(t, 8) + le(t - 4000, 8) + f32(static_cast<float>(10 * seconds(t - 4000.0))));
    // a command acts when published; its timestamp_sample is the gyro sample it came from
    w.data(2, le(t, 8) + le(t - 3000, 8) + f32(static_cast<float>(10 * seconds(t))));
  }
  const runtime::CsvTable table =
      fit::read_log(write_file("quadgen_sample_times.ulg", w.bytes()),
                    write_file("quadgen_sample_times.yaml", "name: s\ncolumns:\n  t: {source: t}\n"
                                                            "  p: {source: imu.gyro}\n  q: {source: att.v}\n"
                                                            "  ax: {source: imu.accelerometer_m_s2}\n"
                                                            "  r: {source: actuator_motors.control}\n"),
                    100.0);
  ASSERT_GT(table.rows.size(), 150u);
  const int p = table.column("p"), q = table.column("q"), ax = table.column("ax"), r = table.column("r");
  for (size_t k = 2; k + 2 < table.rows.size(); ++k) {
    const auto& row = table.rows[k];
    EXPECT_NEAR(row[static_cast<size_t>(q)], row[static_cast<size_t>(p)], 1e-4) << row[0];
    EXPECT_NEAR(row[static_cast<size_t>(ax)], row[static_cast<size_t>(p)], 1e-4) << row[0];
    EXPECT_NEAR(row[static_cast<size_t>(r)], row[static_cast<size_t>(p)], 1e-4) << row[0];
  }
}

// PX4's estimator resets its states (a yaw alignment at take-off, a GPS glitch) and counts each
// reset in the topic: the value jumps there. Read as motion the jump would be a spike of
// acceleration; it is a gap instead, said in a note, and no grid value mixes the two sides.
// The hole is wider than what reads across a short one (0.1 s: rollouts, multiple shooting;
// the derivatives' window), also for a signal logged faster than the grid (250 Hz here: a
// grid point between the two samples need not exist; helper-156). A heading reset is the
// attitude's, not the position's.
TEST(LogReader, AnEstimatorResetIsAGapNotAJump) {
  Writer w;
  w.flag_bits().format(
      "pos:uint64_t timestamp;float x;uint8_t xy_reset_counter;uint8_t z_reset_counter;uint8_t heading_reset_counter;");
  w.add(0, 0, "pos");
  const auto x_at = [](int k) { return 1.0 + 0.008 * k + (k > 250 ? 5.0 : 0.0); };  // 2 m/s, 5 m jump after 1 s
  for (int k = 0; k <= 500; ++k)  // 250 Hz, 2 s; the heading reset at 1.5 s
    w.data(0, le(1000000 + 4000 * static_cast<std::uint64_t>(k), 8) + f32(static_cast<float>(x_at(k))) +
                  le(k > 250 ? 1 : 0, 1) + le(3, 1) + le(k > 375 ? 1 : 0, 1));
  const runtime::CsvTable t =
      fit::read_log(write_file("quadgen_reset.ulg", w.bytes()),
                    write_file("quadgen_reset.yaml", "name: r\ncolumns:\n  t: {source: t}\n  x: {source: pos.x}\n"), 100.0);
  const int x = t.column("x");
  size_t after = 0;
  double hole = 0;
  for (size_t r = 0; r < t.rows.size(); ++r) {
    const double at = t.rows[r][0], side = at > 1.002 ? 5.0 : 0.0;
    // within 0.011 m of the line on its side: a grid value beside the gap is its stretch's
    // half-interval mean; one mixing the two sides would be metres off
    EXPECT_NEAR(t.rows[r][static_cast<size_t>(x)], 1.0 + 2 * at + side, 0.011) << at;
    after += at > 1.002 ? 1 : 0;
    if (r > 0) {
      const double step = at - t.rows[r - 1][0];
      hole = std::max(hole, step);
      if (step > 0.015) EXPECT_TRUE(t.rows[r - 1][0] < 1.0 && at > 1.004) << at;  // the one hole: at the reset
    }
  }
  EXPECT_GT(after, 70u);
  EXPECT_GT(hole, 0.2);  // outlasts the 0.1 s across which rollouts and multiple shooting read
  const std::string notes = output::joined(t.notes, "\n");
  EXPECT_NE(notes.find("quadgen_reset.ulg: the estimate in pos was reset 1 time (xy_reset_counter changed): its signals "
                       "have a gap at each"),
            std::string::npos)
      << notes;
}

// PX4 publishes its landed flag when it changes and once a second besides: the flag holds its
// value between samples (drawn as a straight line it would cross 0.5 up to half a second early),
// and a flag logged at 1 Hz is no slow topic to be said.
TEST(LogReader, TheLandedFlagHoldsItsValueBetweenSamples) {
  Writer w;
  w.flag_bits()
      .format("imu:uint64_t timestamp;float gyro;")
      .format("vehicle_land_detected:uint64_t timestamp;bool landed;")
      .add(0, 0, "imu")
      .add(0, 1, "vehicle_land_detected");
  for (int k = 0; k <= 400; ++k) {
    const std::uint64_t t = 1000000 + 10000 * static_cast<std::uint64_t>(k);  // 100 Hz, 4 s
    w.data(0, le(t, 8) + f32(0.0f));
    if (k % 100 == 0 || k == 270) w.data(1, le(t, 8) + le(k < 270 ? 1 : 0, 1));  // take-off at 2.7 s
  }
  const runtime::CsvTable t =
      fit::read_log(write_file("quadgen_landed.ulg", w.bytes()),
                    write_file("quadgen_landed.yaml", "name: l\ncolumns:\n  t: {source: t}\n  p: {source: imu.gyro}\n"
                                                      "  landed: {source: vehicle_land_detected.landed}\n"),
                    100.0);
  const int landed = t.column("landed");
  for (const auto& row : t.rows) {
    const double at = row[0], flag = row[static_cast<size_t>(landed)];
    if (at < 2.69) EXPECT_NEAR(flag, 1.0, 1e-9) << at;  // straight lines from 2.0 s would fall below 0.5 at 2.35 s
    if (at > 2.71) EXPECT_NEAR(flag, 0.0, 1e-9) << at;
  }
  EXPECT_TRUE(t.notes.empty()) << output::joined(t.notes, "\n");
}

// A hexacopter's rotors 60 degrees apart, the log's airframe written from the vehicle file
// itself (forward-left-up to forward-right-down, spin to KM's sign): in the file's order
// nothing is said; two neighbours swapped in the log, each column names the other rotor.
TEST(LoggedRotors, AHexacopterSwappedPairIsNamed) {
  const Vehicle hexa = load_vehicle(std::string(QUADGEN_SOURCE_DIR) + "/vehicles/hexa_plus.yaml");
  ASSERT_EQ(hexa.rotors.size(), 6u);
  std::map<std::string, double> p{{"CA_ROTOR_COUNT", 6}};
  std::string mapping = "name: hexa\ncolumns:\n  t: {source: t}\n";
  for (int n = 0; n < 6; ++n) {
    const Rotor& r = hexa.rotors[static_cast<size_t>(n)];
    const std::string key = "CA_ROTOR" + std::to_string(n) + "_";
    p[key + "PX"] = r.position[0];
    p[key + "PY"] = -r.position[1];
    p[key + "KM"] = spin_sign(r) * 0.05;
    p["PWM_MAIN_FUNC" + std::to_string(n + 1)] = 101 + n;
    mapping += "  u_" + r.name + ": {source: \"actuator_outputs.output[" + std::to_string(n) + "]\", scale: 0.001, offset: -1}\n";
  }
  const fit::ColumnMapping m = fit::load_mapping(write_file("quadgen_hexa.yaml", mapping));
  EXPECT_TRUE(fit::logged_rotor_notes("h.ulg", p, m, hexa).empty());
  std::swap(p["PWM_MAIN_FUNC2"], p["PWM_MAIN_FUNC3"]);  // channel 1 drives motor 3, channel 2 motor 2
  const auto swapped = fit::logged_rotor_notes("h.ulg", p, m, hexa);
  ASSERT_EQ(swapped.size(), 2u) << output::joined(swapped, "\n");
  EXPECT_NE(swapped[0].find("u_R2 reads actuator_outputs.output[1], PX4's motor 3"), std::string::npos) << swapped[0];
  EXPECT_NE(swapped[0].find("its R3 where that motor is"), std::string::npos) << swapped[0];
  EXPECT_NE(swapped[1].find("its R2 where that motor is"), std::string::npos) << swapped[1];
}
