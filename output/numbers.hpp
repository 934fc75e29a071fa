// Numbers in sentences for people (the diagnosis' reasons, what limits a prediction): one
// format everywhere, so that the same value reads the same in the console, the report and
// diagnosis.json's reasons.
#pragma once
#include <string>

namespace quadgen::output {

// Three significant digits ("0.0524", "1.32e-06", "208").
std::string short_number(double v);
// Six significant digits ("0.265851", "1.7e+308"): where a reader adds numbers up by eye (a
// weight beside the thrusts that carry it), and never hundreds of digits.
std::string six_digits(double v);
// Every digit a double holds (17 significant): where a value differs from the one it is
// compared with only beyond six ("-1.0000000000000002" below a bound of -1).
std::string full_number(double v);

}  // namespace quadgen::output
