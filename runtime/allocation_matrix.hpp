// The believed rotor layout as a matrix (rows total thrust, roll, pitch, yaw; one column per
// rotor: allocation_columns), for code that solves with it or reads its rank. Kept apart from
// closed_loop.hpp, which stays free of Eigen.
#pragma once
#include <Eigen/Dense>

#include "runtime/closed_loop.hpp"

namespace quadgen::runtime {

inline Eigen::MatrixXd allocation_matrix(const ControllerModel& b) {
  const auto columns = allocation_columns(b);
  Eigen::MatrixXd A(4, static_cast<Eigen::Index>(columns.size()));
  for (size_t i = 0; i < columns.size(); ++i)
    for (size_t r = 0; r < 4; ++r) A(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(i)) = columns[i][r];
  return A;
}

}  // namespace quadgen::runtime
