// SPDX-License-Identifier: Apache-2.0
// Mathematical constants of the whole project (C++17 has no std::numbers), in the lowest layer so
// that the container library, the runtime, the baker, the tools, the tests and the benchmarks all
// share one definition.
#pragma once

namespace glintbake {

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kTwoPi = 2.0 * kPi;  // exactly twice kPi: the same double as 2.0 * kPi

}  // namespace glintbake
