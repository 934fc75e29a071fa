// Decimal numbers from the vehicle file as exact GiNaC rationals, so that derived
// expressions do not depend on floating-point rounding and print deterministically.
#pragma once
#include <ginac/ginac.h>

namespace quadgen {
GiNaC::numeric exact(double v);
}
