#include "output/numbers.hpp"

#include <sstream>

namespace quadgen::output {

std::string short_number(double v) {
  std::ostringstream os;
  os.precision(3);
  os << v;
  return os.str();
}

std::string six_digits(double v) {
  std::ostringstream os;
  os.precision(6);
  os << v;
  return os.str();
}

std::string full_number(double v) {
  std::ostringstream os;
  os.precision(17);
  os << v;
  return os.str();
}

}  // namespace quadgen::output
