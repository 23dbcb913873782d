#pragma once
// the short form numbers take in messages ("got 0.2; expected [0.5, 20] m").

#include <string>

namespace penumbra {

/// `v` as printf's "%g" writes it: 6 significant digits, trailing zeros dropped, an exponent
/// below 1e-4 or from 1e6 on ("1e-05"), "inf", "-inf", "nan".
std::string FormatG(double v);

}  // namespace penumbra
