// Functions the model needs beyond GiNaC's built-ins, with derivatives that stay
// finite everywhere: d|x|/dx = sign(x), d sign(x)/dx = 0. GiNaC's own abs()
// differentiates to x/|x|, which is 0/0 at rest, exactly where a hovering vehicle is.
#pragma once
#include <ginac/ginac.h>

namespace quadgen {
DECLARE_FUNCTION_1P(abs_value)
DECLARE_FUNCTION_1P(sign_of)
}  // namespace quadgen
