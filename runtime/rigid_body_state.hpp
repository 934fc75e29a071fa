// Where the rigid body sits in every derived model's state vector. derive/dynamics.cpp
// declares these thirteen states first and in this order for every vehicle; effects append
// theirs after them (motor_lag: one rotor speed per rotor). Runtime code that reads a pose
// out of a state vector uses these offsets rather than bare numbers
// (`Model.RigidBodyStatesComeFirstInTheirOrder` checks the order against a derived model).
#pragma once
#include <array>

#include "runtime/attitude.hpp"

namespace quadgen::runtime::rigid_body {

inline constexpr int kPosition = 0;    // x, y, z [m], world frame, z up
inline constexpr int kVelocity = 3;    // vx, vy, vz [m/s], world frame
inline constexpr int kAttitude = 6;    // qw, qx, qy, qz [1], body -> world, scalar first
inline constexpr int kBodyRate = 10;   // p, q, r [rad/s], body frame
inline constexpr int kNumStates = 13;  // the first state an effect adds

// The states' names, in order (also the canonical flight-log columns of a pose).
inline constexpr const char* kStateNames[kNumStates] = {"x",  "y",  "z",  "vx", "vy", "vz", "qw",
                                                        "qx", "qy", "qz", "p",  "q",  "r"};

// The derivatives an equation-error fit compares with the model's, its residual's six
// channels as --channels, fit.json and a term found beyond the catalogue name them: the
// acceleration, then the angular acceleration (the gyro's derivative). The acceleration is the
// accelerometer's specific force in body axes or the differentiated velocity in world axes:
// fit calls both ax, ay, az; a diagnosis tells the world ones apart by their own names.
inline constexpr const char* kResidualChannels[6] = {"ax", "ay", "az", "pdot", "qdot", "rdot"};
inline constexpr const char* kWorldAccelerationChannels[3] = {"ax_world", "ay_world", "az_world"};
inline constexpr const char* kResidualChannelUnits[6] = {"m/s^2", "m/s^2", "m/s^2", "rad/s^2", "rad/s^2", "rad/s^2"};

// The velocity in body axes, R^T v, of a state vector.
inline std::array<double, 3> body_velocity(const double* x) {
  const Rotation R = rotation_matrix(&x[kAttitude]);
  const double* v = &x[kVelocity];
  std::array<double, 3> b{};
  for (int a = 0; a < 3; ++a) b[a] = R.m[0][a] * v[0] + R.m[1][a] * v[1] + R.m[2][a] * v[2];
  return b;
}

// The Z-Y-X Euler angles (roll, pitch, yaw) of a state vector's attitude [rad].
inline std::array<double, 3> euler_angles(const double* x) {
  const double* q = &x[kAttitude];
  return euler_zyx(q[0], q[1], q[2], q[3]);
}

// The heading (Z-Y-X yaw) of a state vector [rad].
inline double heading(const double* x) { return euler_angles(x)[2]; }

}  // namespace quadgen::runtime::rigid_body
