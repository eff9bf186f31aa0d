#ifndef KINCAL_DATA_EXTENSION_KINDS_H_
#define KINCAL_DATA_EXTENSION_KINDS_H_

// Which kind of error model a robot file's extension entry describes, decided
// from its cause and keys (data/robot.h Extension), in one place for the
// reader and the solver.

#include "data/robot.h"

namespace kincal {

// True when `e` is a transmission with Fourier coefficients a1 .. a32,
// b1 .. b32 (any one present): a periodic error over the joint's revolution
// rather than the sine series s1 .. s24 over its travel (lo, hi).
bool IsPeriodicTransmission(const Extension& e);

}  // namespace kincal

#endif  // KINCAL_DATA_EXTENSION_KINDS_H_
