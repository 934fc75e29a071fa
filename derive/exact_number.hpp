// Decimal numbers from the vehicle file as exact GiNaC rationals, so that derived
// expressions do not depend on floating-point rounding and print deterministically.
#pragma once
#include <ginac/ginac.h>

#include <string>

namespace quadgen {
GiNaC::numeric exact(double v);
// The shortest decimal text that reads back as the same double (a bound as the file wrote
// it; a generated header's constants).
std::string shortest_text(double v);
}
